//! The bake's tests: tiny bakes of the BRDF and of small maps, what ships.

use super::*;
use nuld_core::blob::{BlobKind, Layout, SectionTag};

/// A bake of a few steps of a tiny network: checks the files, not quality.
fn tiny() -> BakeConfig {
    BakeConfig {
        train: TrainConfig {
            n: 8,
            hidden: vec![6],
            steps: 3,
            pretrain_steps: 2,
            conditions_per_step: 2,
            instances_per_condition: 2,
            pool_conditions: 3,
            pool_caps: 32,
            caps_per_step: 16,
            ..TrainConfig::default()
        },
        instances: 3,
        quality_grid: 0,
        ..BakeConfig::default()
    }
}

/// A fresh scratch directory for test `name` holding the map `img` as
/// `map.hdr`: the directory and the map's path.
fn scratch_map(name: &str, img: image::Rgb32FImage) -> (PathBuf, PathBuf) {
    let dir = std::env::temp_dir().join(format!("nuld-bake-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let map = dir.join("map.hdr");
    image::DynamicImage::ImageRgb32F(img).save(&map).unwrap();
    (dir, map)
}

/// Resuming `config`'s finished run in `dir` trains nothing and writes `blob`
/// again, byte for byte.
fn resuming_writes_the_same_blob(config: &BakeConfig, dir: &Path, blob: &[u8]) {
    let resumed = BakeConfig {
        resume: true,
        ..config.clone()
    };
    let again = bake(&resumed, dir).unwrap();
    assert_eq!(again.blob_bytes, blob.len());
    assert_eq!(std::fs::read(dir.join(config.blob_name())).unwrap(), blob);
}

#[test]
fn a_tiny_bake_writes_a_blob_whose_sections_match_its_counts() {
    let dir = std::env::temp_dir().join(format!("nuld-bake-tiny-{}", std::process::id()));
    let config = BakeConfig {
        grid: [2, 3],
        weight_grid: [4, 2],
        ..tiny()
    };
    let report = bake(&config, &dir).unwrap();
    let blob = crate::pointset::AlignedBytes::read(&dir.join("brdf.nuld")).unwrap();
    let bytes = blob.as_slice();
    assert_eq!(bytes.len(), report.blob_bytes);
    let layout = Layout::read(bytes).unwrap();
    assert_eq!(layout.header().kind, BlobKind::Conditional as u32);
    let len = |tag: SectionTag| layout.section(tag).unwrap().1.len();
    let shape = config.train.shape().unwrap();
    assert_eq!(len(SectionTag::NetworkParams), 2 * shape.param_len());
    // A layer per metallic node (the default axis: 0, 0.5, 0.95).
    assert_eq!(len(SectionTag::MetallicNodes), 4 * 3);
    assert_eq!(len(SectionTag::PointTable), 3 * 4 * 2 * 3 * 3 * 8);
    // The dielectric's albedo, then the metal's.
    assert_eq!(len(SectionTag::WeightTable), 4 * 8 * 2);
    // The metal layer's network and point table, as long as the shared
    // network and one layer of its table.
    assert_eq!(len(SectionTag::MetalNetworkParams), 2 * shape.param_len());
    assert_eq!(len(SectionTag::MetalPointTable), 4 * 2 * 3 * 3 * 8);
    // The tabulated prior's five sections.
    let prior = crate::sphere::brdf_prior::BrdfPrior::shared();
    assert_eq!(len(SectionTag::BrdfPriorData), 4 * prior.data.len());
    assert_eq!(len(SectionTag::BrdfPriorMasses), 4 * prior.masses.len());
    for f in [
        "report.json",
        "loss.png",
        "sets.png",
        "checkpoint.bin",
        "checkpoint-metal.bin",
    ] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    // Instance 0's first point is served at every condition, metallic 0
    // and 1, both modes: under the plain offset hash its offset is (0, y),
    // the square's edge, which the prior sends below the horizon (pdf 0).
    let cs = nuld_runtime::Blob::parse(bytes)
        .unwrap()
        .conditional()
        .unwrap();
    for (r, t, m) in (0..16).map(|j| (0.1 + 0.06 * j as f32, 5.6 * j as f32, (j % 2) as f32)) {
        let c = glam::Vec2::new(r, t);
        for s in [
            cs.sample_metallic(c, m, 0, 0),
            cs.network().sample_metallic(c, m, 0, 0),
        ] {
            assert!(s.pdf > 0.0 && s.weight > 0.0, "({r}, {t}, {m}): {s:?}");
        }
    }
    // Resuming a finished run trains nothing and writes the same blob.
    resuming_writes_the_same_blob(&config, &dir, bytes);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Sets that check worse than the unbiased mode do not ship: untrained
/// weights (a random residual over the lattice) on a constant sky give way
/// to the lattice itself, whose check is what the report keeps.
#[test]
fn sets_worse_than_the_lattice_ship_as_the_lattice() {
    let grey = image::Rgb32FImage::from_pixel(64, 32, image::Rgb([0.5f32; 3]));
    let (dir, map) = scratch_map("ship", grey);
    let config = tiny().with_envmap(TrainTarget::envmap(&map).unwrap());
    let target = config.train.target.load().unwrap();
    let random = Params::init(config.train.shape().unwrap(), 11);
    let shipped = ship(random.clone(), None, &target, 2, true).unwrap();
    let trained = shipped.trained_quality.expect("a random residual is worse");
    assert!(!trained.training_helps());
    assert_eq!(shipped.params, random.without_residual().unwrap());
    assert!(shipped.metal.is_none());
    let lattice = shipped.quality.unwrap();
    assert!(lattice.mean_ratio < trained.mean_ratio);
    // The same lattice at fixed offsets and at random shifts: alike.
    assert!((lattice.mean_ratio - lattice.mean_randomized_ratio).abs() < 0.25);
    // Without a check nothing is judged and the trained weights ship.
    let unchecked = ship(random.clone(), None, &target, 0, true).unwrap();
    assert_eq!(unchecked.params, random);
    assert!(unchecked.quality.is_none() && unchecked.trained_quality.is_none());
    // Networks that were not trained are checked as they are, with nothing
    // to compare them with.
    let lattice_params = random.without_residual().unwrap();
    let untrained = ship(lattice_params.clone(), None, &target, 2, false).unwrap();
    assert_eq!(untrained.params, lattice_params);
    assert!(untrained.trained_quality.is_none());
    assert_eq!(
        untrained.quality.unwrap().mean_ratio.to_bits(),
        lattice.mean_ratio.to_bits()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A bake of no training steps builds no pool and trains nothing (no
/// checkpoint, and an earlier bake's loss curve in the directory goes), and
/// its blob serves the prior's shifted lattice: instance `k`'s point `i` in
/// network and table mode is the rank-1 lattice point shifted by the
/// instance's offset, warped by the map's tree at the normal (computed here
/// from the lattice's definition and the tree's `f64` warp).
#[test]
fn a_bake_of_no_steps_ships_the_lattice_through_the_prior() {
    // A sky brighter towards one side: a warp that is not the identity.
    let img = image::Rgb32FImage::from_fn(128, 64, |x, y| {
        image::Rgb([0.1 + (x as f32 / 128.0).powi(3) * (1.0 + y as f32 / 16.0); 3])
    });
    let (dir, map) = scratch_map("untrained", img);
    let mut config = BakeConfig {
        grid: [3, 3],
        weight_grid: [4, 4],
        ..tiny()
    }
    .with_envmap(TrainTarget::envmap(&map).unwrap());
    config.train.steps = 0;
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("loss.png"), b"an earlier bake's").unwrap();
    let report = bake(&config, &out).unwrap();
    assert_eq!((report.timings.train_s, report.loss_curve.len()), (0.0, 0));
    assert!(out.join("envmap.nuld").is_file() && out.join("sets.png").is_file());
    assert!(!out.join("loss.png").exists() && !out.join("checkpoint.bin").exists());

    let blob = crate::pointset::AlignedBytes::read(&out.join("envmap.nuld")).unwrap();
    let env = nuld_runtime::Blob::parse(blob.as_slice())
        .unwrap()
        .envmap()
        .unwrap();
    let target = config.train.target.load().unwrap();
    let LoadedTarget::Envmap(target) = target else {
        panic!("an environment target")
    };
    let tree = target.tree.tree();
    let shape = config.train.shape().unwrap();
    let (n, g) = (shape.n(), shape.lattice_generator());
    let mut worst = 0.0f64;
    for normal in [
        DVec3::Z,
        DVec3::new(0.6, -0.3, 0.2).normalize(),
        DVec3::new(-0.2, 0.9, -0.4).normalize(),
    ] {
        for k in 0..config.instances {
            let z: [f64; 2] = shape.instance_offset(k);
            for i in 0..n {
                // The lattice's definition: (i / n, frac(i g / n)), shifted.
                let u = [
                    (i as f64 / n as f64 + z[0]).fract(),
                    ((i as f64 * g as f64 / n as f64).fract() + z[1]).fract(),
                ];
                let want = DVec3::from(tree.sample(normal.to_array(), u).0);
                for got in [
                    env.sample(normal.as_vec3(), k, i).direction,
                    env.network().sample(normal.as_vec3(), k, i).direction,
                ] {
                    worst = worst.max(got.as_dvec3().angle_between(want));
                }
            }
        }
    }
    // f32 against f64, and the table's stored points.
    assert!(worst < 2e-3, "{worst} rad");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An environment bake of a constant sky: its weight table is the irradiance
/// of a constant map, `pi L` at every normal (the closed form; the pixel-centre
/// cosine sum is within 1e-3 of it), sets serve through `EnvmapSampler::sample`, and a
/// resumed finished run writes the same blob.
#[test]
fn an_envmap_bake_tabulates_pi_l_for_a_constant_sky_and_resumes() {
    let lum = 0.75f32;
    let grey = image::Rgb32FImage::from_pixel(128, 64, image::Rgb([lum; 3]));
    let (dir, map) = scratch_map("envmap", grey);
    let config = BakeConfig {
        grid: [3, 3],
        weight_grid: [5, 4],
        ..tiny()
    }
    .with_envmap(TrainTarget::envmap(&map).unwrap());
    assert_eq!(config.blob_name(), "envmap.nuld");
    let out = dir.join("out");
    let report = bake(&config, &out).unwrap();
    let blob = crate::pointset::AlignedBytes::read(&out.join("envmap.nuld")).unwrap();
    assert_eq!(blob.as_slice().len(), report.blob_bytes);
    let cs = nuld_runtime::Blob::parse(blob.as_slice())
        .unwrap()
        .envmap()
        .unwrap();
    assert_eq!(cs.conditional().domain(), Domain::Sphere);
    let pi_l = std::f64::consts::PI * lum as f64;
    for n in [
        DVec3::Z,
        DVec3::NEG_Z,
        DVec3::new(0.3, -0.8, 0.1).normalize(),
    ] {
        let s = cs.sample(n.as_vec3(), 1, 2);
        assert!(
            (s.weight as f64 / pi_l - 1.0).abs() < 1e-3,
            "{n}: {}",
            s.weight
        );
        assert!((s.direction.length() - 1.0).abs() < 1e-5);
    }
    for f in ["report.json", "loss.png", "sets.png", "checkpoint.bin"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    resuming_writes_the_same_blob(&config, &out, blob.as_slice());
    // Another map under the same directory is refused on resume.
    std::fs::write(&map, b"not a map any more").unwrap();
    let other = BakeConfig {
        resume: true,
        ..BakeConfig::default().with_envmap(TrainTarget::Envmap {
            path: map.clone(),
            content_hash: 1,
        })
    };
    assert!(bake(&other, &out).is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}
