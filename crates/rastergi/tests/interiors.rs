//! An interior as exporters write them: the built-in `sunroom`, a room lit by the sun and the
//! sky through two windows, standing on a ground plane 200 m across. Against Mitsuba 3 on the
//! same geometry (references: `scripts/mitsuba_reference.py` on `rastergi export sunroom`,
//! tests/data/README.md), the sun's and the sky's light each; and the photon grid's fine
//! cells where the camera reads the map, not over the ground.

mod common;

use glam::Vec3;
use rastergi::environment::Environment;
use rastergi::passes::film::Show;
use rastergi::progressive::Progressive;
use rastergi::scene::Scene;
use rastergi::scene::generate::sunroom;
use rastergi::settings::{PhotonRegionChoice, RenderSettings};
use rastergi::surface::PreparedScene;

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

/// The room under its sun alone, or under the test sky alone.
fn room(sun: bool) -> Scene {
    let mut s = sunroom();
    if !sun {
        s.lights.clear();
        s.environment = Some(Environment::load(&common::data("env/sky_64x32.exr"), 1.0).unwrap());
    }
    s
}

/// The settings the command line fits to the room (grid, photons; the photon region by the
/// camera), the traced gather.
fn settings(scene: &Scene, seed: u32, region: PhotonRegionChoice) -> RenderSettings {
    let grid = rastergi::fit::grid_resolution(&scene.bounds());
    RenderSettings {
        width: WIDTH,
        height: HEIGHT,
        seed,
        grid_resolution: grid,
        photons: rastergi::fit::photon_count(scene, grid),
        gather: rastergi::gather::GatherMethod::Trace,
        photon_region: region,
        pass_iterations: PASS_ITERATIONS,
        ..Default::default()
    }
}

#[test]
fn the_photon_region_of_a_room_on_a_ground_plane_is_the_room() {
    // The camera and its gather rays read the room (x ∈ [0, 6], z ∈ [0, 5], y ∈ [0.05, 3]) and
    // the ground just outside its windows: the region holds the room and is a small part of
    // the 200 m ground, its cells many times finer than the scene's.
    let scene = room(true);
    let prepared = PreparedScene::new(&scene);
    let grid = rastergi::fit::grid_resolution(&scene.bounds());
    let region =
        rastergi::fit::photon_region(&prepared, &scene.camera, WIDTH as f32 / HEIGHT as f32, grid).expect("a region");
    println!("region {:?}, factor {}", region.bounds, region.factor);
    let b = region.bounds;
    assert!(b.min.cmple(Vec3::new(0.3, 0.1, 0.3)).all() && b.max.cmpge(Vec3::new(5.7, 2.9, 4.7)).all(), "{b:?}");
    assert!(b.extent().max_element() < 20.0, "{b:?}");
    assert!(region.factor >= 8, "factor {}", region.factor);
}

/// Renders the room (sun or sky) with seeds 1 and 2 and compares their mean with the
/// reference pair `stem`.
fn against_mitsuba(sun: bool, iterations: u32, stem: &str) -> (rastergi::metrics::Comparison, f64, f64) {
    let gpu = common::gpu();
    let scene = room(sun);
    let seed: u32 = std::env::var("RASTERGI_TEST_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let a = common::render(&gpu, &scene, settings(&scene, seed, PhotonRegionChoice::Camera), iterations, Show::Full);
    let b =
        common::render(&gpu, &scene, settings(&scene, seed + 1, PhotonRegionChoice::Camera), iterations, Show::Full);
    let (reference, ref_noise) = common::reference_pair(stem, None);
    let (c, noise, bias) = common::against_reference(&a, &b, &reference, ref_noise, None);
    common::print_agreement(
        &format!("sunroom, {}, {iterations} iterations", if sun { "sun" } else { "sky" }),
        &c,
        noise,
        bias,
    );
    (c, noise, bias)
}

#[test]
fn a_sunlit_room_on_a_large_ground_plane_matches_mitsuba_in_the_suns_light() {
    let (c, _noise, bias) = against_mitsuba(true, ITERATIONS, "sunroom_sun_path_96");
    common::assert_agreement(&c, bias, MAX_BIAS, MAX_BLOCK, MAX_RATIO);
}

#[test]
fn a_sunlit_room_on_a_large_ground_plane_matches_mitsuba_in_the_skys_light() {
    let (c, _noise, bias) = against_mitsuba(false, ITERATIONS, "sunroom_sky_path_96");
    common::assert_agreement(&c, bias, MAX_BIAS, MAX_BLOCK, MAX_RATIO);
}

/// The room under its sun and the sky at once, the sun's direct light at the gather's hits
/// taken from a sample of it with a shadow ray and the rest from the map
/// (`HitLight::Punctual`): the sun's photons skip their first surface, the sky's do not.
/// Light adds, so the reference is the sum of the two pairs' means, its noise their noises'
/// root sum of squares; the bounds are the sun's. Seeds 1–2, 3–4, 5–6: bias beyond the noise
/// 2.2, 2.0, 2.8 %, block-mean error 0.21–0.34 %, channel means within 0.31 %; with the sun's
/// first deposits kept as well (its light counted twice) the means were 6.9 % high, without the
/// punctual lights' share of the table in the sample's weight 23 % high.
#[test]
fn a_room_under_sun_and_sky_matches_mitsuba_with_the_suns_light_sampled_at_gather_hits() {
    let gpu = common::gpu();
    let mut scene = room(true);
    scene.environment = room(false).environment;
    let seed: u32 = std::env::var("RASTERGI_TEST_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
    let settings = |seed| RenderSettings {
        hit_light: rastergi::gather::HitLight::Punctual,
        ..settings(&scene, seed, PhotonRegionChoice::Camera)
    };
    let a = common::render(&gpu, &scene, settings(seed), ITERATIONS, Show::Full);
    let b = common::render(&gpu, &scene, settings(seed + 1), ITERATIONS, Show::Full);
    let (sun, sun_noise) = common::reference_pair("sunroom_sun_path_96", None);
    let (sky, sky_noise) = common::reference_pair("sunroom_sky_path_96", None);
    let reference = rastergi::image_io::LinearImage {
        pixels: sun.pixels.iter().zip(&sky.pixels).map(|(p, q)| [0, 1, 2].map(|c| p[c] + q[c])).collect(),
        ..sun
    };
    let (c, noise, bias) = common::against_reference(&a, &b, &reference, sun_noise.hypot(sky_noise), None);
    common::print_agreement("sunroom, sun and sky, the sun sampled at gather hits", &c, noise, bias);
    common::assert_agreement(&c, bias, MAX_BIAS, MAX_BLOCK, MAX_RATIO);
}

const ITERATIONS: u32 = 128;
/// Iterations per photon pass: 8 passes in the test's iterations, so the map's noise averages
/// as it does in a long render (the fitted cadence, 4·photons/pixels, would keep this small
/// image on its first map for over a thousand iterations).
const PASS_ITERATIONS: u32 = 16;
/// Bounds from the spread over three seed pairs (1–2, 3–4, 5–6; RASTERGI_TEST_SEED picks the
/// first): bias beyond the noise 1.5–1.8 % (sun), 0–2.7 % (sky); block-mean error 0.47–0.68 %,
/// 0.62–0.94 %; channel means within 0.62 %, 1.02 % — about twice the largest of each. The
/// grid over the whole scene (before the photon region) was 11 % off in its blocks and 5–8 %
/// in its means here; losing the deposits on cell boundaries, 4 % in its means.
const MAX_BIAS: f64 = 0.04;
const MAX_BLOCK: f64 = 0.015;
const MAX_RATIO: f64 = 0.02;

/// The error estimate in a room with windows (issue 45: the sky seen through them, bright and
/// all but noise-free, filled the estimate's mean, and a path-traced living room stopped at
/// "5 %" with 26 % of error). The path tracer (unbiased: its error is its noise) renders the
/// sky-lit room; the film's estimate, from its halves over the pixels that never saw the sky
/// or an emitter (`FilmState::sees_light`), against the relative RMSE measured over the same
/// pixels against Mitsuba's pair less the pair's own noise: within the ratios the Cornell box's
/// estimate keeps (tests of `--target-error` in long_renders.rs: 0.75–1.1; the halves' blocks
/// of 16 iterations err on the safe side by about a tenth).
#[test]
fn the_error_estimate_leaves_the_sky_through_the_windows_out() {
    let gpu = common::gpu();
    let scene = room(false);
    let settings = RenderSettings { width: WIDTH, height: HEIGHT, seed: 3, ..Default::default() };
    let mut pt = rastergi::path_tracer::PathTracer::new(&gpu, &scene, settings).expect("path tracer");
    for i in 0..128 {
        pt.iterate();
        if i % 16 == 15 {
            pt.wait().unwrap();
        }
    }
    let film = pt.film_state().unwrap();
    let image = pt.read_linear().unwrap();
    let estimate = film.error_estimate().expect("both halves hold iterations");
    let ra = rastergi::image_io::read_exr(&common::data("sunroom_sky_path_96_a.exr")).unwrap();
    let rb = rastergi::image_io::read_exr(&common::data("sunroom_sky_path_96_b.exr")).unwrap();
    let (mut mse, mut mean, mut n, mut sky) = (0.0f64, 0.0f64, 0.0f64, 0usize);
    for (i, ((p, a), b)) in image.pixels.iter().zip(&ra.pixels).zip(&rb.pixels).enumerate() {
        if film.sees_light(i) {
            sky += 1;
            continue;
        }
        for ch in 0..3 {
            let r = 0.5 * (a[ch] as f64 + b[ch] as f64);
            // (x − r)² less the reference mean's own variance, (a − b)²/4.
            mse += (p[ch] as f64 - r).powi(2) - 0.25 * (a[ch] as f64 - b[ch] as f64).powi(2);
            mean += r;
            n += 1.0;
        }
    }
    let measured = (mse / n).max(0.0).sqrt() / (mean / n);
    println!(
        "sunroom under the sky, path tracer, 128 iterations: {sky} of {} pixels see the sky; estimated relative error {estimate:.4}, measured against Mitsuba {measured:.4}",
        image.pixels.len()
    );
    assert!(sky > 0 && sky < image.pixels.len() / 2, "{sky} pixels see the sky");
    assert!((0.75..1.1).contains(&(measured / estimate)), "estimated {estimate}, measured {measured}");
}
