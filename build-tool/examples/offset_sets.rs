//! How much a fixed-instance render depends on which offsets the blob's
//! instances hold: rewrites the point table of an environment or BRDF blob with
//! each instance's rank-1 lattice (the unbiased mode's lattice, no training)
//! shifted by the offset of instance `k + BASE` instead of `k`, `cargo run
//! --release -p nuld-build-tool --example offset_sets -- BLOB OUT BASE [r2 |
//! cosets]`.
//!
//! With `BASE` 0 the table holds what an untrained bake ships at each instance's
//! own offset (`bake --envmap MAP --n 16 --steps 1` ships it where the trained
//! sets check worse, as on the shared maps); with 64, 128, ... it holds as many
//! other sets of shifts, drawn by the same hash. Every seed of a render reads the
//! same 64 sets, so the spread of a render over `BASE` is an uncertainty that
//! the seeds' standard errors do not hold. With `r2` the offsets are terms `k +
//! BASE` of the R2 sequence instead (the plastic number's Kronecker sequence,
//! whose consecutive terms are evenly spread over the square), to see whether
//! offsets spread evenly spread a render's luck less. With `cosets` instance `k`
//! holds the coset number `bitreverse(k)` of the lattice in a rank-1 lattice of
//! `S n` points that contains it (`S` instances, a power of two), all moved by
//! one shift drawn from `BASE`: the union of the instances is that finer
//! lattice, and the shifts are a lattice rule over the shifts that give
//! different sets. The blob's other sections, and its
//! metal layer if it has one, are left as they are (a BRDF blob's metal table
//! then keeps its own points). Results: docs/results/rendering.md#offset-sets.
use glam::DVec2;
use nuld_build_tool::conditional::distill::fill_lattice_table;
use nuld_build_tool::metrics::l2::asd_uniform;
use nuld_build_tool::pointset::AlignedBytes;
use nuld_build_tool::train::{gcd, shortest_lattice_vector};
use nuld_core::blob::{checksum, Layout, SectionTag, CHECKSUM_OFFSET};
use nuld_core::conditional::ConditionalInfo;
use nuld_core::network::{shifted_lattice_point, Shape};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(4..=5).contains(&args.len()) {
        eprintln!("usage: offset_sets BLOB OUT BASE [r2 | cosets]");
        std::process::exit(2);
    }
    let base: u32 = args[3].parse().expect("BASE an instance number");
    let blob = AlignedBytes::read(Path::new(&args[1])).unwrap();
    let layout = Layout::read(blob.as_slice()).unwrap();
    let (_, info) = layout.section(SectionTag::ConditionalInfo).unwrap();
    let info: ConditionalInfo = bytemuck::pod_read_unaligned(info);
    let shape = info.shape().expect("a conditional sampler's shape");
    let (table, _) = layout.section(SectionTag::PointTable).unwrap();
    let range = table.offset as usize..(table.offset + table.len) as usize;
    let mut bytes = blob.as_slice().to_vec();
    let mut codes: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes[range.clone()]);
    // The hash's own offset of `key + BASE`, not `Shape::instance_offset`,
    // which would wrap `k + BASE` at the network's instance slots.
    let kind = args.get(4).map_or("hash", |a| a.as_str());
    let cosets = Cosets::new(shape.n(), shape.lattice_generator(), info.instances);
    let shift: [f64; 2] = shape.offset_hash().offset(base);
    let offset = |k: u32| match kind {
        "r2" => r2_offset(k + base),
        "cosets" => cosets.offset(k, shift),
        _ => shape.offset_hash().offset(shape.instance_key(k) + base),
    };
    fill_lattice_table(&mut codes, &shape, info.instances, offset);
    print_torus_spread(&shape, info.instances, offset);
    bytes[range].copy_from_slice(bytemuck::cast_slice(&codes));
    let sum = checksum(&bytes);
    bytes[CHECKSUM_OFFSET..CHECKSUM_OFFSET + 8].copy_from_slice(&sum.to_le_bytes());
    std::fs::write(&args[2], &bytes).unwrap();
    eprintln!(
        "wrote {}: n {}, {} instances at the offsets of {base}..{}",
        args[2],
        info.n,
        info.instances,
        base + info.instances
    );
}

/// Term `k` of the R2 sequence (the plastic number's Kronecker sequence), in
/// 24-bit fixed point: `frac(k (0.7548776662, 0.5698402910))`.
fn r2_offset(k: u32) -> [f64; 2] {
    [0xc13f_a9a9u32, 0x91e1_0da7].map(|a| (k.wrapping_mul(a) >> 8) as f64 / (1u32 << 24) as f64)
}

/// How the instances' shifted lattices sit in the unit square before any warp
/// (what the shifts alone decide): the average squared discrepancy of the union
/// of all instances over that of one (mean over the instances), and the
/// nearest-neighbour distance on the torus from instance `k`'s points to instance
/// `k + 1`'s over that within a set (the bake check's union and NN ratios, here
/// of the unwarped lattices).
fn print_torus_spread(shape: &Shape, instances: u32, offset: impl Fn(u32) -> [f64; 2]) {
    let (n, g) = (shape.n(), shape.lattice_generator());
    let set = |k: u32| -> Vec<DVec2> {
        (0..n)
            .map(|i| DVec2::from(shifted_lattice_point::<f64>(i, n, g, offset(k))))
            .collect()
    };
    let sets: Vec<_> = (0..instances).map(set).collect();
    let one = sets.iter().map(|s| asd_uniform(s)).sum::<f64>() / instances as f64;
    let union: Vec<DVec2> = sets.concat();
    let torus = |a: DVec2, b: DVec2| {
        let d = (a - b).abs();
        d.min(DVec2::ONE - d).length()
    };
    let nearest = |p: DVec2, s: &[DVec2], skip: bool| {
        s.iter()
            .map(|&q| torus(p, q))
            .filter(|&d| !skip || d > 0.0)
            .fold(f64::INFINITY, f64::min)
    };
    let within = sets[0]
        .iter()
        .map(|&p| nearest(p, &sets[0], true))
        .sum::<f64>()
        / n as f64;
    let across = sets
        .windows(2)
        .map(|w| w[0].iter().map(|&p| nearest(p, &w[1], false)).sum::<f64>() / n as f64)
        .sum::<f64>()
        / (instances.max(2) - 1) as f64;
    eprintln!(
        "unwarped: union of {instances} over one (average squared discrepancy) {:.3}, \
         nearest neighbour across consecutive instances over within {:.3}",
        asd_uniform(&union) / one,
        across / within
    );
}

/// The cosets of the rank-1 lattice of `n` points and generator `g` in the
/// rank-1 lattice of `S n` points and generator `G` (`G = g mod n`, so that it
/// holds the smaller one; of those coprime to `S n`, the one with the longest
/// shortest vector on the torus), in bit-reversed order so that consecutive
/// instances lie far apart.
struct Cosets {
    count: u32,
    big_n: u64,
    big_g: u64,
}

impl Cosets {
    fn new(n: u32, g: u32, count: u32) -> Self {
        assert!(
            count.is_power_of_two(),
            "cosets: the instances a power of two"
        );
        let big_n = n as u64 * count as u64;
        let big_g = (0..count as u64)
            .map(|j| g as u64 + j * n as u64)
            .filter(|&c| gcd(c, big_n) == 1)
            .max_by(|&a, &b| {
                let s = |c| shortest_lattice_vector(big_n, c);
                s(a).total_cmp(&s(b)).then(b.cmp(&a))
            })
            .unwrap_or(g as u64);
        Self {
            count,
            big_n,
            big_g,
        }
    }

    fn offset(&self, k: u32, shift: [f64; 2]) -> [f64; 2] {
        let bits = self.count.trailing_zeros();
        let c = if bits == 0 {
            0
        } else {
            ((k % self.count).reverse_bits() >> (32 - bits)) as u64
        };
        let p = [c, c * self.big_g % self.big_n].map(|v| v as f64 / self.big_n as f64);
        [0, 1].map(|a| (p[a] + shift[a]).fract())
    }
}
