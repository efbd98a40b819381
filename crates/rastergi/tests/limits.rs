//! Requests beyond the device's limits end in one clear error before anything is allocated:
//! a scene whose triangle buffer exceeds the storage-binding limit, a photon grid and a
//! ray-view bundle too large for this device. (`limits.rs` tests the same rules for given
//! limits without a GPU.)

mod common;

use glam::Vec3;
use rastergi::path_tracer::PathTracer;
use rastergi::progressive::Denoising;
use rastergi::renderer::Renderer;
use rastergi::scene::{Material, Scene, cornell_box};
use rastergi::settings::RenderSettings;

fn settings() -> RenderSettings {
    RenderSettings { width: 32, height: 32, photons: 1 << 12, grid_resolution: 16, ..RenderSettings::default() }
}

#[test]
fn a_scene_beyond_the_storage_binding_limit_is_refused_with_its_size() {
    let gpu = common::gpu();
    let limits = gpu.device.limits();
    let max = rastergi::gpu::limits::max_storage_buffer(&limits);
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
    let max = rastergi::gpu::limits::max_storage_buffer(&gpu.device.limits());
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

/// A browser's WebGPU grants 10 storage buffers per shader stage (counted over a pipeline
/// layout's bind groups, used by the shader or not), where lavapipe allows far more. On a
/// device opened with that limit, everything a web page runs must build and give the image
/// the full device gives (the same shaders: bit for bit): the photon map with the traced
/// gather, the photon view, the caustics and the specular chains (a glass sphere), the
/// denoiser's guides, and the path tracer. The raster gathers, which bind more, are refused in
/// one line.
#[test]
fn what_a_web_page_runs_fits_a_browsers_storage_buffer_limit() {
    use rastergi::gather::GatherMethod;
    use rastergi::gpu::{Gpu, GpuOptions, WEB_STORAGE_BUFFERS};
    use rastergi::passes::film::Show;
    let full = common::gpu();
    let web =
        Gpu::new(&GpuOptions { max_storage_buffers: Some(WEB_STORAGE_BUFFERS), ..GpuOptions::default() }).unwrap();
    assert_eq!(web.device.limits().max_storage_buffers_per_shader_stage, WEB_STORAGE_BUFFERS);
    let glass = rastergi::scene::load_obj(&common::data("obj/mat_glass.obj")).unwrap();
    let s = RenderSettings {
        gather: GatherMethod::Trace,
        show_photon_map: true,
        photon_passes: 2,
        pass_iterations: 2,
        ..settings()
    };
    for (name, scene) in [("cornell", cornell_box()), ("glass sphere", glass)] {
        let images = [&full, &web].map(|gpu| {
            let mut r = Renderer::new(gpu, &scene, s.clone()).unwrap();
            r.enable_denoiser().unwrap();
            for _ in 0..4 {
                r.iterate().unwrap();
            }
            let image = r.read_linear(Show::Full).unwrap();
            let photon_view = r.read_linear(Show::PhotonMap).unwrap();
            let denoised = r.read_denoised(&Default::default()).unwrap();
            let mut pt = PathTracer::new(gpu, &scene, s.clone()).unwrap();
            for _ in 0..2 {
                pt.iterate();
            }
            let path = pt.read_linear().unwrap();
            gpu.check().unwrap();
            [image, photon_view, denoised, path]
        });
        for (k, what) in ["image", "photon view", "denoised image", "path tracer"].iter().enumerate() {
            assert_eq!(images[0][k].pixels, images[1][k].pixels, "{name}: the {what} differs on the limited device");
        }
        assert!(images[1][0].pixels.iter().flatten().any(|&v| v > 0.0), "{name}: a black image");
    }
    // The raster gathers bind RASTER_STORAGE_BUFFERS: a device with that many builds and runs
    // them, one with fewer refuses them before a pipeline fails.
    let n = rastergi::gather::RASTER_STORAGE_BUFFERS;
    let enough = Gpu::new(&GpuOptions { max_storage_buffers: Some(n), ..GpuOptions::default() }).unwrap();
    let fewer = Gpu::new(&GpuOptions { max_storage_buffers: Some(n - 1), ..GpuOptions::default() }).unwrap();
    for method in [GatherMethod::Raster, GatherMethod::Lists] {
        let mut r = Renderer::new(&enough, &cornell_box(), RenderSettings { gather: method, ..settings() }).unwrap();
        r.iterate().unwrap();
        r.wait().unwrap();
        enough.check().unwrap();
        let e = Renderer::new(&fewer, &cornell_box(), RenderSettings { gather: method, ..settings() })
            .err()
            .expect("the raster gather was built on a device that cannot bind it")
            .to_string();
        println!("{e}");
        assert!(e.contains("storage buffers") && e.contains("trace gather"), "{e}");
    }
}
