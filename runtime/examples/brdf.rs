//! Loads a BRDF sampler baked by `build-tool bake --brdf` and estimates the light
//! a surface reflects toward a viewer, in table mode and in network mode:
//! `cargo run -p nuld-runtime --features std --example brdf -- out/brdf/brdf.nuld`.
use nuld_runtime::glam::Vec3;
use nuld_runtime::{AlignedBuf, Blob};

/// Radiance arriving from `direction` (local frame, z = the surface normal): a
/// stand-in for what a renderer traces.
fn incoming(direction: Vec3) -> f32 {
    1.0 + direction.x.max(0.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage: brdf FILE.nuld")?;
    // A `Vec<u8>` is not 16-byte aligned; `AlignedBuf` is. Parse validates once.
    let buf = AlignedBuf::read(&path)?;
    let blob = Blob::parse(buf.as_bytes()).map_err(|e| format!("{path}: {e}"))?;
    // An environment-map blob is refused here with `BlobError::WrongTarget`.
    let brdf = blob.brdf()?;

    let wo = Vec3::new(0.5, 0.2, 0.8); // the view, local frame, any length
    let (roughness, metallic) = (0.3, 0.0); // glTF's material parameters
    let instance = 17; // decorrelates pixels: e.g. a hash of the pixel
    let n = brdf.len();
    // Table mode: O(1) per sample, no allocation; weight = f cos / pdf.
    let mut table = 0.0;
    for i in 0..n {
        let s = brdf.sample(wo, roughness, metallic, instance, i);
        table += s.weight * incoming(s.direction) / n as f32;
    }
    // Network mode evaluates the trained network per sample; decoding its f16
    // weights once (per blob, as a renderer uploads tables once) gives the same
    // bits faster.
    let mut weights = vec![0.0f32; brdf.decoded_network_len()];
    let network = brdf
        .decode_network(&mut weights)
        .ok_or("buffer too short")?;
    let mut net = 0.0;
    for i in 0..n {
        let s = network.sample(wo, roughness, metallic, instance, i);
        net += s.weight * incoming(s.direction) / n as f32;
    }
    println!("{path}: N = {n}; reflected radiance: table {table:.5}, network {net:.5}");
    Ok(())
}
