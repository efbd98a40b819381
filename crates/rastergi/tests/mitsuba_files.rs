//! `load_mitsuba` on files the tests write or break, and on the shared public scenes: a
//! `.serialized` mesh written here with flate2, independently of the reader; malformed,
//! truncated and mutated XML, each of which must give one error line naming the file, never a
//! panic; the Wooden Staircase and Sponza (`../shared/scenes`) where they exist, and Mitsuba's
//! `sunsky` against Mitsuba 3's own values. The scenes written by hand are `mitsuba_xml.rs`'s.

use std::f32::consts::PI;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::mpsc;
use std::time::{Duration, Instant};

use glam::{Vec2, Vec3};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use rastergi::scene::{MitsubaOptions, MitsubaScene, Scene, load_mitsuba};

mod common;

use common::mitsuba::*;

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
    let e = load_err_of(
        "bad.xml",
        b"<scene version=\"0.6.0\">\n  <shape type=\"cube\">\n    <float name=\"x\" value=\"1\">\n  </shape>\n</scene>\n",
        &["bad.xml: line 4, column", "not well-formed XML"],
    );
    assert_eq!(e.lines().count(), 1);
    // Not a scene, not UTF-8, not there.
    let dir = scratch(&[("a.xml", b"<gltf/>"), ("b.xml", b"<scene version=\"0.6\">\xff</scene>")]);
    assert!(load_err(&dir.path().join("a.xml")).contains("a Mitsuba scene file has <scene>"));
    assert!(load_err(&dir.path().join("b.xml")).contains("UTF-8"));
    assert!(load_err(&dir.path().join("none.xml")).contains("none.xml: no such file"));
    // An unknown reference and a duplicate id are errors where they are.
    load_err_of(
        "r.xml",
        b"<scene version=\"3.0.0\">\n<bsdf type=\"diffuse\" id=\"a\"/>\n<shape type=\"cube\">\n<ref id=\"b\"/></shape></scene>",
        &["r.xml: line 4, column 1", "no object has the id 'b'"],
    );
}

#[test]
fn a_missing_mesh_or_texture_is_named() {
    for (name, xml, needles) in [
        (
            "m.xml",
            b"<scene version=\"0.6.0\">\n\t<shape type=\"obj\">\n\t\t<string name=\"filename\" value=\"models/gone.obj\"/>\n\t</shape>\n</scene>" as &[u8],
            ["m.xml: line 2, column 2", "models/gone.obj: no such file"],
        ),
        (
            "t.xml",
            b"<scene version=\"0.6.0\">\n<shape type=\"cube\"><bsdf type=\"diffuse\">\n<texture type=\"bitmap\" name=\"reflectance\"><string name=\"filename\" value=\"wood.jpg\"/></texture>\n</bsdf></shape></scene>" as &[u8],
            ["t.xml: line 3, column 1", "wood.jpg: no such file"],
        ),
    ] {
        load_err_of(name, xml, &needles);
    }
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

/// The shared scene `scene` (a path in `../shared/scenes`) loaded, if this machine has it,
/// with how many of its triangles emit; prints, after `label`, its triangle count, of them
/// the emitting ones (`light`: what they are) and the time the load took.
fn load_shared(scene: &str, label: &str, light: &str) -> Option<(MitsubaScene, usize)> {
    let path = shared(scene)?;
    let start = Instant::now();
    let m = load(&path);
    let emitting = m.scene.emissive_triangles().len();
    println!(
        "{label}: {} triangles ({emitting} of them {light}) in {:.2} s",
        m.scene.triangles.len(),
        start.elapsed().as_secs_f64()
    );
    Some((m, emitting))
}

/// The camera a Mitsuba lookat names: eye, unit view direction, and up made orthogonal.
fn lookat(origin: Vec3, target: Vec3, up: Vec3) -> (Vec3, Vec3, Vec3) {
    let dir = (target - origin).normalize();
    let left = up.cross(dir).normalize();
    (origin, dir, dir.cross(left))
}

#[test]
fn the_shared_staircase_and_sponza_load_as_their_files_say() {
    if let Some((m, light)) = load_shared("staircase/scene.xml", "staircase", "the light") {
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
    if let Some((m, tessellated_light)) = load_shared("sponza/scene.xml", "sponza", "the tessellated spherical light") {
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
