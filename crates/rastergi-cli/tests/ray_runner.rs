//! `scripts/ray_render.py` end to end on a local Ray cluster of this machine (two CPU workers,
//! lavapipe): seed shards with a worker killed mid-shard, retried from its checkpoint and
//! merged; a camera path rendered as frames. Ray comes from scripts/setup.sh (a virtual
//! environment under ~/.local/share/rastergi, or any `python3` that imports it, or
//! RASTERGI_PYTHON).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use rastergi::image_io::read_exr;

const TIMEOUT: Duration = Duration::from_secs(600);

/// A Python that imports Ray.
fn python() -> String {
    common::python_importing("ray", true)
}

fn script() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/ray_render.py")
}

/// The render options of every shard here: the Cornell box at 32², traced gather, few photons,
/// the fitted photon budget and one light sample an iteration (the balanced budget and light
/// samples follow the clock, so a shard resumed from its checkpoint repeats the uninterrupted
/// render bit for bit only with these).
const RENDER: [&str; 12] = [
    "--width",
    "32",
    "--height",
    "32",
    "--gather",
    "trace",
    "--photons",
    "20000",
    "--photon-budget",
    "fitted",
    "--light-samples",
    "1",
];

/// The runner's arguments: the Cornell box with `options`, this build's rastergi, and the
/// render options of every shard here.
fn runner_args(options: &[&str]) -> Vec<String> {
    let mut args = vec![script().to_string_lossy().into_owned(), "cornell".into()];
    args.extend(options.iter().map(|s| s.to_string()));
    args.extend(["--rastergi", env!("CARGO_BIN_EXE_rastergi"), "--"].map(String::from));
    args.extend(RENDER.iter().map(|s| s.to_string()));
    args
}

fn rastergi(dir: &Path, args: &[&str]) {
    let run = common::rastergi(dir, args, TIMEOUT);
    assert!(run.status.success(), "rastergi {args:?}: {}", run.stderr);
}

#[test]
fn shards_survive_a_killed_worker_and_merge_to_the_uninterrupted_image() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let work = d.join("work");
    let args = runner_args(&[
        "--shards",
        "2",
        "--iterations",
        "400",
        "--out",
        "m.exr",
        "--work-dir",
        "work",
        "--gpus-per-task",
        "0",
        "--checkpoint-every",
        "0",
        "--retries",
        "2",
    ]);
    let child = Command::new(python())
        .args(&args)
        .current_dir(d)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Kill shard 1's worker once the shard has written a checkpoint.
    let start = Instant::now();
    let (pid, ckpt) = (work.join("shard-1.pid"), work.join("shard-1.ckpt"));
    while !(pid.exists() && ckpt.exists()) {
        assert!(start.elapsed() < TIMEOUT, "shard 1 never wrote a checkpoint");
        std::thread::sleep(Duration::from_millis(20));
    }
    let worker = std::fs::read_to_string(&pid).unwrap();
    let worker: libc::pid_t = worker.trim().parse().unwrap();
    // SAFETY: kill(2) on the Ray worker's pid (it runs until its task ends, long after this).
    assert_eq!(unsafe { libc::kill(worker, libc::SIGKILL) }, 0, "could not kill worker {worker}");
    let out = child.wait_with_output().unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "the runner failed:\n{stdout}\n{stderr}");
    assert!(stdout.contains("shard-1: 400 iterations (2 attempts)"), "{stdout}\n{stderr}");
    assert!(
        format!("{stdout}{stderr}").contains("shard-1: attempt 2 resumes from its checkpoint"),
        "{stdout}\n{stderr}"
    );
    // The same shards rendered here without interruption, merged: the same image, bit for bit.
    for seed in ["1", "2"] {
        let mut a = vec!["render", "cornell", "--seed", seed, "--iterations", "400"];
        a.extend_from_slice(&RENDER);
        let (o, c) = (format!("d{seed}.exr"), format!("d{seed}.ckpt"));
        a.extend_from_slice(&["--out", &o, "--checkpoint", &c]);
        rastergi(d, &a);
    }
    rastergi(d, &["merge", "d1.ckpt", "d2.ckpt", "--out", "dm.exr"]);
    assert!(read_exr(&d.join("m.exr")).unwrap() == read_exr(&d.join("dm.exr")).unwrap(), "merged images differ");
}

#[test]
fn a_camera_path_renders_one_frame_per_interpolated_camera() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = r#"{"frames": 3, "keys": [
        {"t": 0, "eye": [0, 0, 3.9], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 40},
        {"t": 1, "eye": [0.4, 0.2, 3.5], "target": [0, -0.2, 0], "up": [0, 1, 0], "fov": 50}]}"#;
    std::fs::write(d.join("path.json"), path).unwrap();
    let args = runner_args(&[
        "--camera-path",
        "path.json",
        "--iterations",
        "16",
        "--out",
        "f_{:02d}.exr",
        "--work-dir",
        "work",
        "--gpus-per-task",
        "0",
    ]);
    let out = Command::new(python()).args(&args).current_dir(d).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    // Frame 1 is halfway between the keys; rendered directly, it is the same image.
    let mut a = vec![
        "render",
        "cornell",
        "--seed",
        "1",
        "--iterations",
        "16",
        "--eye",
        "0.2,0.1,3.7",
        "--target",
        "0,-0.1,0",
        "--up",
        "0,1,0",
        "--fov",
        "45",
        "--out",
        "direct.exr",
    ];
    a.extend_from_slice(&RENDER);
    rastergi(d, &a);
    for k in 0..3 {
        assert!(d.join(format!("f_{k:02}.exr")).exists(), "frame {k} missing");
    }
    assert!(read_exr(&d.join("f_01.exr")).unwrap() == read_exr(&d.join("direct.exr")).unwrap(), "frame 1 differs");
}
