//! Helpers of the Mitsuba loader's tests (`mitsuba_xml.rs`, `mitsuba_files.rs`): the test data,
//! loading, finding materials, and the warnings the loader logs.

use std::path::{Path, PathBuf};
use std::sync::{Mutex, Once};

use glam::Vec3;
use rastergi::scene::{Material, MitsubaOptions, MitsubaScene, Scene, load_mitsuba};

pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/mitsuba").join(name)
}

pub fn load(path: &Path) -> MitsubaScene {
    load_mitsuba(path, &MitsubaOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

pub fn load_err(path: &Path) -> String {
    match load_mitsuba(path, &MitsubaOptions::default()) {
        Ok(_) => panic!("{} loaded, but an error was expected", path.display()),
        Err(e) => e.to_string(),
    }
}

/// The error of loading the scene file `name` holding `xml`, written alone into a scratch
/// folder; asserts that it holds each of `needles`.
pub fn load_err_of(name: &str, xml: &[u8], needles: &[&str]) -> String {
    let dir = scratch(&[(name, xml)]);
    let e = load_err(&dir.path().join(name));
    for needle in needles {
        assert!(e.contains(needle), "'{needle}' not in: {e}");
    }
    e
}

pub fn material<'a>(scene: &'a Scene, name: &str) -> &'a Material {
    scene.materials.iter().find(|m| m.name == name).unwrap_or_else(|| {
        panic!("no material '{name}' among {:?}", scene.materials.iter().map(|m| &m.name).collect::<Vec<_>>())
    })
}

pub fn triangles_of(scene: &Scene, name: &str) -> Vec<usize> {
    (0..scene.triangles.len()).filter(|&i| scene.material_of(i).name == name).collect()
}

pub fn close(a: Vec3, b: Vec3, eps: f32) -> bool {
    (a - b).abs().max_element() <= eps
}

/// Warnings logged while the tests run (a logger of this test binary).
pub static WARNINGS: Mutex<Vec<String>> = Mutex::new(Vec::new());

struct Capture;

static CAPTURE: Capture = Capture;

impl log::Log for Capture {
    fn enabled(&self, m: &log::Metadata) -> bool {
        m.level() <= log::Level::Warn
    }
    fn log(&self, r: &log::Record) {
        if r.level() <= log::Level::Warn {
            WARNINGS.lock().unwrap().push(r.args().to_string());
        }
    }
    fn flush(&self) {}
}

/// The warnings that name `file`.
pub fn warnings_about(file: &Path) -> Vec<String> {
    static INIT: Once = Once::new();
    INIT.call_once(|| {
        let _ = log::set_logger(&CAPTURE);
        log::set_max_level(log::LevelFilter::Warn);
    });
    let name = file.display().to_string();
    WARNINGS.lock().unwrap().iter().filter(|w| w.contains(&name)).cloned().collect()
}

pub fn start_capture() {
    warnings_about(Path::new(""));
}

/// A scratch folder with `files` written into it.
pub fn scratch(files: &[(&str, &[u8])]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.path().join(name), bytes).unwrap();
    }
    dir
}

/// Linear sRGB of a flat emission spectrum of value 1 in Mitsuba 3's RGB variants, printed by
/// mitsuba 3.9.1 for `<spectrum name="radiance" value="1"/>` on an area emitter
/// (`SRGBReflectanceSpectrum[value = [1.20479, 0.948291, 0.908916]]`): `<spectrum>` values
/// on emitters are emission spectra there, `<rgb>` and `<float>` stay as given.
pub const EQUAL_ENERGY_SRGB: Vec3 = Vec3::new(1.20479, 0.948291, 0.908916);
