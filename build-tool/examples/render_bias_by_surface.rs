//! Where the BRDF samplers' bias sits in the render scene: the mean signed error
//! of `render`'s BRDF images split by surface (dielectric spheres, metal spheres,
//! ground), `cargo run --release -p nuld-build-tool --example
//! render_bias_by_surface -- MAP N=BLOB...` (e.g. `16=brdf-n16/brdf.nuld`).
//!
//! The images are `render`'s own at 160 x 120 pixels (the same samplers, seeds 0
//! to 3, so bit for bit those of `render --size 160x120 --seeds 4`): `nuld-table`,
//! `nuld-unbiased` and `owen-sobol` at `N` spp with the blob of `N`. The
//! reference is the renderer's (1024 + 1024 samples per pixel, seed 7): its mean
//! over a surface class of thousands of pixels is known to about 1e-4.
use nuld_build_tool::lab::render::environment::Environment;
use nuld_build_tool::lab::render::reference::Reference;
use nuld_build_tool::lab::render::sampler::Technique;
use nuld_build_tool::pointset::AlignedBytes;
use std::path::Path;
use surfaces::{EvalScene, CLASSES};

mod surfaces;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: render_bias_by_surface MAP N=BLOB...");
        std::process::exit(2);
    }
    let env = Environment::from_file(Path::new(&args[1])).unwrap();
    let eval = EvalScene::new(&env);
    let (setup, lobes) = (eval.setup(&env), &eval.lobes);
    let reference = Reference::render(&setup, lobes, 1024, 7, &|| {});
    let class: Vec<Option<usize>> = (eval.pixels.iter()).map(|p| p.map(|p| p.class)).collect();
    for arg in &args[2..] {
        let (n, path) = arg.split_once('=').expect("N=BLOB");
        let n: u32 = n.parse().expect("N a sample count");
        let blob = AlignedBytes::read(Path::new(path)).unwrap();
        for name in ["nuld-table", "nuld-unbiased", "owen-sobol"] {
            // Per class: sum of errors, sum of reference values, pixels.
            let mut sums = [[0.0f64; 3]; 3];
            for seed in 0..4u64 {
                let blobs = [Some(blob.as_slice()), None];
                let [img] = &eval.render(&env, &[Technique::Brdf], blobs, (n, seed), &[name])[..]
                else {
                    unreachable!("one image a name")
                };
                for (i, c) in class.iter().enumerate() {
                    if let Some(c) = *c {
                        sums[c][0] += img.values[i] - reference.image.values[i];
                        sums[c][1] += reference.image.values[i];
                        sums[c][2] += 1.0;
                    }
                }
            }
            let parts: Vec<String> = CLASSES
                .iter()
                .zip(sums)
                .map(|(label, [e, r, k])| {
                    format!("{label} {:+.2e} of {:.3} ({} px)", e / k, r / k, k / 4.0)
                })
                .collect();
            let total =
                sums.iter().map(|c| c[0]).sum::<f64>() / sums.iter().map(|c| c[2]).sum::<f64>();
            println!("{n} spp {name}: image {total:+.2e}; {}", parts.join("; "));
        }
    }
}
