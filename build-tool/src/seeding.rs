//! Seed derivation: one user seed fixes every random stream of a run.
//!
//! Each consumer (a point set, an epoch's boxes, a chunk of work) asks for its own
//! stream by a `(seed, stream)` pair, so results do not depend on how work is split
//! across threads.

use rand_pcg::Pcg64Mcg;

/// SplitMix64 finalizer: a bijective 64-bit mix with good avalanche.
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// The seed of sub-stream `stream` of `seed`.
pub fn derive_seed(seed: u64, stream: u64) -> u64 {
    mix64(mix64(seed ^ 0x9e37_79b9_7f4a_7c15).wrapping_add(mix64(stream)))
}

/// A fast PRNG for sub-stream `stream` of `seed`.
pub fn rng(seed: u64, stream: u64) -> Pcg64Mcg {
    Pcg64Mcg::new(
        derive_seed(seed, stream) as u128 | 1 | ((derive_seed(seed, !stream) as u128) << 64),
    )
}

/// A 64-bit hash of `bytes` (for cache keys; not cryptographic): FNV-1a folded
/// through [`mix64`].
pub fn content_hash(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h = (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3);
    }
    mix64(h)
}
