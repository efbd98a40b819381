//! A room as an architect's glTF exporter writes one (issue 34), `tests/data/gltf/thick_room.gltf`
//! from `scripts/make_thick_room.py`: one watertight shell with 0.2 m walls whose every face
//! looks into free space, a window cut through one wall, one-sided Lambertian materials, flat
//! NORMALs, a point light under a rotated parent node and the sun shining in through the window,
//! no environment. Against its Mitsuba 3 pair (the file read by `scripts/mitsuba_gltf.py`), and,
//! with glTF's default dielectric layer on every material, against rastergi's path tracer and
//! the energy the layer must conserve.

mod common;

use glam::Vec3;
use rastergi::metrics::{compare, masked_mean};
use rastergi::passes::film::Show;
use rastergi::scene::{Light, Scene, load_gltf};

fn room() -> Scene {
    load_gltf(&common::data("gltf/thick_room.gltf")).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn the_lights_are_where_the_node_hierarchy_puts_them() {
    // make_thick_room.py: the bulb's parent is translated (0.4, 1.2, -0.2) and turned 90° about
    // +y, the bulb translated (0.6, 1.0, 0.4) in its frame: R_y(90°)(x, y, z) = (z, y, -x), so
    // the bulb is at (0.4, 1.2, -0.2) + (0.4, 1.0, -0.6). The sun travels down at 35°, turned
    // 12° from +x towards -z.
    let scene = room();
    let (e, a) = (35f32.to_radians(), 12f32.to_radians());
    let travel = Vec3::new(e.cos() * a.cos(), -e.sin(), -e.cos() * a.sin());
    let mut found = (false, false);
    for light in &scene.lights {
        match *light {
            Light::Point { position, intensity } => {
                assert!((position - Vec3::new(0.8, 2.2, -0.8)).abs().max_element() < 1e-5, "{position}");
                assert!((intensity - Vec3::new(6.0, 5.4, 4.8)).abs().max_element() < 1e-5);
                found.0 = true;
            }
            Light::Distant { direction, irradiance, angular_radius } => {
                assert!((direction - travel).abs().max_element() < 1e-5, "{direction} vs {travel}");
                assert!((irradiance - Vec3::new(30.0, 28.5, 27.0)).abs().max_element() < 1e-4);
                assert_eq!(angular_radius, 0.0);
                found.1 = true;
            }
            _ => panic!("unexpected light {light:?}"),
        }
    }
    assert_eq!(found, (true, true));
    assert!(scene.materials.iter().all(|m| !m.two_sided), "every material is one-sided");
}

#[test]
fn a_thick_walled_one_sided_room_lit_through_its_window_matches_mitsuba() {
    // References: scripts/mitsuba_reference.py --scene tests/data/gltf/thick_room.gltf --spp 16384
    // --seed 11|12 (tests/data/README.md); their pair's relative RMSE 1.79 %.
    let scene = room();
    let gpu = common::gpu();
    let a = common::render(&gpu, &scene, common::fitted_settings(&scene, 128, 1), 256, Show::Full);
    let b = common::render(&gpu, &scene, common::fitted_settings(&scene, 128, 2), 256, Show::Full);
    let (reference, ref_noise) = common::reference_pair("thick_room_path_128", None);
    let (c, noise, bias) = common::against_reference(&a, &b, &reference, ref_noise, None);
    // Two seeds of ours against each other: the block-mean error that noise alone gives.
    let seeds = compare(&a, &b, None);
    println!(
        "thick room: relative RMSE {:.4} = noise {noise:.4} ⊕ bias {bias:.4}; block-mean error {:.4} \
         (seed against seed {:.4}); mean ratio {:?}",
        c.relative_rmse, c.block_mean_error, seeds.block_mean_error, c.mean_ratio
    );
    assert!(bias < 0.01, "bias {bias}");
    // The mean of two seeds has √2 less noise than one seed against another has √2 more: the
    // block means of ours against the reference are within noise at half the seeds' spread,
    // with a margin for the reference's own noise and the map's blur.
    assert!(c.block_mean_error < 0.75 * seeds.block_mean_error + 0.003, "block-mean error {}", c.block_mean_error);
    for r in c.mean_ratio {
        assert!((r - 1.0).abs() < 0.005, "channel means {:?}", c.mean_ratio);
    }
}

/// The room with glTF's default dielectric specular layer on every material (the
/// KHR_materials_specular that makes them Lambertian taken out): metallic 0, roughness 1, as a
/// material an exporter writes for a matte wall.
fn layered_room() -> Scene {
    let path = common::data("gltf/thick_room.gltf");
    let mut json: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    for m in json["materials"].as_array_mut().unwrap() {
        m.as_object_mut().unwrap().remove("extensions");
    }
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("layered_room.gltf");
    std::fs::write(&file, serde_json::to_vec(&json).unwrap()).unwrap();
    let scene = load_gltf(&file).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.materials.iter().all(|m| m.specular == 1.0 && m.roughness == 1.0 && m.metallic == 0.0));
    scene
}

#[test]
fn gltf_default_layer_conserves_energy_and_the_gather_agrees_with_the_path_tracer() {
    // The layer reflects E_L(μ) and the base under it (1 − E_L(μ))·c, so a layered wall reflects
    // E_L + (1 − E_L)·c ≥ c: the room can be no darker than its Lambertian twin (Mitsuba's pair
    // above). Until issue 34 the base gave up sF(μ) while rough GGX reflected less than that:
    // this room came out 9–12 % darker than the Lambertian one.
    let scene = layered_room();
    let gpu = common::gpu();
    let size = 64;
    let gather = common::render(&gpu, &scene, common::fitted_settings(&scene, size, 3), 256, Show::Full);
    let path = common::path_trace(&gpu, &scene, common::fitted_settings(&scene, size, 4), 1024);
    let path_b = common::path_trace(&gpu, &scene, common::fitted_settings(&scene, size, 5), 256);
    let c = compare(&gather, &path, None);
    let noise = compare(&path_b, &path, None);
    let lambertian = common::reference_pair("thick_room_path_128", None).0;
    let ratio = masked_mean(&path, None) / masked_mean(&lambertian, None);
    println!(
        "layered room: gather against the path tracer: block-mean error {:.4} (path tracer 256 against 1024 \
         iterations {:.4}), mean ratio {:?}; path tracer / Lambertian (Mitsuba) {ratio:.4}",
        c.block_mean_error, noise.block_mean_error, c.mean_ratio
    );
    assert!(ratio > 0.995, "the layered room is darker than its Lambertian twin: {ratio}");
    assert!(c.block_mean_error < noise.block_mean_error, "block-mean error {}", c.block_mean_error);
    for r in c.mean_ratio {
        assert!((r - 1.0).abs() < 0.01, "channel means {:?}", c.mean_ratio);
    }
}
