//! `build-tool export`: a blob's points as CSV, read through the runtime so that the
//! CSV shows exactly what a renderer gets.

use crate::pointset::AlignedBytes;
use anyhow::{anyhow, bail, Result};
use clap::Args;
use nuld_runtime::{Blob, BlobKind};
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `build-tool export`.
#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The blob to export.
    pub file: PathBuf,
}

/// Writes the CSV of a blob to `out`: header `set,index,x,y` for 2D point sets,
/// `set,index,x,y,z` for direction sets; values as the runtime returns them (f32,
/// shortest round-trip decimal).
pub fn write_csv(bytes: &[u8], out: &mut impl Write) -> Result<()> {
    let blob = Blob::parse(bytes).map_err(|e| anyhow!("{e}"))?;
    match blob.kind() {
        BlobKind::PointSet2D => {
            let pts = blob.point_set_2d().map_err(|e| anyhow!("{e}"))?;
            writeln!(out, "set,index,x,y")?;
            for s in 0..pts.set_count() {
                for i in 0..pts.len() {
                    let p = pts.point(s, i);
                    writeln!(out, "{s},{i},{},{}", p.x, p.y)?;
                }
            }
        }
        BlobKind::DirectionSet => {
            let dirs = blob.direction_set().map_err(|e| anyhow!("{e}"))?;
            writeln!(out, "set,index,x,y,z")?;
            for s in 0..dirs.set_count() {
                for i in 0..dirs.len() {
                    let d = dirs.direction(s, i);
                    writeln!(out, "{s},{i},{},{},{}", d.x, d.y, d.z)?;
                }
            }
        }
        BlobKind::Conditional => {
            bail!(
                "the blob holds a conditional sampler: print its samples with `build-tool sample`"
            )
        }
    }
    Ok(())
}

/// Runs `build-tool export`.
///
/// A reader that stops early (`export big.nuld | head`) closes the pipe; the
/// resulting `BrokenPipe` write error ends the export normally, with exit code 0.
pub fn run(a: ExportArgs) -> Result<()> {
    let bytes = AlignedBytes::read(&a.file)?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let written = write_csv(bytes.as_slice(), &mut out).and_then(|()| Ok(out.flush()?));
    match written {
        Err(e) if is_broken_pipe(&e) => Ok(()),
        other => other.map_err(|e| anyhow!("{}: {e}", a.file.display())),
    }
}

/// Whether `e` is a write to a pipe whose reader has gone.
pub(crate) fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.downcast_ref::<std::io::Error>()
        .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
}
