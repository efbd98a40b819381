//! The guided gather (`RenderSettings::gather_guiding`, `gather/guide.rs`) against the
//! cosine's own sampling: both unbiased, so the indirect light agrees in the mean. The warp's
//! density is checked against its samples by a χ² test on the CPU twin
//! (`gather::guide::tests`); this checks the GPU's: a warp that drew other directions than
//! `guided_gather_density` says would bias the guided image.

mod common;

use rastergi::passes::film::Show;
use rastergi::scene::generate::sunroom;
use rastergi::settings::RenderSettings;

#[test]
fn the_guided_gather_agrees_with_the_cosines_sampling_in_the_mean() {
    let gpu = common::gpu();
    let scene = sunroom();
    let (w, h, iterations) = (64u32, 48u32, 128u32);
    let settings = |seed: u32, gather_guiding: bool| RenderSettings {
        width: w,
        height: h,
        seed,
        photons: 1 << 16,
        gather: rastergi::gather::GatherMethod::Trace,
        gather_guiding,
        photon_budget: rastergi::settings::PhotonBudget::Fitted,
        ..Default::default()
    };
    let seed: u32 = std::env::var("RASTERGI_TEST_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let luminance = |p: &[f32; 3]| (p[0] + p[1] + p[2]) as f64 / 3.0;
    // Per pixel the difference of the guided and the unguided indirect light over the same
    // photon maps (one seed, a fixed pass cadence): given the maps, the pixels' differences
    // are independent (each pixel its own scrambled directions), so the mean difference's
    // standard error is their spread over √N, and the maps' own noise, common to both, drops
    // out.
    let mut d = Vec::new();
    for s in [seed, seed + 1] {
        let on = common::render(&gpu, &scene, settings(s, true), iterations, Show::Indirect);
        let off = common::render(&gpu, &scene, settings(s, false), iterations, Show::Indirect);
        // The guide must have drawn most pixels' directions, or this test says nothing.
        let changed = on.pixels.iter().zip(&off.pixels).filter(|(a, b)| a != b).count();
        assert!(changed > on.pixels.len() / 2, "only {changed} pixels guided");
        for (a, b) in on.pixels.iter().zip(&off.pixels) {
            let (a, b) = (luminance(a), luminance(b));
            assert!(a.is_finite() && b.is_finite());
            d.push((a - b, b));
        }
    }
    let (mean, level, se) = common::mean_difference(&d);
    println!("guided − unguided {mean:.6} (of {level:.5}), standard error {se:.6}");
    assert!(
        mean.abs() < 3.0 * se,
        "guided − unguided indirect light {mean:.5} (of {level:.4}) against a standard error of {se:.5}"
    );
}
