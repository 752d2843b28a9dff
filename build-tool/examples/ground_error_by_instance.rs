//! How a fixed-instance render's error on the ground splits over the blob's
//! instances: `cargo run --release -p nuld-build-tool --example
//! ground_error_by_instance -- MAP REFERENCE_DIR N ENVMAP_BLOB [envmap | mis]`
//! (seconds at 16 spp).
//!
//! Renders table mode (`nuld-table`) of `render --techniques T --size 160x120
//! --seeds 4` at `N` spp, seeds 0 to 3, bit for bit, against the reference
//! `render` cached in `REFERENCE_DIR`, and gives each ground pixel's squared
//! error to the environment instance it read (the pixel key's instance modulo
//! the blob's instances; under MIS the environment half's). Prints the instances'
//! mean squared errors: their spread (coefficient of variation), the shares of
//! the ground's squared error that the worst 1, 4 and 8 instances hold against
//! their share of its pixels, and the worst instances. If a few instances held
//! most of the error, a set of 64 offsets' luck would be whether it drew them.
//! Results: docs/results/rendering.md#offset-designs.
use nuld_build_tool::lab::render::environment::Environment;
use nuld_build_tool::lab::render::sampler::{PixelKey, Technique};
use nuld_build_tool::lab::render::scene::SurfaceClass;
use nuld_build_tool::pointset::AlignedBytes;
use nuld_core::blob::{Layout, SectionTag};
use nuld_core::conditional::ConditionalInfo;
use std::path::Path;
use surfaces::{cached_reference, EvalScene, SurfacePixel};

mod surfaces;

/// The ground's index among the surface classes.
const GROUND: usize = SurfaceClass::Ground.index();

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if !(5..=6).contains(&args.len()) {
        eprintln!("usage: ground_error_by_instance MAP REFERENCE_DIR N ENVMAP_BLOB [envmap | mis]");
        std::process::exit(2);
    }
    let env = Environment::from_file(Path::new(&args[1])).unwrap();
    let n: u32 = args[3].parse().expect("N a sample count");
    let technique = match args.get(5).map_or("envmap", |a| a.as_str()) {
        "mis" => Technique::Mis,
        _ => Technique::Envmap,
    };
    let (width, height) = EvalScene::SIZE;
    let eval = EvalScene::new(&env);
    let reference = cached_reference(Path::new(&args[2]), width, height);
    let pixels = &eval.pixels;
    let envmap = AlignedBytes::read(Path::new(&args[4])).unwrap();
    let layout = Layout::read(envmap.as_slice()).unwrap();
    let (_, info) = layout.section(SectionTag::ConditionalInfo).unwrap();
    let instances = bytemuck::pod_read_unaligned::<ConditionalInfo>(info).instances as usize;
    let (mut sum, mut count) = (vec![0.0f64; instances], vec![0u64; instances]);
    for seed in 0..4u64 {
        let blobs = [None, Some(envmap.as_slice())];
        let [img] = &eval.render(&env, &[technique], blobs, (n, seed), &["nuld-table"])[..] else {
            unreachable!("one image a name")
        };
        for (i, p) in pixels.iter().enumerate() {
            if let Some(SurfacePixel { class: GROUND, .. }) = *p {
                let (x, y) = (i as u32 % width, i as u32 / width);
                let key = PixelKey::new(seed, eval.camera.pixel_index(x, y));
                let k = key.instance() as usize % instances;
                let e = img.values[i] - reference.image.values[i];
                sum[k] += e * e;
                count[k] += 1;
            }
        }
    }
    let mse: Vec<f64> = (sum.iter().zip(&count))
        .map(|(s, &c)| s / c.max(1) as f64)
        .collect();
    let mean = mse.iter().sum::<f64>() / instances as f64;
    let sd = (mse.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / (instances - 1) as f64).sqrt();
    let mut order: Vec<usize> = (0..instances).collect();
    order.sort_by(|&a, &b| mse[b].total_cmp(&mse[a]));
    let (total, pixels_total) = (sum.iter().sum::<f64>(), count.iter().sum::<u64>());
    let share = |m: usize| {
        let top = &order[..m.min(instances)];
        (
            100.0 * top.iter().map(|&k| sum[k]).sum::<f64>() / total,
            100.0 * top.iter().map(|&k| count[k]).sum::<u64>() as f64 / pixels_total as f64,
        )
    };
    let shares: Vec<String> = [1, 4, 8]
        .map(|m| {
            let (e, p) = share(m);
            format!("worst {m}: {e:.1} % of the error on {p:.1} % of the pixels")
        })
        .into();
    let worst: Vec<String> = (order.iter().take(4))
        .map(|&k| format!("{k} ({:.2}x)", mse[k] / mean))
        .collect();
    println!(
        "{} instances, {pixels_total} ground pixel-seeds: mean squared error a pixel {mean:.3e}, \
         sd over instances / mean {:.2}, best {:.2}x, worst {:.2}x; {}; worst instances {}",
        instances,
        sd / mean,
        mse[order[instances - 1]] / mean,
        mse[order[0]] / mean,
        shares.join(", "),
        worst.join(", ")
    );
}
