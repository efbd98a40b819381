//! `rastergi view` as a user and a script meet it: under Xvfb (CI installs it; lavapipe
//! renders) a scripted session's screenshots agree with headless renders of the same view,
//! resizing rebuilds the image at the window's size, and without a display or with a bad
//! script it fails with one clear line.

mod common;

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Duration;

use common::{Run, run};
use rastergi::image_io::{LinearImage, read_exr};
use rastergi::metrics::{compare, emitter_mask};

/// Longer than any of these runs takes on lavapipe; a run past it is killed and fails the test.
const TIMEOUT: Duration = Duration::from_secs(180);

/// Small and quick: the comparisons need no more.
const SIZE: &[&str] = &["--width", "64", "--height", "64"];
const PHOTONS: &[&str] = &["--photons", "65536", "--grid", "32"];
/// One light sample an iteration in the viewer and the renders alike: the balanced count is
/// chosen from timings, and a viewer's iterations in row bands are not timed (they draw one),
/// so the two draw the same light samples only at a fixed count.
const LIGHT: &[&str] = &["--light-samples", "1"];

impl Run {
    fn check_success(&self, what: &str) {
        assert!(
            self.status.success() && !self.stderr.contains("panicked"),
            "{what} failed ({}):\nstdout:\n{}\nstderr:\n{}",
            self.status,
            self.stdout,
            self.stderr
        );
    }
}

fn rastergi(dir: &Path, args: &[&str]) -> Run {
    common::rastergi(dir, args, TIMEOUT)
}

/// `rastergi view` on a virtual X server. Wayland variables are removed so the window opens
/// on Xvfb even inside a desktop session. One at a time: `xvfb-run -a` started twice at once
/// can pick the same display number.
fn view(dir: &Path, args: &[&str]) -> Run {
    static XVFB: Mutex<()> = Mutex::new(());
    let _one_at_a_time = XVFB.lock().unwrap_or_else(|e| e.into_inner());
    let mut all = vec!["-a", "-s", "-screen 0 320x240x24", env!("CARGO_BIN_EXE_rastergi"), "view"];
    all.extend_from_slice(args);
    run(dir, "xvfb-run", &all, &[("WAYLAND_DISPLAY", None), ("WAYLAND_SOCKET", None)], TIMEOUT)
}

/// A screenshot line of the viewer's stdout: the two files, the iteration count, the size
/// and the camera as `render` options.
struct Shot {
    png: PathBuf,
    exr: PathBuf,
    iterations: u32,
    size: (u32, u32),
    camera: Vec<String>,
}

fn screenshots(dir: &Path, stdout: &str) -> Vec<Shot> {
    stdout
        .lines()
        .filter_map(|l| l.strip_prefix("screenshot: "))
        .map(|l| {
            let words: Vec<&str> = l.split_whitespace().collect();
            let (details, camera) = l.split_once("camera ").expect("the camera is printed");
            let iterations = details.split_once('(').unwrap().1.split_whitespace().next().unwrap().parse().unwrap();
            let size = details.split(", ").nth(1).unwrap();
            let (w, h) = size.split_once('x').unwrap();
            Shot {
                png: dir.join(words[0]),
                exr: dir.join(words[1]),
                iterations,
                size: (w.parse().unwrap(), h.parse().unwrap()),
                camera: camera.trim_end_matches(')').split_whitespace().map(str::to_owned).collect(),
            }
        })
        .collect()
}

/// The Cornell box in the viewer (64², few photons) with `options`, driven by `script` in
/// `d`, which must succeed: its run and screenshots.
fn scripted_view(d: &Path, script: &str, options: &[&str]) -> (Run, Vec<Shot>) {
    std::fs::write(d.join("script.txt"), script).unwrap();
    let mut args = vec!["cornell", "--script", "script.txt"];
    args.extend_from_slice(options);
    args.extend_from_slice(SIZE);
    args.extend_from_slice(PHOTONS);
    args.extend_from_slice(LIGHT);
    let run = view(d, &args);
    run.check_success(&format!("view {}", options.join(" ")));
    let shots = screenshots(d, &run.stdout);
    (run, shots)
}

/// A headless render of the Cornell box, `iterations` with `extra` options (camera, seed, show).
fn render(dir: &Path, out: &str, seed: u32, iterations: u32, extra: &[String]) -> LinearImage {
    render_scene(dir, "cornell", out, seed, iterations, extra)
}

/// [`render`] of any scene.
fn render_scene(dir: &Path, scene: &str, out: &str, seed: u32, iterations: u32, extra: &[String]) -> LinearImage {
    let (seed, iterations) = (seed.to_string(), iterations.to_string());
    let mut args = vec!["render", scene, "--seed", &seed, "--iterations", &iterations, "--out", out];
    args.extend_from_slice(SIZE);
    args.extend_from_slice(PHOTONS);
    args.extend_from_slice(LIGHT);
    args.extend(extra.iter().map(String::as_str));
    rastergi(dir, &args).check_success("render");
    read_exr(&dir.join(out)).unwrap()
}

fn srgb_byte(linear: f32) -> u8 {
    let c = linear.clamp(0.0, 1.0);
    let v = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
    (v * 255.0).round() as u8
}

#[test]
fn screenshots_after_a_scripted_move_match_headless_renders_of_the_same_view() {
    const N: u32 = 32;
    const SEED: u32 = 3;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // An earlier screenshot: the viewer must count past it and leave it alone.
    std::fs::write(d.join("rastergi-0001.png"), b"an earlier screenshot").unwrap();
    // N iterations, a camera move (restart), N more, then the full image at exposure +1 and
    // the direct component: neither a new exposure nor a new view restarts the image.
    let script = format!(
        "after {N} iterations: orbit 8,4\nafter {N} iterations: exposure 1\nscreenshot\nshow direct\nscreenshot\nquit\n"
    );
    let (run, shots) = scripted_view(d, &script, &["--seed", &SEED.to_string()]);
    assert!(run.stdout.contains("Keys and mouse:"), "the keys are printed at start:\n{}", run.stdout);
    assert_eq!(shots.len(), 2, "{}", run.stdout);
    assert_eq!(std::fs::read(d.join("rastergi-0001.png")).unwrap(), b"an earlier screenshot");
    let names: Vec<_> = shots.iter().map(|s| s.png.file_name().unwrap().to_str().unwrap().to_owned()).collect();
    assert_eq!(names, ["rastergi-0002.png", "rastergi-0003.png"]);
    for s in &shots {
        assert_eq!((s.iterations, s.size), (N, (64, 64)), "N iterations after the move, at the window's size");
        assert_eq!(s.camera, shots[0].camera);
    }
    let camera = &shots[0].camera;
    assert!(!run.stdout.contains("--eye 0,0,3.9 "), "the camera moved:\n{}", run.stdout);

    // The PNG is what was shown: the EXR's radiance at +1 stop, clamped, sRGB-encoded.
    let full = read_exr(&shots[0].exr).unwrap();
    let png = image::open(&shots[0].png).unwrap().to_rgba8();
    assert_eq!(png.dimensions(), (64, 64));
    for (p, l) in png.pixels().zip(&full.pixels) {
        for c in 0..3 {
            assert!(p[c].abs_diff(srgb_byte(2.0 * l[c])) <= 1, "PNG {:?} vs linear {l:?}", p.0);
        }
    }

    // The direct component draws the same random numbers as a fresh render's (they depend on
    // the seed, the iteration and the pixel only): identical images, so the camera and the
    // iteration count are exactly those of the render.
    let mut direct_options = camera.clone();
    direct_options.extend(["--show".into(), "direct".into()]);
    let direct = render(d, "direct.exr", SEED, N, &direct_options);
    let viewer_direct = read_exr(&shots[1].exr).unwrap();
    let c = compare(&viewer_direct, &direct, None);
    assert!(c.relative_rmse < 1e-5, "direct component differs from the render's: {c:?}");

    // The full image differs from the render's only through the final gather's directions
    // (a restart rotates them); photon map, light samples and pixel jitter are shared. So
    // its expected squared error is at most that between two renders with different seeds,
    // which differ in everything. Over six seeds the ratio of the two relative RMSEs was
    // 0.86 to 1.12 (the gather's noise is correlated across the image, so the estimate of
    // its size varies); 1.5 leaves room for that variation.
    let reference = render(d, "a.exr", SEED, N, camera);
    let other_seed = render(d, "b.exr", SEED + 1, N, camera);
    let mask = emitter_mask(&reference, 3.0);
    let noise = compare(&other_seed, &reference, Some(&mask)).relative_rmse;
    let viewer = compare(&full, &reference, Some(&mask));
    assert!(
        viewer.relative_rmse < 1.5 * noise,
        "viewer vs render: relative RMSE {:.3}, two seeds: {noise:.3}",
        viewer.relative_rmse
    );
}

#[test]
fn a_frame_budget_no_iteration_fits_moves_on_previews_and_refines_to_the_renders_image() {
    // 0.01 ms a frame: while the script moves the camera each frame draws the coarsest
    // preview; after the stop the previews refine and the window's iterations run a row band
    // a frame. The screenshot holds the window's own iterations: its direct component is the
    // render's of the same view bit for bit (it draws the same random numbers), so neither the
    // previews nor the bands entered the film.
    const SEED: u32 = 4;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = "show direct\norbit 4,2\norbit 4,2\npan 3,1\nafter 3 iterations: screenshot\nquit\n";
    let (run, shots) = scripted_view(d, script, &["--seed", &SEED.to_string(), "--frame-budget", "0.01"]);
    assert_eq!(shots.len(), 1, "{}", run.stdout);
    assert_eq!(shots[0].iterations, 3);
    let mut options = shots[0].camera.clone();
    options.extend(["--show".into(), "direct".into()]);
    let render = render(d, "direct.exr", SEED, 3, &options);
    let c = compare(&read_exr(&shots[0].exr).unwrap(), &render, None);
    assert!(c.relative_rmse < 1e-5, "the viewer's direct component differs from the render's: {c:?}");
}

#[test]
fn resizing_and_retracing_rebuild_the_image_at_the_window_size() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = "after 2 iterations: resize 48,40\nafter 3 iterations: screenshot\nphotons 8192\ngrid 8\n\
                  after 2 iterations: screenshot\nquit\n";
    std::fs::create_dir(d.join("shots")).unwrap();
    let (run, shots) = scripted_view(d, script, &["--screenshot-dir", "shots"]);
    assert_eq!(shots.len(), 2, "{}", run.stdout);
    assert_eq!((shots[0].iterations, shots[0].size), (3, (48, 40)));
    assert_eq!((shots[1].iterations, shots[1].size), (2, (48, 40)), "the new photon map restarted the image");
    for s in &shots {
        assert!(s.png.starts_with(d.join("shots")), "{}", s.png.display());
        assert_eq!(image::open(&s.png).unwrap().to_rgba8().dimensions(), (48, 40));
        let exr = read_exr(&s.exr).unwrap();
        assert_eq!((exr.width, exr.height), (48, 40));
        assert!(exr.mean().iter().all(|&m| m > 0.0), "the lit box is not black");
    }
    // A coarser map with fewer photons gives a different indirect estimate.
    let (a, b) = (read_exr(&shots[0].exr).unwrap(), read_exr(&shots[1].exr).unwrap());
    assert_ne!(a, b);
}

#[test]
fn turning_the_sun_re_traces_and_shows_what_a_render_with_that_sun_shows() {
    // The sun through the Cornell box's open front, turned by the script (as the J/L I/K keys
    // do): each screenshot's direct light equals a headless render's with `--sun` at those
    // angles (the same seed and iteration count draw the same light samples).
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = "show direct\nafter 4 iterations: screenshot\nsun 340,15\nafter 4 iterations: screenshot\nquit\n";
    let (run, shots) = scripted_view(d, script, &["--sun", "20,25,1.5"]);
    assert_eq!(shots.len(), 2, "{}", run.stdout);
    assert_eq!(shots[1].iterations, 4, "the new sun restarted the image");
    for (shot, sun) in shots.iter().zip(["20,25,1.5", "340,15,1.5"]) {
        let options: Vec<String> = ["--sun", sun, "--show", "direct"].map(String::from).to_vec();
        let out = format!("sun-{}.exr", sun.split(',').next().unwrap());
        let rendered = render(d, &out, 0, 4, &options);
        let c = compare(&read_exr(&shot.exr).unwrap(), &rendered, None);
        assert!(c.relative_rmse < 1e-4, "sun {sun}: the viewer's direct light differs from the render's: {c:?}");
    }
    let (a, b) = (read_exr(&shots[0].exr).unwrap(), read_exr(&shots[1].exr).unwrap());
    assert!(compare(&a, &b, None).relative_rmse > 0.05, "turning the sun changes the light");
}

#[test]
fn the_panels_actions_switch_the_method_the_gather_and_the_scene_as_render_options_do() {
    // The panel's widgets give these actions (`view::panel`'s tests click them); here a
    // script gives them, a scene that does not exist among them. A renderer built for new settings starts afresh with the seed, so
    // its image is the one `render` gives with the same options, bit for bit.
    const SEED: u32 = 3;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = "method path\nafter 4 iterations: screenshot\nmethod gather\ngather trace\n\
                  gather-directions shared\ndirections 2\nafter 4 iterations: screenshot\nopen no-such.obj\nopen rooms\n\
                  after 2 iterations: screenshot\nquit\n";
    let (run, shots) = scripted_view(d, script, &["--seed", &SEED.to_string()]);
    assert_eq!(shots.len(), 3, "{}", run.stdout);
    let gather = ["--gather", "trace", "--gather-directions", "shared", "--directions", "2"];
    let cases = [
        ("cornell", 4, vec!["--method", "path"]),
        ("cornell", 4, gather.to_vec()),
        // The opened scene keeps the gather settings; its camera is the rooms' own.
        ("rooms", 2, gather.to_vec()),
    ];
    for (i, ((scene, iterations, options), shot)) in cases.into_iter().zip(&shots).enumerate() {
        assert_eq!((shot.iterations, shot.size), (iterations, (64, 64)));
        let mut options: Vec<String> = options.into_iter().map(String::from).collect();
        options.extend(shot.camera.iter().cloned());
        let rendered = render_scene(d, scene, &format!("{i}.exr"), SEED, iterations, &options);
        let c = compare(&read_exr(&shot.exr).unwrap(), &rendered, None);
        assert!(c.relative_rmse < 1e-6, "screenshot {i} ({scene} {options:?}) differs from the render's: {c:?}");
    }
    assert_ne!(shots[2].camera, shots[0].camera, "the opened scene brings its camera");
    // A scene that cannot be opened is one warning; the viewer goes on with the one it has.
    let warning: Vec<&str> = run.stderr.lines().filter(|l| l.contains("no-such.obj")).collect();
    assert_eq!(warning.len(), 1, "{}", run.stderr);
    assert!(warning[0].starts_with("warning: ") && warning[0].contains("no-such.obj"), "{}", warning[0]);
}

#[test]
fn the_denoiser_toggle_shows_what_render_denoise_writes() {
    // `--denoise` from the start: the viewer's renderer accumulates the guides from its first
    // iteration, as `render --denoise` does, so with the same seed, camera and gather the
    // denoised screenshot is `render --denoise`'s image and, turned off, the raw one its
    // NAME.raw.exr. The PNG is the EXR at the exposure, clamped, sRGB (computed here).
    const SEED: u32 = 4;
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let script = "after 4 iterations: screenshot\nexposure 1\nscreenshot\ndenoise off\nscreenshot\nquit\n";
    let (run, shots) = scripted_view(d, script, &["--seed", &SEED.to_string(), "--denoise", "--gather", "trace"]);
    assert_eq!(shots.len(), 3, "{}", run.stdout);
    let lines: Vec<&str> = run.stdout.lines().filter(|l| l.starts_with("screenshot: ")).collect();
    for (line, denoised) in lines.iter().zip([true, true, false]) {
        assert_eq!(line.contains("show full denoised,"), denoised, "{line}");
    }
    assert!(shots.iter().all(|s| s.iterations == 4), "neither the exposure nor the toggle restarts");
    let mut options: Vec<String> = ["--gather", "trace", "--denoise"].map(String::from).to_vec();
    options.extend(shots[0].camera.iter().cloned());
    let denoised = render(d, "r.exr", SEED, 4, &options);
    let raw = read_exr(&d.join("r.raw.exr")).unwrap();
    let (a, b, c) =
        (read_exr(&shots[0].exr).unwrap(), read_exr(&shots[1].exr).unwrap(), read_exr(&shots[2].exr).unwrap());
    assert_eq!(a, denoised, "the viewer's denoised image is render --denoise's");
    assert_eq!(b, denoised, "a new exposure changes the display only");
    assert_eq!(c, raw, "turned off: the raw image, render --denoise's NAME.raw.exr");
    let change = compare(&a, &c, None).relative_rmse;
    println!("--denoise, 4 iterations: equal to render --denoise's image; denoised vs raw relative RMSE {change:.4}");
    assert!(change > 0.01, "the denoiser changed the image by {change}");
    let png = image::open(&shots[1].png).unwrap().to_rgba8();
    for (p, l) in png.pixels().zip(&b.pixels) {
        for ch in 0..3 {
            assert!(p[ch].abs_diff(srgb_byte(2.0 * l[ch])) <= 1, "PNG {:?} vs denoised linear {l:?}", p.0);
        }
    }

    // Turned on mid-render (the script's `denoise on`, as N or the checkbox): the guides
    // start then, so the image restarts and the screenshot holds the 3 iterations since;
    // turned off, the same iterations raw.
    let script = "after 2 iterations: denoise on\nafter 3 iterations: screenshot\ndenoise off\nscreenshot\nquit\n";
    let (run, shots) = scripted_view(d, script, &["--seed", &SEED.to_string()]);
    assert_eq!(shots.len(), 2, "{}", run.stdout);
    assert!(shots.iter().all(|s| s.iterations == 3), "{}", run.stdout);
    assert!(run.stdout.contains("show full denoised,"), "{}", run.stdout);
    let (den, raw) = (read_exr(&shots[0].exr).unwrap(), read_exr(&shots[1].exr).unwrap());
    let change = compare(&den, &raw, None).relative_rmse;
    println!("turned on at 2 iterations, 3 since: denoised vs raw relative RMSE {change:.4}");
    assert!(change > 0.01, "the denoiser changed the image by {change}");
}

#[test]
fn view_without_a_display_fails_with_one_clear_line() {
    let dir = tempfile::tempdir().unwrap();
    let env = [("DISPLAY", None), ("WAYLAND_DISPLAY", None), ("WAYLAND_SOCKET", None)];
    let run = run(dir.path(), env!("CARGO_BIN_EXE_rastergi"), &["view", "cornell"], &env, TIMEOUT);
    let line = run.sole_error_line();
    assert!(line.contains("cannot open a window") && line.contains("DISPLAY"), "{line}");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0, "nothing written");
}

#[test]
fn a_bad_script_is_one_error_line_naming_the_line_before_any_window_opens() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("s.txt"), "# turn\nafter 4 iterations: orbit 10,0\nafter 4 iterations: jump\n")
        .unwrap();
    // No display either: the script is checked first.
    let env = [("DISPLAY", None), ("WAYLAND_DISPLAY", None), ("WAYLAND_SOCKET", None)];
    let run = run(dir.path(), env!("CARGO_BIN_EXE_rastergi"), &["view", "cornell", "--script", "s.txt"], &env, TIMEOUT);
    let line = run.sole_error_line();
    assert!(line.contains("s.txt") && line.contains("line 3") && line.contains("unknown action 'jump'"), "{line}");
    let missing = rastergi(dir.path(), &["view", "cornell", "--script", "none.txt"]);
    let line = missing.sole_error_line();
    assert!(line.contains("none.txt"), "{line}");
}

#[test]
fn view_help_lists_the_keys_and_the_script_format() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["view", "--help"]);
    run.check_success("view --help");
    for expected in [
        "W A S D",
        "Tab",
        "Shift",
        "scroll",
        "1 2 3 4",
        "+ -",
        "N ",
        "P ",
        "Esc",
        "after N iterations:",
        "--script",
        "denoise on|off",
        "--denoise",
    ] {
        assert!(run.stdout.contains(expected), "help lacks '{expected}':\n{}", run.stdout);
    }
    // The shared options of `render` are there too.
    for option in ["--eye", "--photons", "--grid", "--bundle", "--seed", "--show", "--exposure", "--backend"] {
        assert!(run.stdout.contains(option), "help lacks {option}:\n{}", run.stdout);
    }
    let top = rastergi(dir.path(), &["--help"]);
    assert!(top.stdout.lines().any(|l| l.trim_start().starts_with("view ")), "{}", top.stdout);
}
