// A renderer's compute shader that samples a BRDF blob: appended to
// `nuld_runtime::shader::WGSL`, which provides the `nuld_*` functions.
@group(0) @binding(0) var<storage, read> nuld_blob: array<u32>;
@group(0) @binding(1) var<storage, read_write> out: array<vec4<f32>>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = nuld_len(); // points per set
    if id.x >= arrayLength(&out) {
        return;
    }
    let pixel = id.x / n; // the instance: any u32, e.g. a hash of the pixel
    let i = id.x % n;
    let wo = normalize(vec3<f32>(0.3, 0.4, 0.866)); // view, local frame, z = normal
    let roughness = 0.4;
    let metallic = 0.0; // glTF's material parameters
    let s = nuld_sample_brdf(wo, roughness, metallic, pixel, i); // table mode
    // estimate of the pixel: 1 / n * sum over i of s.weight * L(s.direction)
    out[id.x] = vec4<f32>(s.direction, s.weight);
}
