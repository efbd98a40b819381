//! Point, spot and distant lights against closed forms: the direct pass and the path tracer
//! (irradiance on an open floor), and the photon pass (the flux that reaches the floor).

mod common;

use std::f64::consts::PI;

use glam::{Vec2, Vec3};
use rastergi::passes::film::Show;
use rastergi::path_tracer::PathTracer;
use rastergi::photons::map::GridSpec;
use rastergi::photons::{PhotonSettings, cpu, gpu::GpuPhotonMap};
use rastergi::renderer::{Overrides, Renderer};
use rastergi::scene::{Camera, Light, Material, Scene};
use rastergi::settings::RenderSettings;
use rastergi::surface::PreparedScene;

const ALBEDO: f32 = 0.5;
/// Half the side of the floor, y = 0, x and z in [−A, A].
const A: f32 = 4.0;

/// A one-sided square floor of albedo ½ facing up (nothing else: no light comes back to it),
/// seen from above, lit by `light`.
fn floor(light: Light) -> Scene {
    let camera = Camera { eye: Vec3::new(0.0, 3.0, 0.001), target: Vec3::ZERO, up: Vec3::Z, fov_y_deg: 60.0 };
    let mut s = Scene::new(camera);
    let m = s.add_material(Material::diffuse("floor", Vec3::splat(ALBEDO)));
    let (p, q, r, t) = (Vec3::new(-A, 0.0, -A), Vec3::new(A, 0.0, -A), Vec3::new(A, 0.0, A), Vec3::new(-A, 0.0, A));
    s.add_triangle([p, t, r], m);
    s.add_triangle([p, r, q], m);
    s.lights.push(light);
    s
}

fn point() -> Light {
    Light::Point { position: Vec3::new(0.3, 1.0, -0.2), intensity: Vec3::new(1.0, 2.0, 0.5) }
}

fn spot() -> Light {
    let direction = Vec3::new(0.2, -1.0, 0.1).normalize();
    Light::Spot { position: Vec3::new(0.0, 1.5, 0.0), direction, intensity: Vec3::splat(3.0), inner: 0.3, outer: 0.6 }
}

fn distant(angular_radius: f32) -> Light {
    Light::Distant { direction: Vec3::new(0.6, -0.8, 0.0), irradiance: Vec3::new(2.0, 1.0, 0.5), angular_radius }
}

/// The irradiance `light` gives the floor point x (normal +Y), from its definition.
fn irradiance(light: &Light, x: Vec3) -> Vec3 {
    match *light {
        Light::Point { position, intensity } => {
            let d = position - x;
            intensity * (d.y / d.length()) / d.length_squared()
        }
        Light::Spot { position, direction, intensity, inner, outer } => {
            let d = position - x;
            let cos = direction.dot(-d.normalize());
            let t = ((cos - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0);
            intensity * (t * t) * (d.y / d.length()) / d.length_squared()
        }
        // A disc of uniform radiance well above the horizon: E cos θ of its centre, to
        // (1 − cos r)/2 ≈ r²/4 relatively.
        Light::Distant { direction, irradiance, .. } => irradiance * -direction.y,
    }
}

/// Every visible floor pixel's direct light against ρ/π·E(x + n·ε) at its visible point x
/// (no jitter), after `iterations`: the largest relative difference and the pixels compared.
fn direct_against_closed_form(light: Light, iterations: u32) -> (f32, usize) {
    let gpu = common::gpu();
    let scene = floor(light);
    let settings = RenderSettings { width: 48, height: 48, photons: 1 << 12, grid_resolution: 8, ..Default::default() };
    let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
    let o = Overrides { pixel_jitter: Some(Vec2::ZERO), ..Default::default() };
    for _ in 0..iterations {
        r.iterate_with(&o).unwrap();
    }
    let img = r.read_linear(Show::Direct).unwrap();
    let prepared = PreparedScene::new(&scene);
    let gbuffer = r.read_gbuffer().unwrap();
    let (mut worst, mut n) = (0.0f32, 0);
    for (i, &g) in gbuffer.iter().enumerate() {
        let Some(v) = common::VisiblePoint::decode(&prepared.scene, g) else { continue };
        // The pass shades from x + n·ε (its shadow rays' origin).
        let x = v.pos + v.normal * prepared.ray_epsilon();
        let expected = irradiance(&light, x) * (ALBEDO / std::f32::consts::PI);
        let got = Vec3::from(img.pixels[i]);
        if expected.max_element() < 1e-4 {
            assert!(got.max_element() < 1e-4, "pixel {i} at {}: {got} where the light gives nothing", v.pos);
            continue;
        }
        worst = worst.max(((got - expected) / expected).abs().max_element());
        n += 1;
    }
    (worst, n)
}

#[test]
fn a_point_light_gives_the_floor_i_cos_over_d_squared() {
    // A delta light: every light sample is the same, so the pass is exact up to rounding.
    let (worst, n) = direct_against_closed_form(point(), 1);
    println!("point light: {n} pixels, largest relative difference {worst:.2e}");
    assert!(n > 1500 && worst < 1e-5, "{n} pixels, worst {worst}");
}

#[test]
fn a_spot_light_follows_the_gltf_falloff_between_its_cones() {
    // Exact up to rounding, which the ramp amplifies near the outer cone (where the light
    // falls under 1e-4 of its peak the pixels only need to be dark).
    let (worst, n) = direct_against_closed_form(spot(), 1);
    println!("spot light: {n} pixels lit, largest relative difference {worst:.2e}");
    assert!(n > 300 && worst < 1e-4, "{n} pixels, worst {worst}");
}

#[test]
fn a_distant_light_gives_e_cos_theta_and_a_small_disc_the_same() {
    let (worst, n) = direct_against_closed_form(distant(0.0), 1);
    println!("distant light: {n} pixels, largest relative difference {worst:.2e}");
    assert!(n > 1500 && worst < 1e-5, "{n} pixels, worst {worst}");
    // A 5°-wide sun: each sample's E cos θ lies within cos(θ ± 2.5°), here cos θ = 0.8: ±3.3 %
    // at most per sample, and after 64 samples the mean is within (1 − cos r)/2 ≈ 5·10⁻⁴ of
    // E cos θ plus the samples' noise, well under 1 %.
    let (worst, n) = direct_against_closed_form(distant(2.5f32.to_radians()), 64);
    println!("a 5° disc: {n} pixels, largest relative difference {worst:.2e}");
    assert!(n > 1500 && worst < 0.01 && worst > 1e-5, "{n} pixels, worst {worst}");
}

#[test]
fn the_path_tracer_sees_the_same_point_light() {
    // The floor sees no other surface, so the path tracer's image is the direct light alone,
    // and with a delta light its next-event estimate is exact: only the pixel jitter moves the
    // visible points, so compare the image's mean over the floor with the closed form's mean
    // over the same view (the direct pass, checked above, averaged the same way).
    let gpu = common::gpu();
    let scene = floor(point());
    let settings = RenderSettings { width: 32, height: 32, ..Default::default() };
    let mut pt = PathTracer::new(&gpu, &scene, settings.clone()).unwrap();
    let mut r =
        Renderer::new(&gpu, &scene, RenderSettings { photons: 1 << 12, grid_resolution: 8, ..settings }).unwrap();
    for _ in 0..64 {
        pt.iterate();
        r.iterate().unwrap();
    }
    let (a, b) = (pt.read_linear().unwrap(), r.read_linear(Show::Direct).unwrap());
    for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        let (p, q) = (Vec3::from(*p), Vec3::from(*q));
        assert!((p - q).abs().max_element() <= 1e-4 * q.max_element() + 1e-6, "pixel {i}: path {p}, direct {q}");
    }
}

/// (GPU total flux, CPU twin total flux) of maps of first hits only (albedo 0 floor).
fn first_hit_flux(light: Light, photons: u32) -> (Vec3, Vec3, Vec3) {
    let gpu = common::gpu();
    let mut scene = floor(light);
    scene.materials[0].albedo = Vec3::ZERO;
    let settings = PhotonSettings {
        count: photons,
        seed: 5,
        grid_resolution: 8,
        sampled_direct: Default::default(),
        region: None,
        guided: false,
    };
    let prepared = PreparedScene::new(&scene);
    let gs = rastergi::gpu_scene::GpuScene::new(&gpu, &prepared).unwrap();
    let g = GpuPhotonMap::build(&gpu, &gs, &prepared, &settings).unwrap().read(&gpu).unwrap().total_flux();
    let c = cpu::trace(&prepared, &GridSpec::new(&scene.bounds(), 8), &settings).total_flux();
    let f = |v: [f64; 3]| Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32);
    (f(g), f(c), prepared.lights.power)
}

/// The solid angle of the floor from a point at height h above (x0, z0): 4 rectangles from
/// the foot point, each Ω = atan(ab / (h √(a² + b² + h²))).
fn floor_solid_angle(x0: f64, h: f64, z0: f64) -> f64 {
    let a = (A as f64 - x0, A as f64 + x0);
    let b = (A as f64 - z0, A as f64 + z0);
    let part = |a: f64, b: f64| (a * b / (h * (a * a + b * b + h * h).sqrt())).atan();
    part(a.0, b.0) + part(a.0, b.1) + part(a.1, b.0) + part(a.1, b.1)
}

#[test]
fn photons_carry_each_lights_flux_to_the_floor() {
    let n = 1 << 16;
    // Point: I·Ω of the floor. Each photon's flux is 4π·I/N: the total is binomial in the
    // photons that hit, relative noise √((1−p)/(pN)).
    let Light::Point { position, intensity } = point() else { unreachable!() };
    let omega = floor_solid_angle(position.x as f64, position.y as f64, position.z as f64);
    let expected = intensity * omega as f32;
    let p = omega / (4.0 * PI);
    let tol = 5.0 * ((1.0 - p) / (p * n as f64)).sqrt() as f32;
    let (g, c, power) = first_hit_flux(point(), n);
    println!("point: GPU {g}, CPU {c}, I·Ω {expected}, power {power} (tolerance {tol:.4})");
    assert!(((g - expected) / expected).abs().max_element() < tol, "GPU {g} against {expected}");
    assert!(((c - expected) / expected).abs().max_element() < tol, "CPU {c} against {expected}");
    assert!((power - intensity * 4.0 * std::f32::consts::PI).abs().max_element() < 1e-4 * power.max_element());

    // Distant: E·cos θ·floor area, the disc's photons that cross the floor (a fraction of the
    // disc: binomial again).
    let Light::Distant { direction, irradiance, .. } = distant(0.0) else { unreachable!() };
    let area = (2.0 * A) * (2.0 * A);
    let expected = irradiance * (-direction.y * area);
    let (g, c, power) = first_hit_flux(distant(0.0), n);
    let p = (expected.x / power.x) as f64;
    let tol = 5.0 * ((1.0 - p) / (p * n as f64)).sqrt() as f32;
    println!("distant: GPU {g}, CPU {c}, E cos θ A {expected} ({:.3} of the disc's power; tolerance {tol:.4})", p);
    assert!(((g - expected) / expected).abs().max_element() < tol, "GPU {g} against {expected}");
    assert!(((c - expected) / expected).abs().max_element() < tol, "CPU {c} against {expected}");

    // Spot: ∫ I s(cos θ) over the floor's solid angle, by quadrature over the floor:
    // dΩ = cos θ_floor dA / d².
    let Light::Spot { position, direction, intensity, inner, outer } = spot() else { unreachable!() };
    let k = 800;
    let mut sum = 0.0f64;
    for i in 0..k {
        for j in 0..k {
            let x =
                Vec3::new(-A + 2.0 * A * (i as f32 + 0.5) / k as f32, 0.0, -A + 2.0 * A * (j as f32 + 0.5) / k as f32);
            let d = x - position;
            let cos = direction.dot(d.normalize());
            let t = ((cos - outer.cos()) / (inner.cos() - outer.cos())).clamp(0.0, 1.0);
            sum += (t * t) as f64 * (-d.y / d.length()) as f64 / d.length_squared() as f64;
        }
    }
    let expected = intensity * (sum * (2.0 * A as f64 / k as f64).powi(2)) as f32;
    let (g, c, power) = first_hit_flux(spot(), n);
    // The whole outer cone reaches the floor, so the quadrature is the light's power (its
    // closed form, independent of the quadrature), to the quadrature's error.
    assert!(((power - expected) / expected).abs().max_element() < 2e-3, "power {power}, quadrature {expected}");
    // Every photon hits, with flux ∝ s ∈ [0, 1]: the total's relative noise is
    // std(s)/(E[s]·√N) ≤ √((1 − E[s])/(E[s]·N)), E[s] = Φ/(I·Ω_cone).
    let mean_s = power.x / (intensity.x * 2.0 * std::f32::consts::PI * (1.0 - outer.cos()));
    let tol = 5.0 * ((1.0 - mean_s) / (mean_s * n as f32)).sqrt();
    println!("spot: GPU {g}, CPU {c}, ∫ I s dΩ {expected}, power {power} (tolerance {tol:.4})");
    assert!(((g - expected) / expected).abs().max_element() < tol, "GPU {g} against {expected}");
    assert!(((c - expected) / expected).abs().max_element() < tol, "CPU {c} against {expected}");
}

/// The sun of rastergi's `--sun AZIMUTH,ELEVATION,IRRADIANCE` with `--sun-size 0`
/// (`rastergi-cli`'s `sun_light`, restated: travelling along −(sin a cos e, sin e, cos a cos e)).
fn sun(azimuth: f32, elevation: f32, irradiance: f32) -> Light {
    let (a, e) = (azimuth.to_radians(), elevation.to_radians());
    let towards = Vec3::new(a.sin() * e.cos(), e.sin(), a.cos() * e.cos());
    Light::Distant { direction: -towards, irradiance: Vec3::splat(irradiance), angular_radius: 0.0 }
}

#[test]
fn the_cornell_box_with_a_point_light_and_the_sun_through_its_open_front_matches_mitsuba() {
    // References: scripts/mitsuba_reference.py --spp 8192 --seed 5|6
    //   --point=-0.5,0.5,0.3,0.3,0.3,0.3 --sun 20,25,1.5 (tests/data/README.md).
    let mut scene = rastergi::scene::cornell_box();
    scene.lights.push(Light::Point { position: Vec3::new(-0.5, 0.5, 0.3), intensity: Vec3::splat(0.3) });
    scene.lights.push(sun(20.0, 25.0, 1.5));
    common::matches_mitsuba(
        "cornell + point + sun",
        &scene,
        rastergi::gather::HitLight::Punctual,
        256,
        "cornell_lights_path_128",
        true,
        Show::Full,
        None,
    );
}

#[test]
fn the_cornell_box_with_a_hard_edged_spot_matches_mitsuba() {
    // References: scripts/mitsuba_reference.py --spp 8192 --seed 7|8
    //   --spot=-0.4,0.9,0.4,0.2,-1,-0.2,1.5,1.5,1.5,25 (tests/data/README.md): Mitsuba's `spot`
    // with beam_width = cutoff_angle is a step at 25°, which is rastergi's spot with equal
    // cones (glTF's smooth ramp has no Mitsuba twin).
    let mut scene = rastergi::scene::cornell_box();
    let (position, aim) = (Vec3::new(-0.4, 0.9, 0.4), Vec3::new(0.2, -1.0, -0.2));
    let angle = 25f32.to_radians();
    let direction = (aim - position).normalize();
    scene.lights.push(Light::Spot { position, direction, intensity: Vec3::splat(1.5), inner: angle, outer: angle });
    common::matches_mitsuba(
        "cornell + spot",
        &scene,
        rastergi::gather::HitLight::Punctual,
        256,
        "cornell_spot_path_128",
        true,
        Show::Full,
        None,
    );
}
