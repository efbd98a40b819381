//! Robustness of `load_obj` against hostile input: arbitrary bytes, OBJ/MTL lines drawn from
//! the format's grammar with hostile values, and mutations of the valid fixtures in
//! `tests/data/obj/`. Every input must end in `Ok` with a scene that passes validation, or in
//! a one-line error that names a file — never a panic, never a hang (each load runs under a
//! watchdog). Inputs that once failed are kept in `tests/data/obj/corpus/` and loaded by
//! `regression_corpus_loads_or_is_refused_by_name`.
//!
//! The number of generated cases is bounded so the whole file runs in seconds; set
//! `RASTERGI_FUZZ_CASES` (or `PROPTEST_CASES`) to fuzz longer.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use rastergi::scene::load_obj;

/// Generated cases per strategy (overridden by `RASTERGI_FUZZ_CASES` or `PROPTEST_CASES`).
const CASES: u32 = 2000;
/// A load that takes longer than this on a few kilobytes of text is a hang.
const WATCHDOG: Duration = Duration::from_secs(20);

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/obj").join(name)
}

fn config() -> Config {
    let cases = ["RASTERGI_FUZZ_CASES", "PROPTEST_CASES"]
        .iter()
        .find_map(|v| std::env::var(v).ok().and_then(|c| c.parse().ok()))
        .unwrap_or(CASES);
    // Failures are reported with the shrunk input; nothing is written beside the sources.
    Config { cases, failure_persistence: None, ..Config::default() }
}

/// Loads `obj` (with the files `others` beside it) in a fresh directory, under a watchdog,
/// and checks the outcome: a valid scene, or a one-line error naming a file. Counts the
/// accepted inputs in `accepted`.
fn check_load(obj: &[u8], others: &[(&str, Vec<u8>)], accepted: &AtomicU32) -> Result<(), TestCaseError> {
    let dir = tempfile::tempdir().map_err(|e| TestCaseError::fail(e.to_string()))?;
    let path = dir.path().join("fuzz.obj");
    std::fs::write(&path, obj).map_err(|e| TestCaseError::fail(e.to_string()))?;
    for (name, bytes) in others {
        std::fs::write(dir.path().join(name), bytes).map_err(|e| TestCaseError::fail(e.to_string()))?;
    }
    let outcome = load_under_watchdog(&path)?;
    if outcome.is_ok() {
        accepted.fetch_add(1, Ordering::Relaxed);
    }
    check_outcome(&path, dir.path(), outcome)
}

/// Fails unless at least `min` of the runner's cases were accepted: a fuzzer whose inputs are
/// all refused at the first line never reaches the code after it.
fn report(what: &str, accepted: &AtomicU32, cases: u32, min: f64) {
    let fraction = accepted.load(Ordering::Relaxed) as f64 / cases as f64;
    println!("{what}: {:.1} % of {cases} inputs loaded", 100.0 * fraction);
    assert!(fraction >= min, "{what}: only {:.1} % of the inputs loaded", 100.0 * fraction);
}

/// `load_obj(path)` on another thread: `Err` if it panicked or did not return in time.
fn load_under_watchdog(path: &Path) -> Result<Result<rastergi::scene::Scene, String>, TestCaseError> {
    let (tx, rx) = mpsc::channel();
    let owned = path.to_path_buf();
    std::thread::spawn(move || {
        let result = std::panic::catch_unwind(|| load_obj(&owned).map_err(|e| e.to_string()));
        let _ = tx.send(result);
    });
    match rx.recv_timeout(WATCHDOG) {
        Ok(Ok(result)) => Ok(result),
        Ok(Err(panic)) => {
            let message = panic
                .downcast_ref::<String>()
                .cloned()
                .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                .unwrap_or_default();
            Err(TestCaseError::fail(format!("load_obj panicked: {message}")))
        }
        Err(_) => Err(TestCaseError::fail(format!("load_obj did not return within {WATCHDOG:?}"))),
    }
}

fn check_outcome(
    path: &Path,
    dir: &Path,
    outcome: Result<rastergi::scene::Scene, String>,
) -> Result<(), TestCaseError> {
    match outcome {
        Ok(scene) => {
            prop_assert!(!scene.triangles.is_empty());
            prop_assert!(scene.validate().is_ok(), "an accepted scene fails validation: {:?}", scene.validate());
        }
        Err(message) => {
            // The OBJ itself or a file it names (an MTL library, a texture) beside it.
            let names_a_file =
                message.contains(&path.display().to_string()) || message.contains(&dir.display().to_string());
            prop_assert!(names_a_file, "the error names no file: {}", message);
            prop_assert!(!message.contains('\n'), "the error is not one line: {}", message);
        }
    }
    Ok(())
}

/// Numbers as they appear in real and broken files.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-10.0f32..10.0).prop_map(|x| format!("{x}")),
        2 => (0u32..8).prop_map(|i| i.to_string()),
        1 => prop::sample::select(vec![
            "nan", "NaN", "inf", "-inf", "1e39", "-1e39", "1e-45", "-0", "0x10", "1,5", "", "e", ".", "-", "+1",
            "3.4028235e38", "99999999999", "-99999999999", "18446744073709551616", "9223372036854775807",
            "-9223372036854775808",
        ])
        .prop_map(str::to_owned),
    ]
}

/// A vertex reference of an `f`, `l` or `p` line: `v`, `v/vt`, `v//vn` or `v/vt/vn`, with
/// in-range, relative, zero, huge and malformed indices.
fn vertex_ref() -> impl Strategy<Value = String> {
    let index = prop_oneof![
        6 => (1i64..6).prop_map(|i| i.to_string()),
        3 => (-5i64..0).prop_map(|i| i.to_string()),
        1 => prop::sample::select(vec![
            "0", "99999999999", "-99999999999", "9223372036854775807", "-9223372036854775808",
            "18446744073709551616", "4294967296", "4294967295", "2147483648", "", "a", "1.5", "--1",
        ])
        .prop_map(str::to_owned),
    ];
    (index.clone(), index.clone(), index, 0usize..4).prop_map(|(v, t, n, form)| match form {
        0 => v,
        1 => format!("{v}/{t}"),
        2 => format!("{v}//{n}"),
        _ => format!("{v}/{t}/{n}"),
    })
}

fn name() -> impl Strategy<Value = String> {
    prop::sample::select(vec![
        "m",
        "light",
        "grey",
        "missing",
        "",
        " ",
        "a b",
        "fuzz.mtl",
        "other.mtl",
        "nope.mtl",
        ".",
        "..",
        "/",
        "/dev/null",
        "/dev/zero",
        "fuzz.obj",
        "tex.png",
        "bad.png",
        "missing.png",
    ])
    .prop_map(str::to_owned)
}

/// One line of an OBJ file.
fn obj_line() -> impl Strategy<Value = String> {
    let numbers = |n: std::ops::Range<usize>| prop::collection::vec(number(), n).prop_map(|v| v.join(" "));
    prop_oneof![
        6 => numbers(0..7).prop_map(|n| format!("v {n}")),
        5 => prop::collection::vec(vertex_ref(), 0..9).prop_map(|r| format!("f {}", r.join(" "))),
        1 => numbers(0..4).prop_map(|n| format!("vt {n}")),
        1 => numbers(0..4).prop_map(|n| format!("vn {n}")),
        1 => prop::collection::vec(vertex_ref(), 0..4).prop_map(|r| format!("l {}", r.join(" "))),
        1 => prop::collection::vec(vertex_ref(), 0..3).prop_map(|r| format!("p {}", r.join(" "))),
        2 => name().prop_map(|n| format!("usemtl {n}")),
        1 => name().prop_map(|n| format!("mtllib {n}")),
        1 => name().prop_map(|n| format!("o {n}")),
        1 => name().prop_map(|n| format!("g {n}")),
        1 => prop::sample::select(vec!["s 1", "s off", "# comment", "", "   ", "\\", "v 1 2 \\", "usemtl", "mtllib", "f", "vt", "\r"])
            .prop_map(str::to_owned),
        1 => "[ -~]{0,40}",
    ]
}

/// One line of an MTL file.
fn mtl_line() -> impl Strategy<Value = String> {
    let numbers = |n: std::ops::Range<usize>| prop::collection::vec(number(), n).prop_map(|v| v.join(" "));
    let option =
        prop::sample::select(vec!["", "-o 1 2 ", "-s 1 ", "-clamp on ", "-mm 0 1 ", "-bm ", "-zz 1 ", "-o ", "-o a "]);
    prop_oneof![
        3 => name().prop_map(|n| format!("newmtl {n}")),
        4 => (prop::sample::select(vec!["Kd", "Ke", "Ka", "Ks"]), numbers(0..5)).prop_map(|(k, n)| format!("{k} {n}")),
        1 => (prop::sample::select(vec!["Ns", "Ni", "d", "Tr", "illum"]), numbers(0..3)).prop_map(|(k, n)| format!("{k} {n}")),
        2 => (option, name()).prop_map(|(o, n)| format!("map_Kd {o}{n}")),
        1 => "[ -~]{0,40}",
    ]
}

/// A well-formed OBJ line, given five vertices and three texture coordinates before it.
fn valid_obj_line() -> impl Strategy<Value = String> {
    let coordinate = || (-10.0f32..10.0).prop_map(|x| format!("{x}"));
    let index = |n: i64| prop_oneof![(1..=n).prop_map(|i| i.to_string()), (-n..=-1).prop_map(|i| i.to_string())];
    let corner = (index(5), index(3), index(5), 0usize..4).prop_map(|(v, t, n, form)| match form {
        0 => v,
        1 => format!("{v}/{t}"),
        2 => format!("{v}//{n}"),
        _ => format!("{v}/{t}/{n}"),
    });
    prop_oneof![
        3 => (coordinate(), coordinate(), coordinate()).prop_map(|(x, y, z)| format!("v {x} {y} {z}")),
        1 => (coordinate(), coordinate(), coordinate(), 0.5f32..2.0).prop_map(|(x, y, z, w)| format!("v {x} {y} {z} {w}")),
        1 => (0.0f32..1.0, 0.0f32..1.0).prop_map(|(u, v)| format!("vt {u} {v}")),
        6 => prop::collection::vec(corner, 3..7).prop_map(|c| format!("f {}", c.join(" "))),
        2 => prop::sample::select(vec!["m", "light", "textured", "undefined"]).prop_map(|n| format!("usemtl {n}")),
        1 => prop::sample::select(vec!["o a", "g b", "s 1", "# comment", ""]).prop_map(str::to_owned),
    ]
}

/// A well-formed MTL line.
fn valid_mtl_line() -> impl Strategy<Value = String> {
    let colour = |max: f32| (0.0..max, 0.0..max, 0.0..max).prop_map(|(r, g, b)| format!("{r} {g} {b}"));
    prop_oneof![
        2 => prop::sample::select(vec!["m", "light", "textured"]).prop_map(|n| format!("newmtl {n}")),
        3 => colour(1.0).prop_map(|c| format!("Kd {c}")),
        1 => colour(20.0).prop_map(|c| format!("Ke {c}")),
        1 => Just("map_Kd tex.png".to_owned()),
    ]
}

/// An OBJ that names `fuzz.mtl`, and that MTL, drawn line by line from the grammar: mostly
/// well-formed lines, one in ten from the hostile generators.
fn obj_and_mtl() -> impl Strategy<Value = (String, String)> {
    let obj_lines = prop_oneof![9 => valid_obj_line(), 1 => obj_line()];
    let obj = prop::collection::vec(obj_lines, 0..24).prop_map(|lines| {
        let mut text =
            String::from("mtllib fuzz.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nv 1 1 1\nvt 0 0\nvt 1 0\nvt 0 1\n");
        text.push_str(&lines.join("\n"));
        text
    });
    let mtl_lines = prop_oneof![9 => valid_mtl_line(), 1 => mtl_line()];
    let mtl = prop::collection::vec(mtl_lines, 0..10).prop_map(|lines| format!("newmtl m\n{}", lines.join("\n")));
    (obj, mtl)
}

/// A fixture pair: the OBJ and the MTL library it names.
fn fixtures() -> Vec<(Vec<u8>, &'static str, Vec<u8>)> {
    let read = |n: &str| std::fs::read(data(n)).unwrap_or_else(|e| panic!("fixture {n}: {e}"));
    [("scene.obj", "scene.mtl"), ("room.obj", "room.mtl"), ("emitter_sides.obj", "emitter_sides.mtl")]
        .into_iter()
        .map(|(obj, mtl)| (read(obj), mtl, read(mtl)))
        .collect()
}

/// One edit of a file: delete a range, insert bytes, insert a grammar line, replace a number
/// with a hostile one, duplicate or truncate.
#[derive(Clone, Debug)]
enum Mutation {
    Delete(usize, usize),
    Insert(usize, Vec<u8>),
    InsertLine(usize, String),
    ReplaceNumber(usize, String),
    DuplicateLine(usize),
    Truncate(usize),
}

fn mutation(line: BoxedStrategy<String>) -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1usize..16).prop_map(|(at, n)| Mutation::Delete(at, n)),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..8)).prop_map(|(at, b)| Mutation::Insert(at, b)),
        (any::<usize>(), line).prop_map(|(at, l)| Mutation::InsertLine(at, l)),
        (any::<usize>(), number()).prop_map(|(at, n)| Mutation::ReplaceNumber(at, n)),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        any::<usize>().prop_map(Mutation::Truncate),
    ]
}

fn apply(text: &mut Vec<u8>, m: &Mutation) {
    let len = text.len();
    let pos = |at: usize| if len == 0 { 0 } else { at % (len + 1) };
    let line_starts: Vec<usize> =
        std::iter::once(0).chain(text.iter().enumerate().filter(|(_, b)| **b == b'\n').map(|(i, _)| i + 1)).collect();
    match m {
        Mutation::Delete(at, n) => {
            let a = pos(*at);
            text.drain(a..(a + n).min(len));
        }
        Mutation::Insert(at, bytes) => {
            let a = pos(*at);
            text.splice(a..a, bytes.iter().copied());
        }
        Mutation::InsertLine(at, line) => {
            let a = line_starts[at % line_starts.len()];
            text.splice(a..a, format!("{line}\n").into_bytes());
        }
        Mutation::ReplaceNumber(at, number) => {
            // The k-th maximal run of digits, signs and dots.
            let is_num = |b: u8| b.is_ascii_digit() || b == b'.' || b == b'-';
            let runs: Vec<(usize, usize)> = {
                let mut runs = Vec::new();
                let mut i = 0;
                while i < len {
                    if is_num(text[i]) {
                        let s = i;
                        while i < len && is_num(text[i]) {
                            i += 1;
                        }
                        runs.push((s, i));
                    } else {
                        i += 1;
                    }
                }
                runs
            };
            if !runs.is_empty() {
                let (s, e) = runs[at % runs.len()];
                text.splice(s..e, number.bytes());
            }
        }
        Mutation::DuplicateLine(at) => {
            let k = at % line_starts.len();
            let (s, e) = (line_starts[k], line_starts.get(k + 1).copied().unwrap_or(len));
            let line: Vec<u8> = text[s..e].to_vec();
            text.splice(e..e, line.iter().copied().chain((!line.ends_with(b"\n")).then_some(b'\n')));
        }
        Mutation::Truncate(at) => text.truncate(pos(*at)),
    }
}

#[test]
fn arbitrary_bytes_load_or_are_refused_without_panicking() {
    let none = AtomicU32::new(0);
    let mut runner = TestRunner::new(config());
    let bytes = prop::collection::vec(any::<u8>(), 0..600);
    runner.run(&bytes, |b| check_load(&b, &[], &none)).unwrap();
    // Mostly printable text reaches further into the parser than random bytes do.
    runner.run(&"[ -~\n]{0,600}", |t| check_load(t.as_bytes(), &[], &none)).unwrap();
}

/// A 2×2 PNG for `map_Kd tex.png`, and the same cut short for `map_Kd bad.png`.
fn textures() -> [(&'static str, Vec<u8>); 2] {
    let image = image::RgbImage::from_fn(2, 2, |x, y| image::Rgb([(x * 200) as u8, (y * 200) as u8, 90]));
    let mut png = Vec::new();
    image.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).expect("PNG encoding");
    let cut = png[..png.len() / 2].to_vec();
    [("tex.png", png), ("bad.png", cut)]
}

#[test]
fn grammar_generated_obj_and_mtl_load_or_are_refused_without_panicking() {
    let [tex, bad] = textures();
    let accepted = AtomicU32::new(0);
    let mut runner = TestRunner::new(config());
    runner
        .run(&obj_and_mtl(), |(obj, mtl)| {
            check_load(obj.as_bytes(), &[("fuzz.mtl", mtl.into_bytes()), tex.clone(), bad.clone()], &accepted)
        })
        .unwrap();
    report("grammar", &accepted, config().cases, 0.1);
}

/// Large but legitimate input loads, in linear time: a polygon of 100 000 corners (a fan of
/// 99 998 triangles) and 100 000 faces reusing three vertices.
#[test]
fn deep_polygons_and_many_faces_load_quickly() {
    let n = 100_000;
    let mut polygon = String::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        polygon.push_str(&format!("v {:.6} {:.6} 0\n", a.cos(), a.sin()));
    }
    polygon.push('f');
    (1..=n).for_each(|k| polygon.push_str(&format!(" {k}")));
    let mut faces = String::from("v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    (0..n).for_each(|_| faces.push_str("f -3 -2 -1\n"));
    for (text, triangles) in [(polygon, n - 2), (faces, n)] {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.obj");
        std::fs::write(&path, text).unwrap();
        let start = std::time::Instant::now();
        let scene = load_under_watchdog(&path).unwrap().unwrap();
        println!("{triangles} triangles in {:.2} s", start.elapsed().as_secs_f64());
        assert_eq!(scene.triangles.len(), triangles);
    }
}

#[test]
fn mutated_fixtures_load_or_are_refused_without_panicking() {
    let fixtures = fixtures();
    let accepted = AtomicU32::new(0);
    let mut runner = TestRunner::new(config());
    let strategy = (
        0..fixtures.len(),
        prop::collection::vec(mutation(obj_line().boxed()), 0..6),
        prop::collection::vec(mutation(mtl_line().boxed()), 0..4),
    );
    runner
        .run(&strategy, |(k, obj_edits, mtl_edits)| {
            let (obj, mtl_name, mtl) = &fixtures[k];
            let (mut obj, mut mtl) = (obj.clone(), mtl.clone());
            obj_edits.iter().for_each(|m| apply(&mut obj, m));
            mtl_edits.iter().for_each(|m| apply(&mut mtl, m));
            // The fixture's OBJ names its MTL by its own name: keep it beside it.
            check_load(&obj, &[(mtl_name, mtl)], &accepted)
        })
        .unwrap();
    report("mutated fixtures", &accepted, config().cases, 0.2);
}

/// Inputs that once failed, and hostile files written by hand: each must be refused with an
/// error that names the file (and contains the text of its first line `# expect: …`), or
/// (`ok_*`) load, quickly and without a panic.
#[test]
fn regression_corpus_loads_or_is_refused_by_name() {
    let dir = data("corpus");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no corpus in {}", dir.display());
    for path in &files {
        let outcome = load_under_watchdog(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let stem = path.file_stem().unwrap().to_string_lossy();
        match outcome {
            Ok(scene) => {
                assert!(
                    stem.starts_with("ok_"),
                    "{} was accepted ({} triangles)",
                    path.display(),
                    scene.triangles.len()
                );
                scene.validate().unwrap();
            }
            Err(message) => {
                assert!(!stem.starts_with("ok_"), "{} was refused: {message}", path.display());
                let text = std::fs::read_to_string(path).unwrap_or_default();
                if let Some(expected) = text.lines().next().and_then(|l| l.strip_prefix("# expect: ")) {
                    assert!(message.contains(expected.trim()), "{}: '{message}' lacks '{expected}'", path.display());
                }
                assert!(message.contains(&path.display().to_string()), "the error does not name the file: {message}");
                assert!(!message.contains('\n'), "the error is not one line: {message}");
                println!("{}: {message}", path.file_name().unwrap().to_string_lossy());
            }
        }
    }
}
