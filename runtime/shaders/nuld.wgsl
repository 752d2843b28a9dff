// nuld shader-side samplers (WGSL): the sampling functions of `nuld-runtime`, over
// the bytes of a `.nuld` blob uploaded unchanged as one storage buffer.
//
// Declare the buffer once in your module, under this name, at any group and
// binding (WGSL resolves module-scope names in any order, so before or after this
// text):
//
//     @group(0) @binding(0) var<storage, read> nuld_blob: array<u32>;
//
// Word `w` of `nuld_blob` holds bytes `4w..4w+4` of the blob (little-endian, as
// every GPU reads a storage buffer). The byte layout and the order of operations
// are those of core/FORMAT.md; every header field and section offset is read from
// the buffer, so one shader serves any blob of a kind.
//
// Validate the blob on the CPU before uploading it (`nuld_runtime::Blob::parse`):
// the functions here trust what it checks. On a blob it rejects they still do not
// read outside the buffer (WGSL bounds every array access) but return meaningless
// values.
//
// Each `nuld_*` function is the Rust function it names, in the same order of
// operations. Table mode and the point lookups reproduce the runtime to `f32`
// rounding of the driver's `sin`, `cos`, `sqrt` and division (`acos` is libm's,
// ported, and so is `atan` for the BRDF prior; an environment sampler's pdf of a
// given direction goes through the driver's `atan`); network mode adds the
// driver's `exp` and the order of its multiply-adds (the runtime's dot product
// order is kept; a driver may still fuse a multiply and an add). The BRDF prior's
// warp (warp 3) inverts tabulated CDFs: where its density is low, a rounding of a
// CDF moves the point by that rounding over the density, for the runtime as for
// the shader.

// ---- Blob layout (core/FORMAT.md): byte offsets and codes ----------------------

// `Header::kind` (core/src/blob/mod.rs).
const NULD_HEADER_KIND: u32 = 12u;
// `Header::section_count`.
const NULD_HEADER_SECTION_COUNT: u32 = 40u;
// `HEADER_LEN`: the section table starts here.
const NULD_HEADER_LEN: u32 = 48u;
// `SECTION_ENTRY_LEN`: bytes per section table row.
const NULD_SECTION_ENTRY_LEN: u32 = 32u;
// `SectionEntry::tag`, `SectionEntry::offset` (a u64; its high word is 0 in any
// blob that fits a buffer).
const NULD_SECTION_TAG: u32 = 0u;
const NULD_SECTION_OFFSET: u32 = 8u;
// `SectionEntry::len` in bytes (a u64; its high word is 0 as the offset's).
const NULD_SECTION_LEN: u32 = 16u;
// `MAX_SECTIONS`: rows a valid blob has at most.
const NULD_MAX_SECTIONS: u32 = 64u;

// `BlobKind` codes.
const NULD_KIND_POINT_SET_2D: u32 = 1u;
const NULD_KIND_DIRECTION_SET: u32 = 2u;
const NULD_KIND_CONDITIONAL: u32 = 3u;

// `SectionTag` codes.
const NULD_TAG_POINT_SET_INFO: u32 = 1u;
const NULD_TAG_POINTS: u32 = 2u;
const NULD_TAG_CONDITIONAL_INFO: u32 = 3u;
const NULD_TAG_NETWORK_PARAMS: u32 = 4u;
const NULD_TAG_POINT_TABLE: u32 = 5u;
const NULD_TAG_WEIGHT_TABLE: u32 = 6u;
const NULD_TAG_ENVMAP_TREE_INFO: u32 = 7u;
const NULD_TAG_ENVMAP_TREE_NODES: u32 = 8u;
const NULD_TAG_ENVMAP_TREE_TOP: u32 = 9u;
const NULD_TAG_ENVMAP_TREE_CORNERS: u32 = 19u;
const NULD_TAG_ENVMAP_TREE_DETAIL_INDEX: u32 = 20u;
const NULD_TAG_ENVMAP_TREE_DETAIL: u32 = 21u;
const NULD_TAG_ENVMAP_TREE_FINE_DETAIL: u32 = 22u;
const NULD_TAG_BRDF_PRIOR_INFO: u32 = 24u;
const NULD_TAG_BRDF_PRIOR_DATA: u32 = 11u;
const NULD_TAG_BRDF_PRIOR_MARGINAL: u32 = 12u;
const NULD_TAG_BRDF_PRIOR_CONDITIONAL: u32 = 13u;
const NULD_TAG_BRDF_PRIOR_MASSES: u32 = 14u;
const NULD_TAG_METAL_NETWORK_PARAMS: u32 = 16u;
const NULD_TAG_METAL_POINT_TABLE: u32 = 17u;
const NULD_TAG_METALLIC_NODES: u32 = 18u;
// `MAX_METALLIC_NODES` (core/src/conditional/metallic_axis.rs).
const NULD_MAX_METALLIC_NODES: u32 = 8u;

// `Domain` codes.
const NULD_DOMAIN_SQUARE: u32 = 0u;
const NULD_DOMAIN_SPHERE: u32 = 1u;
const NULD_DOMAIN_HEMISPHERE: u32 = 2u;

// `PointSetInfo` fields.
const NULD_POINT_SET_LEN: u32 = 0u;
const NULD_POINT_SET_COUNT: u32 = 4u;
const NULD_POINT_SET_DOMAIN: u32 = 8u;

// `ConditionalInfo` fields (two-element fields: the second element 4 bytes on).
const NULD_INFO_N: u32 = 0u;
const NULD_INFO_INSTANCES: u32 = 4u;
const NULD_INFO_DOMAIN: u32 = 8u;
const NULD_INFO_TARGET: u32 = 12u;
const NULD_INFO_GRID: u32 = 16u;
const NULD_INFO_WEIGHT_GRID: u32 = 24u;
const NULD_INFO_COND_MIN: u32 = 32u;
const NULD_INFO_COND_MAX: u32 = 40u;
const NULD_INFO_HIDDEN: u32 = 48u;
const NULD_INFO_ACTIVATION: u32 = 60u;
const NULD_INFO_LATTICE_GENERATOR: u32 = 64u;
const NULD_INFO_WARP: u32 = 68u;
const NULD_INFO_INSTANCE_SLOTS: u32 = 72u;
const NULD_INFO_OFFSET_HASH: u32 = 76u;

// `nuld_core::network`: `INPUTS`, `MAX_WIDTH`, `MAX_HIDDEN_LAYERS`, `OUTPUTS`, and
// the dot product's partial sums (`DOT_LANES`).
const NULD_INPUTS: u32 = 11u;
const NULD_MAX_WIDTH: u32 = 128u;
const NULD_MAX_HIDDEN_LAYERS: u32 = 3u;
const NULD_OUTPUTS: u32 = 2u;
const NULD_DOT_LANES: u32 = 8u;
// `Activation` codes.
const NULD_ACTIVATION_RELU: u32 = 0u;
const NULD_ACTIVATION_SILU: u32 = 1u;
// `PointWarp` codes (core/src/conditional/mod.rs).
const NULD_WARP_EQUAL_AREA: u32 = 0u;
const NULD_WARP_BRDF_MIXTURE: u32 = 1u;
const NULD_WARP_ENVMAP_TREE: u32 = 2u;
const NULD_WARP_BRDF_TABLE: u32 = 3u;
// `TreeInfo` fields (core/src/envmap_tree.rs).
const NULD_TREE_INFO_LEVELS: u32 = 0u;
const NULD_TREE_INFO_GRID: u32 = 4u;
const NULD_TREE_INFO_TOP_LEVELS: u32 = 8u;
// `LEGACY_TOP_LEVELS`, `MAX_TOP_LEVELS`, `quadtree::MAX_LEVELS`.
const NULD_TREE_LEGACY_TOP_LEVELS: u32 = 3u;
const NULD_TREE_MAX_TOP_LEVELS: u32 = 5u;
const NULD_TREE_MAX_LEVELS: u32 = 24u;
// `DETAIL_SIDE`, `DETAIL_LEN` (core/src/envmap_tree.rs).
const NULD_TREE_DETAIL_SIDE: u32 = 16u;
const NULD_TREE_DETAIL_LEN: u32 = 272u;
// `FINE_SIDE`, `FINE_LEN`, `FINE_BIT` (core/src/envmap_tree.rs).
const NULD_TREE_FINE_SIDE: u32 = 64u;
const NULD_TREE_FINE_LEN: u32 = 4160u;
const NULD_TREE_FINE_BIT: u32 = 0x80000000u;
// `BrdfPriorInfo` fields (core/src/brdf_prior.rs).
const NULD_PRIOR_INFO_GRID: u32 = 0u;
const NULD_PRIOR_INFO_SIZE: u32 = 12u;
// `MAX_BLEND` (core/src/marginal2d.rs): nodes in one blend, the corners of a
// cell of the prior's three condition axes.
const NULD_MAX_BLEND: u32 = 8u;
// `TOP_FLOOR` and the smallest usable normal length of `unit_or_z`, as the f32
// `T::of` rounds them to (bits 0x3a83126f, 0x1e3ce508).
const NULD_TREE_TOP_FLOOR: f32 = 0.001000000047497451305389404296875;
const NULD_TREE_UNIT_MIN: f32 = 9.999999682655225388967887463487205224055287544615566730499267578125e-21;
// The salts of `randomization_shift` (core/src/conditional/mod.rs).
const NULD_RANDOMIZE_SALT_A: u32 = 0x5eed0b1au;
const NULD_RANDOMIZE_SALT_B: u32 = 0x68e31da4u;
// `OFFSET_SALTS` and `OffsetHash::Salted` (core/src/network/features.rs).
const NULD_OFFSET_SALT_X: u32 = 0x9e3779b9u;
const NULD_OFFSET_SALT_Y: u32 = 0xbb67ae85u;
const NULD_OFFSET_HASH_SALTED: u32 = 1u;

// `f32` constants written as the runtime's `f32` values (a decimal literal would be
// rounded from the exact value, which is not always the same `f32`).
// `FRAC_PI_4`, `FRAC_PI_2` rounded to f32.
const NULD_FRAC_PI_4: f32 = 0.78539818525314331055;
const NULD_FRAC_PI_2: f32 = 1.57079637050628662109;
// `DEGREES_PER_RADIAN` of runtime/src/brdf.rs: `180 / PI` divided in f32.
const NULD_DEGREES_PER_RADIAN: f32 = 57.2957763671875;
// `f32::consts::PI` and `(pi / 180) as f32` (bits 0x40490fdb, 0x3c8efa35).
const NULD_PI: f32 = 3.14159274101257324219;
const NULD_RADIANS_PER_DEGREE: f32 = 0.01745329238474369049;
// The BRDF condition's clamps (core/src/brdf.rs `MIN_ROUGHNESS`, `MAX_ROUGHNESS`,
// `MAX_THETA_O_DEG`), as `f32`.
const NULD_MIN_ROUGHNESS: f32 = 0.10000000149011611938;
const NULD_MAX_ROUGHNESS: f32 = 1.0;
const NULD_MAX_THETA_O_DEG: f32 = 89.0;
// `MAX_ROUGHNESS - MIN_ROUGHNESS` of `unit_condition` (core/src/brdf_prior.rs),
// subtracted in f64 and rounded to f32 (bits 0x3f666666).
const NULD_ROUGHNESS_SPAN: f32 = 0.89999997615814208984375;
// `F0` and `1 - F0` of `schlick_fresnel` (core/src/brdf.rs), the second
// subtracted in f64, both rounded to f32 (bits 0x3d23d70a, 0x3f75c28f).
const NULD_F0: f32 = 0.039999999105930328369140625;
const NULD_ONE_MINUS_F0: f32 = 0.959999978542327880859375;
// `4 / pi` of `hemisphere_to_square_real` (core/src/sphere.rs), divided in f64
// and rounded to f32 (bits 0x3fa2f983).
const NULD_FRAC_4_PI: f32 = 1.27323949337005615234375;
// `2^-20`: the clamp of the shifted lattice point before its logit
// (core/src/network/features.rs `LATTICE_LOGIT_EPS`).
const NULD_LATTICE_LOGIT_EPS: f32 = 0.00000095367431640625;
// `1 / UNORM16_CELLS` (core/src/quantize.rs).
const NULD_UNORM16_SCALE: f32 = 0.0000152587890625;
// `2^-24`: the instance offset's unit (core/src/network/features.rs `instance_offset`).
const NULD_INSTANCE_UNIT: f32 = 0.000000059604644775390625;
// `2^-24`: the smallest binary16 subnormal (`f16_decode_finite(1)`).
const NULD_F16_SUBNORMAL: f32 = 0.000000059604644775390625;

// ---- Buffer access ------------------------------------------------------------

// The u32 at byte offset `byte` (a multiple of 4).
fn nuld_u32(byte: u32) -> u32 {
    return nuld_blob[byte / 4u];
}

// The f32 at byte offset `byte` (a multiple of 4).
fn nuld_f32(byte: u32) -> f32 {
    return bitcast<f32>(nuld_blob[byte / 4u]);
}

// Rust: `Layout::header().kind` (core/src/blob/layout.rs).
fn nuld_kind() -> u32 {
    return nuld_u32(NULD_HEADER_KIND);
}

// Rust: `Layout::section` (core/src/blob/layout.rs): the byte offset of the first section
// with this tag; 0 (the header) if there is none, which a valid blob of the kind
// that needs the section never has.
fn nuld_section(tag: u32) -> u32 {
    return nuld_section_field(tag, NULD_SECTION_OFFSET);
}

// The length in bytes of the first section with this tag; 0 if there is none.
fn nuld_section_len(tag: u32) -> u32 {
    return nuld_section_field(tag, NULD_SECTION_LEN);
}

// The u32 at byte `field` of the first section-table row with this tag; 0 if
// there is none.
fn nuld_section_field(tag: u32, field: u32) -> u32 {
    let count = min(nuld_u32(NULD_HEADER_SECTION_COUNT), NULD_MAX_SECTIONS);
    for (var r = 0u; r < count; r++) {
        let row = NULD_HEADER_LEN + r * NULD_SECTION_ENTRY_LEN;
        if nuld_u32(row + NULD_SECTION_TAG) == tag {
            return nuld_u32(row + field);
        }
    }
    return 0u;
}

// ---- Scalars (core/src/quantize.rs, core/src/real.rs) -------------------------

// Rust: `unorm16_decode`: the cell centre `(q + 0.5) / 65536` of a u16 code.
fn nuld_unorm16_decode(q: u32) -> f32 {
    return (f32(q) + 0.5) * NULD_UNORM16_SCALE;
}

// Rust: `unpack_point` (core/src/conditional/mod.rs): the u16 codes
// `(w & 0xffff, w >> 16)` of a word holding a point (its two little-endian u16).
fn nuld_unpack_point(w: u32) -> vec2<u32> {
    return vec2<u32>(w & 0xffffu, w >> 16u);
}

// Rust: `f32::is_nan`, on the bits: a driver may assume that no float is NaN and
// fold `x != x` away, but not an integer test.
fn nuld_is_nan(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7fffffffu) > 0x7f800000u;
}

// Rust: `f32::is_finite`, on the bits.
fn nuld_is_finite(x: f32) -> bool {
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// Rust: `f32::max(x, 0).min(1)`, NaN as 0 (the unit clamps of `brdf_mixture_real`,
// `AxisCell::locate` and `condition_features`): `x` clamped into `[0, 1]` (WGSL's
// `clamp` leaves NaN to the driver).
fn nuld_clamp01(x: f32) -> f32 {
    if nuld_is_nan(x) {
        return 0.0;
    }
    return clamp(x, 0.0, 1.0);
}

// Rust: `f32::copysign`: the magnitude of `x` with the sign bit of `s`.
fn nuld_copysign(x: f32, s: f32) -> f32 {
    return bitcast<f32>((bitcast<u32>(x) & 0x7fffffffu) | (bitcast<u32>(s) & 0x80000000u));
}

// ---- Equal-area maps (core/src/sphere.rs, core/src/domain.rs) -----------------

// Rust: `square_to_sphere_real`: the octahedral equal-area map (Clarberg 2008, as
// pbrt-v4's `EqualAreaSquareToSphere`) from `[0,1]^2` to the unit sphere.
fn nuld_square_to_sphere(p: vec2<f32>) -> vec3<f32> {
    let u = 2.0 * p.x - 1.0;
    let v = 2.0 * p.y - 1.0;
    let up = abs(u);
    let vp = abs(v);
    let signed_distance = 1.0 - (up + vp);
    let d = abs(signed_distance);
    let r = 1.0 - d;
    var phi = 1.0;
    if r != 0.0 {
        phi = (vp - up) / r + 1.0;
    }
    phi = phi * NULD_FRAC_PI_4;
    let z = nuld_copysign(1.0 - r * r, signed_distance);
    let cos_phi = nuld_copysign(cos(phi), u);
    let sin_phi = nuld_copysign(sin(phi), v);
    let s = r * sqrt(max(2.0 - r * r, 0.0));
    return vec3<f32>(cos_phi * s, sin_phi * s, z);
}

// Rust: `concentric_polar` (core/src/warp.rs): the signed polar form `(r, theta)`
// of the Shirley-Chiu concentric map, `(0, 0)` at the square's centre (where Rust
// has `None`; both callers then give Rust's result bit for bit).
fn nuld_concentric_polar(p: vec2<f32>) -> vec2<f32> {
    let a = 2.0 * p.x - 1.0;
    let b = 2.0 * p.y - 1.0;
    if a == 0.0 && b == 0.0 {
        return vec2<f32>(0.0, 0.0);
    }
    if abs(a) > abs(b) {
        return vec2<f32>(a, NULD_FRAC_PI_4 * (b / a));
    }
    return vec2<f32>(b, NULD_FRAC_PI_2 - NULD_FRAC_PI_4 * (a / b));
}

// Rust: `square_to_hemisphere_real` (core/src/sphere.rs): the concentric map
// lifted to the upper hemisphere, equal-area.
fn nuld_square_to_hemisphere(p: vec2<f32>) -> vec3<f32> {
    let polar = nuld_concentric_polar(p);
    let r = polar.x;
    let theta = polar.y;
    let r2 = r * r;
    let s = r * sqrt(max(2.0 - r2, 0.0));
    return vec3<f32>(s * cos(theta), s * sin(theta), 1.0 - r2);
}

// Rust: `Domain::to_direction_real`: the hemisphere map for the hemisphere, the
// sphere map otherwise.
fn nuld_to_direction(domain: u32, p: vec2<f32>) -> vec3<f32> {
    if domain == NULD_DOMAIN_HEMISPHERE {
        return nuld_square_to_hemisphere(p);
    }
    return nuld_square_to_sphere(p);
}

// ---- The renderer's BRDF mixture warp (core/src/warp.rs, core/src/brdf.rs) -----

// Rust: `normalize_real`: `x * (1 / |x|)`, in its order of operations.
fn nuld_normalize3(x: vec3<f32>) -> vec3<f32> {
    let inv = 1.0 / sqrt(x.x * x.x + x.y * x.y + x.z * x.z);
    return vec3<f32>(x.x * inv, x.y * inv, x.z * inv);
}

// Rust: `square_to_cosine_hemisphere_real`: the concentric disk point lifted by
// `z = sqrt(max(1 - (x^2 + y^2), 0))` (Malley's method).
fn nuld_square_to_cosine_hemisphere(p: vec2<f32>) -> vec3<f32> {
    let polar = nuld_concentric_polar(p);
    let x = polar.x * cos(polar.y);
    let y = polar.x * sin(polar.y);
    return vec3<f32>(x, y, sqrt(max(1.0 - (x * x + y * y), 0.0)));
}

// Rust: `sample_ggx_vndf_real` (with `vndf_frame`): GGX visible normals (Heitz
// 2018, Listing 1) of the unit view `wo`, isotropic `alpha`.
fn nuld_sample_ggx_vndf(wo: vec3<f32>, alpha: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = nuld_normalize3(vec3<f32>(alpha * wo.x, alpha * wo.y, wo.z));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if lensq > 0.0 {
        let len = sqrt(lensq);
        t1 = vec3<f32>(0.0 - vh.y / len, vh.x / len, 0.0);
    }
    let t2 = vec3<f32>(
        vh.y * t1.z - t1.y * vh.z,
        vh.z * t1.x - t1.z * vh.x,
        vh.x * t1.y - t1.x * vh.y,
    );
    let r = sqrt(nuld_clamp01(u.x));
    let phi = 2.0 * NULD_PI * u.y;
    let p1 = r * cos(phi);
    var p2 = r * sin(phi);
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * p2;
    let q = sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0));
    let nh = vec3<f32>(
        p1 * t1.x + p2 * t2.x + q * vh.x,
        p1 * t1.y + p2 * t2.y + q * vh.y,
        p1 * t1.z + p2 * t2.z + q * vh.z,
    );
    return nuld_normalize3(vec3<f32>(alpha * nh.x, alpha * nh.y, max(nh.z, 0.0)));
}

// Rust: `brdf_mixture_direction` (core/src/conditional/mod.rs) and `brdf_mixture_real`
// (core/src/warp.rs): the point `p` warped by the renderer's mixture at the BRDF
// condition `c = (roughness, theta_o in degrees)` with lobe probability `p_s`:
// `p.x < p_s` picks the GGX lobe (visible normals at `(p.x / p_s, p.y)`, reflected),
// otherwise the cosine lobe at `((p.x - p_s) / (1 - p_s), p.y)`; a direction below
// the horizon is mirrored. Step 8 of core/FORMAT.md.
fn nuld_brdf_mixture(c: vec2<f32>, p_s: f32, p: vec2<f32>) -> vec3<f32> {
    let t = min(max(c.y, 0.0), NULD_MAX_THETA_O_DEG) * NULD_RADIANS_PER_DEGREE;
    let wo = vec3<f32>(sin(t), 0.0, cos(t));
    let roughness = min(max(c.x, NULD_MIN_ROUGHNESS), NULD_MAX_ROUGHNESS);
    let alpha = roughness * roughness;
    let ux = nuld_clamp01(p.x);
    var wi: vec3<f32>;
    if ux < p_s {
        let h = nuld_sample_ggx_vndf(wo, alpha, vec2<f32>(min(ux / p_s, 1.0), p.y));
        let d = 2.0 * (wo.x * h.x + wo.y * h.y + wo.z * h.z);
        wi = vec3<f32>(d * h.x - wo.x, d * h.y - wo.y, d * h.z - wo.z);
    } else {
        wi = nuld_square_to_cosine_hemisphere(vec2<f32>(nuld_clamp01((ux - p_s) / (1.0 - p_s)), p.y));
    }
    return nuld_normalize3(vec3<f32>(wi.x, wi.y, abs(wi.z)));
}

// ---- Point and direction sets (kinds 1 and 2; runtime/src/points.rs) ----------

// Rust: `PointSet2D::len`, `DirectionSet::len`, `ConditionalSampler::len`: points
// per set, for any kind.
fn nuld_len() -> u32 {
    if nuld_kind() == NULD_KIND_CONDITIONAL {
        return nuld_u32(nuld_section(NULD_TAG_CONDITIONAL_INFO) + NULD_INFO_N);
    }
    return nuld_u32(nuld_section(NULD_TAG_POINT_SET_INFO) + NULD_POINT_SET_LEN);
}

// Rust: `PointSet2D::set_count`, `DirectionSet::set_count`.
fn nuld_set_count() -> u32 {
    return nuld_u32(nuld_section(NULD_TAG_POINT_SET_INFO) + NULD_POINT_SET_COUNT);
}

// Rust: `DirectionSet::domain` (a `Domain` code).
fn nuld_domain() -> u32 {
    if nuld_kind() == NULD_KIND_CONDITIONAL {
        return nuld_u32(nuld_section(NULD_TAG_CONDITIONAL_INFO) + NULD_INFO_DOMAIN);
    }
    return nuld_u32(nuld_section(NULD_TAG_POINT_SET_INFO) + NULD_POINT_SET_DOMAIN);
}

// Rust: `PointSet2D::raw`: the u16 codes `(qx, qy)` of point `i` (mod len) of set
// `set_index` (mod set count).
fn nuld_raw(set_index: u32, i: u32) -> vec2<u32> {
    let info = nuld_section(NULD_TAG_POINT_SET_INFO);
    let len = nuld_u32(info + NULD_POINT_SET_LEN);
    let sets = nuld_u32(info + NULD_POINT_SET_COUNT);
    let w = nuld_u32(nuld_section(NULD_TAG_POINTS) + 4u * ((set_index % sets) * len + i % len));
    return nuld_unpack_point(w);
}

// Rust: `PointSet2D::point` (also `DirectionSet::square_point`): point `i` of set
// `set_index` in `(0,1)^2`, exactly the runtime's value.
fn nuld_point(set_index: u32, i: u32) -> vec2<f32> {
    let q = nuld_raw(set_index, i);
    return vec2<f32>(nuld_unorm16_decode(q.x), nuld_unorm16_decode(q.y));
}

// Rust: `DirectionSet::direction`: direction `i` of set `set_index`, a unit vector.
// The runtime maps in `f64` and rounds; this maps in `f32` (a few ulps apart).
fn nuld_direction(set_index: u32, i: u32) -> vec3<f32> {
    return nuld_to_direction(nuld_domain(), nuld_point(set_index, i));
}

// ---- Conditional samplers (kind 3; core/src/conditional/) -------------------

// Rust: `ConditionalInfo` (core/src/conditional/mod.rs), field for field at the same
// byte offsets and of the same size (`target` is a reserved word in WGSL; `hidden`
// is a vector, since naga's GLSL front end does not read back arrays in struct
// constructors).
struct NuldConditionalInfo {
    n: u32,
    instances: u32,
    domain: u32,
    target_code: u32,
    grid: vec2<u32>,
    weight_grid: vec2<u32>,
    cond_min: vec2<f32>,
    cond_max: vec2<f32>,
    hidden: vec3<u32>,
    activation: u32,
    lattice_generator: u32,
    warp: u32,
    instance_slots: u32,
    offset_hash: u32,
}

// Rust: `ConditionalSampler::info` (the info section read from the buffer).
fn nuld_info() -> NuldConditionalInfo {
    let o = nuld_section(NULD_TAG_CONDITIONAL_INFO);
    var info: NuldConditionalInfo;
    info.n = nuld_u32(o + NULD_INFO_N);
    info.instances = nuld_u32(o + NULD_INFO_INSTANCES);
    info.domain = nuld_u32(o + NULD_INFO_DOMAIN);
    info.target_code = nuld_u32(o + NULD_INFO_TARGET);
    info.grid = vec2<u32>(nuld_u32(o + NULD_INFO_GRID), nuld_u32(o + NULD_INFO_GRID + 4u));
    info.weight_grid = vec2<u32>(
        nuld_u32(o + NULD_INFO_WEIGHT_GRID),
        nuld_u32(o + NULD_INFO_WEIGHT_GRID + 4u),
    );
    info.cond_min = vec2<f32>(nuld_f32(o + NULD_INFO_COND_MIN), nuld_f32(o + NULD_INFO_COND_MIN + 4u));
    info.cond_max = vec2<f32>(nuld_f32(o + NULD_INFO_COND_MAX), nuld_f32(o + NULD_INFO_COND_MAX + 4u));
    for (var l = 0u; l < NULD_MAX_HIDDEN_LAYERS; l++) {
        info.hidden[l] = nuld_u32(o + NULD_INFO_HIDDEN + 4u * l);
    }
    info.activation = nuld_u32(o + NULD_INFO_ACTIVATION);
    info.lattice_generator = nuld_u32(o + NULD_INFO_LATTICE_GENERATOR);
    info.warp = nuld_u32(o + NULD_INFO_WARP);
    info.instance_slots = nuld_u32(o + NULD_INFO_INSTANCE_SLOTS);
    info.offset_hash = nuld_u32(o + NULD_INFO_OFFSET_HASH);
    return info;
}

// Rust: `ConditionalSampler::instances`: instances stored in the point table.
fn nuld_instances() -> u32 {
    return nuld_u32(nuld_section(NULD_TAG_CONDITIONAL_INFO) + NULD_INFO_INSTANCES);
}

// Rust: `ConditionalSampler` (`ConditionalSampler::view`): the info record and the
// byte offsets of the network, point-table and weight sections, and of the
// metallic axis (section 18) with its node count (0: no axis), read once per
// sample by the `nuld_sample*` functions and passed to the `*_of` functions.
struct NuldConditional {
    info: NuldConditionalInfo,
    params: u32,
    table: u32,
    weights: u32,
    metallic_nodes: u32,
    metallic_count: u32,
}

// Rust: `Blob::conditional`: the sampler of the blob in `nuld_blob`.
fn nuld_conditional() -> NuldConditional {
    return NuldConditional(
        nuld_info(),
        nuld_section(NULD_TAG_NETWORK_PARAMS),
        nuld_section(NULD_TAG_POINT_TABLE),
        nuld_section(NULD_TAG_WEIGHT_TABLE),
        nuld_section(NULD_TAG_METALLIC_NODES),
        // 2 to 8 in a valid blob with the section, 0 without.
        min(nuld_section_len(NULD_TAG_METALLIC_NODES) / 4u, NULD_MAX_METALLIC_NODES),
    );
}

// Rust: `ConditionalSampler::at_metallic`: the sampler whose network and point
// table serve a BRDF query at `metallic`: the metal layer's own (sections 16 and
// 17, present only on a prior with the metal layer) where the query reads that
// layer (metallic 1, clamped, NaN as 0), else the blob's.
fn nuld_conditional_at_metallic(metallic: f32) -> NuldConditional {
    var cs = nuld_conditional();
    // The sections exist only on a prior with the metal layer (validation), so
    // metallic 1 is the whole test; below it nothing more is read.
    if cs.info.warp == NULD_WARP_BRDF_TABLE && nuld_clamp01(metallic) >= 1.0 {
        let params = nuld_section(NULD_TAG_METAL_NETWORK_PARAMS);
        let table = nuld_section(NULD_TAG_METAL_POINT_TABLE);
        // A section never starts at byte 0 (the header): 0 is "absent".
        if params != 0u && table != 0u {
            cs.params = params;
            cs.table = table;
            // The metal layer's network and table have no metallic axis.
            cs.metallic_count = 0u;
        }
    }
    return cs;
}

// Rust: `ConditionalInfo::normalize`: the condition clamped into
// `[cond_min, cond_max]` per axis (NaN to `cond_min`), mapped to `[0,1]`.
fn nuld_normalize(info: NuldConditionalInfo, c: vec2<f32>) -> vec2<f32> {
    var u = vec2<f32>(0.0, 0.0);
    for (var a = 0u; a < 2u; a++) {
        let lo = info.cond_min[a];
        let hi = info.cond_max[a];
        var x = lo;
        if !nuld_is_nan(c[a]) {
            x = clamp(c[a], lo, hi);
        }
        let v = (x - lo) / (hi - lo);
        if nuld_is_finite(v) {
            u[a] = clamp(v, 0.0, 1.0);
        }
    }
    return u;
}

// Rust: `ConditionalInfo::denormalize`: the condition (blob units) of the
// normalized `u`, `cond_min + u (cond_max - cond_min)` per axis.
fn nuld_denormalize(info: NuldConditionalInfo, u: vec2<f32>) -> vec2<f32> {
    let lo = info.cond_min;
    let hi = info.cond_max;
    return vec2<f32>(lo.x + u.x * (hi.x - lo.x), lo.y + u.y * (hi.y - lo.y));
}

// Rust: `GridCell` (`AxisCell` per axis): the lower corner node `j0` and the
// fraction `t` within the cell.
struct NuldGridCell {
    j0: vec2<u32>,
    t: vec2<f32>,
    nodes: vec2<u32>,
}

// Rust: `GridCell::locate` (`AxisCell::locate` per axis): `s = u (nodes - 1)`,
// `j0 = min(floor(s), nodes - 2)`, `t = s - j0`.
fn nuld_locate(u: vec2<f32>, nodes: vec2<u32>) -> NuldGridCell {
    var cell: NuldGridCell;
    cell.nodes = nodes;
    for (var a = 0u; a < 2u; a++) {
        cell.j0[a] = 0u;
        cell.t[a] = 0.0;
        if nodes[a] >= 2u {
            let s = nuld_clamp01(u[a]) * f32(nodes[a] - 1u);
            let j0 = min(u32(s), nodes[a] - 2u);
            cell.j0[a] = j0;
            cell.t[a] = s - f32(j0);
        }
    }
    return cell;
}

// Rust: `GridCell::node`: the linear index `j1 nodes[0] + j0` of corner `(dx, dy)`.
fn nuld_node(cell: NuldGridCell, dx: u32, dy: u32) -> u32 {
    return (cell.j0.y + dy) * cell.nodes.x + (cell.j0.x + dx);
}

// Rust: `GridCell::lerp`, in its order of operations.
fn nuld_lerp(cell: NuldGridCell, v00: f32, v10: f32, v01: f32, v11: f32) -> f32 {
    let a = v00 + (v10 - v00) * cell.t.x;
    let b = v01 + (v11 - v01) * cell.t.x;
    return a + (b - a) * cell.t.y;
}

// Rust: `ConditionalSampler::weight`: the weight table interpolated at `cond`.
fn nuld_weight(cond: vec2<f32>) -> f32 {
    let cs = nuld_conditional();
    return nuld_weight_of(cs, nuld_normalize(cs.info, cond));
}

// `nuld_weight` at the normalized condition `u` of the sampler `cs`.
fn nuld_weight_of(cs: NuldConditional, u: vec2<f32>) -> f32 {
    return nuld_weight_table_lerp(cs, nuld_locate(u, cs.info.weight_grid), 0u);
}

// Rust: `ConditionalSampler::weight_table_lerp`: table `table` of the weight
// section (0: weights, 1: the mixture warp's lobe probabilities) interpolated in
// the weight-grid cell `cell`.
fn nuld_weight_table_lerp(cs: NuldConditional, cell: NuldGridCell, table: u32) -> f32 {
    let w = cs.weights + 4u * table * cs.info.weight_grid.x * cs.info.weight_grid.y;
    return nuld_lerp(
        cell,
        nuld_f32(w + 4u * nuld_node(cell, 0u, 0u)),
        nuld_f32(w + 4u * nuld_node(cell, 1u, 0u)),
        nuld_f32(w + 4u * nuld_node(cell, 0u, 1u)),
        nuld_f32(w + 4u * nuld_node(cell, 1u, 1u)),
    );
}

// Rust: `ConditionalSampler::square_point` (table mode): the four stored points of
// the cell around `cond`, interpolated bilinearly per coordinate (at metallic 0
// with a metallic axis).
fn nuld_square_point(cond: vec2<f32>, instance: u32, i: u32) -> vec2<f32> {
    let cs = nuld_conditional();
    return nuld_square_point_of(cs, nuld_normalize(cs.info, cond), 0.0, instance, i);
}

// Rust: `ConditionalSampler::square_point_at`: `nuld_square_point` at the
// normalized condition `u` of the sampler `cs`; with a metallic axis the points
// of the two layers around `metallic` blended by `a + (b - a) t`.
fn nuld_square_point_of(cs: NuldConditional, u: vec2<f32>, metallic: f32, instance: u32, i: u32) -> vec2<f32> {
    if cs.metallic_count < 2u {
        return nuld_layer_point(cs, u, 0u, instance, i);
    }
    let m = nuld_metallic_cell(cs, metallic);
    let a = nuld_layer_point(cs, u, m.j0, instance, i);
    let b = nuld_layer_point(cs, u, m.j0 + 1u, instance, i);
    return vec2<f32>(a.x + (b.x - a.x) * m.t, a.y + (b.y - a.y) * m.t);
}

// Rust: `MetallicCell` (core/src/conditional/metallic_axis.rs).
struct NuldMetallicCell {
    j0: u32,
    t: f32,
}

// Rust: `MetallicCell::locate`: `metallic` clamped into the axis (NaN as its
// first node), the last layer below the top whose node is `<= m`, and the
// fraction of the way to the next.
fn nuld_metallic_cell(cs: NuldConditional, metallic: f32) -> NuldMetallicCell {
    let first = nuld_f32(cs.metallic_nodes);
    let last = nuld_f32(cs.metallic_nodes + 4u * (cs.metallic_count - 1u));
    var m = first;
    if !nuld_is_nan(metallic) {
        m = clamp(metallic, first, last);
    }
    let top = cs.metallic_count - 2u;
    var j0 = 0u;
    while j0 < top && nuld_f32(cs.metallic_nodes + 4u * (j0 + 1u)) <= m {
        j0 = j0 + 1u;
    }
    let a = nuld_f32(cs.metallic_nodes + 4u * j0);
    let b = nuld_f32(cs.metallic_nodes + 4u * (j0 + 1u));
    return NuldMetallicCell(j0, clamp((m - a) / (b - a), 0.0, 1.0));
}

// Rust: `ConditionalSampler::layer_point`: layer `layer`'s (0 without an axis)
// four stored points around `u`, interpolated bilinearly per coordinate.
fn nuld_layer_point(cs: NuldConditional, u: vec2<f32>, layer: u32, instance: u32, i: u32) -> vec2<f32> {
    let cell = nuld_locate(u, cs.info.grid);
    let k = instance % cs.info.instances;
    let j = i % cs.info.n;
    let base = layer * cs.info.grid.x * cs.info.grid.y;
    let p00 = nuld_corner_point(cs, cell, base, 0u, 0u, k, j);
    let p10 = nuld_corner_point(cs, cell, base, 1u, 0u, k, j);
    let p01 = nuld_corner_point(cs, cell, base, 0u, 1u, k, j);
    let p11 = nuld_corner_point(cs, cell, base, 1u, 1u, k, j);
    return vec2<f32>(
        nuld_lerp(cell, p00.x, p10.x, p01.x, p11.x),
        nuld_lerp(cell, p00.y, p10.y, p01.y, p11.y),
    );
}

// Rust: `ConditionalInfo::point_table_index`: the entry of `(node, instance, i)` in
// the point table, laid out `[node][instance][index]`.
fn nuld_point_table_index(info: NuldConditionalInfo, node: u32, instance: u32, i: u32) -> u32 {
    return (node * info.instances + instance) * info.n + i;
}

// Rust: the `corner` closure of `ConditionalSampler::table_corners`, decoded:
// the point stored at corner `(dx, dy)` of `cell` for instance `k`, index `j`,
// in the layer whose first node is `base`.
fn nuld_corner_point(cs: NuldConditional, cell: NuldGridCell, base: u32, dx: u32, dy: u32, k: u32, j: u32) -> vec2<f32> {
    let at = nuld_point_table_index(cs.info, base + nuld_node(cell, dx, dy), k, j);
    let q = nuld_unpack_point(nuld_u32(cs.table + 4u * at));
    return vec2<f32>(nuld_unorm16_decode(q.x), nuld_unorm16_decode(q.y));
}

// ---- Network mode (core/src/network/) ----------------------------------------

// Rust: `sigmoid`: `1 / (1 + exp(-x))`.
fn nuld_sigmoid(x: f32) -> f32 {
    return 1.0 / (1.0 + exp(-x));
}

// Rust: `Activation::apply`.
fn nuld_activation(code: u32, x: f32) -> f32 {
    if code == NULD_ACTIVATION_SILU {
        return x * nuld_sigmoid(x);
    }
    return max(x, 0.0);
}

// Rust: `hash_u32` (lowbias32), wrapping u32 arithmetic.
fn nuld_hash_u32(x0: u32) -> u32 {
    var x = x0;
    x ^= x >> 16u;
    x *= 0x7feb352du;
    x ^= x >> 15u;
    x *= 0x846ca68bu;
    x ^= x >> 16u;
    return x;
}

// Rust: `instance_offset`: the instance's pseudo-random point of `[0,1)^2` under
// the plain hash (the unbiased mode's, and blobs of offset hash 0).
fn nuld_instance_offset(k: u32) -> vec2<f32> {
    let k2 = k * 2u;
    return vec2<f32>(
        f32(nuld_hash_u32(k2) >> 8u) * NULD_INSTANCE_UNIT,
        f32(nuld_hash_u32(k2 + 1u) >> 8u) * NULD_INSTANCE_UNIT,
    );
}

// Rust: `salted_instance_offset`: the instance's offset under the salted hash
// (blobs of offset hash 1).
fn nuld_salted_instance_offset(k: u32) -> vec2<f32> {
    let k2 = k * 2u;
    return vec2<f32>(
        f32(nuld_hash_u32(k2 ^ NULD_OFFSET_SALT_X) >> 8u) * NULD_INSTANCE_UNIT,
        f32(nuld_hash_u32(k2 ^ NULD_OFFSET_SALT_Y) >> 8u) * NULD_INSTANCE_UNIT,
    );
}

// Rust: `Shape::instance_offset`: the offset of instance `k` (its slot's) under
// the blob's hash.
fn nuld_network_offset(info: NuldConditionalInfo, k: u32) -> vec2<f32> {
    let key = nuld_instance_key(info, k);
    if info.offset_hash == NULD_OFFSET_HASH_SALTED {
        return nuld_salted_instance_offset(key);
    }
    return nuld_instance_offset(key);
}

// `(a b) mod n` for `a < n` as if in 64 bits (WGSL has no u64): the product
// directly when it fits in 32 bits, else by doubling and adding, each step reduced
// mod `n`.
fn nuld_mul_mod(a: u32, b0: u32, n: u32) -> u32 {
    let b = b0 % n;
    if b == 0u || a <= 0xffffffffu / b {
        return (a * b) % n;
    }
    var r = 0u;
    for (var bit = 31i; bit >= 0i; bit--) {
        // r = 2 r mod n, without overflow (r < n).
        if r >= n - r {
            r = r - (n - r);
        } else {
            r = r + r;
        }
        if ((b >> u32(bit)) & 1u) == 1u {
            // r = r + a mod n.
            if r >= n - a {
                r = r - (n - a);
            } else {
                r = r + a;
            }
        }
    }
    return r;
}

// Rust: `lattice_point`: the rank-1 lattice point `(i/n, ((i g) mod n)/n)`,
// `i` mod `n`, `i g` in 64 bits.
fn nuld_lattice_point(i0: u32, n0: u32, g: u32) -> vec2<f32> {
    let n = max(n0, 1u);
    let i = i0 % n;
    let j = nuld_mul_mod(i, g, n);
    let nf = f32(n);
    return vec2<f32>(f32(i) / nf, f32(j) / nf);
}

// Rust: `Shape::instance_key`: the instance whose offset instance `k` uses, `k`
// itself without slots, else its slot `k mod M`.
fn nuld_instance_key(info: NuldConditionalInfo, k: u32) -> u32 {
    if info.instance_slots == 0u {
        return k;
    }
    return k % info.instance_slots;
}

// Rust: `Shape::embedding_row`: the row of `E` index `i` of instance `k` adds.
fn nuld_embedding_row(info: NuldConditionalInfo, k: u32, i: u32) -> u32 {
    let row = i % info.n;
    if info.instance_slots == 0u {
        return row;
    }
    return nuld_instance_key(info, k) * info.n + row;
}

// Rust: `input_features`: the network's 11 inputs (condition, instance offset,
// shifted lattice point, lattice point), each mapped by `2x - 1`; with the
// metallic input (`metallic_input`, a blob with a metallic axis) the third is
// the clamped metallic's (NaN as 0) instead of `u v`'s.
fn nuld_input_features(info: NuldConditionalInfo, c: vec2<f32>, metallic: f32, metallic_input: bool, k: u32, i: u32) -> array<f32, 11> {
    let z = nuld_network_offset(info, k);
    let l = nuld_lattice_point(i, info.n, info.lattice_generator);
    // `shifted_lattice_point`: `frac(l + z)` with `frac(x) = x - floor(x)`.
    let lz = l + z;
    let p = lz - floor(lz);
    // `condition_features`: `(u, v, u v, u^2, v^2)` of the clamped condition.
    let u = nuld_clamp01(c.x);
    let v = nuld_clamp01(c.y);
    var third = u * v;
    if metallic_input {
        third = nuld_clamp01(metallic);
    }
    return array<f32, 11>(
        2.0 * u - 1.0,
        2.0 * v - 1.0,
        2.0 * third - 1.0,
        2.0 * (u * u) - 1.0,
        2.0 * (v * v) - 1.0,
        2.0 * z.x - 1.0,
        2.0 * z.y - 1.0,
        2.0 * p.x - 1.0,
        2.0 * p.y - 1.0,
        2.0 * l.x - 1.0,
        2.0 * l.y - 1.0,
    );
}

// Rust: `f16_decode_finite` (core/src/quantize.rs): finite IEEE binary16 bits to
// the exact `f32`, in integer operations. (`unpack2x16float` would do, but wgpu and
// naga require a capability for it that Mesa's Vulkan drivers grant only with
// `shaderFloat16`; and a subnormal `f32` intermediate could be flushed to zero.)
fn nuld_f16_decode(h: u32) -> f32 {
    let sign = (h & 0x8000u) << 16u;
    let e = (h >> 10u) & 0x1fu;
    let m = h & 0x3ffu;
    if e == 0u {
        // Zero or subnormal: m 2^-24, a normal f32 (or zero), exact.
        return bitcast<f32>(bitcast<u32>(f32(m) * NULD_F16_SUBNORMAL) | sign);
    }
    // Rebias the exponent from 15 to 127.
    return bitcast<f32>(sign | ((e + 112u) << 23u) | (m << 13u));
}

// Rust: `F16Params::get`: parameter `j` of the network section starting at byte
// `params`; the low half of a word is the even parameter.
fn nuld_param(params: u32, j: u32) -> f32 {
    let word = nuld_blob[params / 4u + j / 2u];
    return nuld_f16_decode((word >> (16u * (j & 1u))) & 0xffffu);
}

// Rust: `dot` (core/src/network/kernels.rs): `sum_k w[k] x[k]` over `len` terms, the
// weights from parameter `w`, in eight partial sums `s[k mod 8]` (k ascending),
// combined as `((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7))`.
fn nuld_dot(params: u32, w: u32, x: ptr<function, array<f32, 128>>, len: u32) -> f32 {
    var s0 = 0.0;
    var s1 = 0.0;
    var s2 = 0.0;
    var s3 = 0.0;
    var s4 = 0.0;
    var s5 = 0.0;
    var s6 = 0.0;
    var s7 = 0.0;
    // Whole chunks of NULD_DOT_LANES terms, then the remainder into s0, s1, ...
    let full = len - len % NULD_DOT_LANES;
    var k = 0u;
    for (; k < full; k += NULD_DOT_LANES) {
        s0 = s0 + nuld_param(params, w + k) * (*x)[k];
        s1 = s1 + nuld_param(params, w + k + 1u) * (*x)[k + 1u];
        s2 = s2 + nuld_param(params, w + k + 2u) * (*x)[k + 2u];
        s3 = s3 + nuld_param(params, w + k + 3u) * (*x)[k + 3u];
        s4 = s4 + nuld_param(params, w + k + 4u) * (*x)[k + 4u];
        s5 = s5 + nuld_param(params, w + k + 5u) * (*x)[k + 5u];
        s6 = s6 + nuld_param(params, w + k + 6u) * (*x)[k + 6u];
        s7 = s7 + nuld_param(params, w + k + 7u) * (*x)[k + 7u];
    }
    let rest = len - full;
    if rest > 0u { s0 = s0 + nuld_param(params, w + k) * (*x)[k]; }
    if rest > 1u { s1 = s1 + nuld_param(params, w + k + 1u) * (*x)[k + 1u]; }
    if rest > 2u { s2 = s2 + nuld_param(params, w + k + 2u) * (*x)[k + 2u]; }
    if rest > 3u { s3 = s3 + nuld_param(params, w + k + 3u) * (*x)[k + 3u]; }
    if rest > 4u { s4 = s4 + nuld_param(params, w + k + 4u) * (*x)[k + 4u]; }
    if rest > 5u { s5 = s5 + nuld_param(params, w + k + 5u) * (*x)[k + 5u]; }
    if rest > 6u { s6 = s6 + nuld_param(params, w + k + 6u) * (*x)[k + 6u]; }
    return ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7));
}

// Rust: `Network::evaluate`: the two outputs (before the sigmoid) of the network on
// `input` for index `i`: hidden layer 1 `act((b1[o] + E[i][o]) + dot(W1[o], a))`,
// further layers `act(b[o] + dot(W[o], a))`, outputs `bo[o] + dot(Wo[o], a)`.
fn nuld_network_evaluate(cs: NuldConditional, row: u32, input: array<f32, 11>) -> vec2<f32> {
    let info = cs.info;
    let params = cs.params;
    var a: array<f32, 128>;
    var b: array<f32, 128>;
    for (var k = 0u; k < NULD_INPUTS; k++) {
        a[k] = input[k];
    }
    var fan_in = NULD_INPUTS;
    let h1 = info.hidden[0];
    // `Shape::first_layer_offset` and `Shape::embedding_offset` (`row` is below
    // the rows, `nuld_embedding_row`).
    var off = max(info.instance_slots, 1u) * info.n * h1;
    let embedding = row * h1;
    for (var l = 0u; l < NULD_MAX_HIDDEN_LAYERS; l++) {
        let h = min(info.hidden[l], NULD_MAX_WIDTH);
        if h == 0u {
            break;
        }
        let bias = off + h * fan_in;
        for (var o = 0u; o < h; o++) {
            var acc = nuld_param(params, bias + o);
            if l == 0u {
                acc = acc + nuld_param(params, embedding + o);
            }
            b[o] = nuld_activation(info.activation, acc + nuld_dot(params, off + o * fan_in, &a, fan_in));
        }
        for (var o = 0u; o < h; o++) {
            a[o] = b[o];
        }
        off = bias + h;
        fan_in = h;
    }
    let bias = off + NULD_OUTPUTS * fan_in;
    var out = vec2<f32>(
        nuld_param(params, bias) + nuld_dot(params, off, &a, fan_in),
        nuld_param(params, bias + 1u) + nuld_dot(params, off + fan_in, &a, fan_in),
    );
    if info.warp != NULD_WARP_EQUAL_AREA {
        // Rust: `lattice_logit`: the outputs are a residual on the logit of the
        // shifted lattice point, read back from its input features.
        for (var o = 0u; o < NULD_OUTPUTS; o++) {
            let q = clamp((input[7u + o] + 1.0) * 0.5, NULD_LATTICE_LOGIT_EPS, 1.0 - NULD_LATTICE_LOGIT_EPS);
            out[o] = out[o] + log(q / (1.0 - q));
        }
    }
    return out;
}

// Rust: `NetworkSampler::square_point` (network mode): the network's
// outputs through the sigmoid, for any u32 instance (`nuld_instance_key`).
fn nuld_network_square_point(cond: vec2<f32>, instance: u32, i: u32) -> vec2<f32> {
    let cs = nuld_conditional();
    return nuld_network_square_point_of(cs, nuld_normalize(cs.info, cond), 0.0, instance, i);
}

// `nuld_network_square_point` at the normalized condition `u` and `metallic`
// (read only with a metallic axis) of the sampler `cs`.
fn nuld_network_square_point_of(cs: NuldConditional, u: vec2<f32>, metallic: f32, instance: u32, i: u32) -> vec2<f32> {
    let row = nuld_embedding_row(cs.info, instance, i);
    let input = nuld_input_features(cs.info, u, metallic, cs.metallic_count >= 2u, instance, i);
    let out = nuld_network_evaluate(cs, row, input);
    return vec2<f32>(nuld_sigmoid(out.x), nuld_sigmoid(out.y));
}

// ---- The environment prior (core/src/envmap_tree.rs, core/src/quadtree.rs) ----

// Rust: `EnvmapTree` (`EnvmapTree::view`): the byte offsets of the records and the
// top table, the levels and the top grid.
struct NuldTree {
    nodes: u32,
    top: u32,
    levels: u32,
    grid: u32,
    // `TreeInfo::top_levels` (0 read as the legacy 3) and a top-table row's
    // entries, `node_count(top_levels)`.
    top_levels: u32,
    top_nodes: u32,
    // The leaf shape's corner values (tag 19); 0 without them (uniform leaves).
    corners: u32,
    // The detail index (tag 20) and tables (tag 21); 0 without them.
    detail_index: u32,
    detail: u32,
    // Whole tables in tag 21.
    detail_tables: u32,
    // The fine tables (tag 22; 0 without them) and how many.
    fine: u32,
    fine_tables: u32,
}

// Rust: `ConditionalSampler::tree`: the blob's environment prior.
fn nuld_tree() -> NuldTree {
    let info = nuld_section(NULD_TAG_ENVMAP_TREE_INFO);
    let named = nuld_u32(info + NULD_TREE_INFO_TOP_LEVELS);
    let top_levels = min(select(named, NULD_TREE_LEGACY_TOP_LEVELS, named == 0u), NULD_TREE_MAX_TOP_LEVELS);
    return NuldTree(
        nuld_section(NULD_TAG_ENVMAP_TREE_NODES),
        nuld_section(NULD_TAG_ENVMAP_TREE_TOP),
        min(nuld_u32(info + NULD_TREE_INFO_LEVELS), NULD_TREE_MAX_LEVELS),
        max(nuld_u32(info + NULD_TREE_INFO_GRID), 2u),
        top_levels,
        ((1u << (2u * (top_levels + 1u))) - 4u) / 3u,
        nuld_section(NULD_TAG_ENVMAP_TREE_CORNERS),
        nuld_section(NULD_TAG_ENVMAP_TREE_DETAIL_INDEX),
        nuld_section(NULD_TAG_ENVMAP_TREE_DETAIL),
        nuld_section_len(NULD_TAG_ENVMAP_TREE_DETAIL) / (4u * NULD_TREE_DETAIL_LEN),
        nuld_section(NULD_TAG_ENVMAP_TREE_FINE_DETAIL),
        nuld_section_len(NULD_TAG_ENVMAP_TREE_FINE_DETAIL) / (4u * NULD_TREE_FINE_LEN),
    );
}

// Rust: `EnvmapTree::shape_of`'s detail lookup: the byte offset of leaf
// `(x, y)`'s table and its cells per axis, `(0, 0)` where it has none (entry
// 0, or past the tables).
fn nuld_leaf_detail(t: NuldTree, x: u32, y: u32) -> vec2<u32> {
    if t.detail_index == 0u || t.detail == 0u {
        return vec2<u32>(0u, 0u);
    }
    let e = nuld_u32(t.detail_index + 4u * ((y << t.levels) + x));
    let n = e & ~NULD_TREE_FINE_BIT;
    if (e & NULD_TREE_FINE_BIT) != 0u {
        if n == 0u || n > t.fine_tables || t.fine == 0u {
            return vec2<u32>(0u, 0u);
        }
        return vec2<u32>(t.fine + 4u * (n - 1u) * NULD_TREE_FINE_LEN, NULD_TREE_FINE_SIDE);
    }
    if n == 0u || n > t.detail_tables {
        return vec2<u32>(0u, 0u);
    }
    return vec2<u32>(t.detail + 4u * (n - 1u) * NULD_TREE_DETAIL_LEN, NULD_TREE_DETAIL_SIDE);
}

// Rust: `cell_table::value`: value `i` of the table at byte `table`, as `positive`.
fn nuld_cell_value(table: u32, i: u32) -> f32 {
    return nuld_positive(nuld_f32(table + 4u * i));
}

// Rust: `cell_table::interval`: the interval of `u` among the `k` weights at
// value `first` of the table (of sum `total > 0`), as `(index, place)`.
fn nuld_cell_interval(u: f32, table: u32, first: u32, k: u32, total: f32) -> vec2<f32> {
    let goal = nuld_clamp01(u) * total;
    var below = 0.0;
    var last = 0u;
    for (var i = 0u; i < k; i++) {
        let w = nuld_cell_value(table, first + i);
        if w > 0.0 {
            last = i;
            if goal < below + w {
                return vec2<f32>(f32(i), nuld_clamp01((goal - below) / w));
            }
            below = below + w;
        }
    }
    return vec2<f32>(f32(last), 1.0);
}

// Rust: `cell_table::sum` of the `k` values from value `first`, in order.
fn nuld_cell_sum(table: u32, first: u32, n: u32) -> f32 {
    var s = 0.0;
    for (var i = 0u; i < n; i++) {
        s = s + nuld_cell_value(table, first + i);
    }
    return s;
}

// Rust: `cell_table::sample_table` (its point and density): the detail of step
// 9 at `local` for the table of `k x k` cells at byte `table`, as `(x, y,
// density)`.
fn nuld_cell_sample(local: vec2<f32>, table: u32, k: u32) -> vec3<f32> {
    let u = vec2<f32>(nuld_clamp01(local.x), nuld_clamp01(local.y));
    let total = nuld_cell_sum(table, 0u, k);
    if !(total > 0.0 && nuld_is_finite(total)) {
        return vec3<f32>(u, 1.0);
    }
    let kf = f32(k);
    let ix = nuld_cell_interval(u.x, table, 0u, k, total);
    let a = u32(ix.x);
    let x = nuld_clamp01((ix.x + ix.y) / kf);
    let px = kf * (nuld_cell_value(table, a) / total);
    let column = k + a * k;
    let s = nuld_cell_sum(table, column, k);
    if !(s > 0.0 && nuld_is_finite(s)) {
        return vec3<f32>(x, u.y, px);
    }
    let iy = nuld_cell_interval(u.y, table, column, k, s);
    let y = nuld_clamp01((iy.x + iy.y) / kf);
    return vec3<f32>(x, y, px * (kf * (nuld_cell_value(table, column + u32(iy.x)) / s)));
}

// Rust: `cell_table::table_pdf`: the density at `local` of the table of `k x k`
// cells at byte `table`.
fn nuld_cell_pdf(local: vec2<f32>, table: u32, k: u32) -> f32 {
    let total = nuld_cell_sum(table, 0u, k);
    if !(total > 0.0 && nuld_is_finite(total)) {
        return 1.0;
    }
    let kf = f32(k);
    let a = min(u32(floor(nuld_clamp01(local.x) * kf)), k - 1u);
    let b = min(u32(floor(nuld_clamp01(local.y) * kf)), k - 1u);
    let px = kf * (nuld_cell_value(table, a) / total);
    let column = k + a * k;
    let s = nuld_cell_sum(table, column, k);
    if !(s > 0.0 && nuld_is_finite(s)) {
        return px;
    }
    return px * (kf * (nuld_cell_value(table, column + b) / s));
}

// Rust: `positive` (core/src/bilinear.rs): `v` if positive and finite, else 0.
fn nuld_positive(v: f32) -> f32 {
    if v > 0.0 && nuld_is_finite(v) {
        return v;
    }
    return 0.0;
}

// Rust: `EnvmapTree::corners_of`: leaf `(x, y)`'s corners `w00, w10, w01, w11`,
// each read as `positive`.
fn nuld_leaf_corners(t: NuldTree, x: u32, y: u32) -> vec4<f32> {
    let row = (1u << t.levels) + 1u;
    let c = t.corners + 4u * (y * row + x);
    return vec4<f32>(
        nuld_positive(nuld_f32(c)),
        nuld_positive(nuld_f32(c + 4u)),
        nuld_positive(nuld_f32(c + 4u * row)),
        nuld_positive(nuld_f32(c + 4u * row + 4u)),
    );
}

// Rust: `bilinear::sample_linear`.
fn nuld_sample_linear(u0: f32, a: f32, b: f32) -> f32 {
    let u = nuld_clamp01(u0);
    let d = a + sqrt(max(a * a + (b * b - a * a) * u, 0.0));
    if d > 0.0 {
        return nuld_clamp01(u * (a + b) / d);
    }
    return u;
}

// Rust: `bilinear::linear_pdf`.
fn nuld_linear_pdf(x: f32, a: f32, b: f32) -> f32 {
    if a + b > 0.0 {
        return 2.0 * ((a + (b - a) * nuld_clamp01(x)) / (a + b));
    }
    return 1.0;
}

// Rust: `bilinear::sample_bilinear` (its point and density): the leaf shape of
// step 9 at `local` for corners `w`, as `(x, y, density)`; the identity with
// density 1 where the corners' sum is not positive and finite.
fn nuld_shape(local: vec2<f32>, w: vec4<f32>) -> vec3<f32> {
    let u = vec2<f32>(nuld_clamp01(local.x), nuld_clamp01(local.y));
    let sum = (w.x + w.y) + (w.z + w.w);
    if !(sum > 0.0 && nuld_is_finite(sum)) {
        return vec3<f32>(u, 1.0);
    }
    let a = w.x + w.z;
    let b = w.y + w.w;
    let x = nuld_sample_linear(u.x, a, b);
    let c = w.x + (w.y - w.x) * x;
    let d = w.z + (w.w - w.z) * x;
    let y = nuld_sample_linear(u.y, c, d);
    return vec3<f32>(x, y, nuld_linear_pdf(x, a, b) * nuld_linear_pdf(y, c, d));
}

// Rust: `bilinear::bilinear_pdf`: the leaf shape's density at `local`.
fn nuld_shape_pdf(local: vec2<f32>, w: vec4<f32>) -> f32 {
    let x = nuld_clamp01(local.x);
    let y = nuld_clamp01(local.y);
    let sum = (w.x + w.y) + (w.z + w.w);
    if !(sum > 0.0 && nuld_is_finite(sum)) {
        return 1.0;
    }
    let a = w.x + w.z;
    let b = w.y + w.w;
    let c = w.x + (w.y - w.x) * x;
    let d = w.z + (w.w - w.z) * x;
    return nuld_linear_pdf(x, a, b) * nuld_linear_pdf(y, c, d);
}

// Rust: `quadtree::morton`: `x` on the even bits, `y` on the odd bits (16 bits
// each here: a tree has at most 12 levels).
fn nuld_morton(x: u32, y: u32) -> u32 {
    var a = x & 0xffffu;
    a = (a | (a << 8u)) & 0x00ff00ffu;
    a = (a | (a << 4u)) & 0x0f0f0f0fu;
    a = (a | (a << 2u)) & 0x33333333u;
    a = (a | (a << 1u)) & 0x55555555u;
    var b = y & 0xffffu;
    b = (b | (b << 8u)) & 0x00ff00ffu;
    b = (b | (b << 4u)) & 0x0f0f0f0fu;
    b = (b | (b << 2u)) & 0x33333333u;
    b = (b | (b << 1u)) & 0x55555555u;
    return a | (b << 1u);
}

// Rust: `node_index`: the record of node `(x, y)` of level `level >= 1`.
fn nuld_node_index(level: u32, x: u32, y: u32) -> u32 {
    return ((1u << (2u * level)) - 1u) / 3u - 1u + nuld_morton(x, y);
}

// Rust: `NodeRecord::weight`: `(n.m1 + sqrt((n.m1)^2 + s^2)) / 2` of record `r`.
fn nuld_node_weight(t: NuldTree, r: u32, n: vec3<f32>) -> f32 {
    let o = t.nodes + 16u * r;
    let a = n.x * nuld_f32(o) + n.y * nuld_f32(o + 4u) + n.z * nuld_f32(o + 8u);
    let s = nuld_f32(o + 12u);
    return (a + sqrt(a * a + s * s)) * 0.5;
}

// Rust: `Lit`: the tree lit by the normal `n`, with the top table's cell.
struct NuldLit {
    n: vec3<f32>,
    j0: vec2<u32>,
    t: vec2<f32>,
}

// Rust: `unit_or_z`: `v / |v|`, or `+z` for a zero, tiny or non-finite length.
fn nuld_unit_or_z(v: vec3<f32>) -> vec3<f32> {
    let len = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    if len > NULD_TREE_UNIT_MIN && nuld_is_finite(len) {
        return vec3<f32>(v.x / len, v.y / len, v.z / len);
    }
    return vec3<f32>(0.0, 0.0, 1.0);
}

// Rust: `EnvmapTree::lit_square`: lit by the normal whose octahedral square point
// is `q` (clamped), the top table's cell read from `q`.
fn nuld_lit_square(t: NuldTree, q0: vec2<f32>) -> NuldLit {
    let q = vec2<f32>(nuld_clamp01(q0.x), nuld_clamp01(q0.y));
    var lit: NuldLit;
    lit.n = nuld_unit_or_z(nuld_square_to_sphere(q));
    let g = t.grid - 1u;
    for (var a = 0u; a < 2u; a++) {
        let s = nuld_clamp01(q[a]) * f32(g);
        let j0 = min(u32(floor(s)), g - 1u);
        lit.j0[a] = j0;
        lit.t[a] = s - f32(j0);
    }
    return lit;
}

// Rust: `Lit::top_weights` (one of its four): top-table node `node` interpolated at the normal.
fn nuld_top_weight(t: NuldTree, lit: NuldLit, node: u32) -> f32 {
    let row = lit.j0.y * t.grid + lit.j0.x;
    let w00 = nuld_f32(t.top + 4u * (row * t.top_nodes + node));
    let w10 = nuld_f32(t.top + 4u * ((row + 1u) * t.top_nodes + node));
    let w01 = nuld_f32(t.top + 4u * ((row + t.grid) * t.top_nodes + node));
    let w11 = nuld_f32(t.top + 4u * ((row + t.grid + 1u) * t.top_nodes + node));
    let a = w00 + (w10 - w00) * lit.t.x;
    let b = w01 + (w11 - w01) * lit.t.x;
    return a + (b - a) * lit.t.y;
}

// Rust: `Lit::children` then `usable`: the four children's weights of node
// `(x, y)` of level `level` (`[i + 2 j]`), negative, NaN and infinite ones as 0,
// four zeros as four ones.
fn nuld_children(t: NuldTree, lit: NuldLit, level: u32, x: u32, y: u32) -> vec4<f32> {
    let first = nuld_node_index(level + 1u, 2u * x, 2u * y);
    var w: vec4<f32>;
    for (var k = 0u; k < 4u; k++) {
        var v = nuld_node_weight(t, first + k, lit.n);
        if level < t.top_levels {
            v = max(nuld_top_weight(t, lit, first + k), v * NULD_TREE_TOP_FLOOR);
        }
        if !(v > 0.0 && nuld_is_finite(v)) {
            v = 0.0;
        }
        w[k] = v;
    }
    let sum = (w.x + w.y) + (w.z + w.w);
    if sum > 0.0 && nuld_is_finite(sum) {
        return w;
    }
    return vec4<f32>(1.0, 1.0, 1.0, 1.0);
}

// Rust: `choose` for one axis: the part of `u` below `p` (side 0) or above it
// (side 1), `u` rescaled into it; an empty part is never picked.
struct NuldSplit {
    u: f32,
    side: u32,
}

fn nuld_split(u: f32, p: f32, low: f32, high: f32) -> NuldSplit {
    if (u < p && low > 0.0) || high <= 0.0 {
        return NuldSplit(nuld_clamp01(u / p), 0u);
    }
    return NuldSplit(nuld_clamp01((u - p) / (1.0 - p)), 1u);
}

// Rust: `EnvmapTree::sample_square` (`quadtree::sample`): the direction at primary
// point `u` for the normal whose octahedral square point is `q`, and its
// solid-angle pdf.
struct NuldTreeSample {
    direction: vec3<f32>,
    pdf: f32,
}

fn nuld_tree_sample_square(t: NuldTree, q: vec2<f32>, u: vec2<f32>) -> NuldTreeSample {
    let lit = nuld_lit_square(t, q);
    var ux = nuld_clamp01(u.x);
    var uy = nuld_clamp01(u.y);
    var x = 0u;
    var y = 0u;
    var p = 1.0;
    for (var l = 0u; l < t.levels; l++) {
        let w = nuld_children(t, lit, l, x, y);
        let left = w.x + w.z;
        let right = w.y + w.w;
        let cx = nuld_split(ux, left / (left + right), left, right);
        ux = cx.u;
        let bottom = w[cx.side];
        let top = w[cx.side + 2u];
        let cy = nuld_split(uy, bottom / (bottom + top), bottom, top);
        uy = cy.u;
        p = p * (w[cx.side + 2u * cy.side] / ((w.x + w.y) + (w.z + w.w)));
        x = 2u * x + cx.side;
        y = 2u * y + cy.side;
    }
    let side = f32(1u << t.levels);
    let detail = nuld_leaf_detail(t, x, y);
    if detail.y != 0u || t.corners != 0u {
        var shaped: vec3<f32>;
        if detail.y != 0u {
            shaped = nuld_cell_sample(vec2<f32>(ux, uy), detail.x, detail.y);
        } else {
            shaped = nuld_shape(vec2<f32>(ux, uy), nuld_leaf_corners(t, x, y));
        }
        let point = vec2<f32>(
            min((f32(x) + shaped.x) / side, 1.0),
            min((f32(y) + shaped.y) / side, 1.0),
        );
        return NuldTreeSample(
            nuld_square_to_sphere(point),
            p * side * side * shaped.z / (4.0 * NULD_PI),
        );
    }
    let point = vec2<f32>(min((f32(x) + ux) / side, 1.0), min((f32(y) + uy) / side, 1.0));
    return NuldTreeSample(nuld_square_to_sphere(point), p * side * side / (4.0 * NULD_PI));
}

// Rust: `EnvmapTree::pdf_square` (`quadtree::pdf`): the solid-angle pdf at the
// unit direction `d` for the normal whose octahedral square point is `q`. The
// direction's square point goes through the driver's `atan`
// (`nuld_sphere_to_square`): a direction within its rounding of a leaf's edge may
// be read in the neighbouring leaf.
fn nuld_tree_pdf_square(t: NuldTree, q: vec2<f32>, d: vec3<f32>) -> f32 {
    let lit = nuld_lit_square(t, q);
    let sq = nuld_sphere_to_square(d);
    let side = 1u << t.levels;
    let lx = min(u32(floor(nuld_clamp01(sq.x) * f32(side))), side - 1u);
    let ly = min(u32(floor(nuld_clamp01(sq.y) * f32(side))), side - 1u);
    var prob = 1.0;
    for (var l = 0u; l < t.levels; l++) {
        let shift = t.levels - l - 1u;
        let w = nuld_children(t, lit, l, lx >> (shift + 1u), ly >> (shift + 1u));
        let k = ((lx >> shift) & 1u) + 2u * ((ly >> shift) & 1u);
        prob = prob * (w[k] / ((w.x + w.y) + (w.z + w.w)));
    }
    let s = f32(side);
    let detail = nuld_leaf_detail(t, lx, ly);
    if detail.y != 0u || t.corners != 0u {
        let local = vec2<f32>(
            nuld_clamp01(nuld_clamp01(sq.x) * s - f32(lx)),
            nuld_clamp01(nuld_clamp01(sq.y) * s - f32(ly)),
        );
        if detail.y != 0u {
            return prob * s * s * nuld_cell_pdf(local, detail.x, detail.y) / (4.0 * NULD_PI);
        }
        return prob * s * s * nuld_shape_pdf(local, nuld_leaf_corners(t, lx, ly)) / (4.0 * NULD_PI);
    }
    return prob * s * s / (4.0 * NULD_PI);
}

// Rust: `sphere_to_square_real` (core/src/sphere.rs), with the driver's `atan`.
fn nuld_sphere_to_square(d: vec3<f32>) -> vec2<f32> {
    let x = abs(d.x);
    let y = abs(d.y);
    let z = abs(d.z);
    let r = sqrt(max(1.0 - z, 0.0));
    let a = max(x, y);
    let b = min(x, y);
    var ratio = 0.0;
    if a != 0.0 {
        ratio = b / a;
    }
    var phi = atan(ratio) / NULD_FRAC_PI_2;
    if x < y {
        phi = 1.0 - phi;
    }
    var v = phi * r;
    var u = r - v;
    if d.z < 0.0 {
        let w = u;
        u = 1.0 - v;
        v = 1.0 - w;
    }
    u = nuld_copysign(u, d.x);
    v = nuld_copysign(v, d.y);
    return vec2<f32>(0.5 * (u + 1.0), 0.5 * (v + 1.0));
}

// Rust: `randomization_shift`: the unbiased mode's shift for `seed`, two 24-bit
// unorms.
fn nuld_randomization_shift(seed: u32) -> vec2<f32> {
    let a = nuld_hash_u32(seed ^ NULD_RANDOMIZE_SALT_A);
    let b = nuld_hash_u32(a ^ NULD_RANDOMIZE_SALT_B);
    return vec2<f32>(f32(a >> 8u) * NULD_INSTANCE_UNIT, f32(b >> 8u) * NULD_INSTANCE_UNIT);
}

// Rust: `torus_shift`: `p + shift` on the unit torus, in `[0, 1)`.
fn nuld_torus_shift(p: vec2<f32>, shift: vec2<f32>) -> vec2<f32> {
    var out = vec2<f32>(0.0, 0.0);
    for (var a = 0u; a < 2u; a++) {
        let x = p[a] + shift[a];
        let f = x - floor(x);
        if f < 1.0 && f >= 0.0 {
            out[a] = f;
        }
    }
    return out;
}

// Rust: `randomized_point`: the unbiased mode's primary point, lattice point `i`
// (mod `n`) shifted on the torus by instance `instance`'s offset, then by
// `nuld_randomization_shift(seed)`.
fn nuld_randomized_point(info: NuldConditionalInfo, instance: u32, i: u32, seed: u32) -> vec2<f32> {
    let l = nuld_lattice_point(i, info.n, info.lattice_generator);
    let at_instance = nuld_torus_shift(l, nuld_instance_offset(instance));
    return nuld_torus_shift(at_instance, nuld_randomization_shift(seed));
}

// ---- The glTF BRDF with metallic (core/src/brdf.rs) ----------------------------

// Rust: `clamp_roughness`: `roughness` clamped into `[0.1, 1]`, NaN as 0.1.
fn nuld_clamp_roughness(roughness: f32) -> f32 {
    if nuld_is_nan(roughness) {
        return NULD_MIN_ROUGHNESS;
    }
    return clamp(roughness, NULD_MIN_ROUGHNESS, NULD_MAX_ROUGHNESS);
}

// Rust: `clamp_theta_o_deg`: `theta_o` in degrees clamped into `[0, 89]`, NaN as 0.
fn nuld_clamp_theta_o(theta_o_deg: f32) -> f32 {
    if nuld_is_nan(theta_o_deg) {
        return 0.0;
    }
    return clamp(theta_o_deg, 0.0, NULD_MAX_THETA_O_DEG);
}

// Rust: `view_direction_real`: the xz-plane view `(sin t, 0, cos t)` of `theta_o`
// (degrees, clamped), `t` in radians.
fn nuld_view_direction(theta_o_deg: f32) -> vec3<f32> {
    let t = nuld_clamp_theta_o(theta_o_deg) * NULD_RADIANS_PER_DEGREE;
    return vec3<f32>(sin(t), 0.0, cos(t));
}

// Rust: `ggx_d`: `alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)` for `n.h > 0`
// (above 1 as 1), 0 for `n.h <= 0` or NaN.
fn nuld_ggx_d(n_dot_h: f32, alpha: f32) -> f32 {
    if nuld_is_nan(n_dot_h) || n_dot_h <= 0.0 {
        return 0.0;
    }
    let c = min(n_dot_h, 1.0);
    let a2 = alpha * alpha;
    let t = c * c * (a2 - 1.0) + 1.0;
    return a2 / (NULD_PI * t * t);
}

// Rust: `smith_vis`: the height-correlated Smith visibility
// `0.5 / ((n.l) sqrt(a2 + (1 - a2)(n.v)^2) + (n.v) sqrt(a2 + (1 - a2)(n.l)^2))`,
// `a2 = alpha^2`, the cosines clamped into `[0, 1]` (NaN as 0); 0 when both are 0.
fn nuld_smith_vis(n_dot_v: f32, n_dot_l: f32, alpha: f32) -> f32 {
    let nv = nuld_clamp01(n_dot_v);
    let nl = nuld_clamp01(n_dot_l);
    let a2 = alpha * alpha;
    let denom = nl * sqrt(a2 + (1.0 - a2) * nv * nv) + nv * sqrt(a2 + (1.0 - a2) * nl * nl);
    if denom > 0.0 {
        return 0.5 / denom;
    }
    return 0.0;
}

// Rust: `schlick_fresnel`: `F0 + (1 - F0)(1 - |v.h|)^5`, `|v.h|` clamped into
// `[0, 1]` (NaN as 0, so `F = 1`).
fn nuld_schlick_fresnel(v_dot_h: f32) -> f32 {
    let c = nuld_clamp01(abs(v_dot_h));
    let m = 1.0 - c;
    let m2 = m * m;
    return NULD_F0 + NULD_ONE_MINUS_F0 * m2 * m2 * m;
}

// Rust: `gltf_metallic_parts_of`: the diffuse `(1 - m)(1 - F) / pi` and specular
// `((1 - m) F + m) D Vis` parts from the pair's cosines
// `c = (n.v, n.l, n.h, v.h)`, `alpha` and the clamped metallic `m`.
fn nuld_gltf_metallic_parts_of(c: vec4<f32>, alpha: f32, metallic: f32) -> vec2<f32> {
    let f = nuld_schlick_fresnel(c.w);
    let dielectric = 1.0 - metallic;
    return vec2<f32>(
        dielectric * ((1.0 - f) / NULD_PI),
        (dielectric * f + metallic) * nuld_ggx_d(c.z, alpha) * nuld_smith_vis(c.x, c.y, alpha),
    );
}

// Rust: `gltf_metallic` (`gltf_metallic_parts` with `pair_cosines`, `alpha` and
// `clamp_metallic`): the glTF 2.0 BRDF with metallic `m` and base colour 1,
// `(1 - m)((1 - F)/pi + F D Vis) + m D Vis`, for the unit view `wo` and light
// `wi` (normal `+z`), the roughness clamped into `[0.1, 1]` and the metallic into
// `[0, 1]` (`nuld_clamp01`: `MIN_METALLIC` is 0, `MAX_METALLIC` 1; NaN as 0); 0
// when either direction is at or below the horizon or not finite, or `wo + wi = 0`.
fn nuld_gltf_metallic(wo: vec3<f32>, wi: vec3<f32>, roughness: f32, metallic: f32) -> f32 {
    let finite = nuld_is_finite(wo.x) && nuld_is_finite(wo.y) && nuld_is_finite(wo.z)
        && nuld_is_finite(wi.x) && nuld_is_finite(wi.y) && nuld_is_finite(wi.z);
    if !finite || wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    let s = vec3<f32>(wo.x + wi.x, wo.y + wi.y, wo.z + wi.z);
    let len = sqrt(s.x * s.x + s.y * s.y + s.z * s.z);
    if nuld_is_nan(len) || len <= 0.0 {
        return 0.0;
    }
    let h = vec3<f32>(s.x / len, s.y / len, s.z / len);
    let v_dot_h = wo.x * h.x + wo.y * h.y + wo.z * h.z;
    let c = vec4<f32>(min(wo.z, 1.0), min(wi.z, 1.0), h.z, v_dot_h);
    let r = nuld_clamp_roughness(roughness);
    let parts = nuld_gltf_metallic_parts_of(c, r * r, nuld_clamp01(metallic));
    return parts.x + parts.y;
}

// ---- The BRDF prior (core/src/brdf_prior.rs, core/src/marginal2d.rs) --------

// Rust: `BrdfPrior` (`BrdfPrior::view` over the blob's sections): the condition
// grid `(G_r, G_t, G_m)`, the tables' vertices per axis `S` (`Marginal2D`'s
// `nx = ny`) and the byte offsets of the data, marginal, conditional and mass
// sections (tags 11-14).
struct NuldBrdfPrior {
    grid: vec3<u32>,
    size: u32,
    data: u32,
    marginal: u32,
    conditional: u32,
    masses: u32,
}

// Rust: `ConditionalSampler::brdf_prior`: the blob's BRDF prior (warp 3).
fn nuld_brdf_prior() -> NuldBrdfPrior {
    let info = nuld_section(NULD_TAG_BRDF_PRIOR_INFO);
    let grid = vec3<u32>(
        nuld_u32(info + NULD_PRIOR_INFO_GRID),
        nuld_u32(info + NULD_PRIOR_INFO_GRID + 4u),
        nuld_u32(info + NULD_PRIOR_INFO_GRID + 8u),
    );
    return NuldBrdfPrior(
        max(grid, vec3<u32>(2u, 2u, 2u)),
        max(nuld_u32(info + NULD_PRIOR_INFO_SIZE), 2u),
        nuld_section(NULD_TAG_BRDF_PRIOR_DATA),
        nuld_section(NULD_TAG_BRDF_PRIOR_MARGINAL),
        nuld_section(NULD_TAG_BRDF_PRIOR_CONDITIONAL),
        nuld_section(NULD_TAG_BRDF_PRIOR_MASSES),
    );
}

// Rust: `Blend` (core/src/marginal2d.rs): `(node, weight)` pairs, here always the
// eight corners of the condition's cell in `Blend::multilinear`'s corner order
// (bit `k` of corner `c` = `4 h + l` picks the upper node along axis `k`; `lo`
// holds corners 0-3, `hi` corners 4-7). A corner the Rust blend leaves out has
// weight 0 here, and adds `0 * v = +0` to every sum (`v` finite and `>= 0`): the
// same bits.
struct NuldBlend {
    nodes_lo: vec4<u32>,
    nodes_hi: vec4<u32>,
    weights_lo: vec4<f32>,
    weights_hi: vec4<f32>,
}

// Rust: `reads_metal_layer`: metallic 1 exactly (clamped, NaN as 0) on a grid
// with the metal layer (`G_m = 3`).
fn nuld_reads_metal_layer(pr: NuldBrdfPrior, metallic: f32) -> bool {
    return pr.grid.z == 3u && nuld_clamp01(metallic) >= 1.0;
}

// Rust: `BrdfPrior::blend` (`mass_weighted_blend`, with `unit_condition`,
// `Blend::multilinear` and `Blend::from_pairs`): the nodes around `cond =
// (roughness, theta_o in degrees, metallic)`, clamped (NaN to the lower ends)
// and placed on `[0,1]^3`, each weighed by its multilinear weight times its mass
// (weights not above 0 as 0). With the metal layer (`G_m = 3`) the metallic axis
// spans the first two layers; a query at metallic 1 takes the metal layer's four
// nodes around `(roughness, theta_o)` alone (corners 0-3, past `2 G_r G_t`;
// corners 4-7 repeat them at weight 0, as Rust's two-parameter blend has none).
fn nuld_brdf_blend(pr: NuldBrdfPrior, cond: vec3<f32>) -> NuldBlend {
    // `unit_condition`; the metallic's `(m - 0) / (1 - 0)` is `m` exactly; the
    // view's `1 - sqrt(1 - theta_o / 89)`, nodes crowding towards grazing.
    let rest = max(1.0 - nuld_clamp_theta_o(cond.y) / NULD_MAX_THETA_O_DEG, 0.0);
    var unit = vec3<f32>(
        (nuld_clamp_roughness(cond.x) - NULD_MIN_ROUGHNESS) / NULD_ROUGHNESS_SPAN,
        1.0 - sqrt(rest),
        nuld_clamp01(cond.z),
    );
    let metal = nuld_reads_metal_layer(pr, cond.z);
    let counts = vec3<u32>(pr.grid.xy, min(pr.grid.z, 2u));
    var first = 0u;
    if metal {
        // The metallic coordinate at node 0 of a two-node axis: weight 1 - 0.
        unit.z = 0.0;
        first = 2u * pr.grid.x * pr.grid.y;
    }
    var lower = vec3<u32>(0u, 0u, 0u);
    var frac = vec3<f32>(0.0, 0.0, 0.0);
    var stride = vec3<u32>(0u, 0u, 0u);
    var s = 1u;
    for (var k = 0u; k < 3u; k++) {
        stride[k] = s;
        let c = counts[k];
        s = s * c;
        let pos = nuld_clamp01(unit[k]) * f32(c - 1u);
        let i = min(u32(floor(pos)), c - 2u);
        lower[k] = i;
        frac[k] = pos - f32(i);
    }
    var b: NuldBlend;
    for (var corner = 0u; corner < NULD_MAX_BLEND; corner++) {
        var node = first;
        var w = 1.0;
        for (var k = 0u; k < 3u; k++) {
            let up = (corner >> k) & 1u;
            // A metal query's corners 4-7: the same nodes as 0-3 (at weight 0).
            node = node + (lower[k] + select(up, 0u, metal && k == 2u)) * stride[k];
            if up == 1u {
                w = w * frac[k];
            } else {
                w = w * (1.0 - frac[k]);
            }
        }
        var m = w * nuld_f32(pr.masses + 4u * node);
        if !(m > 0.0) {
            m = 0.0;
        }
        if corner < 4u {
            b.nodes_lo[corner] = node;
            b.weights_lo[corner] = m;
        } else {
            b.nodes_hi[corner - 4u] = node;
            b.weights_hi[corner - 4u] = m;
        }
    }
    return b;
}

// Rust: `Picked::blended` (in `Marginal2D`): the blend of the `f32` at element `at` of each
// node's block of `block` elements of the section at byte `section`, summed pairwise in
// corner order, ((0 + 1) + (2 + 3)) + ((4 + 5) + (6 + 7)). Corners of weight 0 add 0, so
// this is the Rust's pairwise sum over the nodes it keeps, which form a sub-cube.
fn nuld_blended(b: NuldBlend, section: u32, block: u32, at: u32) -> f32 {
    var p: array<f32, 8>;
    for (var k = 0u; k < 4u; k++) {
        p[k] = b.weights_lo[k] * nuld_f32(section + 4u * (b.nodes_lo[k] * block + at));
        p[k + 4u] = b.weights_hi[k] * nuld_f32(section + 4u * (b.nodes_hi[k] * block + at));
    }
    return ((p[0] + p[1]) + (p[2] + p[3])) + ((p[4] + p[5]) + (p[6] + p[7]));
}

// Rust: `Marginal2D::m`: the blend's marginal CDF at row `j`.
fn nuld_prior_m(pr: NuldBrdfPrior, b: NuldBlend, j: u32) -> f32 {
    return nuld_blended(b, pr.marginal, pr.size, j);
}

// Rust: `Marginal2D::c`: the blend's conditional CDF at vertex `i` of row `j`.
fn nuld_prior_c(pr: NuldBrdfPrior, b: NuldBlend, j: u32, i: u32) -> f32 {
    return nuld_blended(b, pr.conditional, pr.size * pr.size, j * pr.size + i);
}

// Rust: `Marginal2D::f`: the blend's density at vertex `i` of row `j`.
fn nuld_prior_f(pr: NuldBrdfPrior, b: NuldBlend, j: u32, i: u32) -> f32 {
    return nuld_blended(b, pr.data, pr.size * pr.size, j * pr.size + i);
}

// Rust: `Marginal2D::c_at`: the conditional CDF at vertex `i` of the row at
// `y = (j + t) dy`.
fn nuld_prior_c_at(pr: NuldBrdfPrior, b: NuldBlend, j: u32, t: f32, i: u32) -> f32 {
    return (1.0 - t) * nuld_prior_c(pr, b, j, i) + t * nuld_prior_c(pr, b, j + 1u, i);
}

// Rust: `Marginal2D::f_at`: the density at vertex `i` of the row at `y = (j + t) dy`.
fn nuld_prior_f_at(pr: NuldBrdfPrior, b: NuldBlend, j: u32, t: f32, i: u32) -> f32 {
    return (1.0 - t) * nuld_prior_f(pr, b, j, i) + t * nuld_prior_f(pr, b, j + 1u, i);
}

// The `cdf` closures of `Marginal2D::sample`'s two `search`es: along `y`
// (`axis` 0) the marginal `m(k)`, along `x` (`axis` 1) the row's `c_at(j, t, k)`.
fn nuld_prior_cdf(pr: NuldBrdfPrior, b: NuldBlend, axis: u32, j: u32, t: f32, k: u32) -> f32 {
    if axis == 0u {
        return nuld_prior_m(pr, b, k);
    }
    return nuld_prior_c_at(pr, b, j, t, k);
}

// Rust: `search` (core/src/marginal2d.rs): the interval `k` in `0..n-1` with
// `cdf(k) <= goal < cdf(k + 1)` (Rust's `target`) of `nuld_prior_cdf` (binary search), stepped off
// intervals without mass: down while empty, then up while empty.
fn nuld_search(pr: NuldBrdfPrior, b: NuldBlend, axis: u32, j: u32, t: f32, n: u32, goal: f32) -> u32 {
    var lo = 0u;
    var hi = n - 1u;
    while hi - lo > 1u {
        let mid = lo + (hi - lo) / 2u;
        if nuld_prior_cdf(pr, b, axis, j, t, mid) <= goal {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    var k = lo;
    // The interval has mass: the common case, and the moves below would not start
    // (two blended reads instead of four, as the Rust).
    if nuld_prior_cdf(pr, b, axis, j, t, k + 1u) > nuld_prior_cdf(pr, b, axis, j, t, k) {
        return k;
    }
    while k > 0u && nuld_prior_cdf(pr, b, axis, j, t, k + 1u) <= nuld_prior_cdf(pr, b, axis, j, t, k) {
        k -= 1u;
    }
    while k + 2u < n && nuld_prior_cdf(pr, b, axis, j, t, k + 1u) <= nuld_prior_cdf(pr, b, axis, j, t, k) {
        k += 1u;
    }
    return k;
}

// Rust: `solve_linear`: the `s` in `[0, 1]` with `a s + (b - a) s^2 / 2 = v`
// (`a, b >= 0`), as `2 v / (a + sqrt(a^2 + 2 (b - a) v))`; 0 without mass.
fn nuld_solve_linear(a: f32, b: f32, v0: f32) -> f32 {
    let v = max(v0, 0.0);
    let disc = max(a * a + 2.0 * (b - a) * v, 0.0);
    let den = a + sqrt(disc);
    if den > 0.0 {
        return nuld_clamp01(2.0 * v / den);
    }
    return 0.0;
}

// Rust: `cell` (core/src/marginal2d.rs): the cell `k <= n - 2` of `x` (clamped into
// `[0, 1]`) on `n` vertices and the position `s` in it, `x = (k + s) / (n - 1)`.
struct NuldVertexCell {
    k: u32,
    s: f32,
}

fn nuld_vertex_cell(x: f32, n: u32) -> NuldVertexCell {
    let pos = nuld_clamp01(x) * f32(n - 1u);
    let k = min(u32(floor(pos)), n - 2u);
    return NuldVertexCell(k, nuld_clamp01(pos - f32(k)));
}

// Rust: `Marginal2D::pdf`: the blend's bilinear value at `p` (clamped) over its
// mass, per unit area of the square; 0 for a blend without mass.
fn nuld_marginal_pdf(pr: NuldBrdfPrior, b: NuldBlend, p: vec2<f32>) -> f32 {
    let total = nuld_prior_m(pr, b, pr.size - 1u);
    if !(total > 0.0) {
        return 0.0;
    }
    let cx = nuld_vertex_cell(p.x, pr.size);
    let cy = nuld_vertex_cell(p.y, pr.size);
    let i = cx.k;
    let s = cx.s;
    let j = cy.k;
    let t = cy.s;
    let lo = (1.0 - s) * nuld_prior_f(pr, b, j, i) + s * nuld_prior_f(pr, b, j, i + 1u);
    let hi = (1.0 - s) * nuld_prior_f(pr, b, j + 1u, i) + s * nuld_prior_f(pr, b, j + 1u, i + 1u);
    return ((1.0 - t) * lo + t * hi) / total;
}

// Rust: `Marginal2D::sample`: the point of the square drawn from the blend's
// density at primary sample `u` (clamped, NaN as 0) and its density
// (`nuld_marginal_pdf`): the marginal's row interval and the root within it for
// `y`, then the same along the row blended at `y` for `x`.
struct NuldPointPdf {
    p: vec2<f32>,
    pdf: f32,
}

fn nuld_marginal_sample(pr: NuldBrdfPrior, b: NuldBlend, u: vec2<f32>) -> NuldPointPdf {
    let n = pr.size;
    let total = nuld_prior_m(pr, b, n - 1u);
    let target_y = nuld_clamp01(u.y) * total;
    let j = nuld_search(pr, b, 0u, 0u, 0.0, n, target_y);
    let dy = 1.0 / f32(n - 1u);
    let r0 = nuld_prior_c(pr, b, j, n - 1u);
    let r1 = nuld_prior_c(pr, b, j + 1u, n - 1u);
    let t = nuld_solve_linear(r0 * dy, r1 * dy, target_y - nuld_prior_m(pr, b, j));
    let y = (f32(j) + t) * dy;
    let row_total = nuld_prior_c_at(pr, b, j, t, n - 1u);
    // A row without mass (only at a row interval's end): any x, density 0.
    var x = nuld_clamp01(u.x);
    if row_total > 0.0 {
        let target_x = nuld_clamp01(u.x) * row_total;
        let i = nuld_search(pr, b, 1u, j, t, n, target_x);
        let dx = 1.0 / f32(n - 1u);
        let g0 = nuld_prior_f_at(pr, b, j, t, i);
        let g1 = nuld_prior_f_at(pr, b, j, t, i + 1u);
        let s = nuld_solve_linear(g0 * dx, g1 * dx, target_x - nuld_prior_c_at(pr, b, j, t, i));
        x = (f32(i) + s) * dx;
    }
    let p = vec2<f32>(min(x, 1.0), min(y, 1.0));
    return NuldPointPdf(p, nuld_marginal_pdf(pr, b, p));
}

// `libm::atanf`'s constants (FreeBSD s_atanf.c): `atan(0.5)`, `atan(1)`,
// `atan(1.5)` and `atan(inf) = pi/2` split in high parts (bits 0x3eed6338,
// 0x3f490fda, 0x3f7b985e, 0x3fc90fda) and low parts (bits 0x31ac3769, 0x33222168,
// 0x33140fb4, 0x33a22168), and the coefficients of its polynomial.
const NULD_ATAN_HI_0: f32 = 4.6364760399e-01;
const NULD_ATAN_HI_1: f32 = 7.8539812565e-01;
const NULD_ATAN_HI_2: f32 = 9.8279368877e-01;
const NULD_ATAN_HI_3: f32 = 1.5707962513e+00;
const NULD_ATAN_LO_0: f32 = 5.0121582440e-09;
const NULD_ATAN_LO_1: f32 = 3.7748947079e-08;
const NULD_ATAN_LO_2: f32 = 3.4473217170e-08;
const NULD_ATAN_LO_3: f32 = 7.5497894159e-08;
const NULD_ATAN_T0: f32 = 3.3333328366e-01;
const NULD_ATAN_T1: f32 = -1.9999158382e-01;
const NULD_ATAN_T2: f32 = 1.4253635705e-01;
const NULD_ATAN_T3: f32 = -1.0648017377e-01;
const NULD_ATAN_T4: f32 = 6.1687607318e-02;

// Rust: `libm::atanf`, operation for operation (its argument reduction to
// `atan(c) + atan((x - c) / (1 + c x))` for `c` of 0.5, 1, 1.5 and inf, `id` 0-3,
// and `id` 4 for none, Rust's -1). The built-in `atan` may be far less accurate
// (Vulkan allows 4096 ulps; lavapipe's moves the BRDF prior's pdf of a direction
// by 3e-4 relative), and the half vector's square point feeds the prior's table
// interpolation.
fn nuld_atan(x0: f32) -> f32 {
    var x = x0;
    let hx = bitcast<u32>(x);
    let negative = (hx >> 31u) != 0u;
    let ix = hx & 0x7fffffffu;
    if ix >= 0x4c800000u {
        // |x| >= 2^26: pi/2 (Rust adds 2^-120, which rounds away), NaN as itself.
        if nuld_is_nan(x) {
            return x;
        }
        if negative {
            return -NULD_ATAN_HI_3;
        }
        return NULD_ATAN_HI_3;
    }
    var id = 4u;
    if ix < 0x3ee00000u {
        // |x| < 0.4375; below 2^-12, x itself.
        if ix < 0x39800000u {
            return x;
        }
    } else {
        x = abs(x);
        if ix < 0x3f980000u {
            if ix < 0x3f300000u {
                // 7/16 <= |x| < 11/16
                x = (2.0 * x - 1.0) / (2.0 + x);
                id = 0u;
            } else {
                // 11/16 <= |x| < 19/16
                x = (x - 1.0) / (x + 1.0);
                id = 1u;
            }
        } else if ix < 0x401c0000u {
            // |x| < 2.4375
            x = (x - 1.5) / (1.0 + 1.5 * x);
            id = 2u;
        } else {
            // 2.4375 <= |x| < 2^26
            x = -1.0 / x;
            id = 3u;
        }
    }
    let z = x * x;
    let w = z * z;
    let s1 = z * (NULD_ATAN_T0 + w * (NULD_ATAN_T2 + w * NULD_ATAN_T4));
    let s2 = w * (NULD_ATAN_T1 + w * NULD_ATAN_T3);
    if id == 4u {
        return x - x * (s1 + s2);
    }
    var hi = NULD_ATAN_HI_3;
    var lo = NULD_ATAN_LO_3;
    if id == 0u {
        hi = NULD_ATAN_HI_0;
        lo = NULD_ATAN_LO_0;
    } else if id == 1u {
        hi = NULD_ATAN_HI_1;
        lo = NULD_ATAN_LO_1;
    } else if id == 2u {
        hi = NULD_ATAN_HI_2;
        lo = NULD_ATAN_LO_2;
    }
    let r = hi - ((x * (s1 + s2) - lo) - x);
    if negative {
        return -r;
    }
    return r;
}

// Rust: `hemisphere_to_square_real` (core/src/sphere.rs), with libm's `atan`
// (`nuld_atan`): the inverse of `nuld_square_to_hemisphere` without `atan2`, per wedge of
// the concentric map (`|x| >= |y|`: `a = r sign(x)`, `b = a atan(y / x) 4/pi`;
// else `b = r sign(y)`, `a = b atan(x / y) 4/pi`) with `r = sqrt(1 - |z|)`; the
// pole and NaN read as the centre.
fn nuld_hemisphere_to_square(d: vec3<f32>) -> vec2<f32> {
    let r = min(sqrt(max(1.0 - abs(d.z), 0.0)), 1.0);
    let x = d.x;
    let y = d.y;
    let planar = x != 0.0 || y != 0.0;
    if !(r > 0.0) || !planar || nuld_is_nan(x) || nuld_is_nan(y) {
        return vec2<f32>(0.5, 0.5);
    }
    var a: f32;
    var b: f32;
    if abs(x) >= abs(y) {
        a = nuld_copysign(r, x);
        b = a * nuld_atan(y / x) * NULD_FRAC_4_PI;
    } else {
        b = nuld_copysign(r, y);
        a = b * nuld_atan(x / y) * NULD_FRAC_4_PI;
    }
    return vec2<f32>(0.5 * (a + 1.0), 0.5 * (b + 1.0));
}

// Rust: the maps of core/src/brdf_prior/square.rs (`half_vector_direction`,
// `half_vector_point`, `star_direction`, `star_point`): a light direction `w`
// (or a square point `w.xy`) and the Jacobian `jac`, the solid angle of `wi`
// per solid angle of the table's hemisphere direction; `jac = 0` where Rust has
// `None`. `nuld_mirror` and `nuld_half_vector_of` hold a direction and `wo.h`.
struct NuldHalfVector {
    w: vec3<f32>,
    jac: f32,
}

// Rust: `stretch`: the half-vector square's stretch `k = roughness^(1/4)` at the
// clamped roughness.
fn nuld_stretch(roughness: f32) -> f32 {
    return sqrt(sqrt(nuld_clamp_roughness(roughness)));
}

// Rust: `mirror`: the mirror `wi = 2 (wo.h) h - wo` (normalized, in `w`) of
// the unit view about the unit half vector and `wo.h` (in `jac`); `jac` 0 where
// `wo.h <= 0` or `wi` has no length.
fn nuld_mirror(wo: vec3<f32>, h: vec3<f32>) -> NuldHalfVector {
    let missing = NuldHalfVector(vec3<f32>(0.0, 0.0, 1.0), 0.0);
    let c = wo.x * h.x + wo.y * h.y + wo.z * h.z;
    if !(c > 0.0) {
        return missing;
    }
    let two_c = 2.0 * c;
    let v = vec3<f32>(two_c * h.x - wo.x, two_c * h.y - wo.y, two_c * h.z - wo.z);
    let len = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    if !(len > 0.0 && nuld_is_finite(len)) {
        return missing;
    }
    return NuldHalfVector(vec3<f32>(v.x / len, v.y / len, v.z / len), c);
}

// Rust: `half_vector_of`: the half vector `h = (wo + wi) / |wo + wi|` (in `w`)
// and `wo.h` (in `jac`); `jac` 0 where `wi.z <= 0`, `h.z <= 0` or `wo.h <= 0`.
fn nuld_half_vector_of(wo: vec3<f32>, wi: vec3<f32>) -> NuldHalfVector {
    let missing = NuldHalfVector(vec3<f32>(0.0, 0.0, 1.0), 0.0);
    if !(wi.z > 0.0) {
        return missing;
    }
    let v = vec3<f32>(wo.x + wi.x, wo.y + wi.y, wo.z + wi.z);
    let len = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    if !(len > 0.0 && nuld_is_finite(len)) {
        return missing;
    }
    let h = vec3<f32>(v.x / len, v.y / len, v.z / len);
    let c = wo.x * h.x + wo.y * h.y + wo.z * h.z;
    if !(h.z > 0.0 && c > 0.0) {
        return missing;
    }
    return NuldHalfVector(h, c);
}

// Rust: `RADIAL_CROSSOVER`, `RADIAL_INVERSE_STEPS`: the radial square's table
// slope where its stretch turns from `k_s` to `k_b`, and the most steps of its
// inverse.
const NULD_RADIAL_CROSSOVER: f32 = 0.25;
const NULD_RADIAL_INVERSE_STEPS: u32 = 64u;

// Rust: `radial_stretch`: the radial square's stretch `g = sigma / t` (in `x`)
// and slope derivative `sigma'(t)` (in `y`) at a unit table direction of
// `rho^2` and `z^2`.
fn nuld_radial_stretch(ks: f32, kb: f32, rho2: f32, z2: f32) -> vec2<f32> {
    let az2 = NULD_RADIAL_CROSSOVER * NULD_RADIAL_CROSSOVER * z2;
    let d = rho2 + az2;
    let g = (kb * rho2 + ks * az2) / d;
    return vec2<f32>(g, g + 2.0 * (kb - ks) * rho2 * az2 / (d * d));
}

// Rust: `radial_direction`: the light direction `wi = 2 (wo.h) h - wo` of the
// half vector `h = (g s.x, g s.y, s.z) / L` of the square point `p` (`s` its
// hemisphere direction, `g` the radial stretch), and `4 (wo.h) g sigma' / L^3`;
// none where `wo.h <= 0` or `wi.z <= 0`.
fn nuld_radial_direction(wo: vec3<f32>, p: vec2<f32>, ks: f32, kb: f32) -> NuldHalfVector {
    let missing = NuldHalfVector(vec3<f32>(0.0, 0.0, 1.0), 0.0);
    let s = nuld_square_to_hemisphere(p);
    let rs = nuld_radial_stretch(ks, kb, s.x * s.x + s.y * s.y, s.z * s.z);
    let g = rs.x;
    let v = vec3<f32>(g * s.x, g * s.y, s.z);
    let len = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    if !(len > 0.0) {
        return missing;
    }
    let m = nuld_mirror(wo, vec3<f32>(v.x / len, v.y / len, v.z / len));
    if !(m.jac > 0.0) {
        return missing;
    }
    let jac = 4.0 * m.jac * g * rs.y / (len * len * len);
    if !(m.w.z > 0.0 && nuld_is_finite(jac) && jac > 0.0) {
        return missing;
    }
    return NuldHalfVector(m.w, jac);
}

// Rust: `radial_table_slope`: the table slope `t` with `t g(t) = sigma`, by
// Newton steps kept inside a shrinking bracket (bisection where a step leaves
// it).
fn nuld_radial_table_slope(ks: f32, kb: f32, sigma: f32) -> f32 {
    if !(sigma > 0.0) {
        return 0.0;
    }
    var lo = sigma / max(kb, ks);
    var hi = sigma / min(kb, ks);
    var t = lo;
    for (var i = 0u; i < NULD_RADIAL_INVERSE_STEPS; i++) {
        // The unit table direction of slope `t` is `(t, 1)` up to scale.
        let rs = nuld_radial_stretch(ks, kb, t * t, 1.0);
        let miss = t * rs.x - sigma;
        if miss > 0.0 {
            hi = t;
        } else {
            lo = t;
        }
        let step = t - miss / rs.y;
        var next = 0.5 * (lo + hi);
        if step > lo && step < hi {
            next = step;
        }
        if !(next > lo && next < hi) || next == t {
            break;
        }
        t = next;
    }
    return t;
}

// Rust: `radial_point`: the square point (in `w.xy`) of the half vector of
// `wo` and `wi` under the radial square, and the same Jacobian; none where
// `wi.z <= 0`, `h.z <= 0`, `wo.h <= 0` or the slope passes `10^18`.
fn nuld_radial_point(wo: vec3<f32>, wi: vec3<f32>, ks: f32, kb: f32) -> NuldHalfVector {
    let missing = NuldHalfVector(vec3<f32>(0.5, 0.5, 0.0), 0.0);
    let hc = nuld_half_vector_of(wo, wi);
    if !(hc.jac > 0.0) {
        return missing;
    }
    let h = hc.w;
    let hxy = sqrt(h.x * h.x + h.y * h.y);
    let sigma = hxy / h.z;
    if !(sigma < 1e18) {
        return missing;
    }
    var e = vec2<f32>(1.0, 0.0);
    if hxy > 0.0 {
        e = vec2<f32>(h.x / hxy, h.y / hxy);
    }
    let t = nuld_radial_table_slope(ks, kb, sigma);
    let z = 1.0 / sqrt(1.0 + t * t);
    let rho = t * z;
    let rs = nuld_radial_stretch(ks, kb, rho * rho, z * z);
    let g = rs.x;
    let len = sqrt(g * g * rho * rho + z * z);
    let jac = 4.0 * hc.jac * g * rs.y / (len * len * len);
    if !(nuld_is_finite(jac) && jac > 0.0) {
        return missing;
    }
    let s = vec3<f32>(rho * e.x, rho * e.y, z);
    return NuldHalfVector(vec3<f32>(nuld_hemisphere_to_square(s), 0.0), jac);
}

// Rust: `horizon_reach`: how far the half vector's slope plane reaches above
// the horizon along the unit direction `e` from the mirror direction (towards
// the viewer without the cancellation).
fn nuld_horizon_reach(wo: vec3<f32>, e: vec2<f32>) -> f32 {
    let t = wo.x / max(wo.z, 1e-6);
    let te = t * e.x;
    let root = sqrt(1.0 + te * te);
    if te < 0.0 {
        return 1.0 / (root - te);
    }
    return te + root;
}

// Rust: `star_jacobian`: `2 (wo.h) k^2 / ((1 + rho^2)^(3/2) den^3)`.
fn nuld_star_jacobian(c: f32, rho: f32, k: f32, den: f32) -> f32 {
    let len2 = 1.0 + rho * rho;
    return 2.0 * c * k * k / (len2 * sqrt(len2) * den * den * den);
}

// Rust: `star_direction`: the light direction of the metal layer's star-disc
// point `p` at the zoom `k`: the square's hemisphere direction to the unit disc
// (Lambert), its radius `r` to the slope `rho = k r / (1 - (1 - k / R(e)) r)`
// along its direction `e`, the half vector `(rho e, 1) / L` and its mirror.
fn nuld_star_direction(wo: vec3<f32>, p: vec2<f32>, k: f32) -> NuldHalfVector {
    let missing = NuldHalfVector(vec3<f32>(0.0, 0.0, 1.0), 0.0);
    let d = nuld_square_to_hemisphere(p);
    let z = max(d.z, 0.0);
    let f = sqrt(1.0 + z);
    let q = vec2<f32>(d.x / f, d.y / f);
    let r = min(sqrt(q.x * q.x + q.y * q.y), 1.0);
    var e = vec2<f32>(1.0, 0.0);
    if r > 0.0 {
        e = vec2<f32>(q.x / r, q.y / r);
    }
    // `1 - (1 - k / R) r` with `1 - r = z / (1 + r)`: no cancellation.
    let den = z / (1.0 + r) + k / nuld_horizon_reach(wo, e) * r;
    let rho = k * r / den;
    let l = sqrt(1.0 + rho * rho);
    let h = vec3<f32>(rho * e.x / l, rho * e.y / l, 1.0 / l);
    let m = nuld_mirror(wo, h);
    if !(m.jac > 0.0) {
        return missing;
    }
    let wi = m.w;
    let c = m.jac;
    let jac = nuld_star_jacobian(c, rho, k, den);
    if !(wi.z > 0.0 && nuld_is_finite(jac) && jac > 0.0) {
        return missing;
    }
    return NuldHalfVector(wi, jac);
}

// Rust: `star_point`: the star-disc point (in `w.xy`) of `wi`: the slope
// `rho e` of `h = (wo + wi) / |wo + wi|` at disc radius `r = rho / g`, `g = k +
// (1 - k / R(e)) rho`, lifted to the hemisphere; none where `wi.z <= 0`, `h.z <= 0`,
// `wo.h <= 0` or the slope is past the horizon's reach.
fn nuld_star_point(wo: vec3<f32>, wi: vec3<f32>, k: f32) -> NuldHalfVector {
    let missing = NuldHalfVector(vec3<f32>(0.5, 0.5, 0.0), 0.0);
    let hc = nuld_half_vector_of(wo, wi);
    if !(hc.jac > 0.0) {
        return missing;
    }
    let h = hc.w;
    let c = hc.jac;
    let s = vec2<f32>(h.x / h.z, h.y / h.z);
    let rho = sqrt(s.x * s.x + s.y * s.y);
    var e = vec2<f32>(1.0, 0.0);
    if rho > 0.0 {
        e = vec2<f32>(s.x / rho, s.y / rho);
    }
    let reach = nuld_horizon_reach(wo, e);
    if !(rho < reach && nuld_is_finite(rho)) {
        return missing;
    }
    let g = k + (1.0 - k / reach) * rho;
    let r = rho / g;
    let den = k / g;
    let z = k * (reach - rho) / (reach * g) * (1.0 + r);
    let jac = nuld_star_jacobian(c, rho, k, den);
    if !(nuld_is_finite(jac) && jac > 0.0) {
        return missing;
    }
    let lift = sqrt(1.0 + z);
    let dir = vec3<f32>(r * e.x * lift, r * e.y * lift, z);
    return NuldHalfVector(vec3<f32>(nuld_hemisphere_to_square(dir), 0.0), jac);
}

// Rust: `query_square`'s `PriorSquare::direction`: the metal layer's star disc
// of zoom `roughness^2` where a query reads it, else the shared layers' radial
// square (`k_s = roughness`, `k_b = roughness^(1/4)`).
fn nuld_prior_direction(pr: NuldBrdfPrior, cond: vec3<f32>, wo: vec3<f32>, p: vec2<f32>) -> NuldHalfVector {
    if nuld_reads_metal_layer(pr, cond.z) {
        let r = nuld_clamp_roughness(cond.x);
        return nuld_star_direction(wo, p, r * r);
    }
    return nuld_radial_direction(wo, p, nuld_clamp_roughness(cond.x), nuld_stretch(cond.x));
}

// Rust: `query_square`'s `PriorSquare::point`: the inverse of
// `nuld_prior_direction`.
fn nuld_prior_point(pr: NuldBrdfPrior, cond: vec3<f32>, wo: vec3<f32>, wi: vec3<f32>) -> NuldHalfVector {
    if nuld_reads_metal_layer(pr, cond.z) {
        let r = nuld_clamp_roughness(cond.x);
        return nuld_star_point(wo, wi, r * r);
    }
    return nuld_radial_point(wo, wi, nuld_clamp_roughness(cond.x), nuld_stretch(cond.x));
}

// Rust: `BrdfPrior::sample`: the light direction of primary sample `u` for the
// xz-plane view of `cond = (roughness, theta_o in degrees, metallic)` and its
// solid-angle pdf, the square's over `2 pi |dwi/dh|`; `(+z, 0)` for a point without
// a direction. Step 11 of core/FORMAT.md.
fn nuld_brdf_prior_sample(pr: NuldBrdfPrior, cond: vec3<f32>, u: vec2<f32>) -> NuldTreeSample {
    let wo = nuld_view_direction(cond.y);
    let s = nuld_marginal_sample(pr, nuld_brdf_blend(pr, cond), u);
    let hv = nuld_prior_direction(pr, cond, wo, s.p);
    if hv.jac > 0.0 {
        let pdf = s.pdf / (2.0 * NULD_PI * hv.jac);
        // Only tables near the float range (a hostile blob's) overflow.
        if nuld_is_finite(pdf) {
            return NuldTreeSample(hv.w, pdf);
        }
    }
    return NuldTreeSample(vec3<f32>(0.0, 0.0, 1.0), 0.0);
}

// Rust: `BrdfPrior::pdf`: the solid-angle pdf of `nuld_brdf_prior_sample`'s
// directions at the unit direction `wi` (xz-plane view); 0 where the prior draws
// nothing.
fn nuld_brdf_prior_pdf(pr: NuldBrdfPrior, cond: vec3<f32>, wi: vec3<f32>) -> f32 {
    let wo = nuld_view_direction(cond.y);
    let hv = nuld_prior_point(pr, cond, wo, wi);
    if hv.jac > 0.0 {
        let pdf = nuld_marginal_pdf(pr, nuld_brdf_blend(pr, cond), hv.w.xy) / (2.0 * NULD_PI * hv.jac);
        if nuld_is_finite(pdf) {
            return pdf;
        }
    }
    return 0.0;
}

// ---- Samples (runtime/src/brdf.rs) -------------------------------------

// Rust: `Sample`: a unit direction (local frame, `z` = normal), the estimator
// weight (of its condition; for BRDF samplers on the tabulated prior, warp 3,
// `f cos / pdf` of the direction), and the prior's solid-angle pdf at the
// direction (0 for a sampler without an exact prior). 32 bytes in a storage
// buffer.
struct NuldSample {
    direction: vec3<f32>,
    weight: f32,
    pdf: f32,
}

// Rust: `ConditionalSampler::sample` (table mode): direction `i` (mod n) of
// instance `instance` (mod instances) at condition `cond` (blob units; for BRDF
// samplers `(roughness, theta_o in degrees)`, the view in the xz-plane, `+x` side;
// for environment samplers the normal's octahedral square point); a BRDF sampler
// on the tabulated prior (warp 3) samples the dielectric (metallic 0).
fn nuld_sample(cond: vec2<f32>, instance: u32, i: u32) -> NuldSample {
    return nuld_sample_metallic(cond, 0.0, instance, i);
}

// Rust: `ConditionalSampler::sample_metallic`: `nuld_sample` for a BRDF of
// metallic `metallic` (clamped into `[0, 1]`, NaN as 0), which warp 3 reads and
// every other warp ignores; at metallic 1 the metal layer's points where the
// blob has them (`nuld_conditional_at_metallic`).
fn nuld_sample_metallic(cond: vec2<f32>, metallic: f32, instance: u32, i: u32) -> NuldSample {
    let cs = nuld_conditional_at_metallic(metallic);
    let u = nuld_normalize(cs.info, cond);
    return nuld_mapped(cs, nuld_square_point_of(cs, u, metallic, instance, i), u, metallic);
}

// Rust: `ConditionalSampler::sample_randomized` (the unbiased mode): the blob's
// lattice point shifted by the instance's offset and `seed`'s random vector
// (`nuld_randomized_point`) through the prior; no table or network read.
fn nuld_sample_randomized(cond: vec2<f32>, instance: u32, i: u32, seed: u32) -> NuldSample {
    return nuld_sample_randomized_metallic(cond, 0.0, instance, i, seed);
}

// Rust: `ConditionalSampler::sample_randomized_metallic`: the unbiased mode at
// metallic `metallic` (`nuld_sample_metallic`).
fn nuld_sample_randomized_metallic(cond: vec2<f32>, metallic: f32, instance: u32, i: u32, seed: u32) -> NuldSample {
    let cs = nuld_conditional();
    let u = nuld_normalize(cs.info, cond);
    return nuld_mapped(cs, nuld_randomized_point(cs.info, instance, i, seed), u, metallic);
}

// Rust: `NetworkSampler::sample` (network mode): as `nuld_sample`;
// instances wrap modulo the instance slots (without slots every u32 is its own set).
fn nuld_sample_network(cond: vec2<f32>, instance: u32, i: u32) -> NuldSample {
    return nuld_sample_network_metallic(cond, 0.0, instance, i);
}

// Rust: `NetworkSampler::sample_metallic`: network mode at metallic `metallic`.
fn nuld_sample_network_metallic(cond: vec2<f32>, metallic: f32, instance: u32, i: u32) -> NuldSample {
    let cs = nuld_conditional_at_metallic(metallic);
    let u = nuld_normalize(cs.info, cond);
    return nuld_mapped(cs, nuld_network_square_point_of(cs, u, metallic, instance, i), u, metallic);
}

// Rust: `NetworkSampler::sample_randomized`: the unbiased mode, the same samples
// as `nuld_sample_randomized` (the network is not evaluated).
fn nuld_sample_network_randomized(cond: vec2<f32>, instance: u32, i: u32, seed: u32) -> NuldSample {
    return nuld_sample_network_randomized_metallic(cond, 0.0, instance, i, seed);
}

// Rust: `NetworkSampler::sample_randomized_metallic`: as
// `nuld_sample_randomized_metallic`.
fn nuld_sample_network_randomized_metallic(cond: vec2<f32>, metallic: f32, instance: u32, i: u32, seed: u32) -> NuldSample {
    return nuld_sample_randomized_metallic(cond, metallic, instance, i, seed);
}

// Rust: `ConditionalSampler::pdf`: the prior's solid-angle pdf at the unit
// `direction` for condition `cond` (environment samplers, and BRDF samplers on
// the tabulated prior at metallic 0; 0 for the others).
fn nuld_pdf(cond: vec2<f32>, direction: vec3<f32>) -> f32 {
    return nuld_pdf_metallic(cond, 0.0, direction);
}

// Rust: `ConditionalSampler::pdf_metallic`: `nuld_pdf` at metallic `metallic`
// (warp 3's prior at the clamped condition; the environment tree at the normal of
// the clamped condition).
fn nuld_pdf_metallic(cond: vec2<f32>, metallic: f32, direction: vec3<f32>) -> f32 {
    let cs = nuld_conditional();
    let c = nuld_denormalize(cs.info, nuld_normalize(cs.info, cond));
    if cs.info.warp == NULD_WARP_ENVMAP_TREE {
        return nuld_tree_pdf_square(nuld_tree(), c, direction);
    }
    if cs.info.warp == NULD_WARP_BRDF_TABLE {
        return nuld_brdf_prior_pdf(nuld_brdf_prior(), vec3<f32>(c.x, c.y, metallic), direction);
    }
    return 0.0;
}

// Rust: `ConditionalSampler::albedo`: the directional albedo at `cond` of a BRDF
// of metallic `metallic` (clamped into `[0, 1]`, NaN as 0): for warp 3
// `(1 - m) A_0 + m A_1`, the weight section's two tables interpolated as the
// weights; for every other warp the weight (`nuld_weight`).
fn nuld_albedo(cond: vec2<f32>, metallic: f32) -> f32 {
    let cs = nuld_conditional();
    let cell = nuld_locate(nuld_normalize(cs.info, cond), cs.info.weight_grid);
    let dielectric = nuld_weight_table_lerp(cs, cell, 0u);
    if cs.info.warp != NULD_WARP_BRDF_TABLE {
        return dielectric;
    }
    let m = nuld_clamp01(metallic);
    return (1.0 - m) * dielectric + m * nuld_weight_table_lerp(cs, cell, 1u);
}

// Rust: `ConditionalSampler::mapped`: the sample of the square point `p` at the
// normalized condition `u`: the direction of the blob's point warp (warp 0: the
// domain's equal-area map; warp 1: the BRDF mixture at the clamped condition with
// the lobe probability of the weight section's second table; warp 2: the
// environment tree at the normal of the clamped condition, with its pdf; warp 3:
// the BRDF prior at the clamped condition and `metallic`, with its pdf) and the
// weight (warp 3: `f cos / pdf` of the direction, `nuld_brdf_table_mapped`).
fn nuld_mapped(cs: NuldConditional, p: vec2<f32>, u: vec2<f32>, metallic: f32) -> NuldSample {
    if cs.info.warp == NULD_WARP_BRDF_TABLE {
        return nuld_brdf_table_mapped(cs, p, u, metallic);
    }
    let cell = nuld_locate(u, cs.info.weight_grid);
    let weight = nuld_weight_table_lerp(cs, cell, 0u);
    if cs.info.warp == NULD_WARP_ENVMAP_TREE {
        let s = nuld_tree_sample_square(nuld_tree(), nuld_denormalize(cs.info, u), p);
        return NuldSample(s.direction, weight, s.pdf);
    }
    var direction: vec3<f32>;
    if cs.info.warp == NULD_WARP_BRDF_MIXTURE {
        let c = nuld_denormalize(cs.info, u);
        direction = nuld_brdf_mixture(c, nuld_weight_table_lerp(cs, cell, 1u), p);
    } else {
        direction = nuld_to_direction(cs.info.domain, p);
    }
    return NuldSample(direction, weight, 0.0);
}

// Rust: the `PointWarp::BrdfTable` branch of `ConditionalSampler::mapped`: the
// prior's direction and pdf at the clamped condition `(roughness, theta_o)` and
// `metallic` (`nuld_brdf_prior_sample`), and the weight `f cos / pdf` with `f` the
// glTF BRDF with metallic (`nuld_gltf_metallic`; 0 where the pdf is 0 or the
// quotient is not finite). Step 11 of core/FORMAT.md.
fn nuld_brdf_table_mapped(cs: NuldConditional, p: vec2<f32>, u: vec2<f32>, metallic: f32) -> NuldSample {
    let c = nuld_denormalize(cs.info, u);
    let s = nuld_brdf_prior_sample(nuld_brdf_prior(), vec3<f32>(c.x, c.y, metallic), p);
    let f = nuld_gltf_metallic(nuld_view_direction(c.y), s.direction, c.x, metallic);
    var weight = 0.0;
    if s.pdf > 0.0 {
        weight = f * s.direction.z / s.pdf;
    }
    if !nuld_is_finite(weight) {
        weight = 0.0;
    }
    return NuldSample(s.direction, weight, s.pdf);
}

// `libm::acosf`'s constants (FreeBSD e_acosf.c): pi/2 split in a high part
// (bits 0x3fc90fda) and a low part (bits 0x33a22168), and the coefficients of its
// rational approximation.
const NULD_ACOS_PIO2_HI: f32 = 1.5707962513e+00;
const NULD_ACOS_PIO2_LO: f32 = 7.5497894159e-08;
const NULD_ACOS_P_S0: f32 = 1.6666586697e-01;
const NULD_ACOS_P_S1: f32 = -4.2743422091e-02;
const NULD_ACOS_P_S2: f32 = -8.6563630030e-03;
const NULD_ACOS_Q_S1: f32 = -7.0662963390e-01;

// Rust: `r` of `libm::acosf`.
fn nuld_acos_r(z: f32) -> f32 {
    let p = z * (NULD_ACOS_P_S0 + z * (NULD_ACOS_P_S1 + z * NULD_ACOS_P_S2));
    let q = 1.0 + z * NULD_ACOS_Q_S1;
    return p / q;
}

// Rust: `libm::acosf`, operation for operation, for `x` in `[-1, 1]` (NaN outside).
// The built-in `acos` may be far less accurate (Vulkan allows thousands of ulps),
// and `theta_o` feeds the table interpolation.
fn nuld_acos(x: f32) -> f32 {
    let hx = bitcast<u32>(x);
    let ix = hx & 0x7fffffffu;
    if ix >= 0x3f800000u {
        if ix == 0x3f800000u {
            if (hx >> 31u) != 0u {
                return 2.0 * NULD_ACOS_PIO2_HI;
            }
            return 0.0;
        }
        return bitcast<f32>(0x7fc00000u);
    }
    if ix < 0x3f000000u {
        if ix <= 0x32800000u {
            return NULD_ACOS_PIO2_HI;
        }
        return NULD_ACOS_PIO2_HI - (x - (NULD_ACOS_PIO2_LO - x * nuld_acos_r(x * x)));
    }
    if (hx >> 31u) != 0u {
        let z = (1.0 + x) * 0.5;
        let s = sqrt(z);
        let w = nuld_acos_r(z) * s - NULD_ACOS_PIO2_LO;
        return 2.0 * (NULD_ACOS_PIO2_HI - (s + w));
    }
    let z = (1.0 - x) * 0.5;
    let s = sqrt(z);
    let df = bitcast<f32>(bitcast<u32>(s) & 0xfffff000u);
    let c = (z - df * df) / (s + df);
    let w = nuld_acos_r(z) * s + c;
    return 2.0 * (df + w);
}

// Rust: `view_condition` (runtime/src/brdf.rs): the condition
// `(roughness, theta_o in degrees)` of the view `wo` (any length; scaled by its
// largest component first) and its azimuth `(cos phi, sin phi)`; a zero, infinite
// or NaN view reads as normal incidence with azimuth `(1, 0)`.
struct NuldView {
    cond: vec2<f32>,
    azimuth: vec2<f32>,
}

fn nuld_view_condition(wo: vec3<f32>, roughness: f32) -> NuldView {
    let m = max(max(abs(wo.x), abs(wo.y)), abs(wo.z));
    let finite = nuld_is_finite(wo.x) && nuld_is_finite(wo.y) && nuld_is_finite(wo.z);
    if !(finite && m > 0.0) {
        return NuldView(vec2<f32>(roughness, 0.0), vec2<f32>(1.0, 0.0));
    }
    let w = vec3<f32>(wo.x / m, wo.y / m, wo.z / m);
    let len = sqrt((w.x * w.x + w.y * w.y) + w.z * w.z);
    let cos_theta = clamp(w.z / len, 0.0, 1.0);
    let theta = nuld_acos(cos_theta) * NULD_DEGREES_PER_RADIAN;
    let planar = sqrt(w.x * w.x + w.y * w.y);
    var azimuth = vec2<f32>(1.0, 0.0);
    if planar > 0.0 {
        azimuth = vec2<f32>(w.x / planar, w.y / planar);
    }
    return NuldView(vec2<f32>(roughness, theta), azimuth);
}

// Rust: `rotate` (runtime/src/brdf.rs): the sample turned about `z` by the
// azimuth `(cos phi, sin phi)`.
fn nuld_rotate(s: NuldSample, azimuth: vec2<f32>) -> NuldSample {
    let d = s.direction;
    let c = azimuth.x;
    let sn = azimuth.y;
    return NuldSample(vec3<f32>(c * d.x - sn * d.y, sn * d.x + c * d.y, d.z), s.weight, s.pdf);
}

// Rust: `unrotate` (runtime/src/brdf.rs): `d` turned about `z` by minus the
// azimuth `(cos phi, sin phi)`, into the frame of the xz-plane view.
fn nuld_unrotate(d: vec3<f32>, azimuth: vec2<f32>) -> vec3<f32> {
    let c = azimuth.x;
    let sn = azimuth.y;
    return vec3<f32>(c * d.x + sn * d.y, -sn * d.x + c * d.y, d.z);
}

// Rust: `BrdfSampler::sample` (table mode, glTF BRDF samplers): the set at
// `(roughness, theta_o)` of the view `wo` (local frame, `z` = normal, any length)
// and `metallic` (clamped into `[0, 1]`, NaN as 0; read by the tabulated prior,
// warp 3, ignored by the mixture prior), turned about `z` to the view's azimuth.
// Warp 3: `pdf` is the prior's and `weight` is `f cos / pdf`; the mixture prior:
// pdf 0 and the dielectric's albedo as the weight.
fn nuld_sample_brdf(wo: vec3<f32>, roughness: f32, metallic: f32, instance: u32, i: u32) -> NuldSample {
    let view = nuld_view_condition(wo, roughness);
    return nuld_rotate(nuld_sample_metallic(view.cond, metallic, instance, i), view.azimuth);
}

// Rust: `BrdfSampler::sample_randomized` (the unbiased mode): `nuld_sample_brdf`
// with the randomly shifted lattice point of `nuld_randomized_point` (`seed`: the
// pixel's random number).
fn nuld_sample_brdf_randomized(wo: vec3<f32>, roughness: f32, metallic: f32, instance: u32, i: u32, seed: u32) -> NuldSample {
    let view = nuld_view_condition(wo, roughness);
    let s = nuld_sample_randomized_metallic(view.cond, metallic, instance, i, seed);
    return nuld_rotate(s, view.azimuth);
}

// Rust: `BrdfNetwork::sample` (network mode): as
// `nuld_sample_brdf` with `nuld_sample_network_metallic`.
fn nuld_sample_brdf_network(wo: vec3<f32>, roughness: f32, metallic: f32, instance: u32, i: u32) -> NuldSample {
    let view = nuld_view_condition(wo, roughness);
    return nuld_rotate(nuld_sample_network_metallic(view.cond, metallic, instance, i), view.azimuth);
}

// Rust: `BrdfNetwork::sample_randomized`: the unbiased mode, the same samples as
// `nuld_sample_brdf_randomized` (the network is not evaluated).
fn nuld_sample_brdf_network_randomized(wo: vec3<f32>, roughness: f32, metallic: f32, instance: u32, i: u32, seed: u32) -> NuldSample {
    return nuld_sample_brdf_randomized(wo, roughness, metallic, instance, i, seed);
}

// Rust: `BrdfSampler::pdf` (both modes share the prior): the solid-angle density
// of the sampler's prior at the unit `direction` (local frame) for the view `wo`,
// `roughness` and `metallic` (multiple importance sampling); 0 below the horizon
// and for the mixture prior.
fn nuld_pdf_brdf(wo: vec3<f32>, roughness: f32, metallic: f32, direction: vec3<f32>) -> f32 {
    let view = nuld_view_condition(wo, roughness);
    return nuld_pdf_metallic(view.cond, metallic, nuld_unrotate(direction, view.azimuth));
}

// Rust: `BrdfSampler::albedo`: the directional albedo `A = integral of f cos` at the
// view `wo`, `roughness` and `metallic` (`nuld_albedo`): the weight of the
// fixed-instance estimator `(A / N) sum L(direction_i)`.
fn nuld_albedo_brdf(wo: vec3<f32>, roughness: f32, metallic: f32) -> f32 {
    let view = nuld_view_condition(wo, roughness);
    return nuld_albedo(view.cond, metallic);
}
