//! `build-tool shader`: the runtime's WGSL sampling kernel in a shading language,
//! translated and checked by [`crate::shader::translate`].

use crate::shader::{translate, Check, Lang};
use anyhow::Result;
use clap::Args;
use std::io::Write;
use std::path::PathBuf;

/// Arguments of `build-tool shader`.
#[derive(Args, Debug)]
pub struct ShaderArgs {
    /// The shading language.
    #[arg(long, value_enum)]
    pub lang: Lang,
    /// Write here (atomically) instead of to standard output.
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// Runs `build-tool shader`: the shader to `--out` (a one-line report on standard
/// error) or to standard output.
pub fn run(a: ShaderArgs) -> Result<()> {
    let t = translate(a.lang)?;
    match a.out {
        Some(path) => {
            crate::output::write_atomic(&path, &t.bytes)?;
            let check = match t.check {
                Check::RoundTrip => "parsed back and validated",
                Check::ValidatedModule => "module validated",
            };
            eprintln!(
                "wrote {} ({} bytes, {}; {check})",
                path.display(),
                t.bytes.len(),
                a.lang.name()
            );
        }
        None => {
            let mut out = std::io::stdout().lock();
            out.write_all(&t.bytes)?;
            out.flush()?;
        }
    }
    Ok(())
}
