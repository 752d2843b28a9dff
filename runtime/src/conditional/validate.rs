//! Validation of a conditional blob's sections against each other, once, in
//! [`crate::Blob::parse`]: each failed check is its own [`ConditionalError`].

use super::{ConditionalSampler, MetalPoints, NetworkParams};
use crate::section::{record, typed_section};
use nuld_core::blob::{BlobError, ConditionalError, Domain, Layout, SectionTag};
use nuld_core::brdf_prior::{has_metal_layer, BrdfPrior, BrdfPriorInfo};
use nuld_core::conditional::{
    check_metallic_nodes, ConditionalInfo, ConditionalTarget, MetallicNodesError, PointWarp,
};
use nuld_core::envmap_tree::{
    corner_len, detail_index_len, node_count, top_len, EnvmapTree, NodeRecord, TreeInfo,
    LEGACY_TOP_LEVELS, MAX_TOP_LEVELS, MAX_TREE_LEVELS,
};
use nuld_core::marginal2d::Marginal2DError;
use nuld_core::network::{Activation, OffsetHash};
use nuld_core::quadtree::QuadtreeError;
use nuld_core::quantize::f16_is_finite;

impl<'a> ConditionalSampler<'a> {
    /// Validates the four sections of a conditional blob against each other (the
    /// checks of `core/FORMAT.md`, one [`BlobError`] variant each) and returns the
    /// sampler. Called by [`crate::Blob::parse`], so every sampler holds:
    /// `n, instances >= 1`; a sphere or hemisphere domain; a known target; grids of
    /// at least 2 x 2 nodes; finite condition ranges with `min < max`; a valid
    /// network shape; exactly `param_len` finite f16 parameters,
    /// `grid[0] grid[1] instances n` table entries, and `weight_grid[0]
    /// weight_grid[1]` finite, non-negative weights; metal points, if any, on a
    /// BRDF prior with the metal layer, as long as their shared twins, every
    /// parameter finite.
    pub(crate) fn validate(layout: &Layout<'a>) -> Result<Self, BlobError> {
        let sampler = Self::view(layout)?;
        sampler.check_values()?;
        if sampler.brdf_prior.is_some() {
            brdf_prior(layout, true)?;
        }
        Ok(sampler)
    }

    /// The sampler over a layout whose values [`Self::validate`] has checked once:
    /// re-checks the counts and section sizes (`O(1)`), not every value.
    pub(crate) fn view(layout: &Layout<'a>) -> Result<Self, BlobError> {
        let info: ConditionalInfo =
            record(layout, SectionTag::ConditionalInfo, |got, expected| {
                ConditionalError::InfoSize { got, expected }
            })?;
        if info.n == 0 {
            return fail(ConditionalError::NoPoints);
        }
        if info.instances == 0 {
            return fail(ConditionalError::NoInstances);
        }
        let domain = match Domain::from_code(info.domain) {
            Some(d @ (Domain::Sphere | Domain::Hemisphere)) => d,
            _ => return fail(ConditionalError::Domain(info.domain)),
        };
        let Some(target) = ConditionalTarget::from_code(info.target) else {
            return fail(ConditionalError::UnknownTarget(info.target));
        };
        if domain != target.domain() {
            return fail(ConditionalError::Domain(info.domain));
        }
        let warp = match info.point_warp() {
            Some(PointWarp::BrdfMixture)
                if !(target == ConditionalTarget::GltfBrdf && domain == Domain::Hemisphere) =>
            {
                return fail(ConditionalError::UnknownPointWarp(info.warp))
            }
            Some(PointWarp::BrdfTable)
                if !(target == ConditionalTarget::GltfBrdf && domain == Domain::Hemisphere) =>
            {
                return fail(ConditionalError::UnknownPointWarp(info.warp))
            }
            Some(PointWarp::EnvmapTree) if target != ConditionalTarget::EnvmapNormal => {
                return fail(ConditionalError::UnknownPointWarp(info.warp))
            }
            Some(w) if target == ConditionalTarget::EnvmapNormal && w != PointWarp::EnvmapTree => {
                return fail(ConditionalError::EnvmapWithoutPrior)
            }
            Some(w) => w,
            None => return fail(ConditionalError::UnknownPointWarp(info.warp)),
        };
        type GridError = fn(u32, u32) -> ConditionalError;
        let grids: [([u32; 2], GridError); 2] = [
            (info.grid, |axis, nodes| ConditionalError::Grid {
                axis,
                nodes,
            }),
            (info.weight_grid, |axis, nodes| {
                ConditionalError::WeightGrid { axis, nodes }
            }),
        ];
        for (grid, error) in grids {
            for (axis, &nodes) in (0u32..).zip(&grid) {
                if nodes < 2 {
                    return fail(error(axis, nodes));
                }
            }
        }
        for axis in 0..2 {
            let (lo, hi) = (info.cond_min[axis], info.cond_max[axis]);
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return fail(ConditionalError::Range {
                    axis: axis as u32,
                    min_bits: lo.to_bits(),
                    max_bits: hi.to_bits(),
                });
            }
        }
        if Activation::from_code(info.activation).is_none() {
            return fail(ConditionalError::UnknownActivation(info.activation));
        }
        if OffsetHash::from_code(info.offset_hash).is_none() {
            return fail(ConditionalError::UnknownOffsetHash(info.offset_hash));
        }
        let shape = info
            .shape_without_slots()
            .ok_or(ConditionalError::NetworkWidths(info.hidden))?
            .with_instance_slots(info.instance_slots)
            .ok_or(ConditionalError::InstanceSlots(info.instance_slots))?;

        let params: &[u16] = typed_section(
            layout,
            SectionTag::NetworkParams,
            ConditionalError::ParamElementSize,
            || {
                // The embedding `max(M, 1) n h1` is below 2^32 (checked by
                // `with_instance_slots`), so it fits a 32-bit `usize`; the sum is
                // taken in u64, where `param_len` could overflow one.
                Ok(shape.first_layer_offset() as u64 + shape.multiply_adds() as u64)
            },
            |expected, got| ConditionalError::ParamsLength { expected, got },
        )?;
        let metallic_nodes = metallic_nodes(layout, warp)?;
        let shape = shape.with_metallic_input(!metallic_nodes.is_empty());
        // The axis's layers (at most `MAX_METALLIC_NODES`) times one layer's length.
        let layers = metallic_nodes.len().max(1) as u64;
        let table: &[u32] = typed_section(
            layout,
            SectionTag::PointTable,
            ConditionalError::PointTableElementSize,
            || {
                info.point_table_len()
                    .and_then(|len| len.checked_mul(layers))
                    .ok_or(ConditionalError::PointTableCountOverflow)
            },
            |expected, got| ConditionalError::PointTableLength { expected, got },
        )?;
        let weights: &[f32] = typed_section(
            layout,
            SectionTag::WeightTable,
            ConditionalError::WeightElementSize,
            // Saturating: two grid counts near 2^32 make a length near 2^64, whose
            // double would overflow (no section is that long, so it is refused).
            || Ok(info.weight_table_len().saturating_mul(info.weight_tables())),
            |expected, got| ConditionalError::WeightTableLength { expected, got },
        )?;
        let tree = match warp {
            PointWarp::EnvmapTree => Some(tree_view(layout)?),
            _ => None,
        };
        let brdf_prior = match warp {
            PointWarp::BrdfTable => Some(brdf_prior(layout, false)?),
            _ => None,
        };
        // The metal layer's table has no metallic axis: one layer's length.
        let layer_len = table.len() / layers as usize;
        let metal = metal_points(layout, &brdf_prior, params.len(), layer_len)?;
        Ok(Self {
            info,
            shape,
            domain,
            target,
            warp,
            params: NetworkParams::F16(params),
            table,
            weights,
            tree,
            brdf_prior,
            metal,
            metallic_nodes,
        })
    }

    /// Every parameter a finite f16 (so [`f16_decode_finite`] applies), every
    /// weight finite and `>= 0`. `O(param_len + weight_table_len)`.
    fn check_values(&self) -> Result<(), BlobError> {
        let NetworkParams::F16(params) = self.params else {
            return Ok(());
        };
        if let Some((index, bits)) = first_non_finite(params) {
            return fail(ConditionalError::NonFiniteParam { index, bits });
        }
        let bad_weight = self
            .weights
            .iter()
            .enumerate()
            .find(|(_, w)| !(w.is_finite() && **w >= 0.0));
        if let Some((index, w)) = bad_weight {
            let (index, bits) = (index as u64, w.to_bits());
            return fail(ConditionalError::BadWeight { index, bits });
        }
        if let Some(MetalPoints {
            params: NetworkParams::F16(params),
            ..
        }) = self.metal
        {
            if let Some((index, bits)) = first_non_finite(params) {
                return fail(ConditionalError::NonFiniteMetalParam { index, bits });
            }
        }
        if let Some(tree) = &self.tree {
            tree.check_values().map_err(ConditionalError::Tree)?;
        }
        Ok(())
    }
}

/// The index and bits of the first f16 infinity or NaN in `params`.
fn first_non_finite(params: &[u16]) -> Option<(u64, u16)> {
    let (index, &bits) = params
        .iter()
        .enumerate()
        .find(|(_, &h)| !f16_is_finite(h))?;
    Some((index as u64, bits))
}

/// The metallic axis ([`SectionTag::MetallicNodes`]), empty if the blob has
/// none: only on a [`PointWarp::BrdfTable`] sampler, `f32` elements, values
/// checked by [`check_metallic_nodes`]. `O(MAX_METALLIC_NODES)`.
fn metallic_nodes<'a>(layout: &Layout<'a>, warp: PointWarp) -> Result<&'a [f32], BlobError> {
    let Ok((_, bytes)) = layout.section(SectionTag::MetallicNodes) else {
        return Ok(&[]);
    };
    if warp != PointWarp::BrdfTable {
        return fail(ConditionalError::MetallicNodesWarp(warp as u32));
    }
    let nodes: &[f32] = typed_section(
        layout,
        SectionTag::MetallicNodes,
        ConditionalError::MetallicNodesElementSize,
        // Any count of whole elements reaches the count check below, which
        // names it.
        || Ok((bytes.len() / 4) as u64),
        |_, got| {
            let got = got.min(u32::MAX as u64) as u32;
            ConditionalError::MetallicNodes(MetallicNodesError::Count(got))
        },
    )?;
    check_metallic_nodes(nodes).map_err(ConditionalError::MetallicNodes)?;
    Ok(nodes)
}

/// The metal layer's network and point table, if the blob has them: both
/// sections, on a BRDF prior with the metal layer, each as long as its shared
/// twin (`params` and `table` entries). `O(1)`.
fn metal_points<'a>(
    layout: &Layout<'a>,
    prior: &Option<BrdfPrior<'a, f32>>,
    params: usize,
    table: usize,
) -> Result<Option<MetalPoints<'a>>, BlobError> {
    let tags = [SectionTag::MetalNetworkParams, SectionTag::MetalPointTable];
    let present = tags.map(|t| layout.section(t).is_ok());
    if present == [false; 2] {
        return Ok(None);
    }
    let layer = prior.is_some_and(|p| has_metal_layer(p.grid()));
    if let Some(i) = present.iter().position(|&p| !p || !layer) {
        return fail(ConditionalError::MetalPoints(tags[i] as u32));
    }
    Ok(Some(MetalPoints {
        params: NetworkParams::F16(metal_section(layout, tags[0], params)?),
        table: metal_section(layout, tags[1], table)?,
    }))
}

/// Metal-points section `tag` as `len` elements of its shared twin's type.
fn metal_section<'a, T: bytemuck::Pod>(
    layout: &Layout<'a>,
    tag: SectionTag,
    len: usize,
) -> Result<&'a [T], BlobError> {
    let code = tag as u32;
    typed_section(
        layout,
        tag,
        |size| ConditionalError::MetalElementSize { tag: code, size },
        || Ok(len as u64),
        |expected, got| ConditionalError::MetalLength {
            tag: code,
            expected,
            got,
        },
    )
}

/// A tree section of the wrong length.
fn tree_length(expected: u64, got: u64) -> ConditionalError {
    ConditionalError::Tree(QuadtreeError::Length { expected, got })
}

/// The environment prior's sections (three, the optional leaf shape and detail), their counts checked against the
/// info (`O(1)`; [`EnvmapTree::check_values`] reads every value once, in
/// [`ConditionalSampler::validate`]).
fn tree_view<'a>(layout: &Layout<'a>) -> Result<EnvmapTree<'a>, BlobError> {
    let info: TreeInfo = record(layout, SectionTag::EnvmapTreeInfo, |got, expected| {
        ConditionalError::TreeInfoSize { got, expected }
    })?;
    if info.reserved != 0 {
        return fail(ConditionalError::TreeReserved);
    }
    // 0 in the blobs written before the field: their depth.
    let top_levels = info.top_levels();
    if !(LEGACY_TOP_LEVELS..=MAX_TOP_LEVELS).contains(&top_levels) {
        return fail(ConditionalError::Tree(QuadtreeError::TopLevels(top_levels)));
    }
    if !(top_levels..=MAX_TREE_LEVELS).contains(&info.levels) {
        return fail(ConditionalError::Tree(QuadtreeError::Levels(info.levels)));
    }
    if !(2..=1024).contains(&info.grid) {
        return fail(ConditionalError::Tree(QuadtreeError::Length {
            expected: top_len(info.grid.clamp(2, 1024), top_levels) as u64,
            got: 0,
        }));
    }
    let nodes: &[NodeRecord] = typed_section(
        layout,
        SectionTag::EnvmapTreeNodes,
        ConditionalError::TreeNodeElementSize,
        || Ok(node_count(info.levels) as u64),
        tree_length,
    )?;
    let top: &[f32] = typed_section(
        layout,
        SectionTag::EnvmapTreeTop,
        ConditionalError::TreeTopElementSize,
        || Ok(top_len(info.grid, top_levels) as u64),
        tree_length,
    )?;
    // The leaf shape is optional: without it the leaves are uniform.
    let corners: &[f32] = if layout.section(SectionTag::EnvmapTreeCorners).is_ok() {
        typed_section(
            layout,
            SectionTag::EnvmapTreeCorners,
            ConditionalError::TreeCornerElementSize,
            || Ok(corner_len(info.levels) as u64),
            tree_length,
        )?
    } else {
        &[]
    };
    // Detailed leaves are optional too: both sections or neither.
    let tags = [
        SectionTag::EnvmapTreeDetailIndex,
        SectionTag::EnvmapTreeDetail,
    ];
    let (index, tables): (&[u32], &[f32]) = match tags.map(|t| layout.section(t).is_ok()) {
        [false, false] => (&[], &[]),
        [true, true] => {
            let index = typed_section(
                layout,
                tags[0],
                ConditionalError::TreeDetailElementSize,
                || Ok(detail_index_len(info.levels) as u64),
                tree_length,
            )?;
            (index, detail_tables(layout, tags[1])?)
        }
        _ => return fail(ConditionalError::TreeDetailAlone),
    };
    // The fine tables, optional, only beside the detail.
    let fine_tag = SectionTag::EnvmapTreeFineDetail;
    let fine: &[f32] = match layout.section(fine_tag) {
        Err(_) => &[],
        Ok(_) if index.is_empty() => return fail(ConditionalError::TreeDetailAlone),
        Ok(_) => detail_tables(layout, fine_tag)?,
    };
    EnvmapTree::view(info.levels, nodes, info.grid, top, top_levels)
        .and_then(|t| t.with_corners(corners))
        .and_then(|t| t.with_detail(index, tables))
        .and_then(|t| t.with_fine_detail(fine))
        .map_err(|e| ConditionalError::Tree(e).into())
}

/// A detail-table section (tag 21 or 22) as `f32` values, its element size
/// checked; whether they make whole tables, [`EnvmapTree::with_detail`] and
/// [`EnvmapTree::with_fine_detail`] check.
fn detail_tables<'a>(layout: &Layout<'a>, tag: SectionTag) -> Result<&'a [f32], BlobError> {
    let values = layout.section(tag)?.1.len() / 4;
    typed_section(
        layout,
        tag,
        ConditionalError::TreeDetailElementSize,
        || Ok(values as u64),
        tree_length,
    )
}

/// The BRDF prior's five sections: with `check`, every value read once
/// ([`BrdfPrior::new`], `O(nodes size^2)`); without, counts only (`O(1)`).
fn brdf_prior<'a>(layout: &Layout<'a>, check: bool) -> Result<BrdfPrior<'a, f32>, BlobError> {
    if layout.section(SectionTag::BrdfPriorInfo).is_err() {
        let earlier = [
            SectionTag::BrdfPriorInfoUnstretched,
            SectionTag::BrdfPriorInfoStretchedMetal,
            SectionTag::BrdfPriorInfoStretchedShared,
        ];
        if let Some(tag) = earlier.into_iter().find(|&t| layout.section(t).is_ok()) {
            return Err(ConditionalError::BrdfPriorEarlier { tag: tag as u32 }.into());
        }
    }
    let info: BrdfPriorInfo = record(layout, SectionTag::BrdfPriorInfo, |got, expected| {
        ConditionalError::BrdfPriorInfoSize { got, expected }
    })?;
    let shape = info
        .shape()
        .ok_or(ConditionalError::BrdfPrior(Marginal2DError::Shape))?;
    let prior_length = |slice: u8| {
        move |expected, got| {
            ConditionalError::BrdfPrior(Marginal2DError::Length {
                slice,
                expected,
                got,
            })
        }
    };
    let table = |tag: SectionTag, slice: u8, len: Option<usize>| {
        typed_section::<f32, ConditionalError>(
            layout,
            tag,
            |size| ConditionalError::BrdfPriorElementSize {
                tag: tag as u32,
                size,
            },
            || Ok(len.map_or(u64::MAX, |n| n as u64)),
            prior_length(slice),
        )
    };
    let data = table(SectionTag::BrdfPriorData, 0, shape.data_len())?;
    let marginal = table(SectionTag::BrdfPriorMarginal, 1, shape.marginal_len())?;
    let conditional = table(SectionTag::BrdfPriorConditional, 2, shape.data_len())?;
    let masses = table(SectionTag::BrdfPriorMasses, 3, Some(shape.nodes as usize))?;
    let prior = if check {
        BrdfPrior::new(info, data, marginal, conditional, masses)
    } else {
        BrdfPrior::view(info, data, marginal, conditional, masses)
    };
    prior.map_err(|e| ConditionalError::BrdfPrior(e).into())
}

/// `Err(e)` as a [`BlobError`].
fn fail<T>(e: ConditionalError) -> Result<T, BlobError> {
    Err(e.into())
}
