//! Long renders: checkpoints and resuming, interruption by a signal, merging the renders of
//! several seeds, the time limit, the error target, and a GPU lost mid-render.

mod common;

use std::path::Path;
use std::time::Duration;

use common::Run;
use rastergi::checkpoint::Checkpoint;
use rastergi::image_io::{LinearImage, read_exr};

const TIMEOUT: Duration = Duration::from_secs(300);

fn rastergi(dir: &Path, args: &[&str]) -> Run {
    common::rastergi(dir, args, TIMEOUT)
}

/// The Cornell box at 32² with the traced gather and photon passes of 4 iterations (so
/// renders cross pass boundaries) and one light sample an iteration (the balanced count
/// follows timings, so only a fixed one repeats bit for bit), seed `seed`, plus `more`.
fn gather_args<'a>(seed: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    let gather =
        ["--gather", "trace", "--photons", "20000", "--pass-iterations", "4", "--light-samples", "1", "--seed", seed];
    common::render_cornell("32", &[&gather[..], more].concat())
}

/// The Cornell box at 32² with the path tracer, seed `seed`, plus `more`.
fn path_args<'a>(seed: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    common::render_cornell("32", &[&["--method", "path", "--seed", seed][..], more].concat())
}

fn ok(run: &Run) {
    assert!(run.status.success(), "the run failed:\n{}", run.stderr);
}

fn exr(dir: &Path, name: &str) -> LinearImage {
    read_exr(&dir.join(name)).unwrap()
}

#[test]
fn a_resumed_render_equals_the_uninterrupted_one_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for label in ["photon map", "path"] {
        let args = |seed: &'static str, more: &[&'static str]| {
            if label == "path" { path_args(seed, more) } else { gather_args(seed, more) }
        };
        // 10 iterations, stop; resume to 24 (across photon passes 2 … 5); against 24 at once.
        ok(&rastergi(d, &args("3", &["--iterations", "10", "--out", "a.exr", "--checkpoint", "a.ckpt"])));
        let c = Checkpoint::read(&d.join("a.ckpt")).unwrap();
        assert_eq!(c.film.samples, 10, "{label}");
        ok(&rastergi(
            d,
            &args("3", &["--iterations", "24", "--out", "b.exr", "--resume", "a.ckpt", "--checkpoint", "b.ckpt"]),
        ));
        ok(&rastergi(d, &args("3", &["--iterations", "24", "--out", "c.exr", "--checkpoint", "c.ckpt"])));
        assert!(exr(d, "b.exr") == exr(d, "c.exr"), "{label}: resumed and uninterrupted images differ");
        let (b, c) = (Checkpoint::read(&d.join("b.ckpt")).unwrap(), Checkpoint::read(&d.join("c.ckpt")).unwrap());
        assert!(b == c, "{label}: resumed and uninterrupted checkpoints differ");
    }
}

#[test]
fn a_signal_at_a_random_moment_leaves_a_valid_image_and_a_checkpoint_that_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let exe = env!("CARGO_BIN_EXE_rastergi");
    // A random moment: a delay drawn from the clock's nanoseconds, after the first checkpoint.
    let nanos = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().subsec_nanos();
    for (k, signal) in [("INT", 130), ("TERM", 143)].into_iter().enumerate() {
        let (name, code) = signal;
        let (out, ckpt) = (format!("i{k}.exr"), format!("i{k}.ckpt"));
        let args = gather_args(
            "5",
            &["--iterations", "1000000", "--out", &out, "--checkpoint", &ckpt, "--checkpoint-every", "0"],
        );
        let child = std::process::Command::new(exe)
            .args(&args)
            .current_dir(d)
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let start = std::time::Instant::now();
        while !d.join(&ckpt).exists() {
            assert!(start.elapsed() < TIMEOUT, "no checkpoint was written");
            std::thread::sleep(Duration::from_millis(10));
        }
        let delay = (nanos >> (8 * k)) % 700;
        std::thread::sleep(Duration::from_millis(delay as u64));
        let sig = if name == "INT" { libc::SIGINT } else { libc::SIGTERM };
        // SAFETY: kill(2) on the child's pid, which is alive until waited for below.
        assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, sig) }, 0, "kill failed");
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(code), "SIG{name} after {delay} ms: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        let c = Checkpoint::read(&d.join(&ckpt)).unwrap();
        let n = c.film.samples;
        let line = format!("interrupted (SIG{name}): {out} holds {n} of 1000000 iterations");
        assert!(stderr.contains(&line), "expected '{line}' in:\n{stderr}");
        // The image is the checkpoint's; resuming it to n + 6 equals n + 6 at once.
        let (image, expected) = (exr(d, &out), c.film.image(rastergi::passes::film::Show::Full));
        let close = image
            .pixels
            .iter()
            .zip(&expected.pixels)
            .all(|(p, q)| (0..3).all(|k| (p[k] - q[k]).abs() <= 1e-6 * q[k].abs().max(1e-3)));
        assert!(close, "SIG{name}: the image is not the checkpoint's mean");
        let total = (n + 6).to_string();
        ok(&rastergi(d, &gather_args("5", &["--iterations", &total, "--out", "r.exr", "--resume", &ckpt])));
        ok(&rastergi(d, &gather_args("5", &["--iterations", &total, "--out", "u.exr"])));
        assert!(exr(d, "r.exr") == exr(d, "u.exr"), "SIG{name} at {n} iterations: resumed ≠ uninterrupted");
    }
}

#[test]
fn checkpoints_of_other_scenes_settings_or_seeds_and_damaged_ones_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&rastergi(d, &gather_args("1", &["--iterations", "8", "--out", "a.exr", "--checkpoint", "a.ckpt"])));
    let bytes = std::fs::read(d.join("a.ckpt")).unwrap();
    std::fs::write(d.join("short.ckpt"), &bytes[..bytes.len() / 2]).unwrap();
    let mut flipped = bytes.clone();
    flipped[bytes.len() / 3] ^= 1;
    std::fs::write(d.join("flipped.ckpt"), &flipped).unwrap();
    std::fs::write(d.join("text.ckpt"), "not a checkpoint").unwrap();
    let cases: [(&str, Vec<&str>, &str); 7] = [
        ("other settings", gather_args("1", &["--grid", "12"]), "grid"),
        (
            "other size",
            gather_args("1", &[]).into_iter().map(|a| if a == "32" { "16" } else { a }).collect(),
            "size 32x32, here 16x16",
        ),
        ("other seed", gather_args("2", &[]), "--seed 1"),
        ("other camera", gather_args("1", &["--fov", "50"]), "another scene or camera"),
        ("other method", path_args("1", &[]), "method gather, here path"),
        ("truncated", gather_args("1", &[]), "truncated or damaged"),
        ("not one", gather_args("1", &[]), "not a rastergi checkpoint"),
    ];
    for (label, mut args, expected) in cases {
        let file = match label {
            "truncated" => "short.ckpt",
            "not one" => "text.ckpt",
            _ => "a.ckpt",
        };
        args.extend_from_slice(&["--iterations", "16", "--out", "x.exr", "--resume", file]);
        let run = rastergi(d, &args);
        let line = run.sole_error_line();
        assert!(line.contains(expected), "{label}: expected '{expected}' in: {line}");
        assert!(!d.join("x.exr").exists(), "{label}: wrote an image");
    }
    let run = rastergi(d, &gather_args("1", &["--iterations", "16", "--out", "x.exr", "--resume", "flipped.ckpt"]));
    assert!(run.sole_error_line().contains("truncated or damaged"));
}

#[test]
fn merged_seeds_equal_one_long_render_within_the_predicted_noise() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // The path tracer (independent iterations): 48 + 16 iterations of seeds 1 and 2 merged,
    // against 64 of seed 3.
    ok(&rastergi(d, &path_args("1", &["--iterations", "48", "--out", "1.exr", "--checkpoint", "1.ckpt"])));
    ok(&rastergi(d, &path_args("2", &["--iterations", "16", "--out", "2.exr", "--checkpoint", "2.ckpt"])));
    ok(&rastergi(d, &path_args("3", &["--iterations", "64", "--out", "3.exr", "--checkpoint", "3.ckpt"])));
    let run = rastergi(d, &["merge", "1.ckpt", "2.ckpt", "--out", "m.exr", "--checkpoint", "m.ckpt"]);
    ok(&run);
    // The merged mean weighs each render by its iterations: (48·a + 16·b)/64 from the images.
    let (a, b, m, long) = (exr(d, "1.exr"), exr(d, "2.exr"), exr(d, "m.exr"), exr(d, "3.exr"));
    for ((pa, pb), pm) in a.pixels.iter().zip(&b.pixels).zip(&m.pixels) {
        for c in 0..3 {
            let expected = (48.0 * pa[c] + 16.0 * pb[c]) / 64.0;
            assert!((pm[c] - expected).abs() <= 1e-5 * expected.abs().max(1.0), "{pm:?} against {expected}");
        }
    }
    // Merged and long are independent estimates of one image, and so are two long renders of
    // other seeds: m − l and l − l' have the same distribution (the merged render's variance
    // that of one as long, up to the slightly worse stratification of two shorter sequences).
    // The path tracer's noise at 64 iterations is heavy-tailed (a few bright paths dominate a
    // sum of squares), so the test compares the medians of |m − l| and |l − l'|.
    ok(&rastergi(d, &path_args("4", &["--iterations", "64", "--out", "4.exr"])));
    let other = exr(d, "4.exr");
    let median_abs = |x: &LinearImage, y: &LinearImage| -> f64 {
        let mut v: Vec<f64> = x
            .pixels
            .iter()
            .zip(&y.pixels)
            .flat_map(|(p, q)| (0..3).map(move |c| (p[c] as f64 - q[c] as f64).abs()))
            .collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let ratio = median_abs(&m, &long) / median_abs(&long, &other);
    println!("merged vs long: median |m − l| / median |l − l'| = {ratio:.3}");
    // Measured over six sets of seeds: 0.95 … 1.08.
    assert!((0.85..1.2).contains(&ratio), "ratio {ratio}");
    // Merging a seed twice is refused; so is a merged checkpoint as a resume.
    let run = rastergi(d, &["merge", "1.ckpt", "m.ckpt", "--out", "x.exr"]);
    assert!(run.sole_error_line().contains("holds seed 1 like 1.ckpt"), "{}", run.stderr);
    let run = rastergi(d, &path_args("1", &["--iterations", "80", "--out", "x.exr", "--resume", "m.ckpt"]));
    assert!(run.sole_error_line().contains("cannot be resumed"), "{}", run.stderr);
    assert!(!d.join("x.exr").exists());
}

#[test]
fn the_time_limit_stops_a_render_that_would_not_end_and_writes_its_image() {
    let dir = tempfile::tempdir().unwrap();
    let run =
        rastergi(dir.path(), &gather_args("1", &["--iterations", "1000000", "--time-limit", "2", "--out", "t.png"]));
    ok(&run);
    assert!(
        run.stderr.contains("--time-limit 2 reached:") && run.stderr.contains("of 1000000 iterations"),
        "{}",
        run.stderr
    );
    assert!(dir.path().join("t.png").exists());
}

#[test]
fn the_target_error_stops_when_the_estimate_reaches_it_and_the_estimate_is_the_true_noise() {
    // The path tracer (unbiased: its error is its noise) against Mitsuba's pair: the error
    // estimated from the halves, against the RMSE measured against the references less their
    // own noise. The estimate errs on the safe side by about a tenth (rastergi::passes::film: blocks of
    // 16 iterations keep the Sobol' sequences' halves stratified).
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let options = ["--iterations", "100000", "--target-error", "0.07", "--out", "e.exr", "--checkpoint", "e.ckpt"];
    let run =
        rastergi(d, &common::render_cornell("128", &[&["--method", "path", "--seed", "4"][..], &options].concat()));
    ok(&run);
    assert!(run.stderr.contains("--target-error 0.07 reached"), "{}", run.stderr);
    let c = Checkpoint::read(&d.join("e.ckpt")).unwrap();
    let estimate = c.film.error_estimate().unwrap();
    assert!(estimate <= 0.07, "stopped at an estimate of {estimate}");
    let (ra, rb) = common::cornell_reference_pair();
    let image = exr(d, "e.exr");
    // Over the pixels the estimate covers: those that never saw the light itself.
    let (mut mse, mut mean, mut n) = (0.0f64, 0.0f64, 0.0f64);
    for (i, ((p, a), b)) in image.pixels.iter().zip(&ra.pixels).zip(&rb.pixels).enumerate() {
        if c.film.sees_light(i) {
            continue;
        }
        n += 3.0;
        for ch in 0..3 {
            let r = 0.5 * (a[ch] as f64 + b[ch] as f64);
            // (x − r)² less the reference mean's own variance, (a − b)²/4.
            mse += (p[ch] as f64 - r).powi(2) - 0.25 * (a[ch] as f64 - b[ch] as f64).powi(2);
            mean += r;
        }
    }
    let measured = (mse / n).max(0.0).sqrt() / (mean / n);
    println!(
        "{} iterations: estimated relative error {estimate:.4}, measured against Mitsuba {measured:.4}",
        c.film.samples
    );
    assert!((0.75..1.1).contains(&(measured / estimate)), "estimated {estimate}, measured {measured}");
}

#[test]
fn a_gpu_lost_mid_render_is_one_error_line_and_leaves_the_last_checkpoint_and_the_old_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("old.png"), b"the previous image").unwrap();
    let args = gather_args(
        "1",
        &["--iterations", "1000", "--out", "old.png", "--checkpoint", "l.ckpt", "--checkpoint-every", "0"],
    );
    let run = common::run(
        d,
        env!("CARGO_BIN_EXE_rastergi"),
        &args,
        &[("RASTERGI_TEST_LOSE_DEVICE_AFTER", Some("20"))],
        TIMEOUT,
    );
    let line = run.sole_error_line();
    assert!(line.contains("lost"), "{line}");
    assert_eq!(std::fs::read(d.join("old.png")).unwrap(), b"the previous image");
    let c = Checkpoint::read(&d.join("l.ckpt")).unwrap();
    assert!(c.film.samples >= 8 && c.film.samples <= 20, "checkpoint of {} iterations", c.film.samples);
}
