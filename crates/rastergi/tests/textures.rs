//! Textured albedo against independent computations: the CPU twin of the GPU's trilinear
//! sampler, the G-buffer's level of detail against a pixel's footprint in closed form, the
//! photon tracer against its CPU twin on a textured scene, the photon view per pixel against
//! the CPU's texture lookup, untextured behaviour unchanged by a white texture, and the full
//! photon-map + final-gather render of the textured room against the reference path tracer.

mod common;

use std::f64::consts::PI;

use common::textured_room::{self as room, Variant};
use glam::{Vec2, Vec3};
use rastergi::gpu::Gpu;
use rastergi::gpu_scene::GpuScene;
use rastergi::metrics::{emitter_mask, rmse};
use rastergi::passes::film::Show;
use rastergi::photons::map::PhotonMap;
use rastergi::photons::{PhotonSettings, cpu, gpu::GpuPhotonMap};
use rastergi::renderer::Renderer;
use rastergi::sampling::Rng;
use rastergi::scene::{Camera, Material, Scene, Texture, cornell_box, load_gltf};
use rastergi::settings::RenderSettings;
use rastergi::surface::PreparedScene;
use rastergi::textures::{TextureAtlas, sample_on_gpu, srgb_to_linear};

fn texture(name: &str, w: u32, h: u32, mut f: impl FnMut(u32, u32) -> [u8; 3]) -> Texture {
    let texels = (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).map(|(x, y)| {
        let [r, g, b] = f(x, y);
        [r, g, b, 255]
    });
    Texture { name: name.into(), width: w, height: h, texels: texels.collect(), linear: false }
}

/// The textured room, loaded from its glTF file.
fn textured_room() -> Scene {
    let dir = tempfile::tempdir().unwrap();
    load_gltf(&room::room_gltf(Variant::External).write(dir.path(), "room.gltf")).unwrap()
}

#[test]
fn cpu_twin_of_the_texture_sampler_agrees_with_the_gpu() {
    let gpu = common::gpu();
    let mut rng = Rng::new(3, 1, 4);
    // High contrast (a checker), a smooth gradient, and noise of sizes that are no powers of
    // two, each at its own size in the atlas.
    let textures = [
        texture("checker", 16, 16, room::checker_texel),
        texture("gradient", 64, 32, |x, y| [(x * 4) as u8, (y * 8) as u8, 128]),
        texture("noise", 37, 23, |_, _| [0; 3].map(|_: u8| (rng.next_u32() >> 24) as u8)),
    ];
    let atlas = TextureAtlas::new(&textures);
    let sizes: Vec<(u32, u32, u32)> = atlas.entries.iter().map(|e| (e.width, e.height, e.levels)).collect();
    assert_eq!(sizes, [(16, 16, 5), (64, 32, 7), (37, 23, 6)]);
    let mut queries = Vec::new();
    for i in 0..30_000 {
        let t = i % 3;
        let levels = atlas.entries[t as usize].levels as f32;
        let uv = Vec2::new(rng.next_f32(), rng.next_f32()) * 5.0 - 2.0;
        // Whole levels, fractional levels, below 0 and beyond the last level.
        let lod = match i % 4 {
            0 => 0.0,
            1 => (rng.next_f32() * levels).floor(),
            _ => rng.next_f32() * (levels + 2.0) - 1.0,
        };
        queries.push((t, uv, lod));
    }
    let gpu_samples = sample_on_gpu(&gpu, &atlas, &queries).unwrap();
    // Both read the same f16 texels and filter them with the same f32 arithmetic, step for
    // step (textures.wgsl against TextureAtlas::sample_rgba): they differ only where a
    // compiler fuses a multiply and an add (one rounding fewer per step, at most 2⁻²⁴ of a
    // value ≤ 1 each, over the seven steps of a trilinear blend), bounded by 10⁻⁶.
    let mut worst = 0.0f32;
    for (&(t, uv, lod), g) in queries.iter().zip(&gpu_samples) {
        let c = atlas.sample_rgba(t, uv, lod);
        let err = (*g - c).abs().max_element();
        worst = worst.max(err);
        assert!(err <= 1e-6, "texture {t} uv {uv} lod {lod}: GPU {g} vs CPU {c}");
    }
    println!("largest GPU−CPU difference: {worst:e}");
}

/// Scene: a square [-1,1]² at z = 0 facing +z, its texture repeated `repeats` times, lit by
/// nothing; the camera on the axis at distance `distance`.
fn frontal_square(repeats: f32, distance: f32) -> Scene {
    let camera = Camera { eye: Vec3::new(0.0, 0.0, distance), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
    let mut s = Scene::new(camera);
    let t = s.add_texture(texture("noise", 64, 64, |x, y| [(x * 4) as u8, (y * 4) as u8, 0]));
    let m = s.add_material(Material { albedo_texture: Some(t), ..Material::diffuse("square", Vec3::ONE) });
    let corners = [Vec3::new(-1., -1., 0.), Vec3::new(1., -1., 0.), Vec3::new(1., 1., 0.), Vec3::new(-1., 1., 0.)];
    let uv = corners.map(|p| Vec2::new(p.x + 1.0, 1.0 - p.y) * 0.5 * repeats);
    s.add_textured_triangle([corners[0], corners[1], corners[2]], [uv[0], uv[1], uv[2]], m);
    s.add_textured_triangle([corners[0], corners[2], corners[3]], [uv[0], uv[2], uv[3]], m);
    s
}

#[test]
fn gbuffer_level_of_detail_is_a_pixels_footprint_in_texels() {
    // A pixel at distance d spans 2·d·tan(fov/2)/H world units; the square's texture
    // coordinates change by repeats/2 per world unit, and a coordinate spans 64 texels, so a
    // pixel covers ρ = 64 · repeats/2 · 2·d·tan(fov/2)/H texels: λ = log2 ρ. The square faces
    // the camera, so ρ is the same at every pixel.
    // The same with the eye pass ray-cast (`EyeMethod::Trace`), whose λ comes from ray
    // differentials instead of the rasterizer's screen-space derivatives.
    let gpu = common::gpu();
    let size = 64;
    let eyes = [rastergi::settings::EyeMethod::Raster, rastergi::settings::EyeMethod::Trace];
    for ((repeats, distance), eye_pass) in
        [(8.0f32, 3.0f32), (8.0, 1.5), (1.0, 3.0), (64.0, 3.0)].into_iter().flat_map(|c| eyes.map(|e| (c, e)))
    {
        let scene = frontal_square(repeats, distance);
        let settings = RenderSettings { width: size, height: size, photons: 0, eye_pass, ..Default::default() };
        let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
        r.iterate().unwrap();
        let rho = 64.0 * repeats / 2.0 * 2.0 * distance * 20f32.to_radians().tan() / size as f32;
        let expected = rho.max(1.0).log2();
        let lods: Vec<f32> =
            r.read_gbuffer().unwrap().iter().filter(|g| g[0] != 0).map(|g| f32::from_bits(g[3])).collect();
        assert!(lods.len() > 1000, "the square covers too few pixels");
        let worst = lods.iter().map(|l| (l - expected).abs()).fold(0.0, f32::max);
        println!(
            "{eye_pass:?}: repeats {repeats}, distance {distance}: expected λ {expected:.3}, largest error {worst:.2e}"
        );
        assert!(worst < 0.01, "λ differs from log2 of the footprint {expected} by {worst}");
    }
}

/// `--texture-filter bilinear` (issue 45: textures as a reference renderer reads them): the
/// G-buffer's visible points read level 0 (λ = 0) however small the texels are on screen: a
/// square whose texture repeats 64 times, which the footprint reads at λ ≈ 6.1
/// (`gbuffer_level_of_detail_is_a_pixels_footprint_in_texels`); the pixel's jittered samples
/// then average the texels themselves.
#[test]
fn bilinear_texture_filter_reads_level_zero_at_every_visible_point() {
    use rastergi::settings::TextureFilter;
    let gpu = common::gpu();
    let size = 64;
    let scene = frontal_square(64.0, 3.0);
    let settings = RenderSettings {
        width: size,
        height: size,
        photons: 0,
        texture_filter: TextureFilter::Bilinear,
        ..Default::default()
    };
    let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
    r.iterate().unwrap();
    let lods: Vec<f32> = r.read_gbuffer().unwrap().iter().filter(|g| g[0] != 0).map(|g| f32::from_bits(g[3])).collect();
    assert!(lods.len() > 1000, "the square covers too few pixels");
    assert!(lods.iter().all(|&l| l == 0.0), "λ {:?}", lods.iter().fold(0.0f32, |a, &b| a.max(b)));
}

fn gpu_map(gpu: &Gpu, scene: &Scene, settings: &PhotonSettings) -> PhotonMap {
    let prepared = PreparedScene::new(scene);
    let gs = GpuScene::new(gpu, &prepared).expect("scene upload");
    GpuPhotonMap::build(gpu, &gs, &prepared, settings).unwrap().read(gpu).unwrap()
}

/// The GPU map and its CPU twin of `scene` with the same seed, checked to agree slot by slot
/// (relative L1 under 1 %, channel totals within 0.2 %): the maps, the L1 difference and
/// the CPU map's total flux.
fn same_seed_maps(gpu: &Gpu, scene: &Scene, settings: &PhotonSettings) -> (PhotonMap, PhotonMap, f64, f64) {
    let g = gpu_map(gpu, scene, settings);
    let c = cpu::trace(&PreparedScene::new(scene), g.grid(), settings);
    let (mut diff, mut total) = (0.0f64, 0.0f64);
    for s in 0..g.flux.len() {
        for ch in 0..3 {
            diff += (g.flux[s][ch] - c.flux[s][ch]).abs();
            total += c.flux[s][ch];
        }
    }
    let (tg, tc) = (g.total_flux(), c.total_flux());
    println!("slot-wise relative L1 difference {:.2e}; totals {tg:?} vs {tc:?}", diff / total);
    assert!(diff / total < 0.01, "the maps differ by {:.3} of their flux", diff / total);
    for ch in 0..3 {
        assert!((tg[ch] / tc[ch] - 1.0).abs() < 2e-3, "channel {ch}: {} vs {}", tg[ch], tc[ch]);
    }
    (g, c, diff, total)
}

/// `KHR_materials_specular`'s textures in both photon tracers: every surface of the textured
/// room but the light a rough layer (roughness 0.5) whose weight is a checker's alpha (1 or
/// 0.24) and whose colour is the checker's RGB × 20 (F₀ up to 0.8 per channel): the same seed
/// gives the same map slot by slot, and without the textures the map differs clearly (a
/// texel read wrongly on one side would change the lobe picked at many bounces).
#[test]
fn photon_tracer_and_its_cpu_twin_read_the_same_specular_texels() {
    use rastergi::scene::TextureRef;
    let gpu = common::gpu();
    let mut scene = textured_room();
    let checker = scene.add_texture(Texture {
        name: "checker".into(),
        width: 8,
        height: 8,
        texels: (0..64)
            .map(|i| {
                let on = (i % 8 + i / 8) % 2 == 0;
                if on { [255, 128, 30, 255] } else { [40, 128, 220, 60] }
            })
            .collect(),
        linear: false,
    });
    for m in scene.materials.iter_mut().filter(|m| !m.is_emitter()) {
        (m.specular, m.roughness, m.metallic, m.specular_color) = (1.0, 0.5, 0.0, Vec3::splat(20.0));
        m.specular_texture = Some(TextureRef::new(checker));
        m.specular_color_texture = Some(TextureRef::new(checker));
    }
    let settings = PhotonSettings { count: 1 << 18, seed: 9, grid_resolution: 16, ..Default::default() };
    let (_, c, diff, total) = same_seed_maps(&gpu, &scene, &settings);
    let mut flat = scene.clone();
    for m in &mut flat.materials {
        (m.specular_texture, m.specular_color_texture) = (None, None);
    }
    assert_changes_the_map(&flat, &c, &settings, diff, total, "without the specular textures");
}

/// The CPU map of `flat` (a scene without some of `c`'s textures) against `c`: it must differ
/// clearly — over 10× the twins' difference `diff` (both relative to `total`) — or the twins'
/// agreement would not see those textures read at the wrong place.
fn assert_changes_the_map(flat: &Scene, c: &PhotonMap, settings: &PhotonSettings, diff: f64, total: f64, what: &str) {
    let f = cpu::trace(&PreparedScene::new(flat), c.grid(), settings);
    let flat_diff: f64 =
        (0..f.flux.len()).map(|s| (0..3).map(|ch| (f.flux[s][ch] - c.flux[s][ch]).abs()).sum::<f64>()).sum();
    println!("{what}: relative L1 difference {:.3}", flat_diff / total);
    assert!(flat_diff / total > 10.0 * diff / total, "{what}: the map barely changes");
}

#[test]
fn photon_tracer_and_its_cpu_twin_read_the_same_texels() {
    // The same seed: both tracers follow the same photons, and each bounce's survival and
    // flux come from the texel's albedo. Paths part only where the two samplers' last digits
    // decide a roulette draw (a draw within ~10⁻³ of the albedo: a few per thousand bounces),
    // so the maps agree slot by slot up to those few paths; a texture read at another point
    // (flipped v, another layer, another level) would change every bounce on the floor, the
    // back wall and the cube, far more than that.
    let gpu = common::gpu();
    let scene = textured_room();
    let settings = PhotonSettings { count: 1 << 18, seed: 9, grid_resolution: 16, ..Default::default() };
    let (_, c, diff, total) = same_seed_maps(&gpu, &scene, &settings);
    // The same scene with the textures' mean colours instead: the maps must differ clearly,
    // or the comparison above would not see a texture read at the wrong place.
    let mut flat = scene.clone();
    for m in &mut flat.materials {
        if let Some(t) = m.albedo_texture.take() {
            let tex = &scene.textures[t];
            let mean: Vec3 = tex.texels.iter().map(|p| Vec3::from_array([0, 1, 2].map(|k| srgb_to_linear(p[k])))).sum();
            m.albedo *= mean / tex.texels.len() as f32;
        }
    }
    assert_changes_the_map(&flat, &c, &settings, diff, total, "untextured map");
}

#[test]
fn photon_view_of_the_textured_room_equals_the_cpu_lookup_per_pixel() {
    // Per pixel: ρ(uv, λ)/π · E(x) with λ from the G-buffer, ρ from the CPU twin of the
    // sampler and E from the CPU read of the GPU's map. The sampler's fixed-point weights
    // allow ~2^-8 of the local texel contrast (see the sampler test), far below the 10⁻²
    // allowed here; a texture read at the wrong coordinates would differ by the checker's
    // contrast (a factor of 4) at most pixels of the floor.
    let gpu = common::gpu();
    let scene = textured_room();
    let (img, prepared, pixels) = common::photon_view_pixels(&gpu, &scene, 64);
    let (mut checked, mut textured, mut worst) = (0, 0, 0.0f64);
    for p in &pixels {
        let v = &p.point;
        let albedo = prepared.albedo_at(v.tri, v.b1, v.b2, v.lod);
        for c in 0..3 {
            let expected = albedo[c] as f64 / PI * p.irradiance[c];
            let got = img.pixels[p.pixel][c] as f64;
            let err = (got - expected).abs() / expected.max(1e-3);
            worst = worst.max(err);
            assert!(err <= 1e-2, "pixel {} channel {c}: {got} vs {expected}", p.pixel);
        }
        checked += 1;
        textured += prepared.scene.material_of(v.tri).albedo_texture.is_some() as usize;
    }
    println!("{checked} pixels ({textured} textured): largest relative difference {worst:.2e}");
    assert!(textured > 1000, "too few textured pixels ({textured})");
}

#[test]
fn a_white_texture_changes_nothing() {
    // Texel 255 decodes to exactly 1, so ρ·1 = ρ: the Cornell box with every material
    // textured white renders what it renders without textures, sample for sample.
    let gpu = common::gpu();
    let plain = cornell_box();
    let mut white = plain.clone();
    let t = white.add_texture(texture("white", 4, 4, |_, _| [255; 3]));
    for m in &mut white.materials {
        m.albedo_texture = Some(t);
    }
    white.uvs = vec![[Vec2::new(0.3, 0.7), Vec2::new(1.4, -2.0), Vec2::new(0.0, 5.5)]; white.triangles.len()];
    // One gather implementation for both: `auto` could time its way to different ones.
    let settings = RenderSettings {
        width: 48,
        height: 48,
        photons: 1 << 16,
        grid_resolution: 16,
        gather: rastergi::gather::GatherMethod::Trace,
        ..Default::default()
    };
    let a = common::render(&gpu, &plain, settings.clone(), 8, Show::Full);
    let b = common::render(&gpu, &white, settings, 8, Show::Full);
    let worst = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs() / p[c].max(1e-3)))
        .fold(0.0, f32::max);
    println!("largest relative difference {worst:.2e}");
    assert!(worst <= 1e-6, "a white texture changed the image by {worst}");
}

#[test]
fn textured_room_render_matches_the_path_tracer_within_noise_and_grid_bias() {
    let gpu = common::gpu();
    let scene = textured_room();
    let (size, n) = (64, 256);
    let settings = |seed| RenderSettings {
        width: size,
        height: size,
        seed,
        photons: 1 << 20,
        grid_resolution: 32,
        ..Default::default()
    };
    let start = std::time::Instant::now();
    let a = common::render(&gpu, &scene, settings(1), n, Show::Full);
    let b = common::render(&gpu, &scene, settings(2), n, Show::Full);
    let rendered = start.elapsed();
    let pa = common::path_trace(&gpu, &scene, settings(3), 2 * n);
    let pb = common::path_trace(&gpu, &scene, settings(4), 2 * n);
    println!("renders {rendered:?}, path tracer {:?}", start.elapsed() - rendered);
    let reference = common::average(&pa, &pb);
    let mask = emitter_mask(&reference, 3.0);
    let ref_noise = rmse(&pa, &pb, Some(&mask)) / 2.0;
    let (c, noise, bias) = common::against_reference(&a, &b, &reference, ref_noise, Some(&mask));
    common::print_agreement("textured room", &c, noise, bias);
    // Both read the same texels: the same filtered texture at the visible points (the
    // G-buffer's λ, the path tracer's ray differentials) and the unfiltered texture at every
    // later point. What is not noise is the photon map's error read at the gather's secondary
    // points, bounded as for the Cornell box (gather.rs) by the map's error read at the visible
    // points themselves: a few percent at 32 cells.
    common::assert_agreement(&c, bias, 0.03, 0.02, 0.015);
}
