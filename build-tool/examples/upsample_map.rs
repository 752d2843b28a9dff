//! Writes a map `K` times larger on each side, every pixel repeated `K x K` times,
//! as a Radiance HDR: the same light at the resolution of a larger map, to time
//! and check `bake --envmap` on it (docs/results/envmap.md#large-maps).
//!
//! `cargo run --release -p nuld-build-tool --example upsample_map -- IN OUT K`,
//! e.g. `../shared/data/envmaps/courtyard.hdr out/maps/courtyard-4k.hdr 4`.
use anyhow::{bail, Context, Result};
use image::codecs::hdr::HdrEncoder;
use image::Rgb;
use std::io::BufWriter;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [input, output, k] = args.as_slice() else {
        bail!("usage: upsample_map IN OUT K");
    };
    let k: u32 = k.parse().context("K is not a positive integer")?;
    if k == 0 {
        bail!("K must be at least 1");
    }
    let img = image::open(input)
        .with_context(|| format!("cannot read {input}"))?
        .to_rgb32f();
    let (w, h) = img.dimensions();
    let (big_w, big_h) = (w * k, h * k);
    let pixels: Vec<Rgb<f32>> = (0..big_h)
        .flat_map(|y| (0..big_w).map(move |x| (x / k, y / k)))
        .map(|(x, y)| *img.get_pixel(x, y))
        .collect();
    let file = std::fs::File::create(output).with_context(|| format!("cannot write {output}"))?;
    HdrEncoder::new(BufWriter::new(file)).encode(&pixels, big_w as usize, big_h as usize)?;
    eprintln!("{output}: {big_w} x {big_h} pixels");
    Ok(())
}
