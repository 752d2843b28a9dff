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
use nuld_core::brdf::{MAX_ROUGHNESS, MAX_THETA_O_DEG, MIN_ROUGHNESS};
use nuld_core::conditional::{ConditionalInfo, PointWarp};
use nuld_core::network::{
    Activation, DOT_LANES, INPUTS, LATTICE_LOGIT_EPS, MAX_HIDDEN_LAYERS, MAX_WIDTH, OUTPUTS,
};
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

/// The value of each `NULD_*` constant the shader must share with Rust.
fn rust_constants() -> Vec<(&'static str, u64)> {
    let f = |x: f32| x.to_bits() as u64;
    vec![
        ("NULD_HEADER_KIND", offset_of!(Header, kind) as u64),
        (
            "NULD_HEADER_SECTION_COUNT",
            offset_of!(Header, section_count) as u64,
        ),
        ("NULD_HEADER_LEN", HEADER_LEN as u64),
        ("NULD_SECTION_ENTRY_LEN", SECTION_ENTRY_LEN as u64),
        ("NULD_SECTION_TAG", offset_of!(SectionEntry, tag) as u64),
        (
            "NULD_SECTION_OFFSET",
            offset_of!(SectionEntry, offset) as u64,
        ),
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
        ("NULD_DOMAIN_SQUARE", Domain::Square as u64),
        ("NULD_DOMAIN_SPHERE", Domain::Sphere as u64),
        ("NULD_DOMAIN_HEMISPHERE", Domain::Hemisphere as u64),
        ("NULD_POINT_SET_LEN", offset_of!(PointSetInfo, len) as u64),
        (
            "NULD_POINT_SET_COUNT",
            offset_of!(PointSetInfo, set_count) as u64,
        ),
        (
            "NULD_POINT_SET_DOMAIN",
            offset_of!(PointSetInfo, domain) as u64,
        ),
        ("NULD_INFO_N", offset_of!(ConditionalInfo, n) as u64),
        (
            "NULD_INFO_INSTANCES",
            offset_of!(ConditionalInfo, instances) as u64,
        ),
        (
            "NULD_INFO_DOMAIN",
            offset_of!(ConditionalInfo, domain) as u64,
        ),
        (
            "NULD_INFO_TARGET",
            offset_of!(ConditionalInfo, target) as u64,
        ),
        ("NULD_INFO_GRID", offset_of!(ConditionalInfo, grid) as u64),
        (
            "NULD_INFO_WEIGHT_GRID",
            offset_of!(ConditionalInfo, weight_grid) as u64,
        ),
        (
            "NULD_INFO_COND_MIN",
            offset_of!(ConditionalInfo, cond_min) as u64,
        ),
        (
            "NULD_INFO_COND_MAX",
            offset_of!(ConditionalInfo, cond_max) as u64,
        ),
        (
            "NULD_INFO_HIDDEN",
            offset_of!(ConditionalInfo, hidden) as u64,
        ),
        (
            "NULD_INFO_ACTIVATION",
            offset_of!(ConditionalInfo, activation) as u64,
        ),
        (
            "NULD_INFO_LATTICE_GENERATOR",
            offset_of!(ConditionalInfo, lattice_generator) as u64,
        ),
        ("NULD_INFO_WARP", offset_of!(ConditionalInfo, warp) as u64),
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
        ("NULD_F16_SUBNORMAL", f(f16_decode_finite(1))),
        ("NULD_WORKGROUP_SIZE", KERNEL_WORKGROUP_SIZE as u64),
        ("NULD_MODE_TABLE", KernelMode::Table as u64),
        ("NULD_MODE_NETWORK", KernelMode::Network as u64),
        ("NULD_MODE_BRDF_TABLE", KernelMode::BrdfTable as u64),
        ("NULD_MODE_BRDF_NETWORK", KernelMode::BrdfNetwork as u64),
    ]
}

/// The bits of an `f32` literal of libm's source (a NaN's bits if it does not parse, which
/// no shader constant equals).
fn libm_literal(text: &str) -> u64 {
    text.parse::<f32>().unwrap_or(f32::NAN).to_bits() as u64
}

/// Struct member offsets and sizes the shader's structs must share with Rust.
fn rust_structs() -> Vec<(&'static str, u64)> {
    vec![
        ("NuldConditionalInfo", size_of::<ConditionalInfo>() as u64),
        (
            "NuldConditionalInfo.n",
            offset_of!(ConditionalInfo, n) as u64,
        ),
        (
            "NuldConditionalInfo.instances",
            offset_of!(ConditionalInfo, instances) as u64,
        ),
        (
            "NuldConditionalInfo.domain",
            offset_of!(ConditionalInfo, domain) as u64,
        ),
        (
            "NuldConditionalInfo.target_code",
            offset_of!(ConditionalInfo, target) as u64,
        ),
        (
            "NuldConditionalInfo.grid",
            offset_of!(ConditionalInfo, grid) as u64,
        ),
        (
            "NuldConditionalInfo.weight_grid",
            offset_of!(ConditionalInfo, weight_grid) as u64,
        ),
        (
            "NuldConditionalInfo.cond_min",
            offset_of!(ConditionalInfo, cond_min) as u64,
        ),
        (
            "NuldConditionalInfo.cond_max",
            offset_of!(ConditionalInfo, cond_max) as u64,
        ),
        (
            "NuldConditionalInfo.hidden",
            offset_of!(ConditionalInfo, hidden) as u64,
        ),
        (
            "NuldConditionalInfo.activation",
            offset_of!(ConditionalInfo, activation) as u64,
        ),
        (
            "NuldConditionalInfo.lattice_generator",
            offset_of!(ConditionalInfo, lattice_generator) as u64,
        ),
        (
            "NuldConditionalInfo.warp",
            offset_of!(ConditionalInfo, warp) as u64,
        ),
        ("NuldKernelParams", size_of::<KernelParams>() as u64),
        (
            "NuldKernelParams.cond_first",
            offset_of!(KernelParams, cond_first) as u64,
        ),
        (
            "NuldKernelParams.cond_step",
            offset_of!(KernelParams, cond_step) as u64,
        ),
        (
            "NuldKernelParams.cond_count",
            offset_of!(KernelParams, cond_count) as u64,
        ),
        (
            "NuldKernelParams.instance_first",
            offset_of!(KernelParams, instance_first) as u64,
        ),
        (
            "NuldKernelParams.instance_count",
            offset_of!(KernelParams, instance_count) as u64,
        ),
        (
            "NuldKernelParams.index_first",
            offset_of!(KernelParams, index_first) as u64,
        ),
        (
            "NuldKernelParams.index_count",
            offset_of!(KernelParams, index_count) as u64,
        ),
        (
            "NuldKernelParams.mode",
            offset_of!(KernelParams, mode) as u64,
        ),
        (
            "NuldKernelParams.reserved",
            offset_of!(KernelParams, reserved) as u64,
        ),
        (
            "NuldKernelParams.view",
            offset_of!(KernelParams, view) as u64,
        ),
        // Direction xyz then weight: one `[f32; 4]` per sample on the host.
        ("NuldSample", SAMPLE_STRIDE),
        ("NuldSample.direction", 0),
        ("NuldSample.weight", 3 * size_of::<f32>() as u64),
    ]
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
