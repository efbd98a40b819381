//! `load_gltf` against the textured room written by the tests (`common/textured_room.rs`):
//! the triangles, texture coordinates, materials, camera and emission it must produce, the
//! same scene from the three ways of storing a glTF file and from OBJ + MTL with `map_Kd`, and
//! the malformed, truncated and hostile files it must refuse with a one-line error naming the
//! file — never a panic, never a hang (targeted cases, a mutation loop over valid files, and
//! the regression corpus in `tests/data/gltf/corpus/`).

mod common;

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use common::textured_room::{self as room, Variant};
use glam::{Vec2, Vec3};
use rastergi::metrics::{compare, emitter_mask, masked_mean, rmse};
use rastergi::passes::film::Show;
use rastergi::scene::{GltfOptions, Scene, load_gltf, load_gltf_with, load_obj, triangle_normal};
use rastergi::settings::RenderSettings;
use serde_json::{Value, json};

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol
}

/// The triangles (corners, texture coordinates) of the material with this name.
fn triangles_of(scene: &Scene, material: &str) -> Vec<([Vec3; 3], [Vec2; 3])> {
    (0..scene.triangles.len())
        .filter(|&i| scene.material_of(i).name == material)
        .map(|i| (scene.triangles[i], scene.uvs[i]))
        .collect()
}

fn load_room(variant: Variant) -> (tempfile::TempDir, PathBuf, Scene) {
    let dir = tempfile::tempdir().unwrap();
    let name = if variant == Variant::Binary { "room.glb" } else { "room.gltf" };
    let path = room::room_gltf(variant).write(dir.path(), name);
    let scene = load_gltf(&path).unwrap_or_else(|e| panic!("{e}"));
    (dir, path, scene)
}

#[test]
fn textured_room_has_the_expected_triangles_and_texture_coordinates() {
    let (_dir, _, scene) = load_room(Variant::External);
    // Room 5 quads, light 1, cube 6, panel twice: 14 quads.
    assert_eq!(scene.triangles.len(), 28);
    assert_eq!(scene.uvs.len(), 28);

    // The floor: y = −1 facing up, uv = 1.5·(x + 1, z + 1) (the checker repeats 3 times).
    let floor = triangles_of(&scene, "floor");
    assert_eq!(floor.len(), 2);
    for (t, uv) in &floor {
        assert_eq!(triangle_normal(t), Vec3::Y);
        for k in 0..3 {
            assert_eq!(t[k].y, -1.0);
            assert!((uv[k] - 1.5 * Vec2::new(t[k].x + 1.0, t[k].z + 1.0)).abs().max_element() < 1e-6);
        }
    }

    // The light: node "lamp" moves its quad from y = 0.98 down by 0.01; it faces down.
    for (t, _) in triangles_of(&scene, "light") {
        assert!(t.iter().all(|p| (p.y - 0.97).abs() < 1e-6), "light at {t:?}");
        assert!(close(triangle_normal(&t), -Vec3::Y, 1e-6));
    }

    // The cube, placed by two nodes: its corner (1, 1, 1) where the hand computation puts it,
    // its centre at (0.3, −0.55, 0.1) and every face facing away from the centre.
    let cube = triangles_of(&scene, "cube");
    assert_eq!(cube.len(), 12);
    let corner = room::cube_corner_world();
    assert!(cube.iter().any(|(t, _)| t.iter().any(|&p| close(p, corner, 1e-5))), "no cube corner at {corner}");
    let centre = Vec3::new(0.3, -0.7, 0.1);
    for (t, _) in &cube {
        for p in t {
            assert!(
                ((*p - centre).abs() - Vec3::splat(0.3 * 2f32.sqrt())).max_element() < 1e-5,
                "{p} is not on the cube"
            );
            assert!((p.y - centre.y).abs() <= 0.3 + 1e-5);
        }
        let mid = (t[0] + t[1] + t[2]) / 3.0;
        assert!(triangle_normal(t).dot(mid - centre) > 0.0, "a cube face {t:?} faces inwards");
    }

    // The panel and its mirror image: both face +z (the mirrored instance's winding is
    // flipped back), each texture coordinate stays with its corner.
    let panels = triangles_of(&scene, "panel");
    assert_eq!(panels.len(), 4);
    let (mut plain, mut mirrored) = (0, 0);
    for (t, uv) in &panels {
        assert!(close(triangle_normal(t), Vec3::Z, 1e-6), "a panel faces {}", triangle_normal(t));
        let origin_x = if t[0].x > 0.0 { 0.2 } else { -0.2 };
        if origin_x > 0.0 {
            plain += 1
        } else {
            mirrored += 1
        }
        for k in 0..3 {
            let local = Vec2::new((t[k].x - origin_x).abs(), t[k].y + 0.2);
            let expected = Vec2::new(local.x / 0.4, 1.0 - local.y / 0.4);
            assert!((uv[k] - expected).abs().max_element() < 1e-5, "corner {} has uv {} not {expected}", t[k], uv[k]);
        }
    }
    assert_eq!((plain, mirrored), (2, 2));
}

#[test]
fn textured_room_has_the_expected_materials_textures_emission_and_camera() {
    let (_dir, _, scene) = load_room(Variant::External);
    for room::MaterialDef { name, factor, texture, double_sided, emissive } in room::MATERIALS {
        let m = scene.materials.iter().find(|m| m.name == name).unwrap_or_else(|| panic!("no material {name}"));
        assert_eq!(m.albedo, Vec3::from(factor), "{name}: albedo");
        assert_eq!(m.two_sided, double_sided, "{name}: doubleSided");
        let expected_emission =
            if emissive { Vec3::from(room::EMISSIVE_FACTOR) * room::EMISSIVE_STRENGTH } else { Vec3::ZERO };
        assert_eq!(m.emission, expected_emission, "{name}: emissiveFactor × emissiveStrength");
        let image = ["checker", "stripes"];
        assert_eq!(m.albedo_texture.map(|t| scene.textures[t].name.as_str()), texture.map(|t| image[t]), "{name}");
    }
    // Two images, each decoded once though three materials use them.
    assert_eq!(scene.textures.len(), 2);
    let checker = scene.textures.iter().find(|t| t.name == "checker").unwrap();
    assert_eq!((checker.width, checker.height), room::CHECKER_SIZE);
    for (x, y) in [(0, 0), (4, 0), (5, 9), (15, 15)] {
        let [r, g, b] = room::checker_texel(x, y);
        assert_eq!(checker.texels[(y * 16 + x) as usize], [r, g, b, 255], "checker texel ({x}, {y})");
    }
    let stripes = scene.textures.iter().find(|t| t.name == "stripes").unwrap();
    assert_eq!((stripes.width, stripes.height), room::STRIPES_SIZE);

    // The first camera: the rig lifts it by 0.2, it looks 3° down.
    let c = scene.camera;
    let (s, co) = (3f32.to_radians().sin(), 3f32.to_radians().cos());
    assert!(close(c.eye, Vec3::new(0.0, 0.2, 3.4), 1e-6), "eye {}", c.eye);
    assert!(close((c.target - c.eye).normalize(), Vec3::new(0.0, -s, -co), 1e-6));
    assert!(close(c.up.normalize(), Vec3::new(0.0, co, -s), 1e-6));
    assert!((c.fov_y_deg - room::YFOV.to_degrees()).abs() < 1e-4);
}

#[test]
fn cameras_are_chosen_by_index_and_a_scene_without_one_is_framed() {
    let dir = tempfile::tempdir().unwrap();
    let path = room::room_gltf(Variant::External).write(dir.path(), "room.gltf");
    let side = load_gltf_with(&path, &GltfOptions { camera: Some(1), ..Default::default() }).unwrap().camera;
    let h = 0.5f32.sqrt();
    assert!(close(side.eye, Vec3::new(2.0, 0.0, 2.0), 1e-6), "side camera at {}", side.eye);
    assert!(close((side.target - side.eye).normalize(), Vec3::new(-h, 0.0, -h), 1e-6));
    let refused = |camera, expected: &str| {
        let e =
            load_gltf_with(&path, &GltfOptions { camera: Some(camera), ..Default::default() }).unwrap_err().to_string();
        assert!(e.contains(expected) && e.contains("room.gltf"), "camera {camera}: {e}");
    };
    refused(2, "orthographic");
    refused(3, "3 cameras");

    let mut g = room::room_gltf(Variant::External);
    let nodes = g.json["nodes"].as_array_mut().unwrap();
    nodes.iter_mut().for_each(|n| {
        n.as_object_mut().unwrap().remove("camera");
    });
    g.json.as_object_mut().unwrap().remove("cameras");
    let scene = load_gltf(&g.write(dir.path(), "no_camera.gltf")).unwrap();
    assert_eq!(scene.camera, scene.default_camera());
}

#[test]
fn embedded_and_binary_files_load_to_the_same_scene_as_external_files() {
    let (_d, _, external) = load_room(Variant::External);
    for variant in [Variant::Embedded, Variant::Binary] {
        let (_d, _, scene) = load_room(variant);
        assert_eq!(scene.triangles, external.triangles, "{variant:?}");
        assert_eq!(scene.uvs, external.uvs, "{variant:?}");
        assert_eq!(scene.material_ids, external.material_ids, "{variant:?}");
        assert_eq!(scene.materials, external.materials, "{variant:?}");
        assert_eq!(scene.textures, external.textures, "{variant:?}");
        assert_eq!(scene.camera, external.camera, "{variant:?}");
    }
}

#[test]
fn the_room_as_obj_with_map_kd_has_the_same_surfaces_as_the_gltf() {
    let (_d, _, gltf) = load_room(Variant::External);
    let dir = tempfile::tempdir().unwrap();
    let obj = load_obj(&room::write_room_obj(dir.path())).unwrap_or_else(|e| panic!("{e}"));
    // Both list the instances in the same order: room, lamp, cube, panel, mirrored panel.
    assert_eq!(obj.triangles.len(), gltf.triangles.len());
    for i in 0..gltf.triangles.len() {
        let (a, b) = (obj.material_of(i), gltf.material_of(i));
        for k in 0..3 {
            assert!(close(obj.triangles[i][k], gltf.triangles[i][k], 1e-6), "triangle {i}");
            assert!((obj.uvs[i][k] - gltf.uvs[i][k]).abs().max_element() < 1e-6, "triangle {i} uv {k}");
        }
        assert_eq!((&a.name, a.albedo, a.emission), (&b.name, b.albedo, b.emission));
        let texels = |s: &Scene, t: Option<usize>| t.map(|t| s.textures[t].texels.clone());
        assert_eq!(texels(&obj, a.albedo_texture), texels(&gltf, b.albedo_texture), "{}", a.name);
    }
}

#[test]
fn the_room_as_obj_with_map_kd_renders_the_same_image_within_noise() {
    let gpu = common::gpu();
    let (_d, _, gltf) = load_room(Variant::External);
    let dir = tempfile::tempdir().unwrap();
    let mut obj = load_obj(&room::write_room_obj(dir.path())).unwrap();
    // OBJ has no camera.
    obj.camera = gltf.camera;
    let settings = |seed| RenderSettings {
        width: 64,
        height: 64,
        seed,
        photons: 1 << 19,
        grid_resolution: 32,
        gather: rastergi::gather::GatherMethod::Trace,
        ..Default::default()
    };
    let n = 256;
    let (g1, g2) = (
        common::render(&gpu, &gltf, settings(1), n, Show::Full),
        common::render(&gpu, &gltf, settings(2), n, Show::Full),
    );
    let (o1, o2) = (
        common::render(&gpu, &obj, settings(3), n, Show::Full),
        common::render(&gpu, &obj, settings(4), n, Show::Full),
    );
    let (g, o) = (common::average(&g1, &g2), common::average(&o1, &o2));
    let mask = emitter_mask(&g, 3.0);
    // Four independent renders (every random choice differs with the seed): the RMS noise of
    // each pair's mean is rmse(a, b)/2, and two means of the same image differ by the root sum
    // of their noises.
    let noise = ((rmse(&g1, &g2, Some(&mask)).powi(2) + rmse(&o1, &o2, Some(&mask)).powi(2)) / 4.0).sqrt();
    let mean = masked_mean(&g, Some(&mask));
    let c = compare(&o, &g, Some(&mask));
    println!(
        "relative RMSE {:.4} (noise {:.4}), block-mean error {:.4}, mean ratio {:?}",
        c.relative_rmse,
        noise / mean,
        c.block_mean_error,
        c.mean_ratio
    );
    // 10 % margin for the noise estimate's own error (4096 pixels × 3 channels).
    assert!(c.relative_rmse < 1.1 * noise / mean, "the OBJ and glTF renders differ beyond noise");
    // Block means of 256 pixels: independent noise would shrink 16×, but the gather's one
    // direction per iteration correlates it across the image: 4× is what two independent
    // renders of the Cornell box show (gather.rs).
    assert!(c.block_mean_error < 2.0 * noise / mean / 4.0, "block means differ: {}", c.block_mean_error);
}

// ----- Hostile files -----------------------------------------------------------------------

/// Loads a file that must be refused; returns the message after checking that it is one line
/// naming the file.
fn refused(path: &Path) -> String {
    let message = match std::panic::catch_unwind(|| load_gltf(path)) {
        Ok(Ok(scene)) => panic!("{} was accepted: {} triangles", path.display(), scene.triangles.len()),
        Ok(Err(e)) => e.to_string(),
        Err(_) => panic!("loading {} panicked", path.display()),
    };
    assert!(message.contains(&path.display().to_string()), "the error does not name the file: {message}");
    assert!(!message.contains('\n'), "the error is not one line: {message}");
    message
}

/// The room (external files) with `edit` applied to its JSON and binary buffer, written to
/// `dir` as `name`.
fn edited(dir: &Path, name: &str, edit: impl FnOnce(&mut Value, &mut Vec<u8>)) -> PathBuf {
    let mut g = room::room_gltf(Variant::External);
    g.json["buffers"][0]["uri"] = json!(format!("{name}.bin"));
    edit(&mut g.json, &mut g.bin);
    g.write(dir, &format!("{name}.gltf"))
}

/// Byte offset in the buffer of accessor `a`'s first element.
fn accessor_offset(json: &Value, a: usize) -> usize {
    let view = &json["bufferViews"][json["accessors"][a]["bufferView"].as_u64().unwrap() as usize];
    (view["byteOffset"].as_u64().unwrap_or(0) + json["accessors"][a]["byteOffset"].as_u64().unwrap_or(0)) as usize
}

/// A PNG whose header claims `w × h` pixels (with valid CRCs) and holds no image data.
fn png_header_only(w: u32, h: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut c = 0xffff_ffffu32;
        for &b in bytes {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 { 0xedb8_8320 ^ (c >> 1) } else { c >> 1 };
            }
        }
        !c
    }
    let mut ihdr = b"IHDR".to_vec();
    ihdr.extend(w.to_be_bytes());
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 6, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png.extend(13u32.to_be_bytes());
    png.extend(&ihdr);
    png.extend(crc32(&ihdr).to_be_bytes());
    png.extend(0u32.to_be_bytes());
    png.extend(b"IEND");
    png.extend(crc32(b"IEND").to_be_bytes());
    png
}

#[test]
fn hostile_files_are_refused_with_one_line_errors_that_name_them() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // (what, file, a fragment the message must contain)
    let mut cases: Vec<(&str, PathBuf, &str)> = Vec::new();
    let mut case = |what, path, fragment| cases.push((what, path, fragment));

    case("missing file", d.join("nothing.gltf"), "no such file");
    case("directory", d.to_path_buf(), "not a file");
    std::fs::write(d.join("empty.gltf"), "").unwrap();
    case("empty file", d.join("empty.gltf"), "JSON");
    std::fs::write(d.join("malformed.gltf"), "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ {").unwrap();
    case("malformed JSON", d.join("malformed.gltf"), "JSON");
    std::fs::write(d.join("not_gltf.gltf"), "{ \"hello\": 1 }").unwrap();
    case("JSON that is not glTF", d.join("not_gltf.gltf"), "glTF");

    // Binary containers: cut short, lying about their length, of another version.
    let glb = room::room_gltf(Variant::Binary).glb();
    for cut in [3, 12, 19, 20, 100, glb.len() / 2, glb.len() - 1] {
        let p = d.join(format!("cut_{cut}.glb"));
        std::fs::write(&p, &glb[..cut]).unwrap();
        case("truncated .glb", p, if cut < 4 { "JSON" } else { "truncated" });
    }
    let mut lying = glb.clone();
    lying[8..12].copy_from_slice(&8u32.to_le_bytes());
    std::fs::write(d.join("short_length.glb"), &lying).unwrap();
    case("header length shorter than the header", d.join("short_length.glb"), "JSON");
    let mut v1 = glb.clone();
    v1[4] = 1;
    std::fs::write(d.join("version1.glb"), &v1).unwrap();
    case("glb version 1", d.join("version1.glb"), "version 1");
    let mut huge_chunk = glb.clone();
    huge_chunk[12..16].copy_from_slice(&u32::MAX.to_le_bytes());
    std::fs::write(d.join("huge_chunk.glb"), &huge_chunk).unwrap();
    case("chunk longer than the file", d.join("huge_chunk.glb"), "truncated");

    // Missing external files.
    let p = edited(d, "missing_bin", |_, _| {});
    std::fs::remove_file(d.join("missing_bin.bin")).unwrap();
    case("missing buffer file", p, "missing_bin.bin");
    let p = edited(d, "missing_texture", |j, _| j["images"][0]["uri"] = json!("no-such-texture.png"));
    case("missing texture file", p, "no-such-texture.png");
    let p = edited(d, "device", |j, _| j["buffers"][0]["uri"] = json!("/dev/zero"));
    case("buffer naming a device", p, "not a regular file");
    let p = edited(d, "remote", |j, _| j["images"][1]["uri"] = json!("https://example.com/t.png"));
    case("remote texture", p, "not a file");
    let p = edited(d, "bad_base64", |j, _| j["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@"));
    case("invalid base64", p, "base64");
    let p = edited(d, "garbage_image", |j, _| j["images"][0]["uri"] = json!("garbage.png"));
    std::fs::write(d.join("garbage.png"), b"this is no image").unwrap();
    case("image that is not an image", p, "image 0");
    let p = edited(d, "huge_image", |j, _| j["images"][0]["uri"] = json!("huge.png"));
    std::fs::write(d.join("huge.png"), png_header_only(100_000, 100_000)).unwrap();
    case("image claiming 10¹⁰ pixels", p, "image 0");

    // Sizes and indices.
    let p = edited(d, "huge_count", |j, _| j["accessors"][0]["count"] = json!(1u64 << 40));
    case("accessor count of 2⁴⁰", p, "do not fit");
    let p = edited(d, "huge_index_count", |j, _| j["accessors"][2]["count"] = json!(u32::MAX));
    case("index count of 2³²", p, "do not fit");
    let p = edited(d, "huge_offset", |j, _| j["accessors"][0]["byteOffset"] = json!(u64::MAX - 7));
    case("accessor offset near 2⁶⁴", p, "do not fit");
    let p = edited(d, "long_view", |j, _| j["bufferViews"][0]["byteLength"] = json!(1u64 << 33));
    case("buffer view past its buffer", p, "past the end");
    let p = edited(d, "long_buffer", |j, b| j["buffers"][0]["byteLength"] = json!(b.len() + 100));
    case("buffer shorter than its byteLength", p, "byteLength");
    let p = edited(d, "bad_index", |j, b| {
        let at = accessor_offset(j, 2);
        b[at..at + 2].copy_from_slice(&999u16.to_le_bytes());
    });
    case("index beyond the vertices", p, "index 999 is out of range");
    let p = edited(d, "narrow_stride", |j, _| j["bufferViews"][0]["byteStride"] = json!(4));
    case("stride smaller than an element", p, "byteStride");
    let p = edited(d, "mesh_index", |j, _| j["nodes"][0]["mesh"] = json!(99));
    case("node naming a mesh that does not exist", p, "invalid glTF");
    let p = edited(d, "scene_node", |j, _| j["scenes"][0]["nodes"] = json!([42]));
    case("scene naming a node that does not exist", p, "invalid glTF");
    let p = edited(d, "positions_vec2", |j, _| j["accessors"][0]["type"] = json!("VEC2"));
    case("positions of the wrong type", p, "POSITION");
    let p = edited(d, "sparse", |j, _| {
        j["accessors"][0]["sparse"] =
            json!({ "count": 1, "indices": { "bufferView": 2, "componentType": 5123 }, "values": { "bufferView": 0 } })
    });
    case("sparse accessor", p, "sparse");

    // Values.
    let p = edited(d, "nan", |j, b| {
        let at = accessor_offset(j, 0);
        b[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    });
    case("NaN position", p, "non-finite POSITION");
    let p = edited(d, "infinite_scale", |j, _| j["nodes"][2]["scale"] = json!([1e39, 1.0, 1.0]));
    case("infinite scale", p, "not finite");
    let p = edited(d, "zero_rotation", |j, _| j["nodes"][3]["rotation"] = json!([0.0, 0.0, 0.0, 0.0]));
    case("zero quaternion", p, "quaternion");
    let p = edited(d, "bright", |j, _| {
        j["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = json!([2.0, 1.0, 1.0, 1.0])
    });
    case("albedo above 1", p, "albedo above 1");

    // Structure.
    let p = edited(d, "cycle", |j, _| j["nodes"][3]["children"] = json!([2]));
    case("node hierarchy with a cycle", p, "appears twice");
    let p = edited(d, "required_extension", |j, _| j["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]));
    case("unsupported required extension", p, "KHR_draco_mesh_compression");
    let p = edited(d, "no_texcoords", |j, _| {
        j["meshes"][0]["primitives"][0]["attributes"].as_object_mut().unwrap().remove("TEXCOORD_0");
    });
    case("textured primitive without texture coordinates", p, "TEXCOORD_0");
    let p = edited(d, "lines", |j, _| {
        for m in j["meshes"].as_array_mut().unwrap() {
            for p in m["primitives"].as_array_mut().unwrap() {
                p["mode"] = json!(1);
            }
        }
    });
    case("lines only", p, "no triangles");

    let mut failures = Vec::new();
    for (what, path, fragment) in &cases {
        let message = refused(path);
        println!("{what}: {message}");
        if !message.contains(fragment) {
            failures.push(format!("{what}: expected '{fragment}' in: {message}"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_primitive_without_material_gets_the_grey_default_and_strips_and_fans_keep_their_winding() {
    let dir = tempfile::tempdir().unwrap();
    // One quad as a strip (0 1 2 3 → 012, 213) and as a fan (0 1 2 3 → 012, 023), both facing +z.
    let p = edited(dir.path(), "modes", |j, b| {
        let quad = [[0f32, 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]];
        let fan = [[0f32, 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
        let start = b.len();
        b.extend(quad.iter().chain(&fan).flatten().flat_map(|v| v.to_le_bytes()));
        let views = j["bufferViews"].as_array_mut().unwrap();
        views.push(json!({ "buffer": 0, "byteOffset": start, "byteLength": 96 }));
        let view = views.len() - 1;
        let accessors = j["accessors"].as_array_mut().unwrap();
        let (min, max) = ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
        accessors.push(
            json!({ "bufferView": view, "componentType": 5126, "count": 4, "type": "VEC3", "min": min, "max": max }),
        );
        accessors.push(
            json!({ "bufferView": view, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3", "min": min, "max": max }),
        );
        let (a, f) = (accessors.len() - 2, accessors.len() - 1);
        j["meshes"] = json!([{ "primitives": [
            { "attributes": { "POSITION": a }, "mode": 5 },
            { "attributes": { "POSITION": f }, "mode": 6 },
        ] }]);
        j["nodes"] = json!([{ "mesh": 0 }]);
        j["scenes"] = json!([{ "nodes": [0] }]);
        j["buffers"][0]["byteLength"] = json!(b.len());
    });
    let scene = load_gltf(&p).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(scene.triangles.len(), 4);
    for (i, t) in scene.triangles.iter().enumerate() {
        assert_eq!(triangle_normal(t), Vec3::Z, "triangle {i}: {t:?}");
        let m = scene.material_of(i);
        assert_eq!((m.albedo, m.albedo_texture, m.two_sided), (Vec3::splat(0.5), None, false));
    }
    assert!(scene.uvs.is_empty(), "no texture coordinates were needed");
}

// ----- Mutation loop and regression corpus --------------------------------------------------

/// Loads `path`, catching panics and timing the load.
fn outcome(path: &Path) -> (std::thread::Result<Result<Scene, String>>, Duration) {
    let start = Instant::now();
    let r = std::panic::catch_unwind(|| load_gltf(path).map_err(|e| e.to_string()));
    (r, start.elapsed())
}

/// Numbers and other values a mutation puts in place of a JSON value.
fn hostile_value(rng: &mut rastergi::sampling::Rng) -> Value {
    let choices = [
        json!(0),
        json!(1),
        json!(-1),
        json!(3),
        json!(255),
        json!(65535),
        json!(1u64 << 31),
        json!(u32::MAX),
        json!(1u64 << 40),
        json!(u64::MAX),
        json!(-1e300),
        json!(1e300),
        json!(0.5),
        json!("x"),
        json!([]),
        json!({}),
        json!(null),
    ];
    choices[(rng.next_u32() as usize) % choices.len()].clone()
}

/// Replaces, removes or duplicates one random element of a JSON tree.
fn mutate_json(v: &mut Value, rng: &mut rastergi::sampling::Rng) {
    let mut node = v;
    loop {
        let r = rng.next_u32();
        let len = match node {
            Value::Object(o) => o.len(),
            Value::Array(a) => a.len(),
            _ => 0,
        };
        // Stop at a leaf, or with probability 1/4 at an inner node.
        if len == 0 || r.is_multiple_of(4) {
            match (rng.next_u32() % 3, &mut *node) {
                (0, Value::Array(a)) if !a.is_empty() => {
                    let i = rng.next_u32() as usize % a.len();
                    let dup = a[i].clone();
                    a.push(dup);
                }
                (1, Value::Object(o)) if !o.is_empty() => {
                    let key = o.keys().nth(rng.next_u32() as usize % o.len()).unwrap().clone();
                    o.remove(&key);
                }
                _ => *node = hostile_value(rng),
            }
            return;
        }
        let i = (rng.next_u32() as usize) % len;
        node = match node {
            Value::Object(o) => o.values_mut().nth(i).unwrap(),
            Value::Array(a) => &mut a[i],
            _ => unreachable!(),
        };
    }
}

/// 1000 cases of each kind by default; `RASTERGI_FUZZ_CASES` and `RASTERGI_FUZZ_SEED` run
/// longer or other searches (`cargo test --release --test gltf mutated -- --nocapture`).
#[test]
fn mutated_files_are_loaded_or_refused_without_panicking_or_hanging() {
    let env = |name: &str, default: u32| std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default);
    let (cases, seed) = (env("RASTERGI_FUZZ_CASES", 1000), env("RASTERGI_FUZZ_SEED", 2024));
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut rng = rastergi::sampling::Rng::new(seed, 7, 0);
    let (mut accepted, mut refused_count, mut slowest) = (0, 0, Duration::ZERO);
    let mut panics = Vec::new();
    let mut check = |path: PathBuf, panics: &mut Vec<PathBuf>| {
        let (r, t) = outcome(&path);
        slowest = slowest.max(t);
        match r {
            Ok(Ok(_)) => accepted += 1,
            Ok(Err(message)) => {
                assert!(!message.contains('\n'), "multi-line error for {}: {message}", path.display());
                refused_count += 1;
            }
            Err(_) => panics.push(path),
        }
    };
    // Byte-level mutations of the binary container: a few bytes overwritten, bits flipped,
    // the file cut or extended.
    let glb = room::room_gltf(Variant::Binary).glb();
    for case in 0..cases {
        let mut bytes = glb.clone();
        for _ in 0..1 + rng.next_u32() % 8 {
            let at = rng.next_u32() as usize % bytes.len();
            match rng.next_u32() % 5 {
                0 => bytes[at] = rng.next_u32() as u8,
                1 => bytes[at] ^= 1 << (rng.next_u32() % 8),
                2 => bytes[at] = 0xff,
                3 => bytes.truncate(at.max(1)),
                _ => {
                    let from = at % glb.len();
                    bytes.extend_from_slice(&glb[from..(from + 64).min(glb.len())]);
                }
            }
        }
        let path = d.join(format!("bytes_{case}.glb"));
        std::fs::write(&path, &bytes).unwrap();
        check(path, &mut panics);
    }
    // Structural mutations of the JSON: a value replaced by a hostile one, a key removed, an
    // array element duplicated; with everything embedded so each case is one file.
    let base = room::room_gltf(Variant::Embedded);
    for case in 0..cases {
        let mut json = base.json.clone();
        for _ in 0..1 + rng.next_u32() % 3 {
            mutate_json(&mut json, &mut rng);
        }
        let path = d.join(format!("json_{case}.gltf"));
        std::fs::write(&path, serde_json::to_vec(&json).unwrap()).unwrap();
        check(path, &mut panics);
    }
    println!("{accepted} accepted, {refused_count} refused, slowest load {slowest:?}");
    if !panics.is_empty() {
        // Keep them for the regression corpus.
        let keep = std::env::temp_dir().join("rastergi-gltf-panics");
        std::fs::create_dir_all(&keep).unwrap();
        for p in &panics {
            std::fs::copy(p, keep.join(p.file_name().unwrap())).unwrap();
        }
        panic!("{} mutated files made the loader panic (copied to {})", panics.len(), keep.display());
    }
    assert!(refused_count > 100 && accepted > 10, "the mutations should both break and spare files");
    assert!(slowest < Duration::from_secs(2), "a load took {slowest:?}");
}

#[test]
fn regression_corpus_files_are_refused_without_panicking() {
    let corpus = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/gltf/corpus");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&corpus).unwrap().map(|e| e.unwrap().path()).collect();
    files.retain(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("gltf" | "glb")));
    files.sort();
    assert!(files.len() >= 5, "the corpus is missing");
    for path in files {
        let message = refused(&path);
        println!("{}: {message}", path.file_name().unwrap().to_string_lossy());
    }
}

/// The room with `lights` (KHR_lights_punctual JSON) on three new root nodes: one translated
/// to (1, 2, 3), one under a parent translated by (0, 1, 0) and turned 90° about +X (its −Z
/// then points down, −Y), one with the identity.
fn with_lights(dir: &Path, name: &str, lights: Value) -> PathBuf {
    edited(dir, name, |j, _| {
        j["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        j["extensions"] = json!({ "KHR_lights_punctual": { "lights": lights } });
        let nodes = j["nodes"].as_array_mut().unwrap();
        let n = nodes.len();
        let h = std::f32::consts::FRAC_1_SQRT_2;
        nodes.push(json!({ "translation": [1.0, 2.0, 3.0], "extensions": { "KHR_lights_punctual": { "light": 0 } } }));
        nodes.push(json!({ "translation": [0.0, 1.0, 0.0], "rotation": [-h, 0.0, 0.0, h], "children": [n + 2] }));
        nodes.push(json!({ "extensions": { "KHR_lights_punctual": { "light": 1 } } }));
        nodes.push(json!({ "extensions": { "KHR_lights_punctual": { "light": 2 } } }));
        let roots = j["scenes"][0]["nodes"].as_array_mut().unwrap();
        roots.extend([json!(n), json!(n + 1), json!(n + 3)]);
    })
}

#[test]
fn punctual_lights_are_placed_by_their_nodes_with_color_times_intensity() {
    use rastergi::scene::Light;
    let dir = tempfile::tempdir().unwrap();
    let lights = json!([
        { "type": "point", "color": [1.0, 0.5, 0.25], "intensity": 4.0 },
        { "type": "spot", "intensity": 2.0, "spot": { "innerConeAngle": 0.2, "outerConeAngle": 0.5 } },
        { "type": "directional", "color": [0.5, 0.5, 1.0], "intensity": 3.0, "range": 5.0 }
    ]);
    let scene = load_gltf(&with_lights(dir.path(), "lit", lights)).unwrap();
    assert_eq!(scene.lights.len(), 3, "{:?}", scene.lights);
    let find = |f: fn(&Light) -> bool| *scene.lights.iter().find(|l| f(l)).expect("the light");
    let Light::Point { position, intensity } = find(|l| matches!(l, Light::Point { .. })) else { unreachable!() };
    assert!(close(position, Vec3::new(1.0, 2.0, 3.0), 1e-6) && close(intensity, Vec3::new(4.0, 2.0, 1.0), 1e-6));
    // Under the parent: at (0, 1, 0), its local −Z turned to −Y; glTF's default colour white.
    let Light::Spot { position, direction, intensity, inner, outer } = find(|l| matches!(l, Light::Spot { .. })) else {
        unreachable!()
    };
    assert!(close(position, Vec3::Y, 1e-6) && close(direction, -Vec3::Y, 1e-6), "{position} {direction}");
    assert!(close(intensity, Vec3::splat(2.0), 1e-6) && inner == 0.2 && outer == 0.5);
    // The identity node: −Z; `range` (a hint) is ignored with a warning.
    let Light::Distant { direction, irradiance, angular_radius } = find(|l| matches!(l, Light::Distant { .. })) else {
        unreachable!()
    };
    assert!(close(direction, -Vec3::Z, 1e-6) && close(irradiance, Vec3::new(1.5, 1.5, 3.0), 1e-6));
    assert_eq!(angular_radius, 0.0);
}

#[test]
fn hostile_punctual_lights_are_refused_with_one_line_errors() {
    let dir = tempfile::tempdir().unwrap();
    let ok_spot = json!({ "type": "spot", "spot": {} });
    let ok_sun = json!({ "type": "directional" });
    let cases = [
        ("negative", json!({ "type": "point", "intensity": -1.0 }), "negative"),
        ("negative_colour", json!({ "type": "point", "color": [1.0, -0.5, 1.0] }), "negative"),
        ("cones", json!({ "type": "spot", "spot": { "innerConeAngle": 0.6, "outerConeAngle": 0.4 } }), "inner ≤ outer"),
        ("wide", json!({ "type": "spot", "spot": { "outerConeAngle": 2.0 } }), "π/2"),
        ("unknown", json!({ "type": "area" }), "type"),
        ("no_spot", json!({ "type": "spot" }), "spot"),
    ];
    for (name, light, fragment) in cases {
        let path = with_lights(dir.path(), name, json!([light, ok_spot.clone(), ok_sun.clone()]));
        let message = refused(&path);
        assert!(message.contains(fragment), "{name}: {message}");
    }
}
