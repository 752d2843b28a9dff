//! Where MIS's squared error sits in the render scene, per sampler and seed:
//! `cargo run --release -p nuld-build-tool --example mis_error_by_pixel -- MAP
//! REFERENCE_DIR N BRDF_BLOB ENVMAP_BLOB SAMPLER...` (e.g. `nuld-both-table
//! nuld-both-unbiased nuld-table`; about 1 min for three samplers at 256 spp).
//!
//! The images are `render`'s own at 160 x 120 pixels (the MIS samplers of the
//! lineup at `N` spp with the two blobs of `N`, seeds 0 to 3: bit for bit those
//! of `render --techniques mis --size 160x120 --seeds 4`), against the reference
//! `render` cached in `REFERENCE_DIR` (its one `reference-KEY.bin`). Prints each
//! image's summed squared error split by surface (dielectric spheres, metal
//! spheres, ground), the share of its ten worst pixels, and the four worst with
//! their roughness, view angle, error and reference value.
//! Results: docs/results/rendering.md#mis-both.
use nuld_build_tool::lab::render::environment::Environment;
use nuld_build_tool::lab::render::sampler::Technique;
use nuld_build_tool::pointset::AlignedBytes;
use std::path::Path;
use surfaces::{cached_reference, EvalScene, SurfacePixel, CLASSES};

mod surfaces;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 7 {
        eprintln!("usage: mis_error_by_pixel MAP REFERENCE_DIR N BRDF_BLOB ENVMAP_BLOB SAMPLER...");
        std::process::exit(2);
    }
    let env = Environment::from_file(Path::new(&args[1])).unwrap();
    let n: u32 = args[3].parse().expect("N a sample count");
    let (width, height) = EvalScene::SIZE;
    let eval = EvalScene::new(&env);
    let reference = cached_reference(Path::new(&args[2]), width, height);
    let pixels = &eval.pixels;
    let brdf = AlignedBytes::read(Path::new(&args[4])).unwrap();
    let envmap = AlignedBytes::read(Path::new(&args[5])).unwrap();
    for seed in 0..4u64 {
        let blobs = [Some(brdf.as_slice()), Some(envmap.as_slice())];
        let names: Vec<&str> = args[6..].iter().map(String::as_str).collect();
        let images = eval.render(&env, &[Technique::Mis], blobs, (n, seed), &names);
        for (name, img) in names.iter().zip(&images) {
            let mut by_class = [0.0f64; 3];
            let mut errors: Vec<(f64, usize)> = Vec::new();
            for (i, p) in pixels.iter().enumerate() {
                if let Some(SurfacePixel { class, .. }) = *p {
                    let e = img.values[i] - reference.image.values[i];
                    by_class[class] += e * e;
                    errors.push((e * e, i));
                }
            }
            errors.sort_by(|a, b| b.0.total_cmp(&a.0));
            let total: f64 = errors.iter().map(|e| e.0).sum();
            let worst10: f64 = errors.iter().take(10).map(|e| e.0).sum();
            let classes: Vec<String> = (CLASSES.iter().zip(by_class))
                .map(|(label, s)| format!("{label} {s:.3e}"))
                .collect();
            let worst: Vec<String> = (errors.iter().take(4))
                .map(|&(e2, i)| {
                    let SurfacePixel {
                        class,
                        roughness: r,
                        theta_o_deg: t,
                    } = pixels[i].unwrap();
                    let (x, y) = (i as u32 % width, i as u32 / width);
                    let v = reference.image.values[i];
                    format!(
                        "{} ({x}, {y}) roughness {r:.2} θo {t:.0}°: error {:.3} of {v:.3}",
                        CLASSES[class],
                        e2.sqrt()
                    )
                })
                .collect();
            println!(
                "seed {seed} {name}: squared error {total:.3e} ({}), worst 10 pixels {:.0} %; {}",
                classes.join(", "),
                100.0 * worst10 / total,
                worst.join("; ")
            );
        }
    }
}
