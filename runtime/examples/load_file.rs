//! Reads a blob at run time and says what it holds:
//! `cargo run -p nuld-runtime --features std --example load_file -- FILE.nuld`.
//! Needs the runtime's `std` feature (or `alloc` and `AlignedBuf::from_bytes` on
//! bytes from elsewhere).
use nuld_runtime::{AlignedBuf, Blob};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: load_file FILE.nuld")?;
    // A `Vec<u8>` is not 16-byte aligned; `AlignedBuf` is.
    let buf = AlignedBuf::read(&path)?;
    let blob = Blob::parse(buf.as_bytes()).map_err(|e| format!("{path}: {e}"))?;
    println!("{path}: {:?} for {}", blob.kind(), blob.metadata().target);
    if let Ok(pts) = blob.point_set_2d() {
        println!("{} sets of {} points", pts.set_count(), pts.len());
    } else if let Ok(dirs) = blob.direction_set() {
        println!("{} sets of {} directions", dirs.set_count(), dirs.len());
    }
    Ok(())
}
