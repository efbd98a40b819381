//! `rastergi render` with glTF scenes: `.gltf`/`.glb` are recognised, `--camera N` picks a
//! camera of the file, and a bad camera index or a broken file is one error line, no panic.

use std::path::Path;
use std::process::{Command, Output};

use rastergi::image_io::{LinearImage, read_exr};

/// Runs the binary with `args` in `dir`.
fn rastergi(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rastergi")).args(args).current_dir(dir).output().unwrap()
}

/// The one `error:` line of a failed run (Mesa's XDG_RUNTIME_DIR notices aside).
fn error_line(run: &Output) -> String {
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success(), "the run succeeded:\n{stderr}");
    assert!(!stderr.contains("panicked"), "the run panicked:\n{stderr}");
    let errors: Vec<&str> =
        stderr.lines().filter(|l| l.starts_with("error:") && !l.contains("XDG_RUNTIME_DIR")).collect();
    assert_eq!(errors.len(), 1, "expected one error line:\n{stderr}");
    errors[0].to_owned()
}

/// A floor (2 × 2 at y = 0) under a small emitter facing down, seen by two cameras: 0 from the
/// front, 1 from above. Written as `scene.gltf` + `scene.bin` in `dir`.
fn write_scene(dir: &Path) {
    let positions: [[f32; 3]; 8] = [
        [-1.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 0.0, -1.0],
        [-1.0, 0.0, -1.0],
        [-0.2, 1.5, -0.2],
        [0.2, 1.5, -0.2],
        [0.2, 1.5, 0.2],
        [-0.2, 1.5, 0.2],
    ];
    let indices: [u16; 12] = [0, 1, 2, 0, 2, 3, 0, 1, 2, 0, 2, 3];
    let mut bin: Vec<u8> = positions.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    bin.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    std::fs::write(dir.join("scene.bin"), &bin).unwrap();
    let s = std::f32::consts::FRAC_1_SQRT_2;
    let json = format!(
        r#"{{
  "asset": {{ "version": "2.0" }},
  "scene": 0,
  "scenes": [{{ "nodes": [0, 1, 2, 3] }}],
  "nodes": [
    {{ "mesh": 0 }},
    {{ "mesh": 1 }},
    {{ "camera": 0, "translation": [0, 1, 3] }},
    {{ "camera": 1, "translation": [0, 3, 0], "rotation": [{r}, 0, 0, {s}] }}
  ],
  "cameras": [
    {{ "type": "perspective", "perspective": {{ "yfov": 0.8, "znear": 0.01 }} }},
    {{ "type": "perspective", "perspective": {{ "yfov": 0.8, "znear": 0.01 }} }}
  ],
  "materials": [
    {{ "pbrMetallicRoughness": {{ "baseColorFactor": [0.8, 0.8, 0.8, 1] }} }},
    {{ "emissiveFactor": [1, 1, 1] }}
  ],
  "meshes": [
    {{ "primitives": [{{ "attributes": {{ "POSITION": 0 }}, "indices": 1, "material": 0 }}] }},
    {{ "primitives": [{{ "attributes": {{ "POSITION": 2 }}, "indices": 3, "material": 1 }}] }}
  ],
  "buffers": [{{ "uri": "scene.bin", "byteLength": {len} }}],
  "bufferViews": [
    {{ "buffer": 0, "byteOffset": 0, "byteLength": 96 }},
    {{ "buffer": 0, "byteOffset": 96, "byteLength": 24 }}
  ],
  "accessors": [
    {{ "bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1] }},
    {{ "bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR" }},
    {{ "bufferView": 0, "byteOffset": 48, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.2, 1.5, -0.2], "max": [0.2, 1.5, 0.2] }},
    {{ "bufferView": 1, "byteOffset": 12, "componentType": 5123, "count": 6, "type": "SCALAR" }}
  ]
}}"#,
        r = -s,
        len = bin.len()
    );
    std::fs::write(dir.join("scene.gltf"), json).unwrap();
}

#[test]
fn gltf_scenes_render_from_the_camera_chosen_with_camera() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    let base = ["render", "scene.gltf", "--width", "16", "--height", "16", "--iterations", "2", "--photons", "4096"];
    for (camera, out) in [("0", "front.png"), ("1", "top.png")] {
        let run = rastergi(dir.path(), &[&base[..], &["--camera", camera, "--out", out]].concat());
        assert!(run.status.success(), "--camera {camera}: {}", String::from_utf8_lossy(&run.stderr));
    }
    let run = rastergi(dir.path(), &[&base[..], &["--out", "default.png"]].concat());
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    let read = |name: &str| std::fs::read(dir.path().join(name)).unwrap();
    assert_eq!(read("default.png"), read("front.png"), "the first camera is the default");
    assert_ne!(read("front.png"), read("top.png"), "the two cameras see the same image");
}

/// [`write_scene`]'s scene in `dir` from above (camera 1), 16², 8 iterations of the traced
/// gather, with `options`, rendered to `out` (EXR), which must succeed: the image and stderr.
fn from_above(dir: &Path, options: &[&str], out: &str) -> (LinearImage, String) {
    let base = ["render", "scene.gltf", "--camera", "1", "--width", "16", "--height", "16", "--iterations", "8"];
    let run = rastergi(dir, &[&base[..], &["--gather", "trace", "--out", out], options].concat());
    let log = String::from_utf8_lossy(&run.stderr).into_owned();
    assert!(run.status.success(), "{log}");
    (read_exr(&dir.join(out)).unwrap(), log)
}

/// Over one view rendered without (`dark`) and with (`lit`) some light: what `lit` shows
/// where `dark` is black, and the green `lit` gains everywhere else.
fn where_black(lit: &LinearImage, dark: &LinearImage) -> (Vec<[f32; 3]>, f32) {
    let (mut black, mut gain) = (Vec::new(), 0.0f32);
    for (l, d) in lit.pixels.iter().zip(&dark.pixels) {
        if d.iter().all(|&v| v == 0.0) {
            black.push(*l);
        } else {
            gain += l[1] - d[1];
        }
    }
    (black, gain)
}

/// [`write_scene`]'s scene seen from above (see [`from_above`]) with `options` and with
/// `--env none`: the first image, the two runs' stderr, and [`where_black`] of the two images.
fn with_and_without_environment(options: &[&str]) -> (LinearImage, [String; 2], Vec<[f32; 3]>, f32) {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    let (lit, lit_log) = from_above(dir.path(), options, "lit.exr");
    let (dark, dark_log) = from_above(dir.path(), &["--env", "none"], "dark.exr");
    let (black, gain) = where_black(&lit, &dark);
    (lit, [lit_log, dark_log], black, gain)
}

#[test]
fn a_physical_sky_lights_a_gltf_scene() {
    // From above (camera 1: straight down, 3 m up), the 2 × 2 floor under the emitter, without
    // and with `--sky 3 --sun 90,30`: the sky and its sun light the floor, and the pixels
    // around it, which look below the horizon, stay black (Mitsuba 3's sunsky is black there).
    let (_, _, background, floor_gain) = with_and_without_environment(&["--sky", "3", "--sun", "90,30"]);
    for s in &background {
        assert_eq!(*s, [0.0; 3], "a pixel below the horizon shows the sky");
    }
    let background = background.len();
    assert!(background > 0 && background < 16 * 16, "{background} background pixels");
    assert!(floor_gain > 0.0, "the sky adds no light to the floor");
}

/// A glTF model whose only light is an emissive surface is lit, as glTF viewers light models,
/// by the neutral grey environment, and says so in one line: seen from above, the pixels
/// around the floor look below the horizon, where that environment's radiance is 0.3 exactly
/// (with `--env none` they are black); the floor gets its light beside the emitter's.
#[test]
fn a_gltf_model_without_lights_is_lit_by_a_neutral_environment() {
    // Each pixel's own sample (not supersampled at the floor's edge against the sky, which
    // would mix the two): a background pixel is the environment's 0.3 or black.
    let (lit, [log, dark_log], black, floor_gain) = with_and_without_environment(&["--emitter-edges", "0"]);
    let said: Vec<&str> = log.lines().filter(|l| l.contains("neutral grey environment")).collect();
    assert_eq!(said.len(), 1, "{log}");
    assert!(said[0].contains("scene.gltf: no lights but its emissive surfaces"), "{log}");
    assert!(!dark_log.contains("neutral"), "{dark_log}");
    // Black without the environment: the background, or the emitter's unlit black back.
    let mut background = 0;
    for l in &black {
        let sky = l.iter().all(|&v| (v - 0.3).abs() < 1e-5);
        assert!(sky || *l == [0.0; 3], "a pixel black without the environment shows {l:?}");
        background += sky as usize;
    }
    assert!((lit.pixels[0][0] - 0.3).abs() < 1e-5, "the corner shows {:?}", lit.pixels[0]);
    assert!(background > 0 && background < 16 * 16, "{background} background pixels");
    assert!(floor_gain > 0.0, "the neutral environment adds no light to the floor");
}

#[test]
fn a_camera_the_file_lacks_or_a_camera_for_another_scene_is_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    write_scene(dir.path());
    let line = error_line(&rastergi(dir.path(), &["render", "scene.gltf", "--camera", "2", "--out", "x.png"]));
    assert!(line.contains("scene.gltf") && line.contains("2 cameras"), "{line}");
    let line = error_line(&rastergi(dir.path(), &["render", "cornell", "--camera", "0", "--out", "x.png"]));
    assert!(line.contains("--camera"), "{line}");
    std::fs::write(dir.path().join("broken.glb"), b"glTF\x02\0\0\0\xff\xff\0\0JSON").unwrap();
    let line = error_line(&rastergi(dir.path(), &["render", "broken.glb", "--out", "x.png"]));
    assert!(line.contains("broken.glb") && line.contains("truncated"), "{line}");
    assert!(!dir.path().join("x.png").exists());
}
