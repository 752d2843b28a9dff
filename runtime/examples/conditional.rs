//! Samples a conditional BRDF sampler (a blob of `build-tool bake --brdf`): table
//! mode, network mode, and any view direction. Here a tiny stand-in blob; a
//! renderer would `include_blob!` its baked `brdf.nuld` instead.
use nuld_runtime::glam::{Vec2, Vec3};
use nuld_runtime::{Blob, BlobError};

fn main() -> Result<(), BlobError> {
    let bytes = nuld_runtime::doc_example_conditional_blob();
    // Validates everything once, no allocation.
    let cs = Blob::parse(&bytes.0)?.conditional()?;
    // N points per set; S instances stored in the table.
    let (n, instances) = (cs.len(), cs.instances());
    // Roughness 0.3, view 60 degrees from the normal in the xz-plane, instance 7:
    let cond = Vec2::new(0.3, 60.0);
    let mut estimate = 0.0;
    for i in 0..n {
        let s = cs.sample(cond, 7, i); // table mode: Sample { direction, weight }
        estimate += s.weight * s.direction.z.max(0.0); // stands for weight * L(direction)
    }
    estimate /= n as f32;
    // Network mode serves any u32 instance; the BRDF view takes any local view
    // direction (z = normal) and rotates the set to its azimuth.
    let b = cs.sample_network(cond, 123_456, 0);
    let c = cs.sample_brdf(Vec3::new(0.2, 0.5, 0.8), 0.3, 7, 0);
    // Network mode runs faster on weights decoded once into the caller's memory
    // (a renderer keeps a Vec of `cs.decoded_network_len()` per blob); the
    // samples are the same bits. `None` if the buffer is too short.
    let mut decoded = [0.0f32; 64];
    if let Some(fast) = cs.decode_network(&mut decoded) {
        assert_eq!(fast.sample_network(cond, 123_456, 0), b);
    }
    println!("N {n}, S {instances}: estimate {estimate}, {b:?}, {c:?}");
    Ok(())
}
