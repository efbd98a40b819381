//! Direct lighting against independent computations: a closed form for a rectangular
//! emitter over a plane, and Mitsuba 3 for the Cornell box.

mod common;

use std::f64::consts::PI;

use glam::{DVec3, Vec3};
use rastergi::image_io::LinearImage;
use rastergi::metrics::emitter_mask;
use rastergi::passes::film::Show;
use rastergi::scene::{Camera, Material, Scene, cornell_box};
use rastergi::settings::RenderSettings;

/// Form factor from a point to the rectangle [0,X]×[0,Z] parallel to its plane at height h,
/// with the point under the corner (Howell's catalogue, C-11), signed by the corner's quadrant.
fn corner_form_factor(x: f64, z: f64, h: f64) -> f64 {
    let (a, b) = (x.abs() / h, z.abs() / h);
    let (sa, sb) = ((1.0 + a * a).sqrt(), (1.0 + b * b).sqrt());
    x.signum() * z.signum() * (a / sa * (b / sa).atan() + b / sb * (a / sb).atan()) / (2.0 * PI)
}

/// Form factor from a point at (px, 0, pz) facing +y to the rectangle [x0,x1]×[z0,z1] at y = h.
fn rect_form_factor(px: f64, pz: f64, [x0, x1, z0, z1]: [f64; 4], h: f64) -> f64 {
    let g = |x: f64, z: f64| corner_form_factor(x - px, z - pz, h);
    g(x1, z1) - g(x0, z1) - g(x1, z0) + g(x0, z0)
}

const RECT: [f64; 4] = [-0.5, 0.5, -0.3, 0.3];
const H: f64 = 1.0;
const ALBEDO: f64 = 0.5;
const LE: [f32; 3] = [2.0, 3.0, 4.0];

/// A white floor at y = 0 under a 1 × 0.6 emitter facing down at y = 1, seen from above.
fn emitter_over_plane() -> Scene {
    let camera = Camera { eye: Vec3::new(0.0, 0.9, 0.0), target: Vec3::ZERO, up: Vec3::NEG_Z, fov_y_deg: 60.0 };
    let mut s = Scene::new(camera);
    let floor = s.add_material(Material::diffuse("floor", Vec3::splat(ALBEDO as f32)));
    let light = s.add_material(Material { emission: Vec3::from(LE), ..Material::diffuse("light", Vec3::ZERO) });
    s.add_quad(
        [
            Vec3::new(-10.0, 0.0, -10.0),
            Vec3::new(-10.0, 0.0, 10.0),
            Vec3::new(10.0, 0.0, 10.0),
            Vec3::new(10.0, 0.0, -10.0),
        ],
        floor,
    );
    let [x0, x1, z0, z1] = RECT.map(|v| v as f32);
    let y = H as f32;
    s.add_quad([Vec3::new(x0, y, z0), Vec3::new(x1, y, z0), Vec3::new(x1, y, z1), Vec3::new(x0, y, z1)], light);
    s
}

/// Floor point seen through image position (u, v) ∈ [0,1]² (v down) of `camera`.
fn floor_point(camera: &Camera, w: u32, h: u32, u: f64, v: f64) -> (f64, f64) {
    let (right, up, forward) = camera.frame();
    let t = (0.5 * camera.fov_y_deg as f64).to_radians().tan();
    let (x, y) = ((2.0 * u - 1.0) * t * w as f64 / h as f64, (1.0 - 2.0 * v) * t);
    let d = forward.as_dvec3() + right.as_dvec3() * x + up.as_dvec3() * y;
    let e = camera.eye.as_dvec3();
    let s = -e.y / d.y;
    (e.x + s * d.x, e.z + s * d.z)
}

/// Mean and variance of the one-sample estimator (ρ/π)·Le·cosθ·cosθ'/r²·A (uniform area
/// sampling of the rectangle) at (px, pz), by midpoint quadrature over the rectangle.
fn estimator_moments(px: f64, pz: f64) -> (f64, f64) {
    let [x0, x1, z0, z1] = RECT;
    let area = (x1 - x0) * (z1 - z0);
    let n = 120;
    let (mut m1, mut m2) = (0.0, 0.0);
    for i in 0..n {
        for j in 0..n {
            let y = DVec3::new(
                x0 + (i as f64 + 0.5) / n as f64 * (x1 - x0),
                H,
                z0 + (j as f64 + 0.5) / n as f64 * (z1 - z0),
            );
            let d = y - DVec3::new(px, 0.0, pz);
            let r2 = d.length_squared();
            let cos = d.y / r2.sqrt();
            let f = ALBEDO / PI * cos * cos / r2 * area;
            m1 += f;
            m2 += f * f;
        }
    }
    let k = (n * n) as f64;
    (m1 / k, m2 / k - (m1 / k).powi(2))
}

#[test]
fn direct_light_under_a_rectangular_emitter_matches_the_closed_form_within_the_measured_noise() {
    let gpu = common::gpu();
    let scene = emitter_over_plane();
    let (w, h, n) = (40u32, 40u32, 64u32);
    let render = |seed| {
        common::render(
            &gpu,
            &scene,
            RenderSettings { width: w, height: h, seed, light_samples: 1, photons: 0, ..Default::default() },
            n,
            Show::Full,
        )
    };
    let (a, b) = (render(3), render(4));
    // The pass shades from x + n·ε (the shadow ray's origin): the closed form at that height.
    // ε = 2e-4 under an emitter at height 1 is about 4e-4 more light, a mean error of 0.0085 σ:
    // hidden by independent samples' noise, 6 standard errors of the stratified samples'.
    let eps = rastergi::surface::PreparedScene::new(&scene).ray_epsilon() as f64;

    // Per pixel: the closed form averaged over the pixel (box filter, 4×4 points) and the
    // standard deviation σ of an n-sample mean of the light-sampling estimator with
    // independent samples (unit Le). Errors are in units of σ: z = (image − expected)/σ.
    let (mut za, mut zb) = (Vec::new(), Vec::new());
    for py in 0..h {
        for px in 0..w {
            let (mut expected, mut var) = (0.0, 0.0);
            for sy in 0..4 {
                for sx in 0..4 {
                    let u = (px as f64 + (sx as f64 + 0.5) / 4.0) / w as f64;
                    let v = (py as f64 + (sy as f64 + 0.5) / 4.0) / h as f64;
                    let (x, z) = floor_point(&scene.camera, w, h, u, v);
                    expected += ALBEDO * rect_form_factor(x, z, RECT, H - eps) / 16.0;
                    if sx == 1 && sy == 1 {
                        var = estimator_moments(x, z).1;
                    }
                }
            }
            for img in [&a, &b] {
                let got = img.at(px, py);
                for c in 0..3 {
                    // Channels scale one light sample by Le_c: they are not independent, but
                    // each must agree; the statistics below use the green channel alone.
                    let rel = got[c] as f64 / LE[c] as f64 / expected;
                    assert!((rel - 1.0).abs() < 0.5, "pixel ({px},{py}) channel {c}: {rel}");
                }
            }
            let sigma = (var / n as f64).sqrt();
            za.push((a.at(px, py)[1] as f64 / LE[1] as f64 - expected) / sigma);
            zb.push((b.at(px, py)[1] as f64 / LE[1] as f64 - expected) / sigma);
        }
    }
    let count = za.len() as f64;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / count;
    let mean_z2 = (za.iter().map(|z| z * z).sum::<f64>() + zb.iter().map(|z| z * z).sum::<f64>()) / (2.0 * count);
    // The noise, measured: the two seeds' images are independent, so E[(a − b)²]/2 is the
    // variance of one (in σ², per pixel, averaged over the image).
    let noise2 = za.iter().zip(&zb).map(|(x, y)| (x - y).powi(2)).sum::<f64>() / (2.0 * count);
    let mean_z = (mean(&za) + mean(&zb)) / 2.0;
    println!("mean z {mean_z:.5}, mean z² {mean_z2:.5}, seed-to-seed noise² {noise2:.5} (independent samples: 1)");
    // The light samples are stratified (Owen-scrambled Sobol' per pixel): under a fully
    // visible emitter the error variance falls far below independent samples' σ² (measured
    // 0.0057 σ², seeds 3 and 4; 1 with the earlier independent samples).
    assert!(mean_z2 < 0.02, "noise not below independent sampling's: mean z² = {mean_z2}");
    // Unbiased: the mean of 3200 errors (1600 pixels, each seed's scramble its own) has
    // standard deviation sqrt(noise² / 3200).
    let se = (noise2 / (2.0 * count)).sqrt();
    assert!(mean_z.abs() < 5.0 * se, "bias: mean standardised error {mean_z} vs its noise {se}");
    // Error against the closed form = the measured noise: mean z² of 3200 values is
    // noise² · (1 ± 0.025) for Gaussian errors, and noise² has ±3.5 % of its own (5σ bounds).
    assert!((mean_z2 / noise2 - 1.0).abs() < 0.25, "error {mean_z2} σ² vs measured noise {noise2} σ²");
    let max_z = za.iter().chain(&zb).fold(0.0f64, |m, z| m.max(z.abs()));
    assert!(max_z < 6.0 * noise2.sqrt(), "an outlier pixel: |z| = {max_z} vs noise {}", noise2.sqrt());
}

#[test]
fn direct_only_cornell_box_matches_mitsuba_within_the_combined_noise() {
    let gpu = common::gpu();
    let scene = cornell_box();
    let n = 256;
    let settings =
        |seed| RenderSettings { width: 128, height: 128, seed, light_samples: 1, photons: 0, ..Default::default() };
    let a = common::render(&gpu, &scene, settings(1), n, Show::Direct);
    let b = common::render(&gpu, &scene, settings(2), n, Show::Direct);
    assert_cornell_direct_matches_mitsuba(&a, &b);
}

/// Two seeds' direct light of the Cornell box at 128² against the Mitsuba pair: within the
/// combined noise, channel means within 0.5 %.
fn assert_cornell_direct_matches_mitsuba(a: &LinearImage, b: &LinearImage) {
    let probe = rastergi::image_io::read_exr(&common::data("cornell_direct_128_a.exr")).unwrap();
    let mask = emitter_mask(&probe, 3.0);
    let (reference, ref_noise) = common::reference_pair("cornell_direct_128", Some(&mask));
    let (c, _) = common::assert_within_combined_noise(a, b, &reference, ref_noise, Some(&mask));
    for ratio in c.mean_ratio {
        assert!((ratio - 1.0).abs() < 0.005, "channel means differ: {:?}", c.mean_ratio);
    }
}

/// The direct pass's estimate of one light sample's variance (the light budget's D, the film's
/// fourth indirect channel) against the one-sample estimator's variance by quadrature: with k
/// samples stratified within an iteration, E[s²] = k·(σ² − Var ē)/(k − 1), between σ² and
/// k/(k − 1)·σ² (Var ē between 0 and σ²/k).
#[test]
fn the_light_sample_variance_matches_the_estimators_quadrature() {
    let gpu = common::gpu();
    let scene = emitter_over_plane();
    let (w, h, n, k) = (40u32, 40u32, 8u32, 16u32);
    let settings = RenderSettings { width: w, height: h, seed: 5, light_samples: k, photons: 0, ..Default::default() };
    let mut r = rastergi::renderer::Renderer::new(&gpu, &scene, settings).unwrap();
    for _ in 0..n {
        r.iterate().unwrap();
    }
    let film = r.film_state().unwrap();
    let measured = film.light_sample_variance() / n as f64;
    let le2: f64 = LE.iter().map(|&l| (l as f64).powi(2)).sum();
    let mut expected = 0.0;
    for py in 0..h {
        for px in 0..w {
            let u = (px as f64 + 0.5) / w as f64;
            let v = (py as f64 + 0.5) / h as f64;
            let (x, z) = floor_point(&scene.camera, w, h, u, v);
            expected += le2 * estimator_moments(x, z).1;
        }
    }
    let ratio = measured / expected;
    println!("s² summed over the pixels: {measured:.5e}, σ²: {expected:.5e}, ratio {ratio:.4}");
    // Under a fully visible emitter the stratified samples' Var ē is a tiny part of σ²/k (the
    // closed-form test above measures 0.6 % of it across iterations), so E[s²] is k/(k − 1)·σ²
    // to a few parts in 10⁴ (measured 1.0657 against 1.0667): a sum divided by k, or not
    // weighted by the path, fails. 1600 pixels × 8 iterations of 16 samples: the mean of s² has
    // a relative noise under 1 %; the jitter moves each point within its pixel (σ² at the
    // centre).
    let most = k as f64 / (k - 1) as f64;
    assert!((ratio - most).abs() < 0.02, "s² / σ² = {ratio}, expected {most:.4}");
}

/// The light budget changes the count as the render goes on (4, 2 and 8 while it times, then
/// its choice): the image stays the expectation, against Mitsuba 3 as the fixed count is above.
#[test]
fn direct_light_with_the_balanced_light_samples_matches_mitsuba() {
    let gpu = common::gpu();
    let scene = cornell_box();
    let n = 256;
    let settings =
        |seed| RenderSettings { width: 128, height: 128, seed, light_balance: true, photons: 0, ..Default::default() };
    let render = |seed| {
        let mut r = rastergi::renderer::Renderer::new(&gpu, &scene, settings(seed)).unwrap();
        for _ in 0..n {
            r.iterate().unwrap();
        }
        // Without indirect light only the jitter's variance competes with the light's: more
        // than one sample.
        assert!(r.light_samples() > 1, "chose {}", r.light_samples());
        r.read_linear(Show::Direct).unwrap()
    };
    assert_cornell_direct_matches_mitsuba(&render(1), &render(2));
}

#[test]
fn red_wall_is_on_the_left_of_the_cornell_box_image() {
    let gpu = common::gpu();
    let img = common::render(
        &gpu,
        &cornell_box(),
        RenderSettings { width: 64, height: 64, seed: 0, light_samples: 1, photons: 0, ..Default::default() },
        8,
        Show::Full,
    );
    let ratio = |x0: u32, x1: u32| {
        let (mut r, mut g) = (0.0, 0.0);
        for y in 16..48 {
            for x in x0..x1 {
                r += img.at(x, y)[0] as f64;
                g += img.at(x, y)[1] as f64;
            }
        }
        r / g
    };
    assert!(ratio(0, 6) > 5.0, "left edge is not red: r/g = {}", ratio(0, 6));
    assert!(ratio(58, 64) < 0.5, "right edge is not green: r/g = {}", ratio(58, 64));
}

/// The area of the convex polygon `poly` (image points, pixels) inside pixel (i, j)'s square:
/// Sutherland–Hodgman clipping against its four sides, then the shoelace formula.
fn pixel_coverage(poly: &[[f64; 2]], i: u32, j: u32) -> f64 {
    let (x0, y0) = (f64::from(i), f64::from(j));
    // Each side: (axis, bound, keep where the coordinate is ≥ the bound).
    let sides = [(0, x0, true), (0, x0 + 1.0, false), (1, y0, true), (1, y0 + 1.0, false)];
    let mut p = poly.to_vec();
    for (axis, bound, above) in sides {
        let inside = |q: &[f64; 2]| if above { q[axis] >= bound } else { q[axis] <= bound };
        let mut out = Vec::new();
        for k in 0..p.len() {
            let (a, b) = (p[k], p[(k + 1) % p.len()]);
            if inside(&a) {
                out.push(a);
            }
            if inside(&a) != inside(&b) {
                let t = (bound - a[axis]) / (b[axis] - a[axis]);
                out.push([a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]);
            }
        }
        p = out;
        if p.is_empty() {
            return 0.0;
        }
    }
    let twice: f64 = (0..p.len()).map(|k| p[k][0] * p[(k + 1) % p.len()][1] - p[(k + 1) % p.len()][0] * p[k][1]).sum();
    0.5 * twice.abs()
}

/// The emission seen at an emitter's edges against the exact box-filtered coverage: a unit
/// square emitter turned 25° in its plane, facing the camera squarely (its image a turned
/// square) before a black wall. Each pixel's value is Le × the area of the square's
/// image inside the pixel, computed here by clipping. With the edge pixels supersampled
/// (`emitter_edges` = 4, 16 stratified rays) one iteration is within a few hundredths of the
/// coverage, where one jittered sample is off by about ½; after 64 iterations the mean error
/// over the edge pixels shows no bias (a sub-pixel ray placed by the wrong jitter would blur
/// the edge by up to a pixel, an error of tenths). Thresholds from seeds 0–8: one iteration
/// 0.045–0.053 (one sample 0.33–0.46), 64 iterations 0.0054–0.0067, mean error within
/// ±0.0011, elsewhere at most 0.0054. The share of each pixel that the film records as seeing
/// light (the direct component's fourth channel, which the viewer's resolve reads to keep a
/// preview's light off the pixels that do not see it) is the same coverage from the same rays
/// at the edge pixels, and elsewhere (coverage within 0.01 of 0 or 1) within one of the 16
/// rays of it: 0 or 1, or a sliver flagged as an edge.
#[test]
fn the_emission_at_an_emitters_edges_is_its_pixel_coverage() {
    let gpu = common::gpu();
    let camera = Camera { eye: Vec3::new(0.0, 0.0, 3.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
    let mut scene = Scene::new(camera);
    let le = 2.0f32;
    let light = scene.add_material(Material { emission: Vec3::splat(le), ..Material::diffuse("light", Vec3::ZERO) });
    let turn = glam::Mat3::from_rotation_z(25f32.to_radians());
    let corners = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]].map(|[x, y]| turn * Vec3::new(x, y, 0.0));
    scene.add_quad(corners, light);
    // A black wall behind it, so that the pixels around the square see a surface, not the
    // (black) sky, which counts as light itself.
    let wall = scene.add_material(Material::diffuse("wall", Vec3::ZERO));
    scene.add_quad([[-3.0, -3.0], [3.0, -3.0], [3.0, 3.0], [-3.0, 3.0]].map(|[x, y]| Vec3::new(x, y, -1.0)), wall);
    let (w, h) = (64u32, 48u32);
    // The corners' images, in pixels from the top-left corner.
    let (right, up, forward) = camera.frame();
    let t = f64::from((0.5 * camera.fov_y_deg).to_radians().tan());
    let image: Vec<[f64; 2]> = corners
        .iter()
        .map(|&c| {
            let d = (c - camera.eye).as_dvec3();
            let z = d.dot(forward.as_dvec3());
            let (x, y) =
                (d.dot(right.as_dvec3()) / (z * t * f64::from(w) / f64::from(h)), d.dot(up.as_dvec3()) / (z * t));
            [0.5 * (x + 1.0) * f64::from(w), 0.5 * (1.0 - y) * f64::from(h)]
        })
        .collect();
    let coverage: Vec<f64> =
        (0..h).flat_map(|j| (0..w).map(move |i| (i, j))).map(|(i, j)| pixel_coverage(&image, i, j)).collect();
    let edge: Vec<usize> = (0..coverage.len()).filter(|&k| coverage[k] > 0.01 && coverage[k] < 0.99).collect();
    assert!(edge.len() > 60, "the square's image should cross many pixels, got {}", edge.len());
    let settings =
        |n| RenderSettings { width: w, height: h, photons: 0, emitter_edges: n, ..RenderSettings::default() };
    // (RMS error, mean error) over the edge pixels, in units of Le, and the largest error over
    // the others (inside: exactly Le; outside: 0).
    let errors = |img: &LinearImage| {
        let e: Vec<f64> = edge.iter().map(|&k| f64::from(img.pixels[k][1]) / f64::from(le) - coverage[k]).collect();
        let rms = (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt();
        let elsewhere = (0..coverage.len())
            .filter(|k| !edge.contains(k))
            .map(|k| (f64::from(img.pixels[k][1]) / f64::from(le) - coverage[k]).abs())
            .fold(0.0, f64::max);
        (rms, e.iter().sum::<f64>() / e.len() as f64, elsewhere)
    };
    let (point, _, _) = errors(&common::render(&gpu, &scene, settings(0), 1, Show::Direct));
    let mut r = rastergi::renderer::Renderer::new(&gpu, &scene, settings(4)).unwrap();
    r.iterate().unwrap();
    let (one, _, _) = errors(&r.read_linear(Show::Direct).unwrap());
    let film = r.film_state().unwrap();
    let share =
        |k: usize| f64::from(film.sums[(rastergi::gpu::consts::FILM_DIRECT as usize * coverage.len() + k) * 4 + 3]);
    let shares = edge.iter().map(|&k| (share(k) - coverage[k]).powi(2)).sum::<f64>() / edge.len() as f64;
    let off_edge =
        (0..coverage.len()).filter(|k| !edge.contains(k)).map(|k| (share(k) - coverage[k]).abs()).fold(0.0, f64::max);
    println!(
        "the film's share of light after one iteration: at the edge pixels RMS error {:.4}, elsewhere at most {off_edge:.4}",
        shares.sqrt()
    );
    assert!(
        shares.sqrt() < 0.06,
        "the film's share of light at the edge pixels is not their coverage (RMS {:.4})",
        shares.sqrt()
    );
    assert!(off_edge <= 1.0 / 16.0 + 0.01, "the film's share of light off the edges is off by {off_edge:.4}");
    let (many, bias, elsewhere) = errors(&common::render(&gpu, &scene, settings(4), 64, Show::Direct));
    println!(
        "{} edge pixels: RMS error of one iteration {point:.4} (one sample) → {one:.4} (16 rays); of 64 iterations {many:.5}, mean {bias:+.5}; elsewhere at most {elsewhere:.4}",
        edge.len()
    );
    assert!(point > 0.2, "one jittered sample should be all or nothing at an edge (RMS {point:.4})");
    assert!(one < 0.06, "16 stratified rays should find the coverage within a few hundredths (RMS {one:.4})");
    assert!(many < 0.015, "64 iterations should converge to the coverage (RMS {many:.5})");
    assert!(bias.abs() < 0.003, "the edge pixels' mean error should vanish (mean {bias:+.5})");
    assert!(elsewhere < 0.02, "pixels off the edge should be exactly Le or 0 ({elsewhere:.4})");
}
