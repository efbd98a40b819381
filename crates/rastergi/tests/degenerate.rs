//! Published meshes carry degenerate triangles by the hundred (zero-area, collinear, duplicate)
//! and albedo-1 surfaces: no pass may write NaN or infinity into the film because of them
//! (issue 45: a classroom's sunbeam edge on two collinear triangles gave NaN pixels from the
//! direct pass on). A sunbeam through a slot in a roof falls on a white floor (albedo 1) that
//! carries every kind of degenerate triangle along the beam's edges; each pass and each
//! gather renders it and the film must hold finite numbers only. Lambertian, like the Cornell
//! box, so that its pipelines are the ones the gather tests compile (lavapipe compiles a new
//! variant for a minute).

mod common;

use glam::Vec3;
use rastergi::environment::Environment;
use rastergi::gather::{GatherDirections, GatherMethod, HitLight};
use rastergi::image_io::validate_finite;
use rastergi::passes::film::Show;
use rastergi::progressive::Denoising;
use rastergi::scene::{Camera, Light, Material, Scene};
use rastergi::settings::RenderSettings;

fn quad(s: &mut Scene, corners: [Vec3; 4], material: u32) {
    s.add_triangle([corners[0], corners[1], corners[2]], material);
    s.add_triangle([corners[0], corners[2], corners[3]], material);
}

/// The floor (y = 0, white), a roof (y = 1) with a slot along z at x ∈ [−0.1, 0.1], the sun
/// almost straight down, a dim sky, a small emitter, and degenerate triangles where the beam's
/// edges meet the floor.
fn scene() -> Scene {
    let camera =
        Camera { eye: Vec3::new(0.0, 2.2, 2.2), target: Vec3::new(0.0, 0.0, 0.0), up: Vec3::Y, fov_y_deg: 50.0 };
    let mut s = Scene::new(camera);
    let white = s.add_material(Material::diffuse("white", Vec3::ONE));
    let grey = s.add_material(Material::diffuse("grey", Vec3::splat(0.5)));
    let lamp = s.add_material(Material { emission: Vec3::splat(5.0), ..Material::diffuse("lamp", Vec3::ZERO) });
    let y = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    quad(&mut s, [y(-1.0, 0.0, -1.0), y(-1.0, 0.0, 1.0), y(1.0, 0.0, 1.0), y(1.0, 0.0, -1.0)], white);
    // The roof in two halves, facing down, leaving the slot open.
    quad(&mut s, [y(-1.0, 1.0, -1.0), y(-0.1, 1.0, -1.0), y(-0.1, 1.0, 1.0), y(-1.0, 1.0, 1.0)], grey);
    quad(&mut s, [y(0.1, 1.0, -1.0), y(1.0, 1.0, -1.0), y(1.0, 1.0, 1.0), y(0.1, 1.0, 1.0)], grey);
    // A block beside the beam.
    quad(&mut s, [y(0.3, 0.3, -0.3), y(0.3, 0.3, 0.3), y(0.6, 0.3, 0.3), y(0.6, 0.3, -0.3)], grey);
    let beam_edge = 0.1;
    for (k, material) in [white, grey, lamp].into_iter().enumerate() {
        let z = -0.5 + 0.4 * k as f32;
        let e = beam_edge * if k % 2 == 0 { 1.0 } else { -1.0 };
        // Zero area: a repeated corner, and all three corners equal.
        s.add_triangle([y(e, 1e-3, z), y(e, 1e-3, z), y(e + 0.05, 1e-3, z + 0.05)], material);
        s.add_triangle([y(e, 1e-3, z); 3], material);
        // Collinear corners across the beam's edge, at the floor and a little above it.
        s.add_triangle([y(e - 0.1, 0.0, z), y(e, 0.0, z), y(e + 0.1, 0.0, z)], material);
        s.add_triangle([y(e - 0.1, 2e-3, z + 0.1), y(e + 0.1, 2e-3, z + 0.1), y(e, 2e-3, z + 0.1)], material);
        // Nearly collinear: an area of about 1e-12.
        s.add_triangle([y(e - 0.1, 3e-3, z), y(e + 0.1, 3e-3, z), y(e, 3e-3 + 1e-10, z + 1e-10)], material);
    }
    // A duplicate of a floor triangle (coplanar, the same corners) and a huge one far below.
    let first = s.triangles[0];
    s.add_triangle(first, white);
    s.add_triangle([y(-1e5, -10.0, -1e5), y(1e5, -10.0, -1e5), y(0.0, -10.0, 1e5)], grey);
    s.lights.push(Light::Distant {
        direction: Vec3::new(0.05, -1.0, 0.02).normalize(),
        irradiance: Vec3::splat(3.0),
        angular_radius: 0.5f32.to_radians(),
    });
    s.environment = Some(std::sync::Arc::new(Environment::constant(Vec3::new(0.2, 0.3, 0.5))));
    s
}

fn settings(gather: GatherMethod, directions: GatherDirections, hit_light: HitLight) -> RenderSettings {
    RenderSettings {
        width: 64,
        height: 64,
        seed: 7,
        photons: 1 << 16,
        grid_resolution: 32,
        gather,
        gather_directions: directions,
        hit_light,
        ..Default::default()
    }
}

#[test]
fn degenerate_triangles_in_a_sunbeam_leave_every_pass_finite() {
    let gpu = common::gpu();
    let scene = scene();
    let mut failures = vec![];
    let mut check = |what: String, image: rastergi::image_io::LinearImage| {
        if let Err(e) = validate_finite(&image) {
            failures.push(format!("{what}: {e}"));
        }
    };
    let trace = settings(GatherMethod::Trace, GatherDirections::PerPixel, HitLight::Map);
    for show in [Show::Direct, Show::PhotonMap, Show::Indirect, Show::Full] {
        let s = RenderSettings { show_photon_map: show == Show::PhotonMap, ..trace.clone() };
        check(format!("{show:?}"), common::render(&gpu, &scene, s, 16, show));
    }
    for (gather, directions, hit_light) in [
        (GatherMethod::Trace, GatherDirections::Shared, HitLight::Exact),
        (GatherMethod::Raster, GatherDirections::Shared, HitLight::Map),
        (GatherMethod::Lists, GatherDirections::Shared, HitLight::Map),
    ] {
        let s = settings(gather, directions, hit_light);
        check(
            format!("{gather:?} gather, {directions:?}, {hit_light:?}"),
            common::render(&gpu, &scene, s, 16, Show::Full),
        );
    }
    check("path tracer".into(), common::path_trace(&gpu, &scene, trace.clone(), 32));
    let mut denoised = rastergi::renderer::Renderer::new(&gpu, &scene, trace).unwrap();
    denoised.enable_denoiser().unwrap();
    for _ in 0..8 {
        denoised.iterate().unwrap();
    }
    check("denoised".into(), denoised.read_denoised(&rastergi::passes::denoise::DenoiseParams::default()).unwrap());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// The shared Japanese Classroom's ceiling carries collinear triangles (three corners on one
/// line along x): zero area, no normal. Projected, rounding leaves their corners a sliver apart
/// and the rasterizer covered pixels with them at barycentrics in the hundreds, whose visible
/// points were NaN (issue 57: 3 NaN pixels at 320 × 180 in 32 iterations of the direct light).
/// The same two triangles, the same camera and image size, over a floor: no G-buffer texel of
/// 64 jittered iterations may name a triangle of zero area, and the film stays finite.
#[test]
fn collinear_triangles_cover_no_pixel_of_the_g_buffer() {
    let camera = Camera {
        eye: Vec3::new(-1.69049, 1.27158, 5.88653),
        target: Vec3::new(-1.5391959, 1.2998871, 4.8984466),
        up: Vec3::new(-0.004284431, 0.99959934, 0.02798101),
        fov_y_deg: 35.983402,
    };
    let mut s = Scene::new(camera);
    let wall = s.add_material(Material::diffuse("Walls", Vec3::new(0.654071, 0.67408, 0.8)));
    let (y, z) = (2.758842, 0.254969);
    s.add_triangle([Vec3::new(3.938532, y, z), Vec3::new(-4.194854, y, z), Vec3::new(-0.248418, y, z)], wall);
    s.add_triangle([Vec3::new(3.938532, y, z), Vec3::new(-0.248418, y, z), Vec3::new(0.284595, y, z)], wall);
    quad(
        &mut s,
        [Vec3::new(-5.0, 0.0, -5.0), Vec3::new(-5.0, 0.0, 6.0), Vec3::new(5.0, 0.0, 6.0), Vec3::new(5.0, 0.0, -5.0)],
        wall,
    );
    s.lights.push(Light::Distant {
        direction: Vec3::new(0.3, -1.0, 0.2).normalize(),
        irradiance: Vec3::splat(3.0),
        angular_radius: 0.0,
    });
    let settings = RenderSettings {
        width: 320,
        height: 180,
        photons: 1 << 16,
        grid_resolution: 32,
        gather: GatherMethod::Trace,
        ..Default::default()
    };
    let gpu = common::gpu();
    let mut r = rastergi::renderer::Renderer::new(&gpu, &s, settings).unwrap();
    let prepared = rastergi::surface::PreparedScene::new(&s);
    let zero_area = |t: usize| {
        let [a, b, c] = prepared.scene.triangles[t];
        (b - a).cross(c - a) == Vec3::ZERO
    };
    let mut covered = 0;
    for _ in 0..64 {
        r.iterate().unwrap();
        covered += r.read_gbuffer().unwrap().iter().filter(|g| g[0] > 0 && zero_area(g[0] as usize - 1)).count();
    }
    assert_eq!(covered, 0, "G-buffer texels on zero-area triangles over 64 iterations");
    validate_finite(&r.read_linear(Show::Full).unwrap()).unwrap();
}

/// The shared Japanese Classroom (`../shared/scenes/classroom`, its own `sunsky`, camera and
/// materials), 1024 iterations at 48 × 27 and the photon map's view kept: every component of
/// the film (direct light, indirect light, the photon map's view) holds finite numbers only.
/// The build before the fix above wrote NaN into 22 of these pixels' direct light.
#[test]
fn the_shared_classroom_stays_finite_in_every_pass_over_1024_iterations() {
    let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/classroom/scene.xml");
    if !path.exists() {
        println!("skipped: {} is not here (the shared public scenes are not on this machine)", path.display());
        return;
    }
    // One photon map (of the fitted grid, 2¹⁶ photons): the 1024 iterations' G-buffers,
    // direct light, gather and photon view are what is checked, not the map's passes, and
    // lavapipe renders them in about 20 s.
    let options = rastergi::session::Options {
        scene: path.to_string_lossy().into_owned(),
        width: Some(48),
        height: Some(27),
        show: Show::PhotonMap,
        photons: Some(1 << 16),
        photon_passes: 1,
        ..Default::default()
    };
    let session = rastergi::session::Session::load(&options).unwrap();
    let gpu = common::gpu();
    let mut r = rastergi::renderer::Renderer::new(&gpu, &session.scene, session.settings.clone()).unwrap();
    for _ in 0..1024 {
        r.iterate().unwrap();
    }
    for show in [Show::Direct, Show::Indirect, Show::PhotonMap, Show::Full] {
        if let Err(e) = validate_finite(&r.read_linear(show).unwrap()) {
            panic!("{show:?}: {e}");
        }
    }
}
