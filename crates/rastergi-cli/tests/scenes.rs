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
    let documented = ["--width", "256", "--height", "256", "--iterations", "1", "--out", "out.exr"];
    let small = ["--width", "16", "--height", "16", "--iterations", "1", "--out", "out.exr"];
    for (scene, size, fitted, ray_view) in [
        // At the size its figures were measured at, 256², the Cornell box keeps 2²⁰ photons and
        // grid 64 (256² · 64/4 = 2²⁰ photons is where the image's cap begins, fit::photons_for_image).
        ("cornell", &documented, "photons 1048576 (fitted), grid 64 (fitted)", "512x512"),
        // A 16² thumbnail: the grid is the scene's, the photons of a pass the floor of the image's
        // cap (16² · 64/4 = 4096 < 2¹⁶).
        ("cornell", &small, "photons 65536 (fitted), grid 64 (fitted)", "128x128"),
        ("atrium", &small, "photons 65536 (fitted), grid 83 (fitted)", "1030x1030"),
    ] {
        let run = rastergi(dir.path(), &[&["render", scene], &size[..]].concat());
        let log = stderr(&run);
        assert!(run.status.success(), "{log}");
        assert!(log.contains(fitted), "{log}");
        assert!(log.contains(&format!("gather ray view: {ray_view} texels")), "{log}");
    }
    // A fixed map (one pass) keeps the scene's count.
    let fixed = [&["render", "atrium", "--photon-passes", "1"], &small[..]].concat();
    let log = stderr(&rastergi(dir.path(), &fixed));
    assert!(log.contains("photons 1048576 (fitted), grid 83 (fitted)"), "{log}");
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

/// `scripts/fetch-scenes.sh --from ../shared/scenes SCENE…` copies shared public scenes into a
/// cache, each file checked against its folder's FILES.txt; run again it leaves them as they
/// are; a truncated file is refused with one line naming it, and an unknown scene or option
/// with one line too.
#[test]
fn fetch_scenes_copies_the_shared_scenes_and_refuses_a_truncated_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let shared = root.join("../shared/scenes");
    if !shared.exists() {
        println!("skipped: {} is not here (the shared public scenes are not on this machine)", shared.display());
        return;
    }
    let (cache, other) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let fetch_to = |dest: &Path, args: &[&std::ffi::OsStr]| {
        Command::new("bash")
            .arg(root.join("scripts/fetch-scenes.sh"))
            .args(args)
            .arg("--dest")
            .arg(dest)
            .output()
            .expect("bash runs")
    };
    let fetch = |args: &[&std::ffi::OsStr]| fetch_to(cache.path(), args);
    let out = |o: &Output| String::from_utf8_lossy(&o.stdout).into_owned();
    // Four of the nine (the staircase's 786 files and the glTF assets' 56 MB copy the same way).
    let some: Vec<&std::ffi::OsStr> =
        ["sponza", "cornell-box-original", "gltf/LightsPunctualLamp", "env"].iter().map(|s| s.as_ref()).collect();
    let from = [&["--from".as_ref(), shared.as_os_str()][..], &some[..]].concat();
    let run = fetch(&from);
    assert!(run.status.success(), "{}{}", out(&run), stderr(&run));
    let lines = out(&run);
    assert_eq!(lines.lines().last(), Some(cache.path().to_str().unwrap()), "{lines}");
    // Every file that FILES.txt lists and the shared folder has, in the cache with its size.
    let mut files = 0;
    for scene in ["sponza", "cornell-box-original", "gltf/LightsPunctualLamp", "env"] {
        assert!(lines.contains(&format!("{scene}: copied")), "{lines}");
        let manifest = std::fs::read_to_string(shared.join(scene).join("FILES.txt")).unwrap();
        for line in manifest.lines() {
            let (size, path) = line.split_once(char::is_whitespace).unwrap();
            if let Ok(m) = std::fs::metadata(shared.join(scene).join(path)) {
                let copied = std::fs::metadata(cache.path().join(scene).join(path)).map(|c| c.len());
                assert_eq!(copied.ok(), Some(m.len()), "{scene}/{path}");
                assert_eq!(m.len().to_string(), size.trim(), "{scene}/{path}: the shared copy against FILES.txt");
                files += 1;
            }
        }
    }
    assert!(files > 40, "{files} files");
    assert!(!lines.contains("staircase"), "a scene not asked for: {lines}");
    let again = fetch(&from);
    assert!(again.status.success() && out(&again).contains("sponza: already in"), "{}", out(&again));
    // A truncated copy of the skies, into an empty cache.
    let bad = tempfile::tempdir().unwrap();
    std::fs::create_dir(bad.path().join("env")).unwrap();
    std::fs::copy(shared.join("env/FILES.txt"), bad.path().join("env/FILES.txt")).unwrap();
    for sky in ["aerodynamics_workshop_1k.hdr", "brown_photostudio_02_1k.hdr"] {
        let bytes = std::fs::read(shared.join("env").join(sky)).unwrap();
        std::fs::write(bad.path().join("env").join(sky), &bytes[..bytes.len() / 2]).unwrap();
    }
    let refused = fetch_to(other.path(), &["--from".as_ref(), bad.path().as_os_str(), "env".as_ref()]);
    let message = stderr(&refused);
    assert!(!refused.status.success(), "a truncated sky was taken: {}", out(&refused));
    assert_eq!(message.lines().count(), 1, "{message}");
    assert!(
        message.contains("aerodynamics_workshop_1k.hdr") && message.contains("FILES.txt says 1488808"),
        "{message}"
    );
    for (args, what) in [(&["nowhere"][..], "unknown scene 'nowhere'"), (&["--bogus"][..], "unknown option '--bogus'")]
    {
        let args: Vec<&std::ffi::OsStr> = args.iter().map(|a| a.as_ref()).collect();
        let run = fetch(&args);
        assert_eq!(run.status.code(), Some(2), "{}", stderr(&run));
        assert!(stderr(&run).contains(what) && stderr(&run).lines().count() == 1, "{}", stderr(&run));
    }
}

/// A Mitsuba file's film and sample count are what `render` makes when not told otherwise: its
/// size (one of `--width` and `--height` given: the other from its aspect) and its iterations.
#[test]
fn a_mitsuba_files_film_and_sample_count_are_the_default_size_and_iterations() {
    let dir = tempfile::tempdir().unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rastergi/tests/data/mitsuba/basic.xml");
    let xml = std::fs::read_to_string(data).unwrap();
    let xml = xml.replace("\"400\"", "\"24\"").replace("\"200\"", "\"12\"").replace("\"64\"", "\"3\"");
    assert!(xml.contains("value=\"24\"") && xml.contains("value=\"3\""), "basic.xml changed: {xml}");
    std::fs::write(dir.path().join("scene.xml"), xml).unwrap();
    let render = |extra: &[&str], out: &str| {
        let run = rastergi(dir.path(), &[&["render", "scene.xml", "--photons", "4096", "--out", out], extra].concat());
        let log = stderr(&run);
        assert!(run.status.success(), "{log}");
        let image = rastergi::image_io::read_exr(&dir.path().join(out)).unwrap();
        let iterations = log
            .lines()
            .find_map(|l| l.split("rastergi_cli::render] ").nth(1)?.strip_suffix(" s")?.split_once(" iterations in "))
            .map(|(n, _)| n.parse::<u32>().unwrap());
        ((image.width, image.height), iterations)
    };
    assert_eq!(render(&[], "film.exr"), ((24, 12), Some(3)));
    assert_eq!(render(&["--width", "48"], "wide.exr"), ((48, 24), Some(3)));
    assert_eq!(render(&["--height", "8", "--iterations", "2"], "small.exr"), ((16, 8), Some(2)));
    assert_eq!(render(&["--width", "10", "--height", "10"], "square.exr"), ((10, 10), Some(3)));
}
