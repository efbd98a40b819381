//! The `rastergi` binary as a user meets it: its help, its one-line errors (never a panic),
//! the files it writes and the ones it must leave alone.

mod common;

use std::path::Path;
use std::time::Duration;

use common::{Run, files_in};

/// Longer than any of these runs takes on lavapipe; a run past it is killed and fails the test.
const TIMEOUT: Duration = Duration::from_secs(300);

impl Run {
    /// The one `error: ` line of a failed run, after checking that the run failed, printed
    /// exactly one such line and did not panic.
    fn error_line(&self) -> &str {
        assert!(!self.status.success(), "the run succeeded; stderr:\n{}", self.stderr);
        assert!(!self.stderr.contains("panicked"), "the run panicked:\n{}", self.stderr);
        let errors: Vec<&str> = self.our_stderr().into_iter().filter(|l| l.starts_with("error:")).collect();
        assert_eq!(errors.len(), 1, "expected one error line, got:\n{}", self.stderr);
        errors[0]
    }
}

/// Runs the binary with `args` in the directory `dir`.
fn rastergi(dir: &Path, args: &[&str]) -> Run {
    common::rastergi(dir, args, TIMEOUT)
}

/// Renders `scene` to x.png in `dir` with `args`, which must be refused with exit status
/// `code` (1: one error line; 2: a usage error) and a message containing `fragment`, before
/// x.png is written.
fn refused_render(dir: &Path, scene: &str, args: &[&str], code: i32, fragment: &str) {
    let run = rastergi(dir, &[&["render", scene, "--out", "x.png"], args].concat());
    assert_eq!(run.status.code(), Some(code), "{args:?}:\n{}", run.stderr);
    let message = if code == 1 { run.sole_error_line().to_owned() } else { run.stderr.clone() };
    assert!(message.contains(fragment), "{args:?}: {message}");
    assert!(!dir.join("x.png").exists());
}

#[test]
fn help_lists_the_render_and_info_commands() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["--help"]);
    assert!(run.status.success(), "{}", run.stderr);
    let commands: Vec<&str> = run.stdout.lines().filter_map(|l| l.split_whitespace().next()).collect();
    assert!(commands.contains(&"render") && commands.contains(&"info"), "{}", run.stdout);
}

/// `info` names the driver and says whether ray queries are offered; Mesa's lavapipe implements
/// `VK_KHR_ray_query` from Mesa 25 on (what scripts/setup.sh installs), so there it must say so.
/// An adapter without ray queries — Mesa's OpenGL through wgpu's GL backend —: `--rays
/// hardware` is one error line naming the option and the way out, with no file; `auto` renders
/// on the compute BVH, and `info` says so.
#[test]
fn rays_hardware_on_an_adapter_without_ray_queries_is_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let info = rastergi(dir.path(), &["info", "--backend", "gl"]);
    assert!(info.status.success(), "{}", info.stderr);
    assert!(info.stdout.contains("ray queries: not offered by this adapter"), "{}", info.stdout);
    assert!(info.stdout.contains("rays:     auto: compute (the adapter offers no ray queries)"), "{}", info.stdout);
    let small = ["--width", "16", "--height", "16", "--iterations", "2", "--photons", "4096", "--backend", "gl"];
    let run =
        rastergi(dir.path(), &[&["render", "cornell", "--rays", "hardware", "--out", "x.png"], &small[..]].concat());
    assert_eq!(run.status.code(), Some(1), "{}", run.stderr);
    let errors: Vec<&str> = run.stderr.lines().filter(|l| l.starts_with("error:")).collect();
    assert_eq!(errors.len(), 1, "{}", run.stderr);
    assert!(errors[0].contains("--rays hardware") && errors[0].contains("use --rays compute or auto"), "{}", errors[0]);
    assert!(!run.stderr.contains("panicked") && files_in(dir.path()).is_empty(), "{}", run.stderr);
    let run =
        rastergi(dir.path(), &[&["render", "cornell", "--rays", "auto", "--out", "auto.png"], &small[..]].concat());
    assert!(run.status.success(), "{}", run.stderr);
    assert_eq!(files_in(dir.path()), ["auto.png"]);
}

#[test]
fn info_names_the_driver_and_whether_ray_queries_are_offered() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["info"]);
    assert!(run.status.success(), "{}", run.stderr);
    let line = |key: &str| {
        run.stdout
            .lines()
            .find_map(|l| l.strip_prefix(key))
            .map(str::trim)
            .unwrap_or_else(|| panic!("no {key}\n{}", run.stdout))
    };
    let (driver, rays) = (line("driver:"), line("ray queries:"));
    assert!(rays == "offered" || rays == "not offered by this adapter", "{rays}");
    // "llvmpipe Mesa 25.0.7-2~bpo12+1 (LLVM 15.0.6)": lavapipe of Mesa 25 or newer.
    let mesa = driver.split_whitespace().skip_while(|w| *w != "Mesa").nth(1);
    let major = mesa.and_then(|v| v.split('.').next()).and_then(|m| m.parse::<u32>().ok());
    if driver.starts_with("llvmpipe") && major.is_some_and(|m| m >= 25) {
        assert_eq!(rays, "offered", "{}", run.stdout);
    }
    // What --rays (default auto) does with them.
    let path = line("rays:");
    let expected = if rays == "offered" { "auto: hardware, unless" } else { "auto: compute (the adapter" };
    assert!(path.starts_with(expected), "{path}");
    println!("{driver}: ray queries {rays}; rays {path}");
}

/// `--rays` takes auto, hardware or compute; anything else is a usage error naming them.
#[test]
fn an_unknown_ray_path_is_a_usage_error_naming_the_choices() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["info", "--rays", "magic"]);
    assert_eq!(run.status.code(), Some(2), "{}", run.stderr);
    assert!(run.stderr.contains("expected auto, hardware or compute"), "{}", run.stderr);
    let run = rastergi(dir.path(), &["info", "--rays", "compute"]);
    assert!(run.status.success() && run.stdout.contains("rays:     compute (asked for"), "{}", run.stdout);
}

/// A reader that closed the pipe before rastergi writes to it (`rastergi compare … | head`):
/// the process ends quietly by SIGPIPE, as other Unix tools do; it panicked in `println!`
/// with a backtrace ("failed printing to stdout: Broken pipe").
#[cfg(unix)]
#[test]
fn a_closed_output_pipe_ends_the_run_quietly() {
    use std::os::unix::process::ExitStatusExt;
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rastergi/tests/data");
    let (a, b) = (data.join("cornell_path_128_a.exr"), data.join("cornell_path_128_b.exr"));
    // The read end is closed before the process starts: its first line meets a pipe with no
    // reader, whatever the timing.
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_rastergi"))
        .args(["compare", a.to_str().unwrap(), b.to_str().unwrap()])
        .stdin(std::process::Stdio::null())
        .stdout(writer)
        .stderr(std::process::Stdio::piped())
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("panicked"), "the run panicked:\n{stderr}");
    assert_eq!(out.status.signal(), Some(libc::SIGPIPE), "{:?}:\n{stderr}", out.status);
}

#[test]
fn unknown_option_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["render", "cornell", "--out", "x.png", "--no-such-option"]);
    assert_eq!(run.status.code(), Some(2), "clap's usage errors exit with 2:\n{}", run.stderr);
    assert!(run.stderr.contains("--no-such-option") && run.stderr.contains("Usage:"), "{}", run.stderr);
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn missing_scene_file_is_one_error_line_naming_it_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["render", "missing.obj", "--out", "x.png"]);
    let line = run.error_line();
    assert!(line.contains("missing.obj"), "{line}");
    assert_eq!(run.our_stderr(), vec![line], "nothing but the error line");
    assert!(files_in(dir.path()).is_empty(), "{:?}", files_in(dir.path()));
}

/// Refused before anything renders: one error line naming the fault, and no file written.
#[test]
fn bad_outputs_sizes_and_cameras_are_one_error_line_and_write_nothing() {
    // Billions of iterations: had a run started rendering, it would hit the timeout.
    let cases: [(&[&str], &[&str]); 5] = [
        // An unsupported output format.
        (&["--iterations", "4000000000", "--out", "x.jpg"], &["x.jpg", ".png", ".exr"]),
        // A missing output directory.
        (&["--iterations", "4000000000", "--out", "no/such/dir/x.png"], &["no/such/dir", "does not exist"]),
        // A width beyond the GPU's limit.
        (&["--width", "100000", "--iterations", "1", "--out", "x.png"], &["100000", "limit"]),
        // Camera errors: a zero field of view, the eye at the target.
        (&["--fov", "0", "--out", "x.png"], &["camera", "field of view"]),
        (&["--eye", "0,0,0", "--target", "0,0,0", "--out", "x.png"], &["camera", "eye and target"]),
    ];
    for (args, words) in cases {
        let dir = tempfile::tempdir().unwrap();
        let run = rastergi(dir.path(), &[&["render", "cornell"], args].concat());
        let line = run.error_line();
        assert!(words.iter().all(|w| line.contains(w)), "{args:?}: {line}");
        assert!(files_in(dir.path()).is_empty(), "{args:?} wrote {:?}", files_in(dir.path()));
    }
}

#[test]
fn time_limit_stops_a_long_render_and_writes_what_it_has() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["render", "cornell", "--method", "path", "--width", "16", "--height", "16"];
    // Billions of iterations: only --time-limit (or its old name, --max-seconds) can end it
    // before the timeout.
    for option in ["--time-limit", "--max-seconds"] {
        let run = rastergi(
            dir.path(),
            &[&args[..], &["--iterations", "4000000000", option, "0.5", "--out", "x.exr"]].concat(),
        );
        assert!(run.status.success(), "{}", run.stderr);
        let note = run.our_stderr().into_iter().find(|l| l.starts_with("note: --time-limit 0.5 reached: "));
        assert!(note.is_some_and(|l| l.contains(" of 4000000000 iterations")), "{}", run.stderr);
        assert_eq!(files_in(dir.path()), ["x.exr"]);
    }
    let bad = rastergi(dir.path(), &[&args[..], &["--time-limit", "0", "--out", "y.exr"]].concat());
    assert!(bad.error_line().contains("--time-limit"), "{}", bad.stderr);
    assert_eq!(files_in(dir.path()), ["x.exr"]);
}

#[test]
fn failed_renders_leave_an_existing_image_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let good = b"the bytes of a good image from an earlier render";
    std::fs::write(dir.path().join("keep.png"), good).unwrap();
    // One failure before the GPU is touched, one after.
    for args in [
        &["render", "no-such-scene", "--out", "keep.png"][..],
        &["render", "cornell", "--width", "100000", "--iterations", "1", "--out", "keep.png"][..],
    ] {
        let run = rastergi(dir.path(), args);
        run.error_line();
        assert_eq!(std::fs::read(dir.path().join("keep.png")).unwrap(), good, "after {args:?}");
        assert_eq!(files_in(dir.path()), ["keep.png"], "after {args:?}");
    }
}

/// Width and height from a PNG's IHDR chunk, after checking the signature.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    assert!(bytes.len() > 33, "{} bytes is too short for a PNG", bytes.len());
    assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&bytes[8..16], b"\0\0\0\x0dIHDR", "the first chunk is a 13-byte IHDR");
    let be = |i: usize| u32::from_be_bytes(bytes[i..i + 4].try_into().unwrap());
    (be(16), be(20))
}

#[test]
fn tiny_renders_write_a_valid_png_and_exr_and_no_temporary_files() {
    let dir = tempfile::tempdir().unwrap();
    let png = rastergi(
        dir.path(),
        &["render", "cornell", "--width", "32", "--height", "32", "--iterations", "4", "--out", "a.png"],
    );
    assert!(png.status.success(), "{}", png.stderr);
    assert!(!png.stderr.contains("panicked"), "{}", png.stderr);
    assert_eq!(png_size(&std::fs::read(dir.path().join("a.png")).unwrap()), (32, 32));

    // Not square, so that a swapped width and height would show.
    let exr = rastergi(
        dir.path(),
        &["render", "cornell", "--width", "32", "--height", "24", "--iterations", "4", "--out", "b.exr"],
    );
    assert!(exr.status.success(), "{}", exr.stderr);
    let image = rastergi::image_io::read_exr(&dir.path().join("b.exr")).unwrap();
    assert_eq!((image.width, image.height, image.pixels.len()), (32, 24, 32 * 24));
    assert!(image.pixels.iter().flatten().all(|c| c.is_finite() && *c >= 0.0), "a pixel is negative or not finite");
    assert!(image.mean().iter().all(|&m| m > 0.0), "the lit Cornell box is not black: mean {:?}", image.mean());

    assert_eq!(files_in(dir.path()), ["a.png", "b.exr"], "no .rastergi-* temporary files are left");
}

#[test]
fn profile_prints_the_gpu_time_of_every_pass_that_ran() {
    let dir = tempfile::tempdir().unwrap();
    for (gather, passes) in [
        ("trace", &["gbuffer", "direct", "gather trace"][..]),
        ("lists", &["gbuffer", "direct", "gather list fill", "gather list project"][..]),
        ("raster", &["gbuffer", "direct", "gather count", "gather peel", "gather project"][..]),
    ] {
        let args = ["render", "cornell", "--width", "32", "--height", "32", "--iterations", "2", "--photons", "4096"];
        let run = rastergi(
            dir.path(),
            &[&args[..], &["--grid", "8", "--gather", gather, "--profile", "--out", "p.exr"]].concat(),
        );
        assert!(run.status.success(), "{}", run.stderr);
        // The set-up's table (the photon passes), then the iterations' with each pass that ran
        // there, 2 iterations of 4 directions.
        let (setup, iterations) = run.stdout.split_once("iterations (GPU timestamps").expect("an iterations table");
        assert!(setup.contains("photon trace") && setup.contains("photon map resolve"), "{}", run.stdout);
        for pass in passes {
            let row = iterations
                .lines()
                .find(|l| l.starts_with(pass))
                .unwrap_or_else(|| panic!("no {pass}:\n{}", run.stdout));
            let count: u32 = row[22..].split_whitespace().next().unwrap().parse().unwrap();
            let expected = match *pass {
                "gbuffer" | "direct" => 2,
                "gather trace" => 2,
                // One per direction; peeled layers: at least one per direction.
                "gather peel" | "gather project" => count.max(8),
                _ => 8,
            };
            assert_eq!(count, expected, "{pass}:\n{}", run.stdout);
        }
        assert!(iterations.contains("GPU total"), "{}", run.stdout);
    }
}

#[test]
fn unknown_gather_method_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(dir.path(), &["render", "cornell", "--gather", "magic", "--out", "x.png"]);
    assert!(!run.status.success());
    assert!(run.stderr.contains("magic") && run.stderr.contains("trace"), "{}", run.stderr);
    assert!(files_in(dir.path()).is_empty());
}

#[test]
fn gather_directions_choose_per_pixel_or_shared_and_reject_others() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["render", "cornell", "--width", "32", "--height", "32", "--iterations", "2", "--photons", "4096"];
    let mut images = Vec::new();
    for directions in ["per-pixel", "shared"] {
        let out = format!("{directions}.exr");
        let extra = ["--grid", "8", "--gather", "trace", "--gather-directions", directions, "--out", &out];
        let run = rastergi(dir.path(), &[&args[..], &extra[..]].concat());
        assert!(run.status.success(), "{}", run.stderr);
        images.push(rastergi::image_io::read_exr(&dir.path().join(&out)).unwrap());
    }
    // The same seed and photon map: only the gather's directions differ.
    assert_ne!(images[0].pixels, images[1].pixels, "per-pixel and shared directions gave the same image");
    let run = rastergi(dir.path(), &["render", "cornell", "--gather-directions", "random", "--out", "x.png"]);
    assert!(!run.status.success());
    assert!(run.stderr.contains("random") && run.stderr.contains("per-pixel"), "{}", run.stderr);
}

#[test]
fn bench_memory_reports_the_allocations_and_their_total() {
    let dir = tempfile::tempdir().unwrap();
    let run = rastergi(
        dir.path(),
        &["bench", "memory", "--width", "64", "--height", "64", "--grid", "16", "--bundle", "128", "--photons", "4096"],
    );
    assert!(run.status.success(), "{}", run.stderr);
    // Film: 3 components × 16 bytes per pixel of accumulation = 192 KiB at 64²; it is under
    // the 1 MiB listing threshold, so only the totals are checked against a floor: the photon
    // map texture alone is 16³ cells × 6 bins × 16 bytes = 384 KiB.
    let totals: Vec<&str> = run.stdout.lines().filter(|l| l.trim_start().starts_with("total")).collect();
    assert_eq!(totals.len(), 2, "{}", run.stdout);
    for t in totals {
        let mib: f64 = t.split_whitespace().nth(1).unwrap().parse().unwrap();
        assert!(mib >= 0.375, "{t}");
    }
}

#[test]
fn bench_rays_refuses_a_batch_beyond_the_gpus_buffers_before_making_it() {
    let dir = tempfile::tempdir().unwrap();
    // 8192² rays of 48 bytes are 3 GiB: past lavapipe's 128 MiB binding (and most GPUs'),
    // refused in one line before 67 M rays are made on the CPU.
    let run = rastergi(dir.path(), &["bench", "rays", "cornell", "--size", "8192"]);
    assert!(!run.status.success());
    assert!(run.stderr.contains("the rays need") && run.stderr.contains("--size"), "{}", run.stderr);
    assert!(!run.stderr.contains("panicked"), "{}", run.stderr);
    let run = rastergi(dir.path(), &["bench", "rays", "cornell", "--size", "0"]);
    assert!(!run.status.success() && run.stderr.contains("--size"), "{}", run.stderr);
}

#[test]
fn bench_motion_refuses_where_its_images_cannot_go_before_rendering() {
    let dir = tempfile::tempdir().unwrap();
    // A file where the directory for the images should be, and a reference in a directory
    // that does not exist: each refused in one line before the converged view is rendered
    // (which takes minutes on a real scene), nothing written.
    std::fs::write(dir.path().join("taken"), "a file").unwrap();
    let run =
        rastergi(dir.path(), &["bench", "motion", "cornell", "--width", "32", "--height", "32", "--images", "taken"]);
    assert!(!run.status.success());
    assert!(run.stderr.contains("--images") && run.stderr.contains("taken"), "{}", run.stderr);
    assert!(!run.stdout.contains("converged view"), "{}", run.stdout);
    let run = rastergi(
        dir.path(),
        &["bench", "motion", "cornell", "--width", "32", "--height", "32", "--reference", "nowhere/ref.exr"],
    );
    assert!(!run.status.success());
    assert!(run.stderr.contains("--reference") && run.stderr.contains("does not exist"), "{}", run.stderr);
    assert!(!run.stderr.contains("panicked") && !dir.path().join("nowhere").exists(), "{}", run.stderr);
}

#[test]
fn bench_resolve_times_the_three_states_a_viewer_resolves_in() {
    let dir = tempfile::tempdir().unwrap();
    let run =
        rastergi(dir.path(), &["bench", "resolve", "cornell", "--width", "32", "--height", "24", "--repeats", "2"]);
    assert!(run.status.success(), "{}", run.stderr);
    for state in ["the film alone: ", "moving: the 1/4 preview upscaled", "after the stop: "] {
        let line = run
            .stdout
            .lines()
            .find(|l| l.contains(state))
            .unwrap_or_else(|| panic!("no '{state}' in:\n{}", run.stdout));
        let ms: f64 = line.rsplit(": ").next().and_then(|f| f.split(' ').next()).and_then(|f| f.parse().ok()).unwrap();
        assert!(ms > 0.0, "{line}");
    }
}

/// A view straight down at [`floor_obj`]'s floor from 3 m, 16 × 16 pixels.
const FLOOR_VIEW: [&str; 10] =
    ["--eye", "0,3,0.01", "--target", "0,0,0", "--fov", "40", "--width", "16", "--height", "16"];

/// Checks that `run` succeeded without the warnings of a scene that has no light of its own.
fn assert_lit_by_its_own_lights(run: &Run) {
    assert!(run.status.success(), "{}", run.stderr);
    assert!(!run.stderr.contains("has no light") && !run.stderr.contains("neutral grey"), "{}", run.stderr);
}

/// A 4 m square floor at y = 0 facing up (grey 0.5, no light), as OBJ in `dir`.
fn floor_obj(dir: &Path) -> &'static str {
    std::fs::write(dir.join("floor.obj"), "v -2 0 -2\nv 2 0 -2\nv 2 0 2\nv -2 0 2\nf 1 3 2\nf 1 4 3\n").unwrap();
    "floor.obj"
}

#[test]
fn a_scene_without_light_is_lit_by_a_neutral_environment_or_the_sun() {
    let dir = tempfile::tempdir().unwrap();
    let floor = floor_obj(dir.path());
    // Without light it is lit by the neutral environment, with one line saying so; with
    // `--env none` too, it renders black, with one line saying that.
    let grey =
        rastergi(dir.path(), &[&["render", floor, "--iterations", "1", "--out", "grey.exr"], &FLOOR_VIEW[..]].concat());
    assert!(grey.status.success(), "{}", grey.stderr);
    let warnings: Vec<&str> = grey.our_stderr().into_iter().filter(|l| l.contains("neutral grey")).collect();
    assert_eq!(warnings.len(), 1, "one warning line:\n{}", grey.stderr);
    assert!(warnings[0].contains("floor.obj: no lights") && warnings[0].contains("--env none"), "{}", warnings[0]);
    let none = ["render", floor, "--iterations", "1", "--env", "none", "--out", "dark.exr"];
    let dark = rastergi(dir.path(), &[&none[..], &FLOOR_VIEW[..]].concat());
    assert!(dark.status.success(), "{}", dark.stderr);
    let warnings: Vec<&str> = dark.our_stderr().into_iter().filter(|l| l.contains("has no light")).collect();
    assert_eq!(warnings.len(), 1, "one warning line:\n{}", dark.stderr);
    let img = rastergi::image_io::read_exr(&dir.path().join("dark.exr")).unwrap();
    assert!(img.pixels.iter().all(|p| *p == [0.0; 3]), "--env none lit the floor");
    // Sun at 30° elevation (azimuth 90°: towards +X), 2 W/m², a point (size 0): the floor gets
    // E sin 30° = 1, radiance ρ/π · 1 everywhere (nothing shadows it, nothing comes back).
    let sun = ["--sun", "90,30,2", "--sun-size", "0"];
    let lit = rastergi(
        dir.path(),
        &[&["render", floor, "--iterations", "4", "--out", "lit.exr"], &FLOOR_VIEW[..], &sun[..]].concat(),
    );
    assert_lit_by_its_own_lights(&lit);
    let img = rastergi::image_io::read_exr(&dir.path().join("lit.exr")).unwrap();
    let expected = 0.5 / std::f32::consts::PI;
    for p in &img.pixels {
        assert!(p.iter().all(|&v| (v - expected).abs() < 1e-5 * expected), "{p:?} against {expected}");
    }
}

#[test]
fn sun_options_out_of_range_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    for (args, fragment) in [
        (&["--sun", "0,100,5"][..], "elevation"),
        (&["--sun", "0,45,-1"][..], "negative"),
        (&["--sun", "0,45,1,2"][..], "IRRADIANCE"),
        (&["--sun", "0,45,1", "--sun-size", "90"][..], "diameter"),
        (&["--sun-size", "1"][..], "--sun"),
    ] {
        refused_render(dir.path(), "cornell", args, 2, fragment);
        assert!(files_in(dir.path()).is_empty());
    }
}

#[test]
fn a_physical_sky_lights_an_open_floor_as_mitsubas_sunsky_does() {
    let dir = tempfile::tempdir().unwrap();
    let floor = floor_obj(dir.path());
    let sky = ["--sky", "3", "--sun", "90,30", "--sun-size", "0", "--gather", "trace"];
    let run = rastergi(
        dir.path(),
        &[&["render", floor, "--iterations", "16", "--out", "sky.exr"], &FLOOR_VIEW[..], &sky[..]].concat(),
    );
    assert_lit_by_its_own_lights(&run);
    // Mitsuba 3.9.1's sunsky (turbidity 3, albedo 0.3, the sun 30° up, its Z-up frame turned
    // to Y up) on an open floor of albedo ½: its sky's irradiance there (a 2000 × 4000
    // midpoint quadrature of `emitter.eval` over the hemisphere) is (0.144370, 0.221091,
    // 0.341498) W/m², its sun's (1.392509, 1.095465, 0.729283) × sin 30°, so the floor's
    // radiance is ½/π times their sum: (0.133790, 0.122362, 0.112386). Measured: within
    // 0.08 % after 16 iterations (the noise of the mean about 0.1 %).
    let img = rastergi::image_io::read_exr(&dir.path().join("sky.exr")).unwrap();
    let (mean, expected) = (img.mean(), [0.13378964, 0.122362, 0.11238556]);
    for c in 0..3 {
        assert!((mean[c] / expected[c] - 1.0).abs() < 0.005, "{mean:?} against Mitsuba's {expected:?}");
    }
}

#[test]
fn physical_sky_errors_are_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    rastergi::image_io::write_exr(
        &d.join("sky.exr"),
        &rastergi::image_io::LinearImage { width: 4, height: 3, pixels: vec![[0.5; 3]; 12] },
    )
    .unwrap();
    for (scene, args, code, fragment) in [
        ("cornell", &["--sky", "0", "--sun", "0,45"][..], 2, "turbidity 0 is not within the model's range 1..10"),
        ("cornell", &["--sky", "11", "--sun", "0,45"][..], 2, "1..10"),
        ("cornell", &["--sky", "clear"][..], 2, "not a number"),
        ("cornell", &["--sky", "3"][..], 1, "--sky needs the sun's position"),
        ("cornell", &["--sky", "3", "--sun", "0,45,1000"][..], 1, "without IRRADIANCE"),
        ("cornell", &["--sun", "0,45"][..], 1, "needs --sky"),
        ("sunroom", &["--sky", "3", "--env", "sky.exr"][..], 1, "give one of them"),
    ] {
        refused_render(d, scene, args, code, fragment);
    }
}

#[test]
fn an_environment_map_lights_an_open_floor_from_exr_and_hdr_alike() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let floor = floor_obj(d);
    // A constant sky of radiance 0.5 (exact in Radiance's RGBE too), 8 × 4 pixels.
    let (w, h) = (8u32, 4u32);
    let sky = rastergi::image_io::LinearImage { width: w, height: h, pixels: vec![[0.5; 3]; (w * h) as usize] };
    rastergi::image_io::write_exr(&d.join("sky.exr"), &sky).unwrap();
    let hdr = image::Rgb32FImage::from_pixel(w, h, image::Rgb([0.5f32; 3]));
    image::DynamicImage::ImageRgb32F(hdr).save_with_format(d.join("sky.hdr"), image::ImageFormat::Hdr).unwrap();
    let mut images = Vec::new();
    for (file, scale) in [("sky.exr", "1"), ("sky.hdr", "1"), ("sky.exr", "2")] {
        let out = format!("{file}-{scale}.exr");
        // The traced gather (auto's choice depends on timing): the same images for the same sky.
        let args = [
            "render",
            floor,
            "--iterations",
            "16",
            "--out",
            &out,
            "--env",
            file,
            "--env-scale",
            scale,
            "--gather",
            "trace",
        ];
        let run = rastergi(d, &[&args[..], &FLOOR_VIEW[..]].concat());
        assert_lit_by_its_own_lights(&run);
        images.push(rastergi::image_io::read_exr(&d.join(out)).unwrap());
    }
    assert_eq!(images[0], images[1], "the same sky from .exr and .hdr renders the same image");
    // E = πL on the open floor: radiance ρL = 0.25, and twice that at --env-scale 2. The mean
    // over the image's 256 pixels after 16 iterations is within 1 % (measured: 0.02 %).
    for (img, l) in [(&images[0], 0.5f32), (&images[2], 1.0)] {
        let mean = img.mean();
        assert!(mean.iter().all(|&m| (m as f32 - 0.5 * l).abs() < 0.01 * 0.5 * l), "{mean:?} against {}", 0.5 * l);
    }
}

#[test]
fn environment_map_errors_are_one_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("sky.exr"), b"not an image").unwrap();
    std::fs::write(d.join("sky.png"), b"not an image either").unwrap();
    for (args, code, fragment) in [
        (&["--env", "missing.exr"][..], 1, "no such environment map"),
        (&["--env", "sky.exr"][..], 1, "cannot read EXR"),
        (&["--env", "sky.png"][..], 1, "use an .exr or .hdr"),
        (&["--env-scale", "2"][..], 2, "--env"),
        (&["--env", "sky.exr", "--env-scale=-1"][..], 2, "finite number"),
    ] {
        refused_render(d, "cornell", args, code, fragment);
    }
}

#[test]
fn point_and_spot_options_light_the_floor_below_them() {
    let dir = tempfile::tempdir().unwrap();
    let floor = floor_obj(dir.path());
    // 15 × 15 pixels looking straight down from 3 m: the centre pixel sees the floor within
    // 0.08 m of the point below the light (1 m up), where E = I·cos θ/d² ∈ [0.98, 1]·I.
    let camera = ["--eye", "0,3,0.001", "--target", "0,0,0", "--fov", "40", "--width", "15", "--height", "15"];
    let centre = |img: &rastergi::image_io::LinearImage| img.pixels[7 * 15 + 7];
    let corner = |img: &rastergi::image_io::LinearImage| img.pixels[0];
    let rho_over_pi = 0.5 / std::f32::consts::PI;
    for (light, out) in [(["--point", "0,1,0,1,1,1"], "point.exr"), (["--spot", "0,1,0,0,0,0,1,1,1,10"], "spot.exr")] {
        let args = [&["render", floor, "--iterations", "8", "--out", out][..], &light[..], &camera[..]].concat();
        let run = rastergi(dir.path(), &args);
        assert_lit_by_its_own_lights(&run);
        let img = rastergi::image_io::read_exr(&dir.path().join(out)).unwrap();
        let c = centre(&img);
        assert!(c.iter().all(|&v| (0.98 * rho_over_pi..=1.0001 * rho_over_pi).contains(&v)), "{out}: centre {c:?}");
        // The corner is 1.5 m out: lit by the point light, outside the spot's 10° cone.
        let k = corner(&img);
        if out == "spot.exr" {
            assert_eq!(k, [0.0; 3], "outside the cone");
        } else {
            assert!(k[0] > 0.01 * rho_over_pi, "{k:?}");
        }
    }
    for (args, fragment) in [
        (&["--point", "0,1,0,1,1"][..], "X,Y,Z,R,G,B"),
        (&["--point", "0,1,0,1,-1,1"][..], "negative"),
        (&["--spot", "0,1,0,0,0,0,1,1,1"][..], "ANGLE"),
        (&["--spot", "0,1,0,0,1,0,1,1,1,10"][..], "aim point"),
        (&["--spot", "0,1,0,0,0,0,1,1,1,100"][..], "cone angles"),
    ] {
        refused_render(dir.path(), "cornell", args, 2, fragment);
    }
}

#[test]
fn denoise_writes_the_denoised_image_to_out_and_the_raw_one_beside_it() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["render", "cornell", "--width", "32", "--height", "32", "--iterations", "8", "--gather", "trace"];
    let plain = rastergi(dir.path(), &[&args[..], &["--out", "plain.exr"]].concat());
    assert!(plain.status.success(), "{}", plain.stderr);
    let extra = ["--denoise", "--albedo", "a.png", "--normal", "n.exr", "--out", "d.exr"];
    let run = rastergi(dir.path(), &[&args[..], &extra[..]].concat());
    assert!(run.status.success(), "{}", run.stderr);
    assert_eq!(files_in(dir.path()), ["a.png", "d.exr", "d.raw.exr", "n.exr", "plain.exr"]);
    let read = |name: &str| rastergi::image_io::read_exr(&dir.path().join(name)).unwrap();
    // The raw image is the one a render without --denoise writes; the denoised one differs.
    assert_eq!(read("d.raw.exr").pixels, read("plain.exr").pixels);
    assert_ne!(read("d.exr").pixels, read("plain.exr").pixels);
    // The normals are unit vectors where a surface is seen, 0 elsewhere; the box fills most
    // of the image.
    let lengths: Vec<f32> =
        read("n.exr").pixels.iter().map(|n| (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt()).collect();
    assert!(lengths.iter().all(|l| *l == 0.0 || (l - 1.0).abs() < 1e-3), "{lengths:?}");
    assert!(lengths.iter().filter(|l| **l > 0.0).count() > 32 * 32 / 2, "{lengths:?}");
    // One-line refusals, before rendering (billions of iterations would hit the timeout).
    let long = ["render", "cornell", "--iterations", "4000000000"];
    let path = rastergi(dir.path(), &[&long[..], &["--method", "path", "--denoise", "--out", "p.exr"]].concat());
    assert!(path.error_line().contains("--method gather"), "{}", path.stderr);
    let png = rastergi(dir.path(), &[&long[..], &["--normal", "n.png", "--out", "q.exr"]].concat());
    assert!(png.error_line().contains(".exr"), "{}", png.stderr);
    let show = rastergi(dir.path(), &[&long[..], &["--show", "direct", "--denoise", "--out", "s.exr"]].concat());
    assert!(show.error_line().contains("--show"), "{}", show.stderr);
    assert_eq!(files_in(dir.path()).len(), 5);
}

/// A command that runs past its timeout is stopped with everything it started (as `xvfb-run`
/// starts Xvfb and a viewer): a shell that starts a background `sleep` and waits; after the
/// timeout's panic the `sleep` must not be running (gone, or a zombie waiting to be reaped).
#[test]
fn a_command_past_its_timeout_is_stopped_with_what_it_started() {
    let dir = tempfile::tempdir().unwrap();
    let started = std::panic::catch_unwind(|| {
        common::run(dir.path(), "sh", &["-c", "sleep 60 & echo $! > pid; wait"], &[], Duration::from_secs(1))
    });
    assert!(started.is_err(), "the shell should have run past its timeout");
    let pid = std::fs::read_to_string(dir.path().join("pid")).unwrap();
    let stat = std::fs::read_to_string(format!("/proc/{}/stat", pid.trim())).unwrap_or_default();
    // The state is the field after the command's name in parentheses.
    let state = stat.rsplit_once(')').map_or("", |(_, rest)| rest.trim_start()).chars().next();
    assert!(matches!(state, None | Some('Z') | Some('X')), "the background sleep still runs: {stat}");
}
