//! The guided sky (`RenderSettings::sky_guiding`, `passes/sky_guide.rs`) against the
//! environment's own sampling: both unbiased, so the direct light (the light samples and the
//! gather's escaping rays, weighed against each other with the guided density) agrees in the
//! mean. The warp's density is checked against its samples by a χ² test on the CPU twin
//! (`passes::sky_guide::tests`); this checks the GPU's: a warp that drew other directions than
//! `sky_density` says would bias the guided image.

mod common;

use rastergi::environment::Environment;
use rastergi::passes::film::Show;
use rastergi::scene::generate::sunroom;
use rastergi::settings::RenderSettings;

#[test]
fn the_guided_sky_agrees_with_the_skys_own_sampling_in_the_mean() {
    let gpu = common::gpu();
    let mut scene = sunroom();
    scene.lights.clear();
    scene.environment = Some(Environment::load(&common::data("env/sky_64x32.exr"), 1.0).unwrap());
    let (w, h, iterations) = (64u32, 48u32, 128u32);
    let settings = |seed: u32, sky_guiding: bool| RenderSettings {
        width: w,
        height: h,
        seed,
        photons: 1 << 16,
        gather: rastergi::gather::GatherMethod::Trace,
        sky_guiding,
        ..Default::default()
    };
    let seed: u32 = std::env::var("RASTERGI_TEST_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    // Per pixel the difference of the guided and the unguided direct light of two seeds each;
    // the pixels' errors are independent (each its own light samples and gather directions),
    // so the mean difference's standard error is their spread over √N.
    let mut d = Vec::new();
    for s in [seed, seed + 2] {
        let on = common::render(&gpu, &scene, settings(s, true), iterations, Show::Direct);
        let off = common::render(&gpu, &scene, settings(s + 1, false), iterations, Show::Direct);
        for (a, b) in on.pixels.iter().zip(&off.pixels) {
            let (a, b) = ((a[0] + a[1] + a[2]) as f64 / 3.0, (b[0] + b[1] + b[2]) as f64 / 3.0);
            assert!(a.is_finite() && b.is_finite());
            // The sky seen through the windows is the eye's, the same in both: left out.
            if b < 3.0 {
                d.push((a - b, b));
            }
        }
    }
    let (mean, level, se) = common::mean_difference(&d);
    println!("guided − unguided {mean:.6} (of {level:.5}), standard error {se:.6}");
    assert!(
        mean.abs() < 3.0 * se,
        "guided − unguided direct light {mean:.5} (of {level:.4}) against a standard error of {se:.5}"
    );
}

/// The GPU's guided warp against its CPU twin (`SkyBlocks::sample`, whose density a χ² test
/// checks): the same direction and density from the same uniforms, for a sky with a sun and a
/// table that opens a window's blocks.
#[test]
fn the_gpus_guided_warp_is_its_cpu_twins() {
    use rastergi::passes::sky_guide::{SkyBlocks, guided_sky_on_gpu};
    let gpu = common::gpu();
    let env = Environment::load(&common::data("env/sky_64x32.exr"), 1.0).unwrap();
    let blocks = SkyBlocks::new(&env);
    let mut openness = vec![0.0f32; blocks.masses.len()];
    for (b, v) in [(5 * 16, 0.43), (5 * 16 + 1, 0.06), (5 * 16 + 15, 0.14), (6 * 16, 0.1), (2 * 16 + 2, 0.5)] {
        openness[b] = v;
    }
    let weights: Vec<f32> = openness.iter().zip(&blocks.masses).map(|(v, m)| v * m).collect();
    let mut rng = rastergi::sampling::Rng::new(11, 0, 0);
    let queries: Vec<[f32; 2]> = (0..4096).map(|_| [rng.next_f32(), rng.next_f32()]).collect();
    let gpu_samples = guided_sky_on_gpu(&gpu, &env, &blocks, &weights, &queries).unwrap();
    let mut far = 0;
    for (q, g) in queries.iter().zip(&gpu_samples) {
        let (d, pdf) = blocks.sample(&env, &weights, q[0], q[1]);
        let gd = glam::Vec3::new(g[0], g[1], g[2]);
        // Rounding may move a sample on a cell's edge to the next cell.
        if (gd - d).length() > 1e-3 || (g[3] - pdf).abs() > 1e-3 * pdf {
            far += 1;
            assert!(far <= 4, "({}, {}): GPU {gd} {} against CPU {d} {pdf}", q[0], q[1], g[3]);
        }
    }
}
