//! `load_mitsuba` against hand-written Mitsuba scene files in `tests/data/mitsuba/` and files
//! the tests write themselves (a `.serialized` mesh written here with flate2, independently of
//! the reader; malformed, truncated and mutated XML). Expected values are computed here from
//! the formulas the loader documents (the lookat frame, the field of view per axis, Fresnel
//! reflectances, the plastic's albedo mapping), never taken from the loader's output.
//! Every bad input must give one error line naming the file, never a panic. The shared public
//! scenes (`../shared/scenes`: the Wooden Staircase, Sponza) are loaded where they exist.

use std::f32::consts::PI;

use glam::{Vec2, Vec3};
use rastergi::scene::{AlphaMode, MitsubaOptions, load_mitsuba, triangle_normal};

mod common;

use common::mitsuba::*;

#[test]
fn defaults_and_parameters_are_substituted_and_overridden() {
    let scene = load(&data("basic.xml")).scene;
    assert_eq!(material(&scene, "paint").albedo, Vec3::splat(0.25));
    let defined = MitsubaOptions {
        defines: vec![("grey".into(), "0.5".into()), ("fov".into(), "90".into())],
        ..Default::default()
    };
    let scene = load_mitsuba(&data("basic.xml"), &defined).unwrap().scene;
    assert_eq!(material(&scene, "paint").albedo, Vec3::splat(0.5));
    // fov 90° along x of a 2:1 film: tan(θ_y/2) = tan(45°)/2.
    assert!((scene.camera.fov_y_deg - 2.0 * 0.5f32.atan().to_degrees()).abs() < 1e-3);
}

#[test]
fn an_undefined_parameter_is_an_error_at_its_element() {
    let e = load_err_of(
        "scene.xml",
        b"<scene version=\"0.6.0\">\n  <shape type=\"sphere\">\n    <float name=\"radius\" value=\"$r\"/>\n  </shape>\n</scene>\n",
        &["scene.xml: line 3, column 5", "$r is not defined", "-D r="],
    );
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

/// Reading is linear in the file's size (each element's position is counted on from the
/// previous one's; it was found by counting from the start, quadratic: 11.6 s for these
/// 100 000 elements): 100 000 elements load in under a second, every shape placed.
#[test]
fn a_hundred_thousand_elements_load_in_under_a_second() {
    let shapes = 100_000 / 3;
    let body: String = (0..shapes)
        .map(|i| {
            format!(
                "<shape type=\"rectangle\"><transform name=\"to_world\"><translate x=\"{i}\"/></transform></shape>\n"
            )
        })
        .collect();
    let mut files = rastergi::scene::MemoryFiles::new();
    files.insert("scene.xml", format!("<scene version=\"3.0.0\">\n{body}</scene>").into_bytes());
    let start = std::time::Instant::now();
    let options = MitsubaOptions::default();
    let scene =
        rastergi::scene::load_mitsuba_in(rastergi::scene::Files::Memory(&files), "scene.xml".as_ref(), &options)
            .unwrap()
            .scene;
    let took = start.elapsed();
    println!("{} elements: {:.3} s", 3 * shapes + 1, took.as_secs_f64());
    assert_eq!(scene.triangles.len(), 2 * shapes);
    assert_eq!(scene.bounds().max.x, shapes as f32);
    assert!(took < std::time::Duration::from_secs(1), "{took:?}");
}
