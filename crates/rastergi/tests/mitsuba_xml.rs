//! `load_mitsuba` against hand-written Mitsuba scene files in `tests/data/mitsuba/` and files
//! the tests write themselves (a `.serialized` mesh written here with flate2, independently of
//! the reader; malformed, truncated and mutated XML). Expected values are computed here from
//! the formulas the loader documents (the lookat frame, the field of view per axis, Fresnel
//! reflectances, the plastic's albedo mapping), never taken from the loader's output.
//! Every bad input must give one error line naming the file, never a panic. The shared public
//! scenes (`../shared/scenes`: the Wooden Staircase, Sponza) are loaded where they exist.

use std::f32::consts::PI;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once, mpsc};
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use rastergi::scene::{AlphaMode, Material, MitsubaOptions, MitsubaScene, Scene, load_mitsuba, triangle_normal};

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/mitsuba").join(name)
}

fn load(path: &Path) -> MitsubaScene {
    load_mitsuba(path, &MitsubaOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn load_err(path: &Path) -> String {
    match load_mitsuba(path, &MitsubaOptions::default()) {
        Ok(_) => panic!("{} loaded, but an error was expected", path.display()),
        Err(e) => e.to_string(),
    }
}

fn material<'a>(scene: &'a Scene, name: &str) -> &'a Material {
    scene.materials.iter().find(|m| m.name == name).unwrap_or_else(|| {
        panic!("no material '{name}' among {:?}", scene.materials.iter().map(|m| &m.name).collect::<Vec<_>>())
    })
}

fn triangles_of(scene: &Scene, name: &str) -> Vec<usize> {
    (0..scene.triangles.len()).filter(|&i| scene.material_of(i).name == name).collect()
}

fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
    (a - b).abs().max_element() <= eps
}

/// Warnings logged while the tests run (a logger of this test binary).
static WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

struct Capture;

static CAPTURE: Capture = Capture;

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if r.level() <= log::Level::Warn {
            WARNINGS.lock().unwrap().push(r.args().to_string());
        }
    }
    fn flush(&self) {}
}

/// The warnings that name `file`.
fn warnings_about(file: &Path) -> Vec<String> {
    static INIT: Once = Once::new();
    INIT.call_once(|| {
        let _ = log::set_logger(&CAPTURE);
        log::set_max_level(log::LevelFilter::Warn);
    });
    let name = file.display().to_string();
    WARNINGS.lock().unwrap().iter().filter(|w| w.contains(&name)).cloned().collect()
}

fn start_capture() {
    warnings_about(Path::new(""));
}

/// A scratch folder with `files` written into it.
fn scratch(files: &[(&str, &[u8])]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    dir
}

#[test]
fn defaults_and_parameters_are_substituted_and_overridden() {
    let scene = load(&data("basic.xml")).scene;
    assert_eq!(material(&scene, "paint").albedo, Vec3::splat(0.25));
    let defined = MitsubaOptions { defines: vec![("grey".into(), "0.5".into()), ("fov".into(), "90".into())] };
    let scene = load_mitsuba(&data("basic.xml"), &defined).unwrap().scene;
    assert_eq!(material(&scene, "paint").albedo, Vec3::splat(0.5));
    // fov 90° along x of a 2:1 film: tan(θ_y/2) = tan(45°)/2.
    assert!((scene.camera.fov_y_deg - 2.0 * 0.5f32.atan().to_degrees()).abs() < 1e-3);
}

#[test]
fn an_undefined_parameter_is_an_error_at_its_element() {
    let dir = scratch(&[(
        "scene.xml",
        b"<scene version=\"0.6.0\">\n  <shape type=\"sphere\">\n    <float name=\"radius\" value=\"$r\"/>\n  </shape>\n</scene>\n",
    )]);
    let e = load_err(&dir.path().join("scene.xml"));
    assert!(e.contains("scene.xml: line 3, column 5"), "{e}");
    assert!(e.contains("$r is not defined") && e.contains("-D r="), "{e}");
    assert_eq!(e.lines().count(), 1);
}

#[test]
fn references_share_one_material_and_find_nested_objects() {
    let scene = load(&data("basic.xml")).scene;
    // The two rectangles name "paint" (with and without name="bsdf"): one material.
    assert_eq!(scene.materials.iter().filter(|m| m.name == "paint").count(), 1);
    assert_eq!(triangles_of(&scene, "paint").len(), 4);
    // "inner" is nested in the twosided "outer" and found by its own id: one-sided.
    let inner = material(&scene, "inner");
    assert_eq!(inner.albedo, Vec3::new(0.1, 0.2, 0.3));
    assert!(!inner.two_sided);
    assert_eq!(triangles_of(&scene, "inner").len(), 12, "the cube");
    assert!(material(&scene, "outer").two_sided);
    assert_eq!(material(&scene, "outer").albedo, Vec3::new(0.1, 0.2, 0.3));
}

#[test]
fn transforms_compose_in_order() {
    let scene = load(&data("basic.xml")).scene;
    // The first rectangle: scale (2, 3, 1), then 90° about +y ((x, y, z) ↦ (z, y, −x)), then
    // translate (1, 2, 3).
    let place = |x: f32, y: f32| {
        let (sx, sy, sz) = (2.0 * x, 3.0 * y, 0.0);
        Vec3::new(sz, sy, -sx) + Vec3::new(1.0, 2.0, 3.0)
    };
    let expected: Vec<Vec3> =
        [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].iter().map(|&(x, y)| place(x, y)).collect();
    let first = &triangles_of(&scene, "paint")[..2];
    for &t in first {
        for p in scene.triangles[t] {
            assert!(expected.iter().any(|e| close(*e, p, 1e-5)), "{p} is not a corner of {expected:?}");
        }
        // Its front face: +z turned by the rotation, +x.
        assert!(close(triangle_normal(&scene.triangles[t]), Vec3::X, 1e-5));
    }
    // Both triangles together cover the 4 × 6 rectangle.
    let area: f32 = first.iter().map(|&t| rastergi::scene::triangle_area(&scene.triangles[t])).sum();
    assert!((area - 24.0).abs() < 1e-4);
}

#[test]
fn the_lookat_camera_and_the_field_of_view_per_axis() {
    let m = load(&data("basic.xml"));
    let c = m.scene.camera;
    assert_eq!(m.film, Some((400, 200)));
    assert_eq!(m.sample_count, Some(64));
    assert!(close(c.eye, Vec3::new(1.0, 2.0, 3.0), 1e-6));
    let (right, up, forward) = c.frame();
    assert!(close(forward, -Vec3::Z, 1e-6) && close(up, Vec3::Y, 1e-6) && close(right, Vec3::X, 1e-6));
    // fov 60° along x of a 400 × 200 film.
    let expected = 2.0 * (30f32.to_radians().tan() / 2.0).atan().to_degrees();
    assert!((c.fov_y_deg - expected).abs() < 1e-3, "{} vs {expected}", c.fov_y_deg);

    // Each axis against tan(θ_y/2) = tan(θ/2) · (1/a, 1, 1/√(1 + a²)), smaller and larger by
    // the aspect, on a landscape and a portrait film.
    for (w, h) in [(400u32, 200u32), (300, 600)] {
        let a = w as f32 / h as f32;
        for axis in ["x", "y", "diagonal", "smaller", "larger"] {
            let xml = format!(
                "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"50\"/>\
                 <string name=\"fov_axis\" value=\"{axis}\"/><film type=\"hdrfilm\"><integer name=\"width\" value=\"{w}\"/>\
                 <integer name=\"height\" value=\"{h}\"/></film></sensor><shape type=\"cube\"/></scene>"
            );
            let dir = scratch(&[("fov.xml", xml.as_bytes())]);
            let got = load(&dir.path().join("fov.xml")).scene.camera.fov_y_deg;
            let t = 25f32.to_radians().tan();
            let factor = match axis {
                "x" => 1.0 / a,
                "y" => 1.0,
                "diagonal" => 1.0 / (1.0 + a * a).sqrt(),
                "smaller" => 1.0 / a.min(1.0),
                _ => 1.0 / a.max(1.0),
            };
            let expected = 2.0 * (t * factor).atan().to_degrees();
            assert!((got - expected).abs() < 1e-3, "{axis} on {w}x{h}: {got} vs {expected}");
        }
    }
}

/// Linear sRGB of a flat emission spectrum of value 1 in Mitsuba 3's RGB variants, printed by
/// mitsuba 3.9.1 for `<spectrum name="radiance" value="1"/>` on an area emitter
/// (`SRGBReflectanceSpectrum[value = [1.20479, 0.948291, 0.908916]]`): `<spectrum>` values
/// on emitters are emission spectra there, `<rgb>` and `<float>` stay as given.
const EQUAL_ENERGY_SRGB: Vec3 = Vec3::new(1.20479, 0.948291, 0.908916);

#[test]
fn an_area_light_on_a_sphere_keeps_its_power() {
    let scene = load(&data("basic.xml")).scene;
    // Radiance 10 (a flat emission spectrum: EQUAL_ENERGY_SRGB × 10 in Mitsuba 3's RGB mode)
    // from a sphere of radius 0.5: Φ = π L · 4π r² = 10 π² × EQUAL_ENERGY_SRGB.
    let power = scene.emitted_power();
    let expected = EQUAL_ENERGY_SRGB * 10.0 * PI * PI;
    assert!((power - expected).abs().max_element() < 1e-3 * 10.0 * PI * PI, "{power}");
    // Mitsuba's default BSDF on an emitter is black; the triangles face out, around (0, 5, 0).
    let lit: Vec<usize> = (0..scene.triangles.len()).filter(|&i| scene.material_of(i).is_emitter()).collect();
    assert!(lit.len() > 1000);
    for &i in &lit {
        let t = scene.triangles[i];
        assert_eq!(scene.material_of(i).albedo, Vec3::ZERO);
        let centre = (t[0] + t[1] + t[2]) / 3.0;
        assert!(triangle_normal(&t).dot(centre - Vec3::new(0.0, 5.0, 0.0)) > 0.0);
        assert!(((centre - Vec3::new(0.0, 5.0, 0.0)).length() - 0.5).abs() < 0.01);
    }
}

/// Fresnel reflectance of a dielectric interface (exact, unpolarised).
fn fresnel(cos_i: f64, eta: f64) -> f64 {
    let sin2 = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2 >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2).sqrt();
    let s = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let p = (cos_t - eta * cos_i) / (cos_t + eta * cos_i);
    0.5 * (s * s + p * p)
}

/// ∫₀¹ 2μ F(μ, η) dμ by Simpson's rule on 20000 intervals: the cosine-weighted Fresnel
/// reflectance F_dr(η).
fn diffuse_fresnel(eta: f64) -> f64 {
    let n = 20000;
    let f = |mu: f64| 2.0 * mu * fresnel(mu, eta);
    let h = 1.0 / n as f64;
    let simpson: f64 = (0..=n)
        .map(|i| {
            let w = if i == 0 || i == n {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(i as f64 * h)
        })
        .sum::<f64>();
    simpson * h / 3.0
}

/// The loader's documented mapping for a smooth plastic, computed here:
/// ρ' = ρ_e (1 − F_dr(η))² / (η² (1 − F̄_s)), ρ_e = ρ/(1 − F_dr(1/η)·ρ) (nonlinear) or
/// ρ/(1 − F_dr(1/η)), F̄_s = f₀ + (1 − f₀)/21 the layer's mean Schlick reflectance.
fn plastic_albedo(rho: f32, eta: f32, nonlinear: bool) -> f32 {
    let f_int = diffuse_fresnel(1.0 / eta as f64) as f32;
    let t = 1.0 - diffuse_fresnel(eta as f64) as f32;
    let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
    let mean = f0 + (1.0 - f0) / 21.0;
    rho * t * t / (eta * eta * (1.0 - mean) * (1.0 - f_int * if nonlinear { rho } else { 1.0 }))
}

#[test]
#[allow(clippy::excessive_precision)] // Mitsuba's RGB η and k of gold, as published
fn each_bsdf_maps_onto_the_material_model() {
    start_capture();
    let path = data("materials.xml");
    let scene = load(&path).scene;
    let d = material(&scene, "diffuse");
    assert!(d.is_lambertian() && d.albedo == Vec3::new(0.2, 0.4, 0.6) && !d.two_sided);

    let p = material(&scene, "plastic");
    assert_eq!((p.specular, p.ior, p.roughness, p.metallic, p.transmission), (1.0, 1.5, 0.0, 0.0, 0.0));
    assert!(
        (p.albedo.x - plastic_albedo(0.5, 1.5, false)).abs() < 1e-3,
        "{} vs {}",
        p.albedo,
        plastic_albedo(0.5, 1.5, false)
    );
    // Linear plastic of η 1.5 keeps nearly its reflectance; a nonlinear one is much darker.
    assert!((p.albedo.x - 0.5).abs() < 0.01);
    // The rough one's terms are Mitsuba's rough interface's (checked against Mitsuba's albedo
    // in the loader's unit tests); nonlinear, it is much darker than its ρ 0.5.
    let rp = material(&scene, "roughplastic");
    assert!((rp.roughness - 0.2).abs() < 1e-6, "roughness √0.04");
    assert!(rp.albedo.x > 0.2 && rp.albedo.x < 0.35, "{}", rp.albedo);

    // Gold: F₀ = ((η − 1)² + k²)/((η + 1)² + k²) per channel of Mitsuba's RGB η and k.
    let g = material(&scene, "gold");
    let f0 = |n: f32, k: f32| ((n - 1.0).powi(2) + k * k) / ((n + 1.0).powi(2) + k * k);
    let gold =
        Vec3::new(f0(0.1431189557, 3.9831604247), f0(0.3749570432, 2.3857207478), f0(1.4424785571, 1.6032152899));
    assert!(close(g.albedo, gold, 1e-5) && g.metallic == 1.0 && g.roughness == 0.0, "{}", g.albedo);
    let r = material(&scene, "roughmetal");
    assert!(close(r.albedo, Vec3::new(f0(1.5, 3.0), f0(1.0, 2.0), f0(0.5, 1.0)), 1e-6));
    assert!((r.roughness - 0.3).abs() < 1e-6);
    let b = material(&scene, "beckmann");
    assert!((b.roughness - 0.5).abs() < 1e-6 && b.metallic == 1.0);

    let glass = material(&scene, "glass");
    assert_eq!((glass.transmission, glass.ior, glass.thin, glass.roughness), (1.0, 1.5, false, 0.0));
    let frosted = material(&scene, "frosted");
    assert!((frosted.ior - 1.333).abs() < 1e-6 && (frosted.roughness - 0.4).abs() < 1e-6 && !frosted.thin);
    let pane = material(&scene, "pane");
    assert!(pane.thin && pane.transmission == 1.0);

    let t = material(&scene, "twosided");
    assert!(t.two_sided && t.albedo == Vec3::splat(0.3));
    let m = material(&scene, "mask");
    assert_eq!((m.alpha_mode, m.opacity), (AlphaMode::Blend, 0.3));
    assert_eq!(material(&scene, "blend").albedo, Vec3::splat(0.9), "weight 0.8: the second BSDF");
    let bump = material(&scene, "bump");
    assert_eq!(bump.albedo, Vec3::splat(0.7));
    assert!(bump.normal_texture.is_none());

    // to_uv: scale (2, 4) then translate (0.5, 0.25): uv' = (2u + 0.5, 4v + 0.25).
    let tex = material(&scene, "textured");
    let texture = tex.albedo_texture.expect("a texture");
    assert_eq!(scene.textures[texture].width, 2);
    let uv = tex.albedo_transform.apply(Vec2::new(0.25, 0.5));
    assert!((uv - Vec2::new(1.0, 2.25)).length() < 1e-6, "{uv}");
    // The checkerboard: color0 where ⌊2u⌋ and ⌊2v⌋ agree (sRGB-encoded 0.8), color1 elsewhere.
    let cb = &scene.textures[material(&scene, "checkerboard").albedo_texture.unwrap()];
    let at = |u: f32, v: f32| {
        cb.texels[(v * cb.height as f32) as usize * cb.width as usize + (u * cb.width as f32) as usize]
    };
    let srgb = |x: f32| (1.055 * x.powf(1.0 / 2.4) - 0.055) * 255.0;
    assert!((at(0.1, 0.1)[0] as f32 - srgb(0.8)).abs() <= 1.0 && (at(0.9, 0.9)[0] as f32 - srgb(0.8)).abs() <= 1.0);
    assert!((at(0.9, 0.1)[0] as f32 - srgb(0.1)).abs() <= 1.0 && (at(0.1, 0.9)[0] as f32 - srgb(0.1)).abs() <= 1.0);

    let pr = material(&scene, "principled");
    assert_eq!((pr.albedo, pr.metallic, pr.roughness), (Vec3::new(0.9, 0.5, 0.1), 0.7, 0.3));
    assert_eq!(material(&scene, "unknown").albedo, Vec3::splat(0.5));

    // The lights.
    assert!(scene.lights.contains(&rastergi::scene::Light::Point {
        position: Vec3::new(0.0, 3.0, 0.0),
        intensity: Vec3::new(5.0, 6.0, 7.0)
    }));
    assert!(scene.lights.contains(&rastergi::scene::Light::Distant {
        direction: -Vec3::Y,
        irradiance: EQUAL_ENERGY_SRGB * 3.0,
        angular_radius: 0.0
    }));
    // The default sunsky: its sky (the environment) and its sun (a third light; values against
    // Mitsuba 3's in `sunsky_reads_as_mitsuba_3s_and_0_6s`).
    assert!(scene.environment.is_some() && scene.lights.len() == 3, "{:?}", scene.lights);

    // What is not used is named, once each.
    let warnings = warnings_about(&path);
    for needle in
        ["fancy-unknown", "mystery-shape", "beckmann microfacet", "bump maps are not supported", "blendbsdf 'blend'"]
    {
        let n = warnings.iter().filter(|w| w.contains(needle)).count();
        assert!(n >= 1, "no warning about {needle}: {warnings:#?}");
    }
}

#[test]
fn emitters_and_spectra() {
    let xml = br#"<scene version="3.0.0">
        <emitter type="spot">
            <transform name="to_world"><lookat origin="0, 4, 0" target="0, 0, 0" up="0, 0, 1"/></transform>
            <rgb name="intensity" value="2, 3, 4"/>
            <float name="cutoff_angle" value="30"/>
            <float name="beam_width" value="10"/>
        </emitter>
        <emitter type="constant"><rgb name="radiance" value="0.25"/></emitter>
        <shape type="rectangle">
            <bsdf type="diffuse"><spectrum name="reflectance" value="360:0.5, 830:0.5"/></bsdf>
        </shape>
        <shape type="cube">
            <bsdf type="diffuse"><spectrum name="reflectance" value="400:0, 590:0, 600:0.8, 700:0.8, 710:0"/></bsdf>
            <emitter type="area"><rgb name="radiance" value="1, 2, 3"/></emitter>
        </shape>
    </scene>"#;
    let dir = scratch(&[("e.xml", xml)]);
    let scene = load(&dir.path().join("e.xml")).scene;
    let [rastergi::scene::Light::Spot { position, direction, intensity, inner, outer }] = scene.lights[..] else {
        panic!("one spot light: {:?}", scene.lights);
    };
    assert!(close(position, Vec3::new(0.0, 4.0, 0.0), 1e-6) && close(direction, -Vec3::Y, 1e-6));
    assert_eq!(intensity, Vec3::new(2.0, 3.0, 4.0));
    assert!((outer - 30f32.to_radians()).abs() < 1e-6 && (inner - 10f32.to_radians()).abs() < 1e-6);
    // The constant environment: 0.25 from every direction.
    let env = scene.environment.as_ref().expect("an environment");
    for d in [Vec3::Y, -Vec3::Y, Vec3::X, Vec3::new(0.6, 0.0, 0.8)] {
        assert!(close(env.eval(d), Vec3::splat(0.25), 1e-6));
    }
    // A flat spectrum over the whole visible range is grey; one of red light only is red.
    let grey = scene.materials.iter().find(|m| m.emission == Vec3::ZERO).unwrap().albedo;
    assert!(close(grey, Vec3::splat(0.5), 1e-3), "{grey}");
    let red = scene.materials.iter().find(|m| m.emission != Vec3::ZERO).unwrap();
    assert!(red.albedo.x > 0.3 && red.albedo.y < 0.2 * red.albedo.x && red.albedo.z < 0.05, "{}", red.albedo);
    assert_eq!(red.emission, Vec3::new(1.0, 2.0, 3.0));
}

#[test]
fn instances_of_a_shapegroup_and_a_normal_map() {
    let xml = br#"<scene version="3.0.0">
        <shape type="shapegroup" id="tile">
            <shape type="rectangle">
                <bsdf type="normalmap">
                    <texture type="bitmap" name="normalmap">
                        <string name="filename" value="checker.png"/>
                        <boolean name="raw" value="true"/>
                    </texture>
                    <bsdf type="diffuse"/>
                </bsdf>
            </shape>
        </shape>
        <shape type="instance">
            <ref id="tile"/>
            <transform name="to_world"><translate x="10"/></transform>
        </shape>
        <shape type="instance">
            <ref id="tile"/>
            <transform name="to_world"><scale value="2"/><translate z="-3"/></transform>
        </shape>
        <sensor type="thinlens"><float name="aperture_radius" value="0.1"/><float name="fov" value="40"/></sensor>
    </scene>"#;
    let checker = std::fs::read(data("checker.png")).unwrap();
    let dir = scratch(&[("checker.png", &checker), ("i.xml", xml)]);
    let scene = load(&dir.path().join("i.xml")).scene;
    // The group itself adds nothing; each instance places its rectangle.
    assert_eq!(scene.triangles.len(), 4);
    let corners: Vec<Vec3> = scene.triangles.iter().flatten().copied().collect();
    assert!(corners[..6].iter().all(|p| p.z == 0.0 && (p.x - 10.0).abs() == 1.0 && p.y.abs() == 1.0));
    assert!(corners[6..].iter().all(|p| p.z == -3.0 && p.x.abs() == 2.0 && p.y.abs() == 2.0));
    // The normal map: the raw bitmap as linear data, and tangents along +u (+x here).
    let m = scene.material_of(0);
    let t = m.normal_texture.expect("a normal map");
    assert!(scene.textures[t.texture].linear);
    assert!(scene.tangents.iter().flatten().all(|t| close(t.truncate(), Vec3::X, 1e-5)));
    // The thin lens is a pinhole of the same field of view (fov along x of 768 × 576).
    let expected = 2.0 * (20f32.to_radians().tan() * 576.0 / 768.0).atan().to_degrees();
    assert!((scene.camera.fov_y_deg - expected).abs() < 1e-3);
}

/// A Radiance .hdr image of `w` × `h` flat (not run-length encoded) RGBE pixels.
fn radiance_hdr(w: usize, h: usize, pixel: impl Fn(usize, usize) -> [u8; 4]) -> Vec<u8> {
    let mut out = format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes();
    for j in 0..h {
        for i in 0..w {
            out.extend(pixel(i, j));
        }
    }
    out
}

#[test]
fn an_envmap_is_scaled_and_turned_by_its_to_world() {
    let hdr = radiance_hdr(4, 5, |i, j| [(40 * i + 10) as u8, (60 * j + 5) as u8, (17 * (i + j) + 3) as u8, 129]);
    let xml = br#"<scene version="3.0.0">
        <emitter type="envmap">
            <string name="filename" value="sky.hdr"/>
            <float name="scale" value="2"/>
            <transform name="to_world"><rotate y="1" angle="90"/></transform>
        </emitter>
        <shape type="cube"/>
    </scene>"#;
    let dir = scratch(&[("sky.hdr", &hdr), ("env.xml", xml)]);
    let scene = load(&dir.path().join("env.xml")).scene;
    let env = scene.environment.expect("an environment");
    let original = rastergi::environment::Environment::load(&dir.path().join("sky.hdr"), 1.0).unwrap();
    assert_eq!((env.width, env.height), (4, 5));
    // The radiance from world direction d is the image's at R⁻¹d (R: 90° about +y), twice,
    // at the pixels' directions off the poles (where every column is the same direction).
    let inverse = glam::Mat3::from_rotation_y(-PI / 2.0);
    for j in 1..4 {
        for i in 0..4 {
            let uv = Vec2::new((i as f32 + 0.5) / 4.0, j as f32 / 4.0);
            let d = rastergi::environment::uv_to_direction(uv);
            let expected = 2.0 * original.eval(inverse * d);
            assert!(
                close(env.eval(d), expected, 1e-4 * expected.max_element().max(1.0)),
                "{d}: {} vs {expected}",
                env.eval(d)
            );
        }
    }
    // Not the unturned map: its columns moved a quarter turn.
    let d = rastergi::environment::uv_to_direction(Vec2::new(0.125, 0.5));
    assert!(!close(env.eval(d), 2.0 * original.eval(d), 1e-3));
}

#[test]
fn meshes_from_obj_and_ply_with_an_include() {
    let path = data("meshes.xml");
    let scene = load(&path).scene;
    // The included file's sRGB #ff0000 is linear (1, 0, 0).
    let red = triangles_of(&scene, "included-red");
    assert_eq!(red.len(), 2);
    assert_eq!(material(&scene, "included-red").albedo, Vec3::X);
    // quad.obj's normals are read; its v is flipped (OBJ's v up the image, the scene's down).
    let (normals, uvs) = (&scene.normals, &scene.uvs);
    let slanted = Vec3::new(0.0, 0.6, 0.8);
    assert!(red.iter().all(|&t| normals[t].iter().all(|n| close(*n, slanted, 1e-6))));
    for &t in &red {
        for k in 0..3 {
            let p = scene.triangles[t][k];
            assert!((uvs[t][k] - Vec2::new(p.x, 1.0 - p.y)).length() < 1e-6);
        }
    }
    // The second OBJ: faceNormals → flat, moved to z = 5; the default material is grey 0.5.
    let moved: Vec<usize> = (0..scene.triangles.len()).filter(|&t| scene.triangles[t][0].z == 5.0).collect();
    assert_eq!(moved.len(), 2);
    assert!(moved.iter().all(|&t| normals[t] == [Vec3::ZERO; 3]));
    assert_eq!(scene.material_of(moved[0]).albedo, Vec3::splat(0.5));
    // The PLY quad flipped: facing −z, at x ≥ 10, uv as written (not flipped).
    let ply: Vec<usize> = (0..scene.triangles.len()).filter(|&t| scene.triangles[t][0].x >= 10.0).collect();
    assert_eq!(ply.len(), 2);
    for &t in &ply {
        assert!(close(triangle_normal(&scene.triangles[t]), -Vec3::Z, 1e-6));
        assert!(normals[t].iter().all(|n| close(*n, -Vec3::Z, 1e-6)));
        for k in 0..3 {
            let p = scene.triangles[t][k];
            assert!((uvs[t][k] - Vec2::new(p.x - 10.0, p.y)).length() < 1e-6);
        }
    }
}

/// One mesh of a `.serialized` file, written from the format's description: header, version,
/// then a zlib stream of flags, name (version 4), counts, positions, normals, uvs and indices.
fn serialized_mesh(
    version: u16,
    positions: &[[f32; 3]],
    normals: Option<&[[f32; 3]]>,
    uvs: Option<&[[f32; 2]]>,
    faces: &[[u32; 3]],
    double: bool,
) -> Vec<u8> {
    let mut body = Vec::new();
    let flags = normals.is_some() as u32 | (uvs.is_some() as u32) << 1 | if double { 0x2000 } else { 0x1000 };
    body.extend(flags.to_le_bytes());
    if version == 4 {
        body.extend(b"a mesh\0");
    }
    body.extend((positions.len() as u64).to_le_bytes());
    body.extend((faces.len() as u64).to_le_bytes());
    let mut floats = |values: &[f32]| {
        for &v in values {
            if double {
                body.extend((v as f64).to_le_bytes());
            } else {
                body.extend(v.to_le_bytes());
            }
        }
    };
    floats(positions.as_flattened());
    if let Some(n) = normals {
        floats(n.as_flattened());
    }
    if let Some(uv) = uvs {
        floats(uv.as_flattened());
    }
    for f in faces {
        for i in f {
            body.extend(i.to_le_bytes());
        }
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&body).unwrap();
    let mut out = Vec::new();
    out.extend(0x041Cu16.to_le_bytes());
    out.extend(version.to_le_bytes());
    out.extend(z.finish().unwrap());
    out
}

/// Meshes one after another, then the offsets (u64 in version 4, u32 in 3) and their count.
fn serialized_file(version: u16, meshes: &[Vec<u8>]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for m in meshes {
        offsets.push(out.len() as u64);
        out.extend(m);
    }
    for o in offsets {
        if version == 4 {
            out.extend(o.to_le_bytes());
        } else {
            out.extend((o as u32).to_le_bytes());
        }
    }
    out.extend((meshes.len() as u32).to_le_bytes());
    out
}

#[test]
fn a_serialized_file_written_here_loads_by_shape_index() {
    let triangle = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let quad = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 2.0, 0.0], [0.0, 2.0, 0.0]];
    let quad_normals = [[0.0, 0.0, 1.0]; 4];
    let quad_uvs = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    for (version, double) in [(4u16, false), (4, true), (3, false)] {
        let file = serialized_file(
            version,
            &[
                serialized_mesh(version, &triangle, None, None, &[[0, 1, 2]], double),
                serialized_mesh(version, &quad, Some(&quad_normals), Some(&quad_uvs), &[[0, 1, 2], [0, 2, 3]], double),
            ],
        );
        let xml = b"<scene version=\"0.6.0\">\n\
            <shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/><integer name=\"shapeIndex\" value=\"1\"/>\
            <transform name=\"toWorld\"><translate x=\"0\" y=\"0\" z=\"7\"/></transform></shape>\n\
            <shape type=\"serialized\"><string name=\"filename\" value=\"m.serialized\"/></shape>\n</scene>\n";
        let dir = scratch(&[("m.serialized", &file), ("scene.xml", xml)]);
        let scene = load(&dir.path().join("scene.xml")).scene;
        assert_eq!(scene.triangles.len(), 3, "version {version}");
        // Mesh 1 (the quad) moved to z = 7, with its normals and uvs.
        assert_eq!(scene.triangles[0], [Vec3::new(0.0, 0.0, 7.0), Vec3::new(2.0, 0.0, 7.0), Vec3::new(2.0, 2.0, 7.0)]);
        assert_eq!(scene.triangles[1][2], Vec3::new(0.0, 2.0, 7.0));
        assert_eq!(scene.uvs[1], [Vec2::ZERO, Vec2::ONE, Vec2::new(0.0, 1.0)]);
        assert_eq!(scene.normals[0], [Vec3::Z; 3]);
        // Mesh 0 without normals: Mitsuba's computed vertex normals, the plane's.
        assert_eq!(scene.triangles[2], triangle.map(Vec3::from));
        assert!(scene.normals[2].iter().all(|n| close(*n, Vec3::Z, 1e-6)));

        // Truncated anywhere, or an index out of range: an error naming the XML and the mesh.
        for cut in [3, 10, file.len() / 2, file.len() - 3] {
            let dir = scratch(&[("m.serialized", &file[..cut]), ("scene.xml", xml)]);
            let e = load_err(&dir.path().join("scene.xml"));
            assert!(e.contains("scene.xml: line 2") && e.contains("m.serialized"), "{e}");
        }
        let wrong = String::from_utf8_lossy(xml).replace("value=\"1\"", "value=\"5\"");
        let dir = scratch(&[("m.serialized", &file), ("scene.xml", wrong.as_bytes())]);
        assert!(load_err(&dir.path().join("scene.xml")).contains("out of range"));
    }
}

#[test]
fn malformed_xml_is_named_by_file_line_and_column() {
    let dir = scratch(&[("bad.xml", b"<scene version=\"0.6.0\">\n  <shape type=\"cube\">\n    <float name=\"x\" value=\"1\">\n  </shape>\n</scene>\n")]);
    let e = load_err(&dir.path().join("bad.xml"));
    assert!(e.contains("bad.xml: line 4, column"), "{e}");
    assert!(e.contains("not well-formed XML"), "{e}");
    assert_eq!(e.lines().count(), 1);
    // Not a scene, not UTF-8, not there.
    let dir = scratch(&[("a.xml", b"<gltf/>"), ("b.xml", b"<scene version=\"0.6\">\xff</scene>")]);
    assert!(load_err(&dir.path().join("a.xml")).contains("a Mitsuba scene file has <scene>"));
    assert!(load_err(&dir.path().join("b.xml")).contains("UTF-8"));
    assert!(load_err(&dir.path().join("none.xml")).contains("none.xml: no such file"));
    // An unknown reference and a duplicate id are errors where they are.
    let dir = scratch(&[(
        "r.xml",
        b"<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\" id=\"a\"/>\n<shape type=\"cube\">\n<ref id=\"b\"/></shape></scene>",
    )]);
    let e = load_err(&dir.path().join("r.xml"));
    assert!(e.contains("r.xml: line 4, column 1") && e.contains("no object has the id 'b'"), "{e}");
}

#[test]
fn a_missing_mesh_or_texture_is_named() {
    let dir = scratch(&[(
        "m.xml",
        b"<scene version=\"0.6.0\">\n\t<shape type=\"obj\">\n\t\t<string name=\"filename\" value=\"models/gone.obj\"/>\n\t</shape>\n</scene>",
    )]);
    let e = load_err(&dir.path().join("m.xml"));
    assert!(e.contains("m.xml: line 2, column 2") && e.contains("models/gone.obj: no such file"), "{e}");
    let dir = scratch(&[(
        "t.xml",
        b"<scene version=\"0.6.0\">\n<shape type=\"cube\"><bsdf type=\"diffuse\">\n<texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"wood.jpg\"/></texture>\n</bsdf></shape></scene>",
    )]);
    let e = load_err(&dir.path().join("t.xml"));
    assert!(e.contains("t.xml: line 3, column 1") && e.contains("wood.jpg: no such file"), "{e}");
}

#[test]
fn unknown_plugins_are_warned_about_once_and_the_scene_loads() {
    start_capture();
    let xml = b"<scene version=\"0.6.0\">\n\
        <integrator type=\"sppm\"><integer name=\"photonCount\" value=\"5\"/></integrator>\n\
        <medium type=\"homogeneous\" id=\"fog\"/>\n\
        <shape type=\"cube\"><bsdf type=\"hk\"/></shape>\n\
        <shape type=\"cube\"><bsdf type=\"hk\"/><float name=\"wobble\" value=\"2\"/></shape>\n\
        <shape type=\"cube\"><float name=\"wobble\" value=\"3\"/></shape>\n\
        <emitter type=\"sky\"/>\n</scene>";
    let dir = scratch(&[("unknown.xml", xml)]);
    let path = dir.path().join("unknown.xml");
    let scene = load(&path).scene;
    assert_eq!(scene.triangles.len(), 36);
    let warnings = warnings_about(&path);
    let count = |needle: &str| warnings.iter().filter(|w| w.contains(needle)).count();
    assert_eq!(count("integrator 'sppm' is not used"), 1, "{warnings:#?}");
    assert_eq!(count("<medium>"), 1, "{warnings:#?}");
    assert_eq!(count("BSDF type 'hk'"), 1, "{warnings:#?}");
    assert_eq!(count("wobble is not used"), 1, "{warnings:#?}");
    // 0.6's `sky` is read (the physical sky's tests): the sky alone, no warning.
    assert!(scene.environment.is_some() && scene.lights.is_empty());
    assert_eq!(count("sky emitter") + count("emitter 'sky'"), 0, "{warnings:#?}");
}

#[test]
fn a_truncated_file_never_panics() {
    let text = std::fs::read(data("materials.xml")).unwrap();
    let checker = std::fs::read(data("checker.png")).unwrap();
    let dir = scratch(&[("checker.png", &checker)]);
    let path = dir.path().join("cut.xml");
    let mut refused = 0;
    for cut in (0..text.len()).step_by(37) {
        std::fs::write(&path, &text[..cut]).unwrap();
        if let Err(e) = load_mitsuba(&path, &MitsubaOptions::default()) {
            let e = e.to_string();
            assert!(e.contains("cut.xml") && e.lines().count() == 1, "{e}");
            refused += 1;
        }
    }
    assert!(refused > 0);
}

/// Attribute values that a loader must refuse or survive.
const HOSTILE: &[&str] = &[
    "",
    "-1",
    "0",
    "nan",
    "inf",
    "1e39",
    "-1e39",
    "1e-45",
    "$x",
    "$",
    "a, b",
    "1 2 3 4",
    "1, 2",
    "#zz0000",
    "#ff00ff",
    "360:1",
    "500:1, 400:2",
    "x:y",
    "4294967296",
    "-4294967297",
    "true",
    "gone.obj",
    "../../etc/passwd",
    "/dev/zero",
    "checker.png",
    "quad.ply",
    "0.0000001",
    "1e30, 1e30, 1e30",
    "0, 0, 0",
    "included.xml",
];

/// Loads `path` on another thread: the outcome, or a failure if it panicked or hung.
fn load_guarded(path: &Path) -> Result<Result<MitsubaScene, String>, String> {
    let (tx, rx) = mpsc::channel();
    let owned = path.to_path_buf();
    std::thread::spawn(move || {
        let r =
            std::panic::catch_unwind(|| load_mitsuba(&owned, &MitsubaOptions::default()).map_err(|e| e.to_string()));
        let _ = tx.send(r);
    });
    match rx.recv_timeout(Duration::from_secs(20)) {
        Ok(Ok(r)) => Ok(r),
        Ok(Err(_)) => Err("the loader panicked".into()),
        Err(_) => Err("the loader did not return within 20 s".into()),
    }
}

#[test]
fn mutated_files_load_or_are_refused_by_name() {
    let sources = ["basic.xml", "materials.xml", "meshes.xml"].map(|n| std::fs::read(data(n)).unwrap());
    let beside: Vec<(&str, Vec<u8>)> = ["checker.png", "quad.obj", "quad.ply", "included.xml"]
        .iter()
        .map(|n| (*n, std::fs::read(data(n)).unwrap()))
        .collect();
    let dir = scratch(&beside.iter().map(|(n, b)| (*n, b.as_slice())).collect::<Vec<_>>());
    let path = dir.path().join("fuzz.xml");
    let cases = std::env::var("RASTERGI_FUZZ_CASES").ok().and_then(|c| c.parse().ok()).unwrap_or(300);
    let mut runner = TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
    let alphabet = b"<>/=\"$ .-0123456789eEx#:,\n\tabcdefghijklmnopqrstuvwxyz";
    let edit = (0usize..5, 0usize..4, any::<prop::sample::Index>(), 0usize..64, any::<prop::sample::Index>());
    let strategy = (0usize..3, prop::collection::vec(edit, 1..4));
    let accepted = std::cell::Cell::new(0u32);
    runner
        .run(&strategy, |(source, edits)| {
            let mut text = sources[source].clone();
            for (kind, _, at, len, pick) in edits {
                let i = at.index(text.len() + 1);
                match kind {
                    0 => {
                        let end = (i + len).min(text.len());
                        text.drain(i..end);
                    }
                    1 => text.insert(i.min(text.len()), alphabet[pick.index(alphabet.len())]),
                    // A hostile value in place of one of the file's attribute values.
                    3 | 4 => {
                        let starts: Vec<usize> =
                            text.windows(7).enumerate().filter(|(_, w)| w == b"value=\"").map(|(k, _)| k + 7).collect();
                        if let Some(&start) = starts.get(at.index(starts.len().max(1))) {
                            let end = text[start..].iter().position(|&b| b == b'"').map_or(text.len(), |e| start + e);
                            let value = HOSTILE[pick.index(HOSTILE.len())].as_bytes();
                            text.splice(start..end, value.iter().copied());
                        }
                    }
                    _ => {
                        let end = (i + len).min(text.len());
                        let copy = text[i.min(end)..end].to_vec();
                        let at = pick.index(text.len() + 1);
                        text.splice(at..at, copy);
                    }
                }
            }
            std::fs::write(&path, &text).unwrap();
            match load_guarded(&path).map_err(TestCaseError::fail)? {
                Ok(m) => {
                    m.scene.validate().map_err(|e| TestCaseError::fail(e.to_string()))?;
                    accepted.set(accepted.get() + 1);
                }
                Err(e) => {
                    prop_assert!(e.contains("fuzz.xml") || e.contains(&*dir.path().to_string_lossy()), "{}", e);
                    prop_assert_eq!(e.lines().count(), 1, "{}", e);
                }
            }
            Ok(())
        })
        .unwrap();
    println!("{} of {cases} mutated files loaded", accepted.get());
    assert!(accepted.get() > 0);
}

/// `../shared/scenes` beside the repository, if this machine has it.
fn shared(scene: &str) -> Option<PathBuf> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes").join(scene);
    if path.exists() {
        Some(path)
    } else {
        println!("skipped: {} is not here (the shared public scenes are not on this machine)", path.display());
        None
    }
}

/// The camera a Mitsuba lookat names: eye, unit view direction, and up made orthogonal.
fn lookat(origin: Vec3, target: Vec3, up: Vec3) -> (Vec3, Vec3, Vec3) {
    let dir = (target - origin).normalize();
    let left = up.cross(dir).normalize();
    (origin, dir, dir.cross(left))
}

#[test]
fn the_shared_staircase_and_sponza_load_as_their_files_say() {
    if let Some(path) = shared("staircase/scene.xml") {
        let start = Instant::now();
        let m = load(&path);
        let light = m.scene.emissive_triangles().len();
        println!(
            "staircase: {} triangles ({light} of them the light) in {:.2} s",
            m.scene.triangles.len(),
            start.elapsed().as_secs_f64()
        );
        // 262,661 in the 774 OBJ meshes, and the rectangle of the light.
        assert_eq!(m.scene.triangles.len() - light, 262_661);
        assert_eq!(m.film, Some((720, 1280)));
        assert_eq!(m.sample_count, Some(100));
        // to_world's columns: x (left), y (up), z (forward), translation.
        let c = m.scene.camera;
        assert!(close(c.eye, Vec3::new(0.0324209, 1.52673, 4.88197), 1e-5));
        let (_, up, forward) = c.frame();
        assert!(close(forward, Vec3::new(-0.00764602, 0.045055, -0.998955).normalize(), 1e-5));
        assert!(close(up, Vec3::new(0.000344842, 0.998984, 0.0450537).normalize(), 1e-4));
        // 35° across a 720 × 1280 film.
        let expected = 2.0 * (17.5f32.to_radians().tan() * 1280.0 / 720.0).atan().to_degrees();
        assert!((c.fov_y_deg - expected).abs() < 1e-3);
        // The rectangular light of radiance 30: one emitter, two triangles.
        let emitters = m.scene.emissive_triangles();
        assert_eq!(emitters.len(), 2);
        assert_eq!(m.scene.material_of(emitters[0] as usize).emission, Vec3::splat(30.0));
    }
    if let Some(path) = shared("sponza/scene.xml") {
        let start = Instant::now();
        let m = load(&path);
        let tessellated_light = m.scene.emissive_triangles().len();
        println!(
            "sponza: {} triangles ({} of them the tessellated spherical light) in {:.2} s",
            m.scene.triangles.len(),
            tessellated_light,
            start.elapsed().as_secs_f64()
        );
        assert_eq!(m.scene.triangles.len() - tessellated_light, 66_445);
        assert_eq!(m.film, Some((1280, 720)));
        let (eye, dir, up) = lookat(
            Vec3::new(2.25067, 8.24132, -0.0492483),
            Vec3::new(3.15037, 7.8048, -0.0501832),
            Vec3::new(0.436514, 0.899693, -0.00291584),
        );
        let c = m.scene.camera;
        let (_, cam_up, forward) = c.frame();
        assert!(close(c.eye, eye, 1e-5) && close(forward, dir, 1e-5) && close(cam_up, up, 1e-4));
        let expected = 2.0 * ((0.5 * 96.6708f32).to_radians().tan() * 720.0 / 1280.0).atan().to_degrees();
        assert!((c.fov_y_deg - expected).abs() < 1e-3);
        // The light: radiance 16000 (a flat spectrum: red EQUAL_ENERGY_SRGB.x × 16000) from a
        // sphere of radius 0.1: Φ = π L 4π r².
        let power = m.scene.emitted_power();
        let expected = PI * 16000.0 * EQUAL_ENERGY_SRGB.x * 4.0 * PI * 0.01;
        assert!((power.x - expected).abs() < 1e-3 * expected, "{power} vs {expected}");
    }
}

/// The environment's radiance at `d` against Mitsuba 3's `emitter.eval` there: within 1 %
/// (the map is bilinear between pixels 0.35° apart; the model varies slowly away from the sun).
fn sky_is(env: &rastergi::environment::Environment, d: Vec3, mitsuba: Vec3) {
    let got = env.eval(d.normalize());
    assert!(((got - mitsuba) / mitsuba).abs().max_element() < 0.01, "{d}: {got} vs Mitsuba 3's {mitsuba}");
}

/// The one light, a distant one: its direction (where light travels) and irradiance.
fn the_sun(scene: &Scene) -> (Vec3, Vec3, f32) {
    let [rastergi::scene::Light::Distant { direction, irradiance, angular_radius }] = scene.lights[..] else {
        panic!("one distant light: {:?}", scene.lights);
    };
    (direction, irradiance, angular_radius)
}

#[test]
fn sunsky_reads_as_mitsuba_3s_and_0_6s() {
    // Values Mitsuba 3.9.1 prints (llvm_ad_rgb, `emitter.eval`; the sun's radiance times its
    // disc's solid angle): a default `sunsky` (Tokyo, 2010-07-10 15:00, turbidity 3, albedo
    // 0.3, Z up), and the same as 0.6 reads it (Y up, albedo 0.15, scale 2) with a given sun.
    let v3 = br#"<scene version="3.0.0"><emitter type="sunsky"/><shape type="cube"/></scene>"#;
    let v06 = br#"<scene version="0.6.0">
        <emitter type="sunsky">
            <vector name="sunDirection" x="0.3" y="0.8" z="-0.5"/>
            <float name="scale" value="2"/>
            <float name="sunRadiusScale" value="0"/>
            <integer name="resolution" value="256"/>
        </emitter>
        <shape type="cube"/>
    </scene>"#;
    let sun_only = br#"<scene version="0.6.0"><emitter type="sun"><vector name="sunDirection" x="0.3" y="0.8" z="-0.5"/><float name="scale" value="2"/></emitter><shape type="cube"/></scene>"#;
    let sky_only = br#"<scene version="0.6.0"><emitter type="sky"><vector name="sunDirection" x="0.3" y="0.8" z="-0.5"/><float name="scale" value="2"/></emitter><shape type="cube"/></scene>"#;
    let both = br#"<scene version="3.0.0"><emitter type="sunsky"><vector name="sun_direction" x="0" y="0" z="1"/><float name="hour" value="9"/></emitter></scene>"#;
    let murky =
        br#"<scene version="3.0.0"><emitter type="sunsky"><float name="turbidity" value="12"/></emitter></scene>"#;
    let dir = scratch(&[
        ("v3.xml", v3),
        ("v06.xml", v06),
        ("sun.xml", sun_only),
        ("sky.xml", sky_only),
        ("both.xml", both),
        ("murky.xml", murky),
    ]);
    start_capture();

    let scene = load(&dir.path().join("v3.xml")).scene;
    let env = scene.environment.as_ref().expect("the sky");
    sky_is(env, Vec3::Z, Vec3::new(0.02435108, 0.04230876, 0.08559478));
    sky_is(env, Vec3::new(1.0, 0.0, 0.2), Vec3::new(0.08044496, 0.13044094, 0.20640446));
    sky_is(env, Vec3::new(0.0, -1.0, 0.5), Vec3::new(0.04145552, 0.0761675, 0.14089988));
    assert_eq!(env.eval(Vec3::new(0.3, 0.2, -0.9).normalize()), Vec3::ZERO, "black below the horizon");
    let (direction, irradiance, radius) = the_sun(&scene);
    assert!(close(-direction, Vec3::new(0.05138512, 0.691748, 0.7203085), 1e-3), "{direction}");
    let mitsuba = Vec3::new(1.4710907, 1.2106092, 0.8957329);
    assert!(((irradiance - mitsuba) / mitsuba).abs().max_element() < 2e-3, "{irradiance} vs {mitsuba}");
    assert!((radius - (0.5 * 0.5358f32).to_radians()).abs() < 1e-7);

    let file = dir.path().join("v06.xml");
    let scene = load(&file).scene;
    let env = scene.environment.as_ref().expect("the sky");
    sky_is(env, Vec3::Y, Vec3::new(0.0553268, 0.08946305, 0.17662245));
    sky_is(env, Vec3::new(1.0, 0.2, 0.0), Vec3::new(0.16776873, 0.26477593, 0.42151704));
    sky_is(env, Vec3::new(0.0, 0.5, 1.0), Vec3::new(0.07120366, 0.13429418, 0.25932977));
    let (direction, irradiance, radius) = the_sun(&scene);
    assert!(close(-direction, Vec3::new(0.3, 0.8, -0.5).normalize(), 1e-6));
    let mitsuba = Vec3::new(2.9825687, 2.482181, 1.8844848);
    assert!(((irradiance - mitsuba) / mitsuba).abs().max_element() < 2e-3, "{irradiance} vs {mitsuba}");
    assert!(radius < 1e-6, "sunRadiusScale 0: a delta direction, not {radius}");
    assert!(warnings_about(&file).iter().any(|w| w.contains("resolution")), "{:?}", warnings_about(&file));

    // 0.6's sun alone and sky alone: the same parts.
    let sun = load(&dir.path().join("sun.xml")).scene;
    assert!(sun.environment.is_none());
    assert_eq!(the_sun(&sun).1, irradiance);
    let sky = load(&dir.path().join("sky.xml")).scene;
    assert!(sky.lights.is_empty());
    sky_is(sky.environment.as_ref().unwrap(), Vec3::Y, Vec3::new(0.0553268, 0.08946305, 0.17662245));

    // Mitsuba 3 refuses both a sun direction and a time, and a turbidity outside 1..10.
    let err = load_err(&dir.path().join("both.xml"));
    assert!(err.contains("not both") && err.contains("line 1"), "{err}");
    let err = load_err(&dir.path().join("murky.xml"));
    assert!(err.contains("turbidity 12"), "{err}");
}
