// nuld sampling kernel (WGSL): appended to nuld.wgsl, a complete compute shader
// that fills a buffer with the samples of a range of (condition, instance, index).
// `build-tool shader` translates the two texts to GLSL, HLSL, MSL and SPIR-V.
//
// Bindings (group 0):
//   0: the blob, unchanged (`nuld_blob`, as nuld.wgsl expects it);
//   1: the output, one `NuldSample` (32 bytes: direction xyz, weight, pdf, and
//      12 bytes of padding) per sample;
//   2: the range, a `NuldKernelParams` uniform (64 bytes; the Rust mirror is
//      `nuld_runtime::shader::KernelParams`).
//
// Sample `e` of the range is condition `(cx, cy)`, instance `k`, index `i` with
// `e = ((cy * cond_count.x + cx) * instance_count + k) * index_count + i`; its
// condition is `cond_first + vec2(cx, cy) * cond_step`, its instance
// `instance_first + k`, its index `index_first + i`. Dispatch
// `ceil(total / 64)` workgroups, up to 65535 along x, then rows along y: every
// invocation past the total returns.
//
// What a sample is depends on the blob's kind and `mode`; every mode of kind 3
// samples at the metallic `view.w` (read by BRDF samplers on the tabulated prior,
// warp 3, ignored by the others):
//   kind 3, mode 0 (and any unknown code): `nuld_sample_metallic` (table mode);
//   kind 3, mode 1: `nuld_sample_network_metallic` (network mode);
//   kind 3, mode 2: `nuld_sample_brdf` at the view `view.xyz`, roughness = the
//                   condition's x (its y unused);
//   kind 3, mode 3: `nuld_sample_brdf_network`, likewise;
//   kind 3, mode 4: `nuld_sample_randomized_metallic` with seed `e` (the unbiased
//                   mode);
//   kind 3, mode 5: `nuld_sample_network_randomized_metallic` with seed `e`;
//   kind 3, mode 6: `nuld_sample_metallic`, its pdf replaced by
//                   `nuld_pdf_metallic` at its direction and its weight by
//                   `nuld_albedo`;
//   kind 3, mode 7: `nuld_sample_brdf_randomized` with seed `e` (as mode 2);
//   kind 3, mode 8: `nuld_sample_brdf_network_randomized` with seed `e`;
//   kind 3, mode 9: `nuld_sample_brdf`, its pdf replaced by `nuld_pdf_brdf` at its
//                   direction and its weight by `nuld_albedo_brdf`;
//   kind 2: `nuld_direction(instance, index)` (the instance is the set), weight 1,
//           pdf 0;
//   kind 1: `nuld_point(instance, index)` as `(x, y, 0)`, weight 1, pdf 0.

@group(0) @binding(0) var<storage, read> nuld_blob: array<u32>;
@group(0) @binding(1) var<storage, read_write> nuld_samples: array<NuldSample>;
@group(0) @binding(2) var<uniform> nuld_params: NuldKernelParams;

// Rust: `nuld_runtime::shader::KernelParams`, field for field.
struct NuldKernelParams {
    cond_first: vec2<f32>,
    cond_step: vec2<f32>,
    cond_count: vec2<u32>,
    instance_first: u32,
    instance_count: u32,
    index_first: u32,
    index_count: u32,
    mode: u32,
    reserved: u32,
    view: vec4<f32>,
}

// Invocations per workgroup (`KERNEL_WORKGROUP_SIZE` in Rust).
const NULD_WORKGROUP_SIZE: u32 = 64u;

// `KernelMode` codes (`NuldKernelParams::mode`).
const NULD_MODE_TABLE: u32 = 0u;
const NULD_MODE_NETWORK: u32 = 1u;
const NULD_MODE_BRDF_TABLE: u32 = 2u;
const NULD_MODE_BRDF_NETWORK: u32 = 3u;
const NULD_MODE_TABLE_RANDOMIZED: u32 = 4u;
const NULD_MODE_NETWORK_RANDOMIZED: u32 = 5u;
const NULD_MODE_PDF: u32 = 6u;
const NULD_MODE_BRDF_TABLE_RANDOMIZED: u32 = 7u;
const NULD_MODE_BRDF_NETWORK_RANDOMIZED: u32 = 8u;
const NULD_MODE_BRDF_PDF: u32 = 9u;

// Rust: `KernelParams::sample_count`.
fn nuld_kernel_sample_count(p: NuldKernelParams) -> u32 {
    return p.cond_count.x * p.cond_count.y * p.instance_count * p.index_count;
}

// The sample of mode `p.mode` at condition `c`, instance `instance`, index
// `index` and seed `e` of a conditional blob: what the mode's functions return,
// composed here from their parts as they compose them (`nuld_sample_brdf` is
// `nuld_rotate` of `nuld_mapped` of the square point at `nuld_view_condition`'s
// condition, `nuld_pdf_brdf` is `nuld_pdf_metallic` of `nuld_unrotate`, ...),
// with one call of each part: a driver inlines every call, and ten calls of the
// `nuld_sample*` functions, each with every warp inlined, took lavapipe minutes to
// compile.
fn nuld_kernel_conditional(p: NuldKernelParams, c: vec2<f32>, instance: u32, index: u32, e: u32) -> NuldSample {
    let mode = p.mode;
    let brdf = mode == NULD_MODE_BRDF_TABLE || mode == NULD_MODE_BRDF_NETWORK
        || mode == NULD_MODE_BRDF_TABLE_RANDOMIZED || mode == NULD_MODE_BRDF_NETWORK_RANDOMIZED
        || mode == NULD_MODE_BRDF_PDF;
    let network = mode == NULD_MODE_NETWORK || mode == NULD_MODE_BRDF_NETWORK
        || mode == NULD_MODE_NETWORK_RANDOMIZED || mode == NULD_MODE_BRDF_NETWORK_RANDOMIZED;
    let randomized = mode == NULD_MODE_TABLE_RANDOMIZED || mode == NULD_MODE_NETWORK_RANDOMIZED
        || mode == NULD_MODE_BRDF_TABLE_RANDOMIZED || mode == NULD_MODE_BRDF_NETWORK_RANDOMIZED;
    let pdf = mode == NULD_MODE_PDF || mode == NULD_MODE_BRDF_PDF;
    let metallic = p.view.w;
    // The BRDF modes sample at the view's condition (roughness = the condition's
    // x), the others at the condition itself.
    var view = NuldView(c, vec2<f32>(1.0, 0.0));
    if brdf {
        view = nuld_view_condition(p.view.xyz, c.x);
    }
    let cs = nuld_conditional_at_metallic(metallic);
    let u = nuld_normalize(cs.info, view.cond);
    var point: vec2<f32>;
    if randomized {
        point = nuld_randomized_point(cs.info, instance, index, e);
    } else if network {
        point = nuld_network_square_point_of(cs, u, metallic, instance, index);
    } else {
        point = nuld_square_point_of(cs, u, metallic, instance, index);
    }
    var out = nuld_mapped(cs, point, u, metallic);
    if brdf {
        out = nuld_rotate(out, view.azimuth);
    }
    if pdf {
        var direction = out.direction;
        if brdf {
            direction = nuld_unrotate(direction, view.azimuth);
        }
        out.pdf = nuld_pdf_metallic(view.cond, metallic, direction);
        out.weight = nuld_albedo(view.cond, metallic);
    }
    return out;
}

@compute @workgroup_size(NULD_WORKGROUP_SIZE)
fn nuld_fill(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(num_workgroups) groups: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
) {
    let p = nuld_params;
    let flat_group = (group.z * groups.y + group.y) * groups.x + group.x;
    let e = flat_group * NULD_WORKGROUP_SIZE + lane;
    if e >= nuld_kernel_sample_count(p) || e >= arrayLength(&nuld_samples) {
        return;
    }
    let i = e % p.index_count;
    let rest = e / p.index_count;
    let k = rest % p.instance_count;
    let c = rest / p.instance_count;
    let cx = c % p.cond_count.x;
    let cy = c / p.cond_count.x;
    let cond = p.cond_first + vec2<f32>(f32(cx), f32(cy)) * p.cond_step;
    let instance = p.instance_first + k;
    let index = p.index_first + i;
    var out: NuldSample;
    let kind = nuld_kind();
    if kind == NULD_KIND_CONDITIONAL {
        out = nuld_kernel_conditional(p, cond, instance, index, e);
    } else if kind == NULD_KIND_DIRECTION_SET {
        out = NuldSample(nuld_direction(instance, index), 1.0, 0.0);
    } else {
        out = NuldSample(vec3<f32>(nuld_point(instance, index), 0.0), 1.0, 0.0);
    }
    nuld_samples[e] = out;
}
