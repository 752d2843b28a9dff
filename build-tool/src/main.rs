//! The `build-tool` binary: see `build-tool --help`.

use clap::Parser;

fn main() {
    let cli = nuld_build_tool::cli::Cli::parse();
    if let Err(e) = nuld_build_tool::cli::run(cli) {
        // One line: the context chain joined by ": ".
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
