//! Shared harness of the command-line tests: run a program with a time limit and keep its
//! exit status and output.
#![allow(dead_code)]

use std::fs::File;
use std::path::Path;
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use rastergi::image_io::{LinearImage, read_exr};

/// A finished run: its exit status and what it printed.
pub struct Run {
    pub status: ExitStatus,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    /// stderr without the lines Mesa prints on its own when XDG_RUNTIME_DIR is not set
    /// ("error: XDG_RUNTIME_DIR is invalid or not set in the environment.") and blank lines.
    pub fn our_stderr(&self) -> Vec<&str> {
        self.stderr.lines().filter(|l| !l.contains("XDG_RUNTIME_DIR") && !l.trim().is_empty()).collect()
    }

    /// The only line of our stderr, after checking that the run failed without a panic and
    /// printed exactly one line, starting with `error: `.
    pub fn sole_error_line(&self) -> &str {
        assert!(!self.status.success(), "the run succeeded; stderr:\n{}", self.stderr);
        assert!(!self.stderr.contains("panicked"), "the run panicked:\n{}", self.stderr);
        let lines = self.our_stderr();
        assert_eq!(lines.len(), 1, "expected one error line, got:\n{}", self.stderr);
        assert!(lines[0].starts_with("error: "), "{}", lines[0]);
        lines[0]
    }
}

/// Runs `program args` in `dir` with the environment changes `env` (`None` removes a
/// variable); a run longer than `timeout` is killed and fails the test.
pub fn run(dir: &Path, program: &str, args: &[&str], env: &[(&str, Option<&str>)], timeout: Duration) -> Run {
    let out = tempfile::tempdir().unwrap();
    let (stdout_path, stderr_path) = (out.path().join("stdout"), out.path().join("stderr"));
    let mut command = Command::new(program);
    command
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::null())
        .stdout(File::create(&stdout_path).unwrap())
        .stderr(File::create(&stderr_path).unwrap());
    for (key, value) in env {
        match value {
            Some(v) => command.env(key, v),
            None => command.env_remove(key),
        };
    }
    // Its own process group, so that a timeout stops what it started too (`xvfb-run` starts
    // Xvfb and the viewer: killing the script alone left them running, a viewer at 80 % of a
    // core slowing every test after it).
    std::os::unix::process::CommandExt::process_group(&mut command, 0);
    let mut child = match command.spawn() {
        Ok(child) => child,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound && program == "xvfb-run" => panic!(
            "xvfb-run is not installed: the viewer tests need an X server; install it with `apt-get install xvfb xauth` (scripts/setup.sh does)"
        ),
        Err(e) => panic!("cannot start {program}: {e}"),
    };
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > timeout {
            let _ = Command::new("kill").args(["-KILL", "--", &format!("-{}", child.id())]).status();
            let _ = child.kill();
            let _ = child.wait();
            panic!("{program} {args:?} ran longer than {timeout:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let read = |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap()).into_owned();
    Run { status, stdout: read(&stdout_path), stderr: read(&stderr_path) }
}

/// The arguments of `rastergi render cornell` at `size` × `size` pixels, then `more`.
pub fn render_cornell<'a>(size: &'a str, more: &[&'a str]) -> Vec<&'a str> {
    [&["render", "cornell", "--width", size, "--height", size][..], more].concat()
}

/// The Cornell box's references at 128² (Mitsuba 3, two independent renders of its path
/// tracer).
pub fn cornell_reference_pair() -> (LinearImage, LinearImage) {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rastergi/tests/data");
    (read_exr(&data.join("cornell_path_128_a.exr")).unwrap(), read_exr(&data.join("cornell_path_128_b.exr")).unwrap())
}

/// Runs the `rastergi` binary with `args` in `dir`.
pub fn rastergi(dir: &Path, args: &[&str], timeout: Duration) -> Run {
    run(dir, env!("CARGO_BIN_EXE_rastergi"), args, &[], timeout)
}

/// The names of the files in `dir`, sorted.
pub fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

/// The first Python that imports `modules` (comma-separated, e.g. "maturin, pytest") among
/// `RASTERGI_PYTHON`, the virtual environment `scripts/setup.sh` makes
/// (`~/.local/share/rastergi/venv`) and `python3` where `system` is set; without one, a panic
/// that says to run the set-up.
pub fn python_importing(modules: &str, system: bool) -> String {
    let mut candidates = Vec::new();
    if let Ok(p) = std::env::var("RASTERGI_PYTHON") {
        candidates.push(p);
    }
    if let Some(home) = std::env::var_os("HOME") {
        candidates.push(Path::new(&home).join(".local/share/rastergi/venv/bin/python").to_string_lossy().into_owned());
    }
    if system {
        candidates.push("python3".to_owned());
    }
    for c in &candidates {
        let ok = Command::new(c).args(["-c", &format!("import {modules}")]).stderr(Stdio::null()).status();
        if ok.is_ok_and(|s| s.success()) {
            return c.clone();
        }
    }
    panic!("no Python importing {modules} among {candidates:?}: run `bash scripts/setup.sh`, which installs them");
}
