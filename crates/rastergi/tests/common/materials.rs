//! Helpers of the material tests (`materials.rs`): the sphere scenes and their camera, the
//! reference path tracer against Mitsuba 3, and the photon map under glass.

use glam::Vec3;

/// The scene of `tests/data/obj/NAME.obj` seen from the camera of its Mitsuba references.
/// Prints `label`'s comparison with its reference and checks it with the criteria of the
/// Lambertian scenes (tests/common): block-mean error under 1.5 %, channel means within 1 %.
pub fn check_against_reference(label: &str, c: &rastergi::metrics::Comparison, noise: f64, bias: f64) {
    println!(
        "{label}: relative RMSE {:.4} = noise {noise:.4} ⊕ bias {bias:.4}; block-mean error {:.4}; mean ratio {:.4?}",
        c.relative_rmse, c.block_mean_error, c.mean_ratio
    );
    assert!(c.block_mean_error < 0.015, "{label}: block-mean error {}", c.block_mean_error);
    for r in c.mean_ratio {
        assert!((r - 1.0).abs() < 0.01, "{label}: mean ratio {:?}", c.mean_ratio);
    }
}

/// The spheres without the rough metal's energy compensation: Mitsuba 3's `roughconductor`,
/// which their references use, is single scattering.
pub fn material_scene(name: &str, camera: rastergi::scene::Camera) -> rastergi::scene::Scene {
    let mut scene = rastergi::scene::load_obj(&super::data(&format!("obj/{name}.obj"))).expect("scene");
    scene.camera = camera;
    scene.single_scattering();
    scene
}

/// The stage's camera (scripts/make_material_scenes.py, tests/data/README.md).
pub fn stage_camera() -> rastergi::scene::Camera {
    rastergi::scene::Camera {
        eye: Vec3::new(0.0, 1.2, 2.6),
        target: Vec3::new(0.0, 0.45, 0.0),
        up: Vec3::Y,
        fov_y_deg: 40.0,
    }
}

/// The reference path tracer's mean of two renders (seeds 1, 2; `iterations` each) against
/// the Mitsuba pair `stem`, emitters left out. Both are unbiased estimates of one integral:
/// per pixel and channel, E[(ours − ref)²] = Var(ours) + Var(ref), each variance estimated
/// without bias by (a − b)²/4 of its pair. The test is a z-test of zero bias on the mean of
/// d² − (a − b)²/4 − (a' − b')²/4 over pixels, against its own standard error (heavy-tailed
/// caustic noise makes a fixed margin on the RMSE meaningless at 64²); block means (16 × 16
/// pixels) and channel means are checked against their expected noise as well.
///
/// Ours render at half the references' size (32² for their 64²), the references box-filtered
/// 2 × 2 to it (exact: both use a box pixel filter), which halves their noise per pixel. At
/// 64² our noise was 2.6–5× Mitsuba's per pixel (0.0136 against 0.0053 relative on
/// metal_rough, 0.0645 against 0.0121 on rough_glass, at 2048 and 1024 iterations): the
/// z-test's standard error, ∝ (Var ours + Var ref)/√pixels, was set by ours. At 32² and 2048
/// iterations each (a quarter of 64²'s cost for the metals, half for the glasses) it is about
/// what it was — measured, in units of the squared mean, 64² → 32²: metal_rough 1.66e-5 →
/// 1.23e-5, mix 1.43e-5 → 1.16e-5, mirror 1.85e-5 → 3.41e-5 at 2048 (1.66e-5 at 4096, which it gets), glass 5.7e-4 →
/// 3.6e-4, rough_glass 3.1e-4 → 2.2e-4 (1024 → 2048). The sharper test sees more of the smooth
/// glass sphere's difference: squared bias 9.0e-4 ± 3.6e-4 (2.5 standard errors; 1.3 at 64²),
/// a per-pixel bias of about 3 % whose block means stay within their noise's 2× (0.0043 against
/// 0.0024) and whose channel means are within 0.4 %; its cause is not found yet.
pub fn path_tracer_matches_mitsuba(scene: &rastergi::scene::Scene, iterations: u32, stem: &str) {
    use rastergi::image_io::read_exr;
    use rastergi::metrics::{compare, emitter_mask, masked_mean, rmse};
    let gpu = super::gpu();
    let ref_a = super::box_half(&read_exr(&super::data(&format!("{stem}_a.exr"))).unwrap());
    let ref_b = super::box_half(&read_exr(&super::data(&format!("{stem}_b.exr"))).unwrap());
    let (width, height) = (ref_a.width, ref_a.height);
    let render = |seed| {
        let settings = rastergi::settings::RenderSettings { width, height, seed, ..Default::default() };
        super::path_trace(&gpu, scene, settings, iterations)
    };
    let (a, b) = (render(1), render(2));
    let mask = emitter_mask(&ref_a, 3.0);
    let reference = super::average(&ref_a, &ref_b);
    let ours = super::average(&a, &b);
    let c = compare(&ours, &reference, Some(&mask));
    let mean_ref = masked_mean(&reference, Some(&mask));
    let (noise_ours, noise_ref) = (rmse(&a, &b, Some(&mask)) / 2.0, rmse(&ref_a, &ref_b, Some(&mask)) / 2.0);
    let expected = (noise_ours.powi(2) + noise_ref.powi(2)).sqrt() / mean_ref;
    // The bias z-test.
    let mut excess = vec![];
    for (i, keep) in mask.iter().enumerate() {
        if *keep {
            for ch in 0..3 {
                let d = (ours.pixels[i][ch] - reference.pixels[i][ch]) as f64;
                let va = ((a.pixels[i][ch] - b.pixels[i][ch]) as f64).powi(2) / 4.0;
                let vr = ((ref_a.pixels[i][ch] - ref_b.pixels[i][ch]) as f64).powi(2) / 4.0;
                excess.push(d * d - va - vr);
            }
        }
    }
    let n = excess.len() as f64;
    let mean = excess.iter().sum::<f64>() / n;
    let se = (excess.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0) / n).sqrt();
    let bias = mean.max(0.0).sqrt() / mean_ref;
    let expected_block = expected / 16.0 * (2.0 / std::f64::consts::PI).sqrt();
    println!(
        "{stem}: relative RMSE {:.4} (noise predicts {expected:.4}: ours {:.4}, Mitsuba {:.4}); squared bias {:.3e} ± {:.3e} (bias {bias:.4}); block-mean error {:.4} (noise {expected_block:.4}); mean ratio {:.4?}",
        c.relative_rmse,
        noise_ours / mean_ref,
        noise_ref / mean_ref,
        mean / mean_ref.powi(2),
        se / mean_ref.powi(2),
        c.block_mean_error,
        c.mean_ratio
    );
    assert!(mean < 3.0 * se, "{stem}: squared bias {mean:.3e} is {:.1} standard errors above 0", mean / se);
    assert!(c.block_mean_error < 2.0 * expected_block, "{stem}: block-mean error {}", c.block_mean_error);
    let pixels = mask.iter().filter(|&&k| k).count() as f64;
    for r in c.mean_ratio {
        // A channel mean's relative standard error is about the image's relative noise over
        // √pixels; 5 of them.
        assert!((r - 1.0).abs() < 5.0 * expected / pixels.sqrt(), "{stem}: mean ratio {:?}", c.mean_ratio);
    }
}

/// What a slab of thickness d (η 1.5, attenuation σ) transmits at normal incidence, all
/// internal reflections summed: (1 − R)²a/(1 − R²a²) with a = exp(−σd).
pub fn slab_transmittance(sigma: Vec3, d: f32) -> Vec3 {
    let r = rastergi::bsdf::fresnel_dielectric(1.0, 1.5);
    let a = (-sigma * d).exp();
    (1.0 - r).powi(2) * a / (Vec3::ONE - r * r * a * a)
}

/// A black floor 4 × 4 at y = 0 under `glass` — a pane 2 × 2 at y = 1, or a slab 2 × 2 of
/// thickness `slab` below y = 1 — (with the scene's texture 0 where given) and a sun straight
/// down: the photon map's irradiance (GPU
/// and CPU twin) under the glass is `transmitted` and beside it 1, within 4 standard errors
/// of the photons' own noise.
pub fn photons_under_glass(
    glass: rastergi::scene::Material,
    slab: Option<f32>,
    texture: Option<rastergi::scene::Texture>,
    transmitted: Vec3,
) {
    use rastergi::gpu_scene::GpuScene;
    use rastergi::photons::map::GridSpec;
    use rastergi::photons::{PhotonSettings, cpu, gpu::GpuPhotonMap};
    use rastergi::scene::{Camera, Light, Material, Scene};
    use rastergi::surface::PreparedScene;
    let camera = Camera { eye: Vec3::new(0.0, 3.0, 0.001), target: Vec3::ZERO, up: Vec3::Z, fov_y_deg: 60.0 };
    let mut s = Scene::new(camera);
    if let Some(t) = texture {
        s.add_texture(t);
    }
    let floor = s.add_material(Material::diffuse("floor", Vec3::ZERO));
    let glass = s.add_material(glass);
    let quad = |h: f32, y: f32| [Vec3::new(-h, y, h), Vec3::new(h, y, h), Vec3::new(h, y, -h), Vec3::new(-h, y, -h)];
    s.add_quad(quad(2.0, 0.0), floor);
    match slab {
        None => s.add_quad(quad(1.0, 1.0), glass),
        Some(d) => {
            rastergi::scene::generate::add_box(&mut s, Vec3::new(-1.0, 1.0 - d, -1.0), Vec3::new(1.0, 1.0, 1.0), glass)
        }
    }
    s.lights.push(Light::Distant { direction: -Vec3::Y, irradiance: Vec3::ONE, angular_radius: 0.0 });
    let settings = PhotonSettings { count: 1 << 20, seed: 5, grid_resolution: 8, ..Default::default() };
    let prepared = PreparedScene::new(&s);
    let gpu = super::gpu();
    let gs = GpuScene::new(&gpu, &prepared).unwrap();
    let g = GpuPhotonMap::build(&gpu, &gs, &prepared, &settings).unwrap().read(&gpu).unwrap();
    let c = cpu::trace(&prepared, &GridSpec::new(&s.bounds(), 8), &settings);
    for (name, map) in [("gpu", &g), ("cpu", &c)] {
        for (x, z, inside) in [(0.0, 0.0, true), (0.4, -0.3, true), (1.6, 0.0, false), (-1.7, 1.6, false)] {
            let e = map.irradiance(Vec3::new(x, 0.0, z), Vec3::Y);
            for ch in 0..3 {
                let want = if inside { transmitted[ch] as f64 } else { 1.0 };
                // The sun's photons start uniformly on a disc of radius 1.01 R across the
                // bounding sphere: about N·A_cells/(π R²) of them land in the lookup's cells;
                // each carries E·πR²/N and passes with probability T: the count that arrives is
                // Poisson with mean T·n, so E's relative variance is 1/(T·n), E's variance T/n
                // (E in units of the sun's).
                let radius = s.bounds().extent().length() / 2.0 * 1.01;
                let cell = s.bounds().extent().max_element() / 8.0;
                let expected_count =
                    settings.count as f64 * (cell * cell) as f64 / (std::f64::consts::PI * (radius * radius) as f64);
                let se = (want / expected_count).sqrt();
                println!("{name}: E({x}, {z})[{ch}] = {:.4}, expected {want:.4} ± {se:.4}", e[ch]);
                assert!(
                    (e[ch] - want).abs() < 4.0 * se + 1e-3,
                    "{name}: E({x}, {z})[{ch}] = {}, expected {want}",
                    e[ch]
                );
            }
        }
    }
}
