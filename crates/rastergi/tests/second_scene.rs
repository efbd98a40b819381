//! Issue 5's "second scene of our making": the built-in `atrium` (columns, arches, windows
//! and a skylight in a closed, colourful hall; see `scene::generate::atrium`) rendered by the
//! photon map + rasterized final gather, against the reference path tracer of the same scene,
//! camera and pixel filter.

mod common;

use std::f64::consts::PI;

use rastergi::film::Show;
use rastergi::fit;
use rastergi::gpu::Gpu;
use rastergi::image_io::LinearImage;
use rastergi::metrics::{compare, emitter_mask, masked_mean, rmse};
use rastergi::path_tracer::PathTracer;
use rastergi::renderer::{RenderSettings, Renderer};
use rastergi::scene::Scene;
use rastergi::scene::generate::atrium;

const WIDTH: u32 = 96;
const HEIGHT: u32 = 72;

fn settings(scene: &Scene, seed: u32) -> RenderSettings {
    // The defaults the command line fits to the scene (grid 83, 2²⁰ photons).
    let grid = fit::grid_resolution(&scene.bounds());
    RenderSettings {
        width: WIDTH,
        height: HEIGHT,
        seed,
        photons: fit::photon_count(scene, grid),
        grid_resolution: grid,
        show_photon_map: true,
        ..RenderSettings::default()
    }
}

/// The full image and the photon-map view after `iterations`.
fn gather(gpu: &Gpu, scene: &Scene, seed: u32, iterations: u32) -> (LinearImage, LinearImage) {
    let start = std::time::Instant::now();
    let mut r = Renderer::new(gpu, scene, settings(scene, seed)).expect("renderer");
    for i in 0..iterations {
        r.iterate().expect("iteration");
        if i % 16 == 15 {
            r.wait().unwrap();
        }
    }
    r.wait().unwrap();
    println!("gather, seed {seed}: {:.1} s", start.elapsed().as_secs_f64());
    (r.read_linear(Show::Full).unwrap(), r.read_linear(Show::PhotonMap).unwrap())
}

fn path_trace(gpu: &Gpu, scene: &Scene, seed: u32, iterations: u32) -> LinearImage {
    let start = std::time::Instant::now();
    let mut p = PathTracer::new(gpu, scene, settings(scene, seed)).expect("path tracer");
    for i in 0..iterations {
        p.iterate();
        if i % 16 == 15 {
            p.wait().unwrap();
        }
    }
    p.wait().unwrap();
    println!("path tracer, seed {seed}: {:.1} s", start.elapsed().as_secs_f64());
    p.read_linear().unwrap()
}

#[test]
fn second_scene_atrium_photon_gather_matches_the_path_tracer_within_noise_and_grid_bias() {
    let gpu = common::gpu();
    let scene = atrium();
    let (a, map_a) = gather(&gpu, &scene, 1, 256);
    let (b, map_b) = gather(&gpu, &scene, 2, 256);
    let (pa, pb) = (path_trace(&gpu, &scene, 3, 512), path_trace(&gpu, &scene, 4, 512));
    let (ours, reference) = (common::average(&a, &b), common::average(&pa, &pb));
    let mask = emitter_mask(&reference, 3.0);
    let mean = masked_mean(&reference, Some(&mask));
    let ours_noise = rmse(&a, &b, Some(&mask)) / 2.0 / mean;
    let ref_noise = rmse(&pa, &pb, Some(&mask)) / 2.0 / mean;
    let noise = (ours_noise.powi(2) + ref_noise.powi(2)).sqrt();
    let c = compare(&ours, &reference, Some(&mask));
    let bias = (c.relative_rmse.powi(2) - noise.powi(2)).max(0.0).sqrt();
    println!(
        "relative RMSE {:.4} = noise {noise:.4} (ours {ours_noise:.4}, path {ref_noise:.4}) ⊕ bias {bias:.4}; block-mean error {:.4}; mean ratio {:?}",
        c.relative_rmse, c.block_mean_error, c.mean_ratio
    );
    let map = common::average(&map_a, &map_b);
    let m = compare(&map, &reference, Some(&mask));
    println!(
        "photon map view vs path: relative RMSE {:.4}, block {:.4}, ratio {:?}",
        m.relative_rmse, m.block_mean_error, m.mean_ratio
    );
    let _ = PI;
}
