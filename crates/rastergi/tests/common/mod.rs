//! Shared test harness: the GPU (lavapipe on CI), renders and references.
#![allow(dead_code)]

pub mod materials;
pub mod mitsuba;
pub mod textured_room;

use std::path::PathBuf;

use base64::Engine as _;
use rastergi::gpu::{Gpu, GpuOptions};
use rastergi::image_io::{LinearImage, read_exr};
use rastergi::passes::film::Show;
use rastergi::progressive::Progressive;
use rastergi::renderer::Renderer;
use rastergi::scene::Scene;
use rastergi::settings::RenderSettings;
use serde_json::{Value, json};

/// The test's device: one per test (each test runs on a thread of its own), so that a test's
/// renderers reuse each other's compiled pipelines (`rastergi::gpu::compiled`) while a device
/// error stays within the test that caused it.
pub fn gpu() -> Gpu {
    thread_local! {
        static GPU: Gpu = Gpu::new(&GpuOptions::default())
            .unwrap_or_else(|e| panic!("tests need a GPU adapter (lavapipe on CI): {e}"));
    }
    GPU.with(Gpu::clone)
}

/// Renders `iterations` iterations and returns the mean image of `show`.
pub fn render(gpu: &Gpu, scene: &Scene, settings: RenderSettings, iterations: u32, show: Show) -> LinearImage {
    let mut r = Renderer::new(gpu, scene, settings).expect("renderer");
    for i in 0..iterations {
        r.iterate().expect("iteration");
        if i % 16 == 15 {
            r.wait().unwrap();
        }
    }
    r.read_linear(show).expect("readback")
}

/// The reference path tracer's mean of `iterations` iterations of `scene` with `settings`.
pub fn path_trace(gpu: &Gpu, scene: &Scene, settings: RenderSettings, iterations: u32) -> LinearImage {
    let mut pt = rastergi::path_tracer::PathTracer::new(gpu, scene, settings).expect("path tracer");
    for i in 0..iterations {
        pt.iterate();
        if i % 16 == 15 {
            pt.wait().unwrap();
        }
    }
    pt.read_linear().expect("readback")
}

/// The settings the command line fits to `scene` (grid, photons) at `size`², the traced
/// gather, seed `seed`: how users render.
pub fn fitted_settings(scene: &Scene, size: u32, seed: u32) -> RenderSettings {
    let grid = rastergi::fit::grid_resolution(&scene.bounds());
    RenderSettings {
        width: size,
        height: size,
        seed,
        grid_resolution: grid,
        photons: rastergi::fit::photon_count(scene, grid),
        gather: rastergi::gather::GatherMethod::Trace,
        ..Default::default()
    }
}

pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// A committed reference pair (two independent renders): their mean, and the RMS noise of
/// that mean estimated from their difference, rmse(a, b)/2.
pub fn reference_pair(stem: &str, mask: Option<&[bool]>) -> (LinearImage, f64) {
    let a = read_exr(&data(&format!("{stem}_a.exr"))).expect("reference a");
    let b = read_exr(&data(&format!("{stem}_b.exr"))).expect("reference b");
    let noise = rastergi::metrics::rmse(&a, &b, mask) / 2.0;
    (average(&a, &b), noise)
}

/// Our renders `a` and `b`, whose seeds differ in every random choice (the photons included),
/// against the mean of a reference pair of RMS noise `ref_noise`: the comparison of our mean
/// with it, the relative noise of that comparison (ours from a − b, the reference's), and
/// the bias beyond that noise, √(RMSE² − noise²).
pub fn against_reference(
    a: &LinearImage,
    b: &LinearImage,
    reference: &LinearImage,
    ref_noise: f64,
    mask: Option<&[bool]>,
) -> (rastergi::metrics::Comparison, f64, f64) {
    let mean = rastergi::metrics::masked_mean(reference, mask);
    let noise = (rastergi::metrics::rmse(a, b, mask).powi(2) / 4.0 + ref_noise.powi(2)).sqrt() / mean;
    let c = rastergi::metrics::compare(&average(a, b), reference, mask);
    let bias = (c.relative_rmse.powi(2) - noise.powi(2)).max(0.0).sqrt();
    (c, noise, bias)
}

/// Prints what [`against_reference`] found, on one line after `label`.
pub fn print_agreement(label: &str, c: &rastergi::metrics::Comparison, noise: f64, bias: f64) {
    println!(
        "{label}: relative RMSE {:.4} = noise {noise:.4} ⊕ bias {bias:.4}; block-mean error {:.4}; mean ratio {:.4?}",
        c.relative_rmse, c.block_mean_error, c.mean_ratio
    );
}

/// Asserts an agreement found by [`against_reference`]: the bias beyond noise under
/// `max_bias`, the block-mean error under `max_block`, every channel's mean ratio within
/// `max_ratio` of 1.
pub fn assert_agreement(c: &rastergi::metrics::Comparison, bias: f64, max_bias: f64, max_block: f64, max_ratio: f64) {
    assert!(bias < max_bias, "bias {bias}");
    assert!(c.block_mean_error < max_block, "block-mean error {}", c.block_mean_error);
    for r in c.mean_ratio {
        assert!((r - 1.0).abs() < max_ratio, "mean ratio {:?}", c.mean_ratio);
    }
}

/// Two unbiased estimates of one image, our renders `a`, `b` (independent seeds) against a
/// reference pair's mean of RMS noise `ref_noise`: their RMS difference is the root sum of
/// squares of the noises, so the relative RMSE must stay under 1.1× that noise (10 % margin
/// for the noise estimates' own error), and the 16×16 block means, whose noise shrinks 16×
/// (|N(0, σ)| averages σ·√(2/π)), under 2× theirs. Returns the comparison and the noise.
pub fn assert_within_combined_noise(
    a: &LinearImage,
    b: &LinearImage,
    reference: &LinearImage,
    ref_noise: f64,
    mask: Option<&[bool]>,
) -> (rastergi::metrics::Comparison, f64) {
    let (c, noise, _) = against_reference(a, b, reference, ref_noise, mask);
    let mean = rastergi::metrics::masked_mean(reference, mask);
    println!(
        "relative RMSE {:.4} (noise predicts {noise:.4}: ours {:.4}, the reference {:.4}), block-mean error {:.5}, mean ratio {:.5?}",
        c.relative_rmse,
        rastergi::metrics::rmse(a, b, mask) / 2.0 / mean,
        ref_noise / mean,
        c.block_mean_error,
        c.mean_ratio
    );
    assert!(c.relative_rmse < 1.1 * noise, "relative RMSE {} vs noise {noise}", c.relative_rmse);
    let block = noise / 16.0 * (2.0 / std::f64::consts::PI).sqrt();
    assert!(c.block_mean_error < 2.0 * block, "block-mean error {} vs noise {block}", c.block_mean_error);
    (c, noise)
}

/// `image` at half its width and height, each pixel the mean of its 2 × 2: with a box pixel
/// filter (rastergi's and the Mitsuba references') exactly the image rendered at that size.
pub fn box_half(image: &LinearImage) -> LinearImage {
    let (w, h) = (image.width / 2, image.height / 2);
    let at = |x: u32, y: u32| image.pixels[(y * image.width + x) as usize];
    let pixels = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let q = [at(2 * x, 2 * y), at(2 * x + 1, 2 * y), at(2 * x, 2 * y + 1), at(2 * x + 1, 2 * y + 1)];
            [0, 1, 2].map(|c| 0.25 * q.iter().map(|p| p[c]).sum::<f32>())
        })
        .collect();
    LinearImage { width: w, height: h, pixels }
}

pub fn average(a: &LinearImage, b: &LinearImage) -> LinearImage {
    LinearImage {
        width: a.width,
        height: a.height,
        pixels: a.pixels.iter().zip(&b.pixels).map(|(p, q)| [0, 1, 2].map(|c| 0.5 * (p[c] + q[c]))).collect(),
    }
}

/// A visible point decoded from a G-buffer texel (`Renderer::read_gbuffer`).
pub struct VisiblePoint {
    /// Triangle index in BVH order (`PreparedScene::scene`).
    pub tri: usize,
    pub b1: f32,
    pub b2: f32,
    /// Texture level of detail.
    pub lod: f32,
    pub pos: glam::Vec3,
    /// The triangle's geometric normal (counter-clockwise front).
    pub normal: glam::Vec3,
}

impl VisiblePoint {
    /// The point of G-buffer texel `g` of `scene` (prepared: triangles in BVH order), or
    /// `None` where the texel saw nothing.
    pub fn decode(scene: &Scene, g: [u32; 4]) -> Option<VisiblePoint> {
        let tri = (g[0] as usize).checked_sub(1)?;
        let (b1, b2, lod) = (f32::from_bits(g[1]), f32::from_bits(g[2]), f32::from_bits(g[3]));
        let t = scene.triangles[tri];
        let pos = t[0] * (1.0 - b1 - b2) + t[1] * b1 + t[2] * b2;
        Some(VisiblePoint { tri, b1, b2, lod, pos, normal: rastergi::scene::triangle_normal(&t) })
    }
}

/// A pixel of a photon-map view and what it must equal: the visible point it shows, whether
/// the camera sees that point's back, and E(x) on that side from the CPU read of the GPU's map.
pub struct PhotonViewPixel {
    pub pixel: usize,
    pub point: VisiblePoint,
    pub back: bool,
    pub irradiance: [f64; 3],
}

/// One iteration of `scene`'s photon-map view (`--show photon-map`; 2^16 photons, a 16³ grid)
/// at `size`², the scene as the renderer prepared it (triangles in BVH order), and every pixel
/// that sees a surface.
pub fn photon_view_pixels(
    gpu: &Gpu,
    scene: &Scene,
    size: u32,
) -> (LinearImage, rastergi::surface::PreparedScene, Vec<PhotonViewPixel>) {
    let settings = RenderSettings {
        width: size,
        height: size,
        photons: 1 << 16,
        grid_resolution: 16,
        show_photon_map: true,
        ..Default::default()
    };
    let mut r = Renderer::new(gpu, scene, settings).unwrap();
    r.iterate().unwrap();
    let img = r.read_linear(Show::PhotonMap).unwrap();
    let gbuffer = r.read_gbuffer().unwrap();
    let map = r.photon_map().unwrap().read(gpu).unwrap();
    let prepared = rastergi::surface::PreparedScene::new(scene);
    let pixels = gbuffer
        .iter()
        .enumerate()
        .filter_map(|(pixel, &g)| {
            let point = VisiblePoint::decode(&prepared.scene, g)?;
            let back = point.normal.dot(scene.camera.eye - point.pos) <= 0.0;
            let irradiance = map.irradiance_on(point.tri, back, point.pos);
            Some(PhotonViewPixel { pixel, point, back, irradiance })
        })
        .collect();
    (img, prepared, pixels)
}

/// Renders `scene` at 128² with the settings the command line fits to it (grid, photons,
/// photon passes), the traced gather and `hit_light`, twice (seeds 1 and 2, `iterations`
/// each), and compares their mean with the committed Mitsuba pair `stem`_{a,b} (emitter
/// pixels left out where `mask_emitters`): relative RMSE under 5 %, block-mean error under
/// 1.5 %, channel means within 1 %. The image compared is `show` (`Show::Full`; a direct-light
/// reference for `Show::Direct`), over the pixels `keep` keeps (all where `None`; emitters
/// left out as well where asked).
#[allow(clippy::too_many_arguments)]
pub fn matches_mitsuba(
    label: &str,
    scene: &Scene,
    hit_light: rastergi::gather::HitLight,
    iterations: u32,
    stem: &str,
    mask_emitters: bool,
    show: Show,
    keep: Option<&[bool]>,
) {
    let gpu = gpu();
    let grid = rastergi::fit::grid_resolution(&scene.bounds());
    let settings = |seed| RenderSettings { hit_light, ..fitted_settings(scene, 128, seed) };
    let a = render(&gpu, scene, settings(1), iterations, show);
    let b = render(&gpu, scene, settings(2), iterations, show);
    // Emitter pixels (over 3 in the reference, and their neighbours) left out where asked.
    let probe = read_exr(&data(&format!("{stem}_a.exr"))).expect("reference a");
    let mut mask = mask_emitters.then(|| rastergi::metrics::emitter_mask(&probe, 3.0));
    if let Some(keep) = keep {
        let m = mask.get_or_insert_with(|| vec![true; keep.len()]);
        m.iter_mut().zip(keep).for_each(|(m, &k)| *m &= k);
    }
    let mask = mask.as_deref();
    let (reference, ref_noise) = reference_pair(stem, mask);
    let (c, noise, bias) = against_reference(&a, &b, &reference, ref_noise, mask);
    print_agreement(&format!("{label} (grid {grid}), {hit_light:?}"), &c, noise, bias);
    assert!(c.relative_rmse < 0.05, "{label}: relative RMSE {}", c.relative_rmse);
    assert!(c.block_mean_error < 0.015, "{label}: block-mean error {}", c.block_mean_error);
    for r in c.mean_ratio {
        assert!((r - 1.0).abs() < 0.01, "{label}: mean ratio {:?}", c.mean_ratio);
    }
}

/// Two photon maps of independent seeds (GPU `g`, CPU twin `c`) agree slot by slot within
/// their noise: per slot with at least 400 deposits, z = ΔΦ/√(2·ΣΦ²) (compound Poisson, the
/// CPU map's squared deposits); mean z² within 0.25 of 1, no |z| of 6. Returns (slots, mean z²).
pub fn maps_agree_within_noise(
    g: &rastergi::photons::map::PhotonMap,
    c: &rastergi::photons::map::PhotonMap,
) -> (usize, f64) {
    let (mut sum_z2, mut max_z, mut cells) = (0.0f64, 0.0f64, 0usize);
    for s in 0..g.flux.len() {
        if c.deposits[s] < 400 {
            continue;
        }
        let z = (g.flux[s][1] - c.flux[s][1]) / (2.0 * c.flux_sq[s]).sqrt();
        sum_z2 += z * z;
        max_z = max_z.max(z.abs());
        cells += 1;
    }
    let mean_z2 = sum_z2 / cells as f64;
    println!("{cells} slots: mean z² {mean_z2:.3}, max |z| {max_z:.2}");
    assert!(cells > 300, "too few populated slots ({cells})");
    assert!((mean_z2 - 1.0).abs() < 0.25, "GPU and CPU maps differ beyond noise: mean z² = {mean_z2}");
    assert!(max_z < 6.0, "a slot differs beyond noise: |z| = {max_z}");
    (cells, mean_z2)
}

/// `doc`, a glTF document, with the `buffers`, `bufferViews` and `accessors` of one triangle,
/// (0, 0, 0), (1, 0, 0), (0, 1, 0): accessor 0 its positions, then one float accessor per
/// entry of `attributes` (its type, "VEC2" to "VEC4", and its values for the three corners),
/// all in one buffer embedded as a base64 `data:` URI.
pub fn with_unit_triangle(mut doc: Value, attributes: &[(&str, &[f32])]) -> Value {
    let positions: [[f32; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let mut bytes: Vec<u8> = positions.as_flattened().iter().flat_map(|v| v.to_le_bytes()).collect();
    let mut views = vec![json!({ "buffer": 0, "byteOffset": 0, "byteLength": 36 })];
    let mut accessors = vec![
        json!({ "bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0] }),
    ];
    for (kind, values) in attributes {
        accessors.push(json!({ "bufferView": views.len(), "componentType": 5126, "count": 3, "type": kind }));
        views.push(json!({ "buffer": 0, "byteOffset": bytes.len(), "byteLength": 4 * values.len() }));
        bytes.extend(values.iter().flat_map(|v| v.to_le_bytes()));
    }
    let uri =
        format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(&bytes));
    doc["buffers"] = json!([{ "byteLength": bytes.len(), "uri": uri }]);
    doc["bufferViews"] = json!(views);
    doc["accessors"] = json!(accessors);
    doc
}

/// Per-pixel pairs (difference of two estimators, the level of one): the mean difference, the
/// mean level, and the mean difference's standard error (the differences' spread over √N, for
/// pixels whose errors are independent).
pub fn mean_difference(d: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = d.len() as f64;
    let mean = d.iter().map(|x| x.0).sum::<f64>() / n;
    let level = d.iter().map(|x| x.1).sum::<f64>() / n;
    let sd = (d.iter().map(|x| (x.0 - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    (mean, level, sd / n.sqrt())
}
