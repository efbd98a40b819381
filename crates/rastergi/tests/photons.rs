//! The photon pass against independent computations: its CPU twin, energy conservation in
//! closed form, a light-leak bound, and Mitsuba 3 for the Cornell box.

mod common;

use glam::Vec3;
use rastergi::gpu_scene::GpuScene;
use rastergi::metrics::emitter_mask;
use rastergi::passes::film::Show;
use rastergi::photons::map::{GridSpec, PhotonMap};
use rastergi::photons::{PhotonSettings, SampledDirect, cpu, gpu::GpuPhotonMap};
use rastergi::scene::{Camera, Material, Scene, cornell_box};
use rastergi::settings::RenderSettings;
use rastergi::surface::PreparedScene;

fn gpu_map(gpu: &rastergi::gpu::Gpu, scene: &Scene, settings: &PhotonSettings) -> PhotonMap {
    let prepared = PreparedScene::new(scene);
    let gs = GpuScene::new(gpu, &prepared).expect("scene upload");
    GpuPhotonMap::build(gpu, &gs, &prepared, settings).unwrap().read(gpu).unwrap()
}

fn total_area(map: &PhotonMap) -> f64 {
    map.area().iter().sum()
}

/// A closed cube [-1,1]³ (walls facing in, albedo a) with a small two-sided emitter of albedo a
/// under its ceiling: every surface reflects with albedo a and nothing escapes.
fn closed_box(a: f32) -> Scene {
    let camera = Camera { eye: Vec3::new(0.0, 0.0, 0.9), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 };
    let mut s = Scene::new(camera);
    let wall = s.add_material(Material::diffuse("wall", Vec3::splat(a)));
    let light = s.add_material(Material {
        emission: Vec3::new(1.0, 2.0, 3.0),
        two_sided: true,
        ..Material::diffuse("light", Vec3::splat(a))
    });
    add_room(&mut s, Vec3::splat(-1.0), Vec3::splat(1.0), wall);
    let y = 0.9;
    s.add_quad(
        [Vec3::new(-0.2, y, -0.2), Vec3::new(0.2, y, -0.2), Vec3::new(0.2, y, 0.2), Vec3::new(-0.2, y, 0.2)],
        light,
    );
    s
}

/// The six walls of the box [lo, hi], facing in.
fn add_room(s: &mut Scene, lo: Vec3, hi: Vec3, m: u32) {
    let c = |x: f32, y: f32, z: f32| {
        Vec3::new(
            if x < 0.5 { lo.x } else { hi.x },
            if y < 0.5 { lo.y } else { hi.y },
            if z < 0.5 { lo.z } else { hi.z },
        )
    };
    s.add_quad([c(0., 0., 0.), c(0., 0., 1.), c(1., 0., 1.), c(1., 0., 0.)], m); // floor, +y
    s.add_quad([c(0., 1., 0.), c(1., 1., 0.), c(1., 1., 1.), c(0., 1., 1.)], m); // ceiling, -y
    s.add_quad([c(0., 0., 0.), c(1., 0., 0.), c(1., 1., 0.), c(0., 1., 0.)], m); // back, +z
    s.add_quad([c(0., 0., 1.), c(0., 1., 1.), c(1., 1., 1.), c(1., 0., 1.)], m); // front, -z
    s.add_quad([c(0., 0., 0.), c(0., 1., 0.), c(0., 1., 1.), c(0., 0., 1.)], m); // left, +x
    s.add_quad([c(1., 0., 0.), c(1., 0., 1.), c(1., 1., 1.), c(1., 1., 0.)], m); // right, -x
}

/// The emitted power of [`closed_box`] of albedo `a`, and its photon map of `count` photons
/// with `seed` (all deposits or, with `indirect_only`, those after the first surface; on a
/// grid of 16 cells along the box) traced on the GPU and by the CPU twin.
fn closed_box_maps(
    a: f64,
    count: u32,
    seed: u32,
    indirect_only: bool,
) -> (glam::DVec3, [(&'static str, PhotonMap); 2]) {
    let sampled_direct = if indirect_only { SampledDirect::All } else { SampledDirect::None };
    let settings = PhotonSettings { count, seed, grid_resolution: 16, sampled_direct, region: None, guided: false };
    let gpu = common::gpu();
    let scene = closed_box(a as f32);
    let grid = GridSpec::new(&scene.bounds(), settings.grid_resolution);
    let cpu_map = cpu::trace(&PreparedScene::new(&scene), &grid, &settings);
    (scene.emitted_power().as_dvec3(), [("gpu", gpu_map(&gpu, &scene, &settings)), ("cpu", cpu_map)])
}

/// Checks a map's `got` for channel `c` against `expected` to four relative standard
/// deviations `sigma`, printing both as the `what` of map `name`.
fn assert_within_four_sigma(name: &str, c: usize, what: &str, got: f64, expected: f64, sigma: f64) {
    println!("{name} channel {c}: {what} {got:.5} expected {expected:.5}");
    assert!((got / expected - 1.0).abs() < 4.0 * sigma, "{name} channel {c}: {got} vs {expected} (σ = {sigma})");
}

#[test]
fn closed_box_average_irradiance_matches_power_over_area_times_one_minus_albedo() {
    let a = 0.5f64;
    let n = 1u32 << 20;
    let (power, maps) = closed_box_maps(a, n, 5, false);
    // Every surface side that reflects: 6 walls of area 4, both sides of the 0.4×0.4 light.
    let area = 24.0 + 2.0 * 0.16;
    // Each photon deposits Φ at every hit and survives with probability a at flux Φ·a/a:
    // the number of hits K is geometric, E[K] = 1/(1−a), Var[K] = a/(1−a)², so the total's
    // relative standard deviation is sqrt(a/N).
    let sigma = (a / n as f64).sqrt();
    for (name, map) in maps {
        assert!((total_area(&map) - area).abs() < 1e-4, "{name}: map area {} vs {area}", total_area(&map));
        let flux = map.total_flux();
        for c in 0..3 {
            let expected = power[c] / (area * (1.0 - a));
            assert_within_four_sigma(name, c, "average irradiance", flux[c] / total_area(&map), expected, sigma);
        }
    }
}

#[test]
fn gpu_and_cpu_photon_maps_agree_cell_by_cell_within_noise() {
    let gpu = common::gpu();
    let scene = cornell_box();
    let n = 1u32 << 19;
    let g = gpu_map(&gpu, &scene, &PhotonSettings { count: n, seed: 11, grid_resolution: 16, ..Default::default() });
    let c = cpu::trace(
        &PreparedScene::new(&scene),
        g.grid(),
        &PhotonSettings { count: n, seed: 12, grid_resolution: 16, ..Default::default() },
    );
    assert_eq!(g.area(), c.area());
    // Independent seeds: per well-populated slot the difference of the two sums has variance
    // ≈ 2·Σφ² (compound Poisson), estimated from the CPU map's squared deposits.
    common::maps_agree_within_noise(&g, &c);
    // Whole-map totals: the same estimator, so equal within the noise of a total.
    let (tg, tc) = (g.total_flux(), c.total_flux());
    for ch in 0..3 {
        assert!((tg[ch] / tc[ch] - 1.0).abs() < 0.01, "channel {ch}: {} vs {}", tg[ch], tc[ch]);
    }
}

#[test]
fn a_thin_wall_keeps_the_dark_room_dark_right_up_to_the_wall() {
    // Two rooms along x, [-1,-0.01] lit and [0.01,1] dark, split by a wall 0.02 thick — a
    // sixth of a cell at grid resolution 16 (cell ≈ 0.125).
    let camera =
        Camera { eye: Vec3::new(-0.5, 0.0, 0.9), target: Vec3::new(-0.5, 0.0, 0.0), up: Vec3::Y, fov_y_deg: 60.0 };
    let mut s = Scene::new(camera);
    let white = s.add_material(Material::diffuse("white", Vec3::splat(0.8)));
    let light = s.add_material(Material { emission: Vec3::splat(5.0), ..Material::diffuse("light", Vec3::splat(0.8)) });
    add_room(&mut s, Vec3::new(-1.0, -1.0, -1.0), Vec3::new(-0.01, 1.0, 1.0), white);
    add_room(&mut s, Vec3::new(0.01, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0), white);
    let y = 0.95;
    s.add_quad(
        [Vec3::new(-0.7, y, -0.2), Vec3::new(-0.3, y, -0.2), Vec3::new(-0.3, y, 0.2), Vec3::new(-0.7, y, 0.2)],
        light,
    );
    let gpu = common::gpu();
    let settings = PhotonSettings { count: 1 << 19, seed: 2, grid_resolution: 16, ..Default::default() };
    let maps = [
        ("gpu", gpu_map(&gpu, &s, &settings)),
        ("cpu", cpu::trace(&PreparedScene::new(&s), &GridSpec::new(&s.bounds(), 16), &settings)),
    ];
    for (name, map) in &maps {
        let h = map.grid().cell;
        // The floors of both rooms share the plane y = −1 and the cells under the wall; the
        // wall's faces separate them there (each slot's separators: the lit floor and the dark
        // floor are different slots), and no lookup on the dark floor reads a cell beyond a
        // separator of its own cell. So the dark room's floor and the dark face of the wall
        // gather no photon at all, right up to the wall.
        for i in 0..40 {
            for k in 0..40 {
                let z = -0.95 + 1.9 * k as f32 / 39.0;
                let yw = -0.95 + 1.9 * i as f32 / 39.0;
                let wall = map.irradiance(Vec3::new(0.01, yw, z), Vec3::X);
                assert_eq!(wall, [0.0; 3], "{name}: light on the dark face of the wall at ({yw}, {z})");
                let x = 0.0101 + 0.99 * i as f32 / 39.0;
                let floor = map.irradiance(Vec3::new(x, -1.0, z), Vec3::Y);
                assert_eq!(floor, [0.0; 3], "{name}: light on the dark floor at x = {x} (cell {h})");
            }
        }
        // The lit room is lit (the test would pass vacuously otherwise), right up to the wall.
        for x in [-0.5, -0.02, -0.0101] {
            let e = map.irradiance(Vec3::new(x, -1.0, 0.0), Vec3::Y)[1];
            assert!(e > 0.1, "{name}: lit floor at x = {x} is dark ({e})");
        }
    }
}

#[test]
fn photon_view_lookup_on_the_gpu_equals_the_cpu_lookup() {
    let gpu = common::gpu();
    let scene = cornell_box();
    let (img, prepared, pixels) = common::photon_view_pixels(&gpu, &scene, 48);
    let mut checked = 0;
    for p in pixels.iter().filter(|p| !p.back) {
        let albedo = prepared.scene.material_of(p.point.tri).albedo;
        for c in 0..3 {
            let expected = albedo[c] as f64 / std::f64::consts::PI * p.irradiance[c];
            let got = img.pixels[p.pixel][c] as f64;
            assert!(
                (got - expected).abs() <= 1e-4 * expected.max(1e-3),
                "pixel {} channel {c}: {got} vs {expected}",
                p.pixel
            );
        }
        checked += 1;
    }
    assert!(checked > 1500);
}

#[test]
fn photon_map_view_of_the_cornell_box_matches_mitsuba_up_to_the_grid_bias() {
    let gpu = common::gpu();
    let scene = cornell_box();
    let settings = |seed| RenderSettings {
        width: 128,
        height: 128,
        seed,
        photons: 1 << 21,
        grid_resolution: 32,
        show_photon_map: true,
        ..Default::default()
    };
    let a = common::render(&gpu, &scene, settings(1), 16, Show::PhotonMap);
    let b = common::render(&gpu, &scene, settings(2), 16, Show::PhotonMap);
    let probe = rastergi::image_io::read_exr(&common::data("cornell_path_128_a.exr")).unwrap();
    let mask = emitter_mask(&probe, 3.0);
    let (reference, ref_noise) = common::reference_pair("cornell_path_128", Some(&mask));
    let (c, noise, bias) = common::against_reference(&a, &b, &reference, ref_noise, Some(&mask));
    common::print_agreement("photon view", &c, noise, bias);
    // The map is read at the visible points themselves here (the final gather hides most of
    // its error): what remains beyond the photon noise is the grid's blur of shadow edges,
    // corners and contact regions, a few percent at 32 cells across the box; the image's
    // energy must agree to 1 % and 16×16 block means to 1.5 %.
    common::assert_agreement(&c, bias, 0.05, 0.015, 0.01);
}

#[test]
fn an_indirect_only_map_holds_the_albedo_times_the_full_maps_energy() {
    // Deposits from the second surface on (`indirect_only`, for exact direct light at the
    // gather's hits): in the closed box of albedo a, each photon's hits after the first
    // number K − 1 with E[K − 1] = a/(1−a), so the map's total is Φ·a/(1−a) — a times the full
    // map's. Var[K − 1] = a/(1−a)² again: relative standard deviation sqrt(1/(aN)).
    let a = 0.5f64;
    let n = 1u32 << 20;
    let (power, maps) = closed_box_maps(a, n, 6, true);
    let sigma = (1.0 / (a * n as f64)).sqrt();
    for (name, map) in maps {
        let flux = map.total_flux();
        for c in 0..3 {
            assert_within_four_sigma(name, c, "indirect flux", flux[c], power[c] * a / (1.0 - a), sigma);
        }
    }
}

/// The punctual lights' photons alone skip their first surface (`SampledDirect::Punctual`,
/// `--hit-light punctual`): in the closed box of albedo a lit by its area emitter (Φ_A) and a
/// point light at its centre (Φ_P = 4π·I), a photon of the emitter deposits K times and one of
/// the point light K − 1, E[K] = 1/(1−a): the map holds Φ_A/(1−a) + Φ_P·a/(1−a), on the GPU
/// and in the CPU twin. Per photon, X = f_l·D with f_l = Φ_l/p_l for the light picked with
/// probability p_l, E[K²] = (1+a)/(1−a)², E[(K−1)²] = a(1+a)/(1−a)²: the relative standard
/// error is √((E[X²] − E[X]²)/N)/E[X]. (Counting the point light's first deposit would add
/// Φ_P, a third of the total here; skipping the emitter's would remove Φ_A, two thirds.)
#[test]
fn only_the_punctual_lights_photons_skip_their_first_surface() {
    let a = 0.5f64;
    let n = 1u32 << 20;
    let mut scene = closed_box(a as f32);
    let intensity = 0.08f32;
    scene.lights.push(rastergi::scene::Light::Point { position: Vec3::ZERO, intensity: Vec3::splat(intensity) });
    let area_power = scene.emitted_power().as_dvec3();
    let point_power = 4.0 * std::f64::consts::PI * intensity as f64;
    let table = rastergi::lights::LightTable::new(&scene);
    let p_point: f64 = table
        .entries
        .iter()
        .filter(|e| e.triangle & rastergi::gpu::consts::PUNCTUAL_LIGHT != 0)
        .map(|e| e.pmf as f64)
        .sum();
    let settings = PhotonSettings {
        count: n,
        seed: 7,
        grid_resolution: 16,
        sampled_direct: SampledDirect::Punctual,
        region: None,
        guided: false,
    };
    let gpu = common::gpu();
    let grid = GridSpec::new(&scene.bounds(), settings.grid_resolution);
    let cpu_map = cpu::trace(&PreparedScene::new(&scene), &grid, &settings);
    let maps = [("gpu", gpu_map(&gpu, &scene, &settings)), ("cpu", cpu_map)];
    let (k1, k2) = (1.0 / (1.0 - a), (1.0 + a) / (1.0 - a).powi(2));
    for (name, map) in maps {
        let flux = map.total_flux();
        for c in 0..3 {
            let (fa, fp) = (area_power[c] / (1.0 - p_point), point_power / p_point);
            let mean = (1.0 - p_point) * fa * k1 + p_point * fp * a * k1;
            let square = (1.0 - p_point) * fa * fa * k2 + p_point * fp * fp * a * k2;
            let sigma = ((square - mean * mean) / n as f64).sqrt() / mean;
            let expected = area_power[c] * k1 + point_power * a * k1;
            assert_within_four_sigma(name, c, "flux", flux[c], expected, sigma);
        }
    }
}

/// The photon pass's rays, counted (`--count-rays`), are its photons' flights: in the closed
/// box of albedo a every flight ends on a wall, and a photon flies again with probability a,
/// so N photons fly K₁ + … + K_N times, K geometric: E[K] = 1/(1−a), Var[K] = a/(1−a)². The
/// GPU's count lies within four standard deviations of N/(1−a) (a pass that traced one more
/// ray per photon, or counted a photon's flight twice, would be hundreds of them away).
#[test]
fn the_photon_pass_traces_one_ray_per_flight() {
    let a = 0.5f64;
    let n = 1u32 << 18;
    let gpu = rastergi::gpu::Gpu::new(&rastergi::gpu::GpuOptions { count_rays: true, ..Default::default() }).unwrap();
    let scene = closed_box(a as f32);
    let prepared = PreparedScene::new(&scene);
    let gs = GpuScene::new(&gpu, &prepared).unwrap();
    let settings = PhotonSettings {
        count: n,
        seed: 3,
        grid_resolution: 16,
        sampled_direct: SampledDirect::None,
        region: None,
        guided: false,
    };
    GpuPhotonMap::build(&gpu, &gs, &prepared, &settings).unwrap();
    let counted = gs.rays_traced(&gpu).unwrap().expect("counted");
    assert_eq!((counted.eye, counted.gather), (0, 0), "the photon pass's rays are the photons'");
    let rays = counted.photons as f64;
    let expected = n as f64 / (1.0 - a);
    let sigma = (n as f64 * a).sqrt() / (1.0 - a);
    println!("{n} photons: {rays} rays, expected {expected} ± {sigma:.0}");
    assert!((rays - expected).abs() < 4.0 * sigma, "{rays} rays, expected {expected} ± {sigma:.0}");
}

/// The sky's photons guided by any table carry the sky's light (`photons::guide`): a constant
/// sky of radiance L over a 20 m floor, aimed at a region of it, with a table per direction
/// bin that sends three quarters of its photons to a few random bins of the guide disc. The
/// floor's top receives A·π·L in closed form; the GPU's map and the CPU twin's hold it within
/// four standard errors, and the two maps agree slot by slot.
#[test]
fn guided_sky_photons_deliver_the_skys_flux_on_the_gpu_and_its_twin() {
    let radiance = 0.7f32;
    guided_photons_deliver(
        |s| {
            s.environment =
                Some(std::sync::Arc::new(rastergi::environment::Environment::constant(Vec3::splat(radiance))))
        },
        std::f64::consts::PI * radiance as f64 * 400.0,
    );
}

/// Photons guided by any table carry the light they would unguided (`photons::guide`): a sun
/// over a 20 m floor, aimed at a region of it, with a table that sends three quarters of the
/// photons to a few random bins of the guide disc. The flux the floor receives is E·cos θ·A in
/// closed form (every photon lands on it); the GPU's map holds it within four standard errors,
/// the CPU twin's too, and the two maps agree slot by slot (the twins start the same photons
/// from the same table).
#[test]
fn guided_sun_photons_deliver_the_suns_flux_on_the_gpu_and_its_twin() {
    let towards = Vec3::new(0.3, 0.8, -0.2).normalize();
    let irradiance = 2.0f32;
    guided_photons_deliver(
        |s| {
            s.lights.push(rastergi::scene::Light::Distant {
                direction: -towards,
                irradiance: Vec3::splat(irradiance),
                angular_radius: 0.0,
            })
        },
        irradiance as f64 * towards.y as f64 * 400.0,
    );
}

/// The photons of the lights `light` adds to a 20 m floor, guided by random tables, traced on the
/// GPU and by the CPU twin: each map holds `expected` watts within four standard errors, and
/// the two agree slot by slot.
fn guided_photons_deliver(light: impl Fn(&mut Scene), expected: f64) {
    use rastergi::photons::guide::{POSITIONS, PhotonGuide, guided_lights};
    let mut s = Scene::new(Camera { eye: Vec3::new(0.0, 5.0, 12.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 });
    let m = s.add_material(Material::diffuse("floor", Vec3::splat(0.0)));
    let (a, b, c, d) = (
        Vec3::new(-10.0, 0.0, -10.0),
        Vec3::new(-10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, 10.0),
        Vec3::new(10.0, 0.0, -10.0),
    );
    s.add_triangle([a, b, c], m);
    s.add_triangle([a, c, d], m);
    light(&mut s);
    let region = rastergi::photons::map::PhotonRegion {
        bounds: rastergi::scene::Aabb { min: Vec3::new(-3.0, 0.0, -2.0), max: Vec3::new(1.0, 1.0, 2.0) },
        factor: 2,
    };
    let settings = PhotonSettings {
        count: 1 << 20,
        seed: 5,
        grid_resolution: 32,
        region: Some(region),
        guided: true,
        ..Default::default()
    };
    let gpu = common::gpu();
    let prepared = PreparedScene::new(&s);
    let gs = GpuScene::new(&gpu, &prepared).unwrap();
    let layout = rastergi::photons::map::MapLayout::within(
        &prepared.scene,
        &prepared.bounds,
        32,
        settings.region.as_ref(),
        &gpu.device.limits(),
    )
    .unwrap();
    let mut guide = PhotonGuide::new(&gpu, layout.grid, &guided_lights(&prepared.lights), true, None);
    // Tables that like 5 % of the bins, at random weights.
    let mut table = guide.table().clone();
    assert_eq!(table.lights.len(), 1, "the light is guided");
    let mut rng = rastergi::sampling::Rng::new(23, 0, 0);
    let n = (POSITIONS * POSITIONS) as usize;
    for d in 0..table.lights[0].directions as usize {
        let weights: Vec<f64> =
            (0..n).map(|_| if rng.next_f32() < 0.05 { 0.1 + rng.next_f32() as f64 } else { 0.0 }).collect();
        table.lights[0].cdfs[d] = rastergi::photons::guide::cumulative(&weights);
    }
    guide.set_table(&gpu, table.clone());
    let map = GpuPhotonMap::with_layout(&gpu, &gs, &prepared, &settings, layout.clone(), &guide).unwrap();
    map.trace(&gpu, &gs);
    let gpu_map = map.read(&gpu).unwrap();
    let tally = cpu::trace_flux_guided(&prepared, &layout, &settings, 0, Some(&table));
    let cpu_map = PhotonMap {
        layout,
        flux: tally.flux,
        flux_sq: tally.flux_sq,
        deposits: tally.deposits,
        dropped: tally.dropped,
    };
    // The sum's standard error from the twin's per-slot squares (each photon one deposit).
    let se = cpu_map.flux_sq.iter().sum::<f64>().sqrt();
    for (name, map) in [("GPU", &gpu_map), ("CPU twin", &cpu_map)] {
        let total: f64 = map.flux.iter().map(|f| f[1]).sum();
        println!("{name}: {total:.3} W on the floor against {expected:.3} (se {se:.3})");
        assert!((total - expected).abs() < 4.0 * se, "{name}: {total} against {expected}");
    }
    assert_same_photons(&gpu_map, &cpu_map);
}

/// Photons bouncing off distant ground towards the region they are aimed at
/// (`photons::lambertian_bounce`: a photon's first Lambertian bounce outside the aim's sphere
/// is drawn from a mixture of the cosine and the sphere's cone): a constant sky over a bright
/// 60 m floor with a 2 m box in a small region. The GPU's map and the CPU twin's agree slot by
/// slot (the same photons, the same bounces — the WGSL against its twin, whose weights a unit
/// test checks against the cosine's), and in total.
#[test]
fn aimed_bounces_are_the_same_on_the_gpu_and_its_twin() {
    let mut s = Scene::new(Camera { eye: Vec3::new(0.0, 3.0, 8.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 60.0 });
    let floor = s.add_material(Material::diffuse("floor", Vec3::splat(0.8)));
    let box_m = s.add_material(Material::diffuse("box", Vec3::splat(0.5)));
    let r = 30.0;
    let (a, b, c, d) = (Vec3::new(-r, 0.0, -r), Vec3::new(-r, 0.0, r), Vec3::new(r, 0.0, r), Vec3::new(r, 0.0, -r));
    s.add_triangle([a, b, c], floor);
    s.add_triangle([a, c, d], floor);
    rastergi::scene::generate::add_box(&mut s, Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 2.0, 1.0), box_m);
    s.environment = Some(std::sync::Arc::new(rastergi::environment::Environment::constant(Vec3::splat(0.7))));
    let region = rastergi::photons::map::PhotonRegion {
        bounds: rastergi::scene::Aabb { min: Vec3::new(-2.0, 0.0, -2.0), max: Vec3::new(2.0, 2.5, 2.0) },
        factor: 4,
    };
    let settings =
        PhotonSettings { count: 1 << 19, seed: 3, grid_resolution: 32, region: Some(region), ..Default::default() };
    let gpu = common::gpu();
    let prepared = PreparedScene::new(&s);
    let gs = GpuScene::new(&gpu, &prepared).unwrap();
    let gpu_map = GpuPhotonMap::build(&gpu, &gs, &prepared, &settings).unwrap().read(&gpu).unwrap();
    let tally = cpu::trace_flux(&prepared, &gpu_map.layout, &settings, 0);
    let cpu_map = PhotonMap {
        layout: gpu_map.layout.clone(),
        flux: tally.flux,
        flux_sq: tally.flux_sq,
        deposits: tally.deposits,
        dropped: tally.dropped,
    };
    let (g, c) = (gpu_map.total_flux()[1], cpu_map.total_flux()[1]);
    let se = cpu_map.flux_sq.iter().sum::<f64>().sqrt();
    println!("total: GPU {g:.3} W, CPU twin {c:.3} W (se {se:.3})");
    assert!((g - c).abs() < 0.5 * se, "GPU {g} against the twin's {c}");
    assert_same_photons(&gpu_map, &cpu_map);
}

/// The GPU's map and the CPU twin's of the same photons: slot by slot the same flux, but for a
/// photon that f32 rounding lands in another slot — each slot within two of its deposits' RMS
/// flux, and the slots that differ at all a few per cent.
fn assert_same_photons(gpu_map: &PhotonMap, cpu_map: &PhotonMap) {
    let (mut compared, mut differ) = (0, 0);
    for s in 0..cpu_map.flux.len() {
        let (g, c) = (gpu_map.flux[s][1], cpu_map.flux[s][1]);
        if cpu_map.deposits[s] == 0 {
            continue;
        }
        let deposit = (cpu_map.flux_sq[s] / cpu_map.deposits[s] as f64).sqrt();
        assert!((g - c).abs() <= 2.0 * deposit, "a slot holds {g} on the GPU, {c} in the twin (a deposit {deposit})");
        compared += 1;
        differ += ((g - c).abs() > 1e-4 * c) as usize;
    }
    println!("{compared} slots, {differ} differ by more than 1e-4");
    assert!(compared > 300 && differ * 20 < compared, "{differ} of {compared} slots differ");
}
