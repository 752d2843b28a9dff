//! [`ConditionalParts`]: the four sections of a conditional blob (kind 3), owned,
//! and their encoding through [`nuld_core::blob::write`].

use crate::pointset::AlignedBytes;
use crate::sphere::brdf_prior::BrdfPrior;
use crate::sphere::EnvmapTree;
use anyhow::{bail, Context, Result};
use nuld_core::blob::{encoded_len, write, BlobKind, Metadata};
use nuld_core::conditional::{
    check_metallic_nodes, metal_sections, metallic_section, sections, ConditionalInfo,
};
use std::path::Path;
use std::sync::Arc;

/// Everything a conditional blob holds besides its metadata (layouts in
/// `core/FORMAT.md` and [`nuld_core::conditional`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ConditionalParts {
    /// Counts, grids, condition ranges and the network's architecture.
    pub info: ConditionalInfo,
    /// The network's parameters as f16 bits ([`nuld_core::network`] order).
    pub params: Vec<u16>,
    /// The point table: `x | y << 16` u16 unorm codes, `[node][instance][index]`;
    /// with a metallic axis one such layer per metallic node.
    pub table: Vec<u32>,
    /// The weight table, one `f32` per weight-grid node, axis 0 fastest; for
    /// [`nuld_core::conditional::PointWarp::BrdfMixture`] followed by the lobe
    /// probabilities on the same nodes.
    pub weights: Vec<f32>,
    /// The prior of a sampler that warps through one, written as its sections
    /// after the four above.
    pub prior: Option<Prior>,
    /// A BRDF sampler's metal points (on a prior with the metal layer), written
    /// last.
    pub metal: Option<MetalParts>,
    /// The metallic axis of a BRDF sampler's shared network and point table
    /// ([`nuld_core::conditional::metallic_axis`]), written after everything
    /// else; empty for none.
    pub metallic_nodes: Vec<f32>,
}

/// The learned part of a BRDF prior's metal layer
/// ([`nuld_core::conditional::metal_sections`]): a network of the sampler's
/// shape and its point table, which a query at metallic 1 reads.
#[derive(Clone, Debug, PartialEq)]
pub struct MetalParts {
    /// The metal network's parameters as f16 bits.
    pub params: Vec<u16>,
    /// Its point table, laid out as [`ConditionalParts::table`].
    pub table: Vec<u32>,
}

/// The tables of a sampler's prior.
#[derive(Clone, Debug, PartialEq)]
pub enum Prior {
    /// An environment sampler's tree
    /// ([`nuld_core::conditional::PointWarp::EnvmapTree`], three sections).
    Envmap(Arc<EnvmapTree>),
    /// A BRDF sampler's tabulated prior
    /// ([`nuld_core::conditional::PointWarp::BrdfTable`], five sections).
    Brdf(Arc<BrdfPrior>),
}

impl ConditionalParts {
    /// Encodes the parts as a blob. Fails if a length disagrees with the counts of
    /// `info` (the runtime would reject the blob).
    pub fn to_blob(&self, meta: &Metadata<'_>) -> Result<AlignedBytes> {
        let info = &self.info;
        let shape = info
            .shape()
            .context("conditional info describes no valid network")?;
        if self.params.len() != shape.param_len() {
            bail!(
                "{} network parameters, the shape calls for {}",
                self.params.len(),
                shape.param_len()
            );
        }
        if !self.metallic_nodes.is_empty() {
            check_metallic_nodes(&self.metallic_nodes)
                .map_err(|e| anyhow::anyhow!("metallic axis {:?}: {e:?}", self.metallic_nodes))?;
        }
        let layers = self.metallic_nodes.len().max(1) as u64;
        let table_len = info.point_table_len().map(|len| len * layers);
        if Some(self.table.len() as u64) != table_len {
            bail!(
                "point table has {} entries, the counts call for {:?}",
                self.table.len(),
                table_len
            );
        }
        let weight_len = info.weight_table_len() * info.weight_tables();
        if self.weights.len() as u64 != weight_len {
            bail!(
                "weight table has {} entries, the grid calls for {}",
                self.weights.len(),
                weight_len
            );
        }
        let meta_bytes = postcard::to_allocvec(meta).context("cannot encode metadata")?;
        let mut sections = sections(info, &self.params, &self.table, &self.weights).to_vec();
        let tree_info = match &self.prior {
            Some(Prior::Envmap(tree)) => Some(tree.info()),
            _ => None,
        };
        let brdf_info = match &self.prior {
            Some(Prior::Brdf(prior)) => Some(prior.info()),
            _ => None,
        };
        match (&self.prior, &tree_info, &brdf_info) {
            (Some(Prior::Envmap(tree)), Some(info), _) => sections.extend(tree.sections(info)),
            (Some(Prior::Brdf(prior)), _, Some(info)) => sections.extend(prior.sections(info)),
            _ => {}
        }
        if let Some(metal) = &self.metal {
            let layer_len = self.table.len() / layers as usize;
            if metal.params.len() != self.params.len() || metal.table.len() != layer_len {
                bail!(
                    "metal points have {} parameters and {} table entries, the sampler's own {} and {}",
                    metal.params.len(),
                    metal.table.len(),
                    self.params.len(),
                    layer_len
                );
            }
            sections.extend(metal_sections(&metal.params, &metal.table));
        }
        if !self.metallic_nodes.is_empty() {
            sections.push(metallic_section(&self.metallic_nodes));
        }
        let mut out = AlignedBytes::zeroed(encoded_len(&meta_bytes, &sections));
        write(
            out.as_mut_slice(),
            BlobKind::Conditional,
            &meta_bytes,
            &sections,
        )?;
        Ok(out)
    }

    /// Writes the blob to `path` atomically (nothing half-written on failure).
    pub fn write_blob(&self, path: &Path, meta: &Metadata<'_>) -> Result<()> {
        crate::output::write_atomic(path, self.to_blob(meta)?.as_slice())
    }
}
