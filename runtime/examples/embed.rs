//! Samples from a blob compiled into the binary: no file I/O, no allocation.
//! `samples.nuld` holds 4 sets of 64 points for `gaussian:0.5,0.5,0.15`, made by
//! `build-tool optimize --n 64 --sets 4 --out DIR` (DIR/set.nuld).
use nuld_runtime::glam::{Vec2, Vec3};
use nuld_runtime::{Blob, BlobError, BlobKind};

// `include_blob!` is `include_bytes!` at the 16-byte alignment `Blob::parse` needs.
static SAMPLES: &[u8] = nuld_runtime::include_blob!("samples.nuld");

/// Which of the blob's sets pixel (x, y) uses: a hash, so that neighbouring pixels
/// get unrelated sets. The set index wraps modulo the blob's set count.
fn set_of_pixel(x: u32, y: u32) -> usize {
    let mut h = x.wrapping_mul(0x9e37_79b9) ^ y; // any good integer hash will do
    h ^= h >> 16;
    h = h.wrapping_mul(0x7feb_352d);
    h ^= h >> 15;
    h = h.wrapping_mul(0x846c_a68b);
    h ^= h >> 16;
    h as usize
}

fn main() -> Result<(), BlobError> {
    let blob = Blob::parse(SAMPLES)?; // validates everything once, no allocation
    let set = set_of_pixel(17, 4);
    // A renderer's estimate: the mean of f/q over the set's points, q the target.
    let (mut sum, mut sets) = (0.0, 1);
    match blob.kind() {
        BlobKind::PointSet2D => {
            let pts = blob.point_set_2d()?;
            sets = pts.set_count();
            for i in 0..pts.len() {
                let p: Vec2 = pts.point(set, i); // O(1), in (0,1)^2, indices wrap
                sum += p.x * p.y; // stands for f(p) / q(p)
            }
            sum /= pts.len() as f32;
        }
        BlobKind::DirectionSet => {
            let dirs = blob.direction_set()?;
            sets = dirs.set_count();
            for i in 0..dirs.len() {
                let w: Vec3 = dirs.direction(set, i); // O(1), unit length
                sum += w.z.max(0.0); // stands for f(w) / q(w)
            }
            sum /= dirs.len() as f32;
        }
        // Conditional samplers take a condition per sample; this blob is not one.
        BlobKind::Conditional => {}
    }
    // The set the lookups used: `set` wraps modulo the blob's set count.
    println!("set {} of {sets}: estimate {sum}", set % sets);
    Ok(())
}
