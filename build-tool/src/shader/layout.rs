//! What the WGSL sampler assumes about the blob, held to the Rust definitions: each
//! `NULD_*` constant of `runtime/shaders/*.wgsl` (byte offsets, codes, sizes,
//! `f32` constants) beside the value `nuld_core`/`nuld_runtime` define, and the
//! byte layout naga computes for the shader's structs (WGSL's host-shareable
//! layout rules, the std430 of Vulkan) beside `core::mem::offset_of!` of their
//! Rust twins.

use super::ShaderError;
use naga::{Expression, Literal, Module, TypeInner};
use nuld_core::blob::{
    BlobKind, Domain, Header, PointSetInfo, SectionEntry, SectionTag, HEADER_LEN, MAX_SECTIONS,
    SECTION_ENTRY_LEN,
};
use nuld_core::brdf::{F0, MAX_ROUGHNESS, MAX_THETA_O_DEG, MIN_ROUGHNESS};
use nuld_core::brdf_prior::{BrdfPriorInfo, RADIAL_CROSSOVER, RADIAL_INVERSE_STEPS};
use nuld_core::conditional::{ConditionalInfo, PointWarp, MAX_METALLIC_NODES, RANDOMIZE_SALTS};
use nuld_core::envmap_tree::{
    TreeInfo, DETAIL_LEN, DETAIL_SIDE, FINE_BIT, FINE_LEN, FINE_SIDE, LEGACY_TOP_LEVELS,
    MAX_TOP_LEVELS, TOP_FLOOR,
};
use nuld_core::marginal2d::MAX_BLEND;
use nuld_core::network::{
    Activation, OffsetHash, DOT_LANES, INPUTS, LATTICE_LOGIT_EPS, MAX_HIDDEN_LAYERS, MAX_WIDTH,
    OFFSET_SALTS, OUTPUTS,
};
use nuld_core::quadtree::MAX_LEVELS;
use nuld_core::quantize::{f16_decode_finite, UNORM16_CELLS};
use nuld_runtime::shader::{KernelMode, KernelParams, KERNEL_WORKGROUP_SIZE, SAMPLE_STRIDE};
use std::mem::{offset_of, size_of};

/// A value the shader assumes and the Rust definition it must equal (`f32`
/// constants compared by their bits).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Assumption {
    /// The WGSL name: a constant, or `Struct.member` (offset) / `Struct` (size).
    pub name: String,
    /// What the shader has (`None`: not found in the shader).
    pub shader: Option<u64>,
    /// What the Rust definition says.
    pub rust: u64,
}

/// `offset_of!` as the `u64` an [`Assumption`] holds.
macro_rules! at {
    ($t:ty, $field:ident) => {
        offset_of!($t, $field) as u64
    };
}

/// Each [`ConditionalInfo`] field: the WGSL constant `nuld_info` reads it at, the
/// `NuldConditionalInfo` member it lands in, and its Rust offset (the two WGSL
/// names of one offset, listed once).
fn info_fields() -> [(&'static str, &'static str, u64); 14] {
    [
        (
            "NULD_INFO_N",
            "NuldConditionalInfo.n",
            at!(ConditionalInfo, n),
        ),
        (
            "NULD_INFO_INSTANCES",
            "NuldConditionalInfo.instances",
            at!(ConditionalInfo, instances),
        ),
        (
            "NULD_INFO_DOMAIN",
            "NuldConditionalInfo.domain",
            at!(ConditionalInfo, domain),
        ),
        (
            "NULD_INFO_TARGET",
            "NuldConditionalInfo.target_code",
            at!(ConditionalInfo, target),
        ),
        (
            "NULD_INFO_GRID",
            "NuldConditionalInfo.grid",
            at!(ConditionalInfo, grid),
        ),
        (
            "NULD_INFO_WEIGHT_GRID",
            "NuldConditionalInfo.weight_grid",
            at!(ConditionalInfo, weight_grid),
        ),
        (
            "NULD_INFO_COND_MIN",
            "NuldConditionalInfo.cond_min",
            at!(ConditionalInfo, cond_min),
        ),
        (
            "NULD_INFO_COND_MAX",
            "NuldConditionalInfo.cond_max",
            at!(ConditionalInfo, cond_max),
        ),
        (
            "NULD_INFO_HIDDEN",
            "NuldConditionalInfo.hidden",
            at!(ConditionalInfo, hidden),
        ),
        (
            "NULD_INFO_ACTIVATION",
            "NuldConditionalInfo.activation",
            at!(ConditionalInfo, activation),
        ),
        (
            "NULD_INFO_LATTICE_GENERATOR",
            "NuldConditionalInfo.lattice_generator",
            at!(ConditionalInfo, lattice_generator),
        ),
        (
            "NULD_INFO_WARP",
            "NuldConditionalInfo.warp",
            at!(ConditionalInfo, warp),
        ),
        (
            "NULD_INFO_INSTANCE_SLOTS",
            "NuldConditionalInfo.instance_slots",
            at!(ConditionalInfo, instance_slots),
        ),
        (
            "NULD_INFO_OFFSET_HASH",
            "NuldConditionalInfo.offset_hash",
            at!(ConditionalInfo, offset_hash),
        ),
    ]
}

/// The value of each `NULD_*` constant the shader must share with Rust.
fn rust_constants() -> Vec<(&'static str, u64)> {
    let f = |x: f32| x.to_bits() as u64;
    let mut constants = vec![
        ("NULD_HEADER_KIND", at!(Header, kind)),
        ("NULD_HEADER_SECTION_COUNT", at!(Header, section_count)),
        ("NULD_HEADER_LEN", HEADER_LEN as u64),
        ("NULD_SECTION_ENTRY_LEN", SECTION_ENTRY_LEN as u64),
        ("NULD_SECTION_TAG", at!(SectionEntry, tag)),
        ("NULD_SECTION_OFFSET", at!(SectionEntry, offset)),
        ("NULD_SECTION_LEN", at!(SectionEntry, len)),
        ("NULD_MAX_SECTIONS", MAX_SECTIONS as u64),
        ("NULD_KIND_POINT_SET_2D", BlobKind::PointSet2D as u64),
        ("NULD_KIND_DIRECTION_SET", BlobKind::DirectionSet as u64),
        ("NULD_KIND_CONDITIONAL", BlobKind::Conditional as u64),
        ("NULD_TAG_POINT_SET_INFO", SectionTag::PointSetInfo as u64),
        ("NULD_TAG_POINTS", SectionTag::Points as u64),
        (
            "NULD_TAG_CONDITIONAL_INFO",
            SectionTag::ConditionalInfo as u64,
        ),
        ("NULD_TAG_NETWORK_PARAMS", SectionTag::NetworkParams as u64),
        ("NULD_TAG_POINT_TABLE", SectionTag::PointTable as u64),
        ("NULD_TAG_WEIGHT_TABLE", SectionTag::WeightTable as u64),
        (
            "NULD_TAG_ENVMAP_TREE_INFO",
            SectionTag::EnvmapTreeInfo as u64,
        ),
        (
            "NULD_TAG_ENVMAP_TREE_NODES",
            SectionTag::EnvmapTreeNodes as u64,
        ),
        ("NULD_TAG_ENVMAP_TREE_TOP", SectionTag::EnvmapTreeTop as u64),
        (
            "NULD_TAG_ENVMAP_TREE_CORNERS",
            SectionTag::EnvmapTreeCorners as u64,
        ),
        (
            "NULD_TAG_ENVMAP_TREE_DETAIL_INDEX",
            SectionTag::EnvmapTreeDetailIndex as u64,
        ),
        (
            "NULD_TAG_ENVMAP_TREE_DETAIL",
            SectionTag::EnvmapTreeDetail as u64,
        ),
        (
            "NULD_TAG_ENVMAP_TREE_FINE_DETAIL",
            SectionTag::EnvmapTreeFineDetail as u64,
        ),
        ("NULD_TAG_BRDF_PRIOR_INFO", SectionTag::BrdfPriorInfo as u64),
        ("NULD_TAG_BRDF_PRIOR_DATA", SectionTag::BrdfPriorData as u64),
        (
            "NULD_TAG_BRDF_PRIOR_MARGINAL",
            SectionTag::BrdfPriorMarginal as u64,
        ),
        (
            "NULD_TAG_BRDF_PRIOR_CONDITIONAL",
            SectionTag::BrdfPriorConditional as u64,
        ),
        (
            "NULD_TAG_BRDF_PRIOR_MASSES",
            SectionTag::BrdfPriorMasses as u64,
        ),
        (
            "NULD_TAG_METAL_NETWORK_PARAMS",
            SectionTag::MetalNetworkParams as u64,
        ),
        (
            "NULD_TAG_METAL_POINT_TABLE",
            SectionTag::MetalPointTable as u64,
        ),
        ("NULD_TAG_METALLIC_NODES", SectionTag::MetallicNodes as u64),
        ("NULD_MAX_METALLIC_NODES", MAX_METALLIC_NODES as u64),
        ("NULD_WARP_ENVMAP_TREE", PointWarp::EnvmapTree as u64),
        ("NULD_WARP_BRDF_TABLE", PointWarp::BrdfTable as u64),
        ("NULD_PRIOR_INFO_GRID", at!(BrdfPriorInfo, grid)),
        ("NULD_PRIOR_INFO_SIZE", at!(BrdfPriorInfo, size)),
        ("NULD_MAX_BLEND", MAX_BLEND as u64),
        ("NULD_TREE_INFO_LEVELS", at!(TreeInfo, levels)),
        ("NULD_TREE_INFO_GRID", at!(TreeInfo, grid)),
        ("NULD_TREE_INFO_TOP_LEVELS", at!(TreeInfo, top_levels)),
        ("NULD_TREE_LEGACY_TOP_LEVELS", LEGACY_TOP_LEVELS as u64),
        ("NULD_TREE_MAX_TOP_LEVELS", MAX_TOP_LEVELS as u64),
        ("NULD_TREE_MAX_LEVELS", MAX_LEVELS as u64),
        ("NULD_TREE_DETAIL_SIDE", DETAIL_SIDE as u64),
        ("NULD_TREE_DETAIL_LEN", DETAIL_LEN as u64),
        ("NULD_TREE_FINE_SIDE", FINE_SIDE as u64),
        ("NULD_TREE_FINE_LEN", FINE_LEN as u64),
        ("NULD_TREE_FINE_BIT", FINE_BIT as u64),
        ("NULD_TREE_TOP_FLOOR", f(TOP_FLOOR as f32)),
        ("NULD_TREE_UNIT_MIN", f(1e-20f64 as f32)),
        ("NULD_RANDOMIZE_SALT_A", RANDOMIZE_SALTS[0] as u64),
        ("NULD_RANDOMIZE_SALT_B", RANDOMIZE_SALTS[1] as u64),
        ("NULD_OFFSET_SALT_X", OFFSET_SALTS[0] as u64),
        ("NULD_OFFSET_SALT_Y", OFFSET_SALTS[1] as u64),
        ("NULD_OFFSET_HASH_SALTED", OffsetHash::Salted as u64),
        ("NULD_DOMAIN_SQUARE", Domain::Square as u64),
        ("NULD_DOMAIN_SPHERE", Domain::Sphere as u64),
        ("NULD_DOMAIN_HEMISPHERE", Domain::Hemisphere as u64),
        ("NULD_POINT_SET_LEN", at!(PointSetInfo, len)),
        ("NULD_POINT_SET_COUNT", at!(PointSetInfo, set_count)),
        ("NULD_POINT_SET_DOMAIN", at!(PointSetInfo, domain)),
        ("NULD_WARP_EQUAL_AREA", PointWarp::EqualArea as u64),
        ("NULD_WARP_BRDF_MIXTURE", PointWarp::BrdfMixture as u64),
        ("NULD_INPUTS", INPUTS as u64),
        ("NULD_MAX_WIDTH", MAX_WIDTH as u64),
        ("NULD_MAX_HIDDEN_LAYERS", MAX_HIDDEN_LAYERS as u64),
        ("NULD_OUTPUTS", OUTPUTS as u64),
        ("NULD_DOT_LANES", DOT_LANES as u64),
        ("NULD_ACTIVATION_RELU", Activation::Relu as u64),
        ("NULD_ACTIVATION_SILU", Activation::Silu as u64),
        ("NULD_FRAC_PI_4", f(core::f32::consts::FRAC_PI_4)),
        ("NULD_FRAC_PI_2", f(core::f32::consts::FRAC_PI_2)),
        ("NULD_DEGREES_PER_RADIAN", f(180.0 / core::f32::consts::PI)),
        ("NULD_PI", f(core::f32::consts::PI)),
        (
            "NULD_RADIANS_PER_DEGREE",
            f((core::f64::consts::PI / 180.0) as f32),
        ),
        ("NULD_MIN_ROUGHNESS", f(MIN_ROUGHNESS as f32)),
        ("NULD_MAX_ROUGHNESS", f(MAX_ROUGHNESS as f32)),
        ("NULD_MAX_THETA_O_DEG", f(MAX_THETA_O_DEG as f32)),
        ("NULD_RADIAL_CROSSOVER", f(RADIAL_CROSSOVER as f32)),
        ("NULD_RADIAL_INVERSE_STEPS", RADIAL_INVERSE_STEPS as u64),
        (
            "NULD_ROUGHNESS_SPAN",
            f((MAX_ROUGHNESS - MIN_ROUGHNESS) as f32),
        ),
        ("NULD_F0", f(F0 as f32)),
        ("NULD_ONE_MINUS_F0", f((1.0 - F0) as f32)),
        ("NULD_FRAC_4_PI", f((4.0 / core::f64::consts::PI) as f32)),
        ("NULD_LATTICE_LOGIT_EPS", f(LATTICE_LOGIT_EPS as f32)),
        ("NULD_UNORM16_SCALE", f(1.0 / UNORM16_CELLS as f32)),
        ("NULD_INSTANCE_UNIT", f((1.0f64 / 16_777_216.0) as f32)),
        // libm's acosf (FreeBSD e_acosf.c), its literals and hex comments.
        ("NULD_ACOS_PIO2_HI", 0x3fc9_0fda),
        ("NULD_ACOS_PIO2_LO", 0x33a2_2168),
        // The coefficients as libm writes them, parsed as Rust parses its `f32`
        // literals (correctly rounded).
        ("NULD_ACOS_P_S0", libm_literal("1.6666586697e-01")),
        ("NULD_ACOS_P_S1", libm_literal("-4.2743422091e-02")),
        ("NULD_ACOS_P_S2", libm_literal("-8.6563630030e-03")),
        ("NULD_ACOS_Q_S1", libm_literal("-7.0662963390e-01")),
        // libm's atanf (FreeBSD s_atanf.c), likewise.
        ("NULD_ATAN_HI_0", 0x3eed_6338),
        ("NULD_ATAN_HI_1", 0x3f49_0fda),
        ("NULD_ATAN_HI_2", 0x3f7b_985e),
        ("NULD_ATAN_HI_3", 0x3fc9_0fda),
        ("NULD_ATAN_LO_0", 0x31ac_3769),
        ("NULD_ATAN_LO_1", 0x3322_2168),
        ("NULD_ATAN_LO_2", 0x3314_0fb4),
        ("NULD_ATAN_LO_3", 0x33a2_2168),
        ("NULD_ATAN_T0", libm_literal("3.3333328366e-01")),
        ("NULD_ATAN_T1", libm_literal("-1.9999158382e-01")),
        ("NULD_ATAN_T2", libm_literal("1.4253635705e-01")),
        ("NULD_ATAN_T3", libm_literal("-1.0648017377e-01")),
        ("NULD_ATAN_T4", libm_literal("6.1687607318e-02")),
        ("NULD_F16_SUBNORMAL", f(f16_decode_finite(1))),
        ("NULD_WORKGROUP_SIZE", KERNEL_WORKGROUP_SIZE as u64),
        ("NULD_MODE_TABLE", KernelMode::Table as u64),
        ("NULD_MODE_NETWORK", KernelMode::Network as u64),
        ("NULD_MODE_BRDF_TABLE", KernelMode::BrdfTable as u64),
        ("NULD_MODE_BRDF_NETWORK", KernelMode::BrdfNetwork as u64),
        (
            "NULD_MODE_TABLE_RANDOMIZED",
            KernelMode::TableRandomized as u64,
        ),
        (
            "NULD_MODE_NETWORK_RANDOMIZED",
            KernelMode::NetworkRandomized as u64,
        ),
        ("NULD_MODE_PDF", KernelMode::Pdf as u64),
        (
            "NULD_MODE_BRDF_TABLE_RANDOMIZED",
            KernelMode::BrdfTableRandomized as u64,
        ),
        (
            "NULD_MODE_BRDF_NETWORK_RANDOMIZED",
            KernelMode::BrdfNetworkRandomized as u64,
        ),
        ("NULD_MODE_BRDF_PDF", KernelMode::BrdfPdf as u64),
    ];
    constants.extend(info_fields().map(|(constant, _, offset)| (constant, offset)));
    constants
}

/// The bits of an `f32` literal of libm's source (a NaN's bits if it does not parse, which
/// no shader constant equals).
fn libm_literal(text: &str) -> u64 {
    text.parse::<f32>().unwrap_or(f32::NAN).to_bits() as u64
}

/// Struct member offsets and sizes the shader's structs must share with Rust.
fn rust_structs() -> Vec<(&'static str, u64)> {
    let mut structs = vec![("NuldConditionalInfo", size_of::<ConditionalInfo>() as u64)];
    structs.extend(info_fields().map(|(_, member, offset)| (member, offset)));
    structs.extend([
        ("NuldKernelParams", size_of::<KernelParams>() as u64),
        ("NuldKernelParams.cond_first", at!(KernelParams, cond_first)),
        ("NuldKernelParams.cond_step", at!(KernelParams, cond_step)),
        ("NuldKernelParams.cond_count", at!(KernelParams, cond_count)),
        (
            "NuldKernelParams.instance_first",
            at!(KernelParams, instance_first),
        ),
        (
            "NuldKernelParams.instance_count",
            at!(KernelParams, instance_count),
        ),
        (
            "NuldKernelParams.index_first",
            at!(KernelParams, index_first),
        ),
        (
            "NuldKernelParams.index_count",
            at!(KernelParams, index_count),
        ),
        ("NuldKernelParams.mode", at!(KernelParams, mode)),
        ("NuldKernelParams.reserved", at!(KernelParams, reserved)),
        ("NuldKernelParams.view", at!(KernelParams, view)),
        // Direction xyz, weight, pdf: two `[f32; 4]` per sample on the host.
        ("NuldSample", SAMPLE_STRIDE),
        ("NuldSample.direction", 0),
        ("NuldSample.weight", 3 * size_of::<f32>() as u64),
        ("NuldSample.pdf", 4 * size_of::<f32>() as u64),
    ]);
    structs
}

/// The value of a module constant that is a plain `u32`, `i32` or `f32` literal
/// (`f32` as its bits).
fn constant_value(module: &Module, name: &str) -> Option<u64> {
    let (_, c) = module
        .constants
        .iter()
        .find(|(_, c)| c.name.as_deref() == Some(name))?;
    match module.global_expressions[c.init] {
        Expression::Literal(Literal::U32(v)) => Some(v as u64),
        Expression::Literal(Literal::I32(v)) => u64::try_from(v).ok(),
        Expression::Literal(Literal::F32(v)) => Some(v.to_bits() as u64),
        _ => None,
    }
}

/// The size (`Struct`) or member offset (`Struct.member`) naga laid out.
fn struct_value(module: &Module, name: &str) -> Option<u64> {
    let (ty, member) = match name.split_once('.') {
        Some((t, m)) => (t, Some(m)),
        None => (name, None),
    };
    let (_, t) = module
        .types
        .iter()
        .find(|(_, t)| t.name.as_deref() == Some(ty))?;
    let TypeInner::Struct { members, span } = &t.inner else {
        return None;
    };
    match member {
        None => Some(*span as u64),
        Some(m) => members
            .iter()
            .find(|x| x.name.as_deref() == Some(m))
            .map(|x| x.offset as u64),
    }
}

/// Every assumption of the kernel module (`nuld_runtime::shader::kernel_wgsl`,
/// parsed and validated by naga), with the shader's and Rust's values.
pub fn assumptions() -> Result<Vec<Assumption>, ShaderError> {
    let (module, _) = super::kernel_module()?;
    let constants = rust_constants().into_iter().map(|(name, rust)| Assumption {
        name: name.to_string(),
        shader: constant_value(&module, name),
        rust,
    });
    let structs = rust_structs().into_iter().map(|(name, rust)| Assumption {
        name: name.to_string(),
        shader: struct_value(&module, name),
        rust,
    });
    Ok(constants.chain(structs).collect())
}

/// The names of the module's `NULD_*` constants that [`assumptions`] does not check.
pub fn unchecked_constants() -> Result<Vec<String>, ShaderError> {
    let (module, _) = super::kernel_module()?;
    let checked: Vec<&str> = rust_constants().iter().map(|(n, _)| *n).collect();
    Ok(module
        .constants
        .iter()
        .filter_map(|(_, c)| c.name.clone())
        .filter(|n| n.starts_with("NULD_") && !checked.contains(&n.as_str()))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shader_layout_matches_the_rust_definitions() {
        let all = assumptions().unwrap();
        assert!(all.len() > 60, "{}", all.len());
        let wrong: Vec<_> = all.iter().filter(|a| a.shader != Some(a.rust)).collect();
        assert!(wrong.is_empty(), "{wrong:#?}");
        assert_eq!(unchecked_constants().unwrap(), Vec::<String>::new());
    }

    /// The output buffer's element stride as naga lays out `array<NuldSample>`, and
    /// the uniform's size, which the host code relies on.
    #[test]
    fn shader_output_stride_is_sixteen_bytes() {
        let (module, _) = crate::shader::kernel_module().unwrap();
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        let stride = module
            .global_variables
            .iter()
            .find(|(_, v)| v.name.as_deref() == Some("nuld_samples"))
            .map(|(_, v)| match module.types[v.ty].inner {
                TypeInner::Array { stride, .. } => stride,
                _ => 0,
            });
        assert_eq!(stride, Some(SAMPLE_STRIDE as u32));
        let (params_ty, _) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("NuldKernelParams"))
            .unwrap();
        assert_eq!(layouter[params_ty].size as usize, size_of::<KernelParams>());
    }
}
