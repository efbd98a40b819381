//! The Python package (`python/`) end to end: builds its wheel with maturin, installs it into
//! a temporary directory (the virtual environment is left as it is) and runs its pytest tests
//! (`python/tests`), which check it against this build's `rastergi` binary: the same images,
//! bit for bit, the same compare numbers, the same error messages. maturin, pytest and numpy
//! come from scripts/setup.sh (the virtual environment under ~/.local/share/rastergi, or
//! RASTERGI_PYTHON).

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..").canonicalize().unwrap()
}

/// A Python with maturin, pytest and numpy.
fn python() -> String {
    common::python_importing("maturin, pytest, numpy", false)
}

fn show(what: &str, out: &Output) -> String {
    format!(
        "{what} failed ({}):\n--- stdout\n{}\n--- stderr\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

#[test]
fn the_python_package_passes_its_tests_against_the_cli() {
    let python = python();
    let repo = repo();
    let dir = tempfile::tempdir().unwrap();
    let (wheels, site) = (dir.path().join("wheels"), dir.path().join("site"));

    // The wheel, built by a nested cargo in the workspace's target/: the cargo running this
    // test has released target/'s lock by then (it does not block), and rastergi and the CLI
    // are built already. maturin's environment (PYO3_PYTHON...) differs from a plain cargo
    // build's, so pyo3, numpy and the module are rebuilt when the two alternate (about 12 s
    // on 2 cores); a target directory of its own would build all of wgpu again instead.
    let start = Instant::now();
    let out = Command::new(&python)
        .args(["-m", "maturin", "build", "--release", "--quiet", "-m"])
        .arg(repo.join("python/Cargo.toml"))
        .arg("-o")
        .arg(&wheels)
        .current_dir(&repo)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", show("maturin build", &out));
    eprintln!("wheel built in {:.1} s", start.elapsed().as_secs_f64());
    let wheel = std::fs::read_dir(&wheels)
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|e| e == "whl"));
    let wheel = wheel.expect("maturin wrote no wheel");
    let out = Command::new(&python)
        .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--no-deps", "--target"])
        .arg(&site)
        .arg(&wheel)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", show("pip install", &out));

    let start = Instant::now();
    let out = Command::new(&python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider"])
        .arg(repo.join("python/tests"))
        .env("PYTHONPATH", &site)
        .env("PYTHONDONTWRITEBYTECODE", "1")
        .env("RASTERGI_BIN", env!("CARGO_BIN_EXE_rastergi"))
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", show("pytest python/tests", &out));
    eprintln!("pytest in {:.1} s:\n{}", start.elapsed().as_secs_f64(), String::from_utf8_lossy(&out.stdout));
}
