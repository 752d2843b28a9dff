//! How much a fixed-instance render depends on which offsets the blob's
//! instances hold: rewrites the point table of an environment or BRDF blob with
//! each instance's rank-1 lattice (the unbiased mode's lattice, no training)
//! shifted by the offset of instance `k + BASE` instead of `k`, `cargo run
//! --release -p nuld-build-tool --example offset_sets -- BLOB OUT BASE`.
//!
//! With `BASE` 0 the table holds what an untrained bake ships at each instance's
//! own offset (`bake --envmap MAP --n 16 --steps 1` ships it where the trained
//! sets check worse, as on the shared maps); with 64, 128, ... it holds as many
//! other sets of shifts, drawn by the same hash. Every seed of a render reads the
//! same 64 sets, so the spread of a render over `BASE` is an uncertainty that
//! the seeds' standard errors do not hold. The blob's other sections, and its
//! metal layer if it has one, are left as they are (a BRDF blob's metal table
//! then keeps its own points). Results: docs/results/rendering.md#offset-sets.
use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::blob::{checksum, Layout, SectionTag, CHECKSUM_OFFSET};
use nuld_core::conditional::{pack_point, torus_shift, ConditionalInfo};
use nuld_core::network::lattice_point;
use nuld_core::quantize::unorm16_encode;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() != 4 {
        eprintln!("usage: offset_sets BLOB OUT BASE");
        std::process::exit(2);
    }
    let base: u32 = args[3].parse().expect("BASE an instance number");
    let blob = AlignedBytes::read(Path::new(&args[1])).unwrap();
    let layout = Layout::read(blob.as_slice()).unwrap();
    let (_, info) = layout.section(SectionTag::ConditionalInfo).unwrap();
    let info: ConditionalInfo = bytemuck::pod_read_unaligned(info);
    let shape = info.shape().expect("a conditional sampler's shape");
    let (n, instances) = (info.n, info.instances);
    let (table, _) = layout.section(SectionTag::PointTable).unwrap();
    let mut bytes = blob.as_slice().to_vec();
    let start = table.offset as usize;
    for at in 0..table.len as usize / 4 {
        let (k, i) = ((at as u32 / n) % instances, at as u32 % n);
        let l = lattice_point::<f64>(i, n, shape.lattice_generator());
        // The hash's own offset of `key + BASE`, not `Shape::instance_offset`,
        // which would wrap `k + BASE` at the network's instance slots.
        let z = shape
            .offset_hash()
            .offset::<f64>(shape.instance_key(k) + base);
        let p = torus_shift(l, z);
        let code = pack_point(unorm16_encode(p[0]), unorm16_encode(p[1]));
        bytes[start + 4 * at..start + 4 * at + 4].copy_from_slice(&code.to_le_bytes());
    }
    let sum = checksum(&bytes);
    bytes[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
    std::fs::write(&args[2], &bytes).unwrap();
    eprintln!(
        "wrote {}: n {n}, {instances} instances at the offsets of {base}..{}",
        args[2],
        base + instances
    );
}
