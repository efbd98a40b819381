//! Built-in scenes, `export`, and the settings `render` fits to a scene when none are given,
//! as a user of the binary meets them.

use std::path::Path;
use std::process::{Command, Output};

fn rastergi(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_rastergi"))
        .args(args)
        .current_dir(dir)
        .env("RUST_LOG", "info")
        .output()
        .expect("the rastergi binary runs")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn cornell_keeps_its_documented_defaults_and_atrium_gets_fitted_ones() {
    let dir = tempfile::tempdir().unwrap();
    let small = ["--width", "16", "--height", "16", "--iterations", "1", "--out", "out.exr"];
    let run = rastergi(dir.path(), &[&["render", "cornell"], &small[..]].concat());
    let log = stderr(&run);
    assert!(run.status.success(), "{log}");
    assert!(log.contains("photons 1048576 (fitted), grid 64 (fitted)"), "{log}");
    assert!(log.contains("gather ray view: 128x128 texels"), "{log}");
    let run = rastergi(dir.path(), &[&["render", "atrium"], &small[..]].concat());
    let log = stderr(&run);
    assert!(run.status.success(), "{log}");
    assert!(log.contains("photons 1048576 (fitted), grid 83 (fitted)"), "{log}");
    assert!(log.contains("gather ray view: 1030x1030 texels"), "{log}");
    // Given values are used as given.
    let given = [&["render", "atrium", "--photons", "4096", "--grid", "16", "--bundle", "200"], &small[..]].concat();
    let run = rastergi(dir.path(), &given);
    let log = stderr(&run);
    assert!(log.contains("photons 4096, grid 16\n") || log.contains("photons 4096, grid 16\r"), "{log}");
    assert!(log.contains("gather ray view: 200x200 texels"), "{log}");
}

#[test]
fn exported_scene_renders_and_a_dim_png_gets_a_fitted_exposure() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["export", "spheres:2000", "--out", "spheres.obj"]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(dir.path().join("spheres.mtl").is_file());
    let text = std::fs::read_to_string(dir.path().join("spheres.obj")).unwrap();
    assert!(text.starts_with("# rastergi export spheres:2000"), "{}", &text[..200]);
    // The same scene, its light 2¹⁰ times dimmer: the PNG is brightened by whole stops, and
    // a note says so; --exposure 0 keeps it as rendered.
    let mtl = std::fs::read_to_string(dir.path().join("spheres.mtl")).unwrap();
    let dim: String = mtl
        .lines()
        .map(|l| match l.strip_prefix("Ke ") {
            Some(v) => {
                let k: Vec<String> =
                    v.split_whitespace().map(|x| (x.parse::<f32>().unwrap() / 1024.0).to_string()).collect();
                format!("Ke {}\n", k.join(" "))
            }
            None => format!("{l}\n"),
        })
        .collect();
    std::fs::write(dir.path().join("spheres.mtl"), dim).unwrap();
    let args = ["render", "spheres.obj", "--width", "24", "--height", "24", "--iterations", "2", "--photons", "4096"];
    let run = rastergi(dir.path(), &[&args[..], &["--out", "auto.png"]].concat());
    let log = stderr(&run);
    assert!(run.status.success(), "{log}");
    assert!(log.contains("note: exposure +"), "{log}");
    let run = rastergi(dir.path(), &[&args[..], &["--out", "raw.png", "--exposure", "0"]].concat());
    assert!(run.status.success() && !stderr(&run).contains("note: exposure"), "{}", stderr(&run));
    let mean = |name: &str| {
        let img = image::open(dir.path().join(name)).unwrap().to_rgb8();
        img.pixels().map(|p| p.0.iter().map(|&c| c as f64).sum::<f64>()).sum::<f64>() / img.len() as f64
    };
    assert!(mean("auto.png") > 4.0 * mean("raw.png"), "{} vs {}", mean("auto.png"), mean("raw.png"));
}

#[test]
fn a_bad_built_in_parameter_is_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["render", "spheres:many", "--out", "x.png"]);
    let log = stderr(&run);
    assert!(!run.status.success() && !log.contains("panicked"), "{log}");
    let errors: Vec<&str> = log.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{log}");
    assert!(errors[0].contains("spheres:many") && errors[0].contains("spheres:1000000"), "{log}");
}
