//! Requests beyond the device's limits end in one clear error before anything is allocated:
//! a scene whose triangle buffer exceeds the storage-binding limit, a photon grid and a
//! ray-view bundle too large for this device. (`limits.rs` tests the same rules for given
//! limits without a GPU.)

mod common;

use glam::Vec3;
use rastergi::path_tracer::PathTracer;
use rastergi::renderer::{RenderSettings, Renderer};
use rastergi::scene::{Material, Scene, cornell_box};

fn settings() -> RenderSettings {
    RenderSettings { width: 32, height: 32, photons: 1 << 12, grid_resolution: 16, ..RenderSettings::default() }
}

#[test]
fn a_scene_beyond_the_storage_binding_limit_is_refused_with_its_size() {
    let gpu = common::gpu();
    let limits = gpu.device.limits();
    let max = rastergi::limits::max_storage_buffer(&limits);
    let stride = std::mem::size_of::<rastergi::gpu_scene::GpuTriangle>() as u64;
    let n = max / stride + 1;
    if n > 8_000_000 {
        println!("skipped: this device binds {} MiB; {n} triangles would take too much memory here", max >> 20);
        return;
    }
    let mut scene = Scene::new(cornell_box().camera);
    let m = scene.add_material(Material { emission: Vec3::ONE, ..Material::diffuse("m", Vec3::splat(0.5)) });
    let t = [Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, -1.0, -1.0), Vec3::new(0.0, 1.0, -1.0)];
    scene.triangles = vec![t; n as usize];
    scene.material_ids = vec![m; n as usize];
    let start = std::time::Instant::now();
    let e = Renderer::new(&gpu, &scene, settings()).err().expect("the renderer accepted the scene").to_string();
    println!("{e} ({:.2} s)", start.elapsed().as_secs_f64());
    assert!(e.contains(&format!("{n} triangles")) && e.contains("fewer triangles"), "{e}");
    let e = PathTracer::new(&gpu, &scene, settings()).err().expect("the path tracer accepted the scene").to_string();
    assert!(e.contains(&format!("{n} triangles")), "{e}");
}

#[test]
fn a_photon_grid_or_bundle_beyond_the_device_is_refused_with_the_option_to_change() {
    let gpu = common::gpu();
    let scene = cornell_box();
    // 2048 cells along the longest axis: 8.5·10⁹ cells, beyond 32-bit cell indices.
    let grid = RenderSettings { grid_resolution: 2048, ..settings() };
    let e = Renderer::new(&gpu, &scene, grid).err().expect("a 2048³ grid was accepted").to_string();
    println!("{e}");
    assert!(e.contains("photon grid of 2038x2048x2038 cells") && e.contains("--grid"), "{e}");
    // 1024³ cells hold about 10⁷ surface slots, more than a 128 MiB binding: the map takes a
    // coarser grid (with a warning) rather than failing or overflowing its table.
    let grid = RenderSettings { grid_resolution: 1024, ..settings() };
    let r = Renderer::new(&gpu, &scene, grid).expect("a 1024³ grid degrades to a coarser one");
    let map = r.photon_map().expect("a photon map");
    let max = rastergi::limits::max_storage_buffer(&gpu.device.limits());
    println!("1024 asked, {} used; {} table entries", map.grid().dims.max_element(), map.layout.table.capacity());
    assert!(map.layout.table.capacity() as u64 * 16 <= max);
    if max < 1 << 30 {
        assert!(map.grid().dims.max_element() < 1024);
    }
    // A bundle past the texture side, or whose counters (4 bytes a texel) exceed a binding.
    let max = gpu.device.limits().max_texture_dimension_2d;
    let bundle = RenderSettings { bundle: max + 1, ..settings() };
    let e = Renderer::new(&gpu, &scene, bundle).err().expect("an oversized bundle was accepted").to_string();
    println!("{e}");
    assert!(e.contains("--bundle"), "{e}");
}
