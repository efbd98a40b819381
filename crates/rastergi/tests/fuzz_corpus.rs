//! The regression corpus of the fuzz targets (`fuzz/`; `rastergi::fuzzing`): every input a
//! fuzzer found to crash, hang or exhaust memory before its fix, and the hostile files of
//! issue 59, in `tests/data/fuzz/TARGET/`, each read as its target reads it. A file named
//! `ok_…` must load (a validated scene, or a checkpoint read), one named `err_…` must be
//! refused with one line; none may panic or take more than a few seconds (a watchdog).

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use rastergi::fuzzing::Target;

/// One input of a few kilobytes taking longer than this is a hang.
const WATCHDOG: Duration = Duration::from_secs(20);

#[test]
fn every_corpus_file_loads_or_is_refused_in_one_line_without_a_panic() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data/fuzz");
    let start = Instant::now();
    let mut count = 0;
    for target in Target::ALL {
        let dir = root.join(target.name());
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_none_or(|e| e != "md"))
            .collect();
        files.sort();
        assert!(!files.is_empty(), "no corpus for {}", target.name());
        for path in files {
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            let data = std::fs::read(&path).unwrap();
            let (send, receive) = mpsc::channel();
            let reading = std::thread::spawn(move || {
                let outcome = Target::read(target, &data).map(|_| ());
                let _ = send.send(outcome);
            });
            let outcome = match receive.recv_timeout(WATCHDOG) {
                Ok(outcome) => outcome,
                Err(mpsc::RecvTimeoutError::Timeout) => {
                    panic!("{}/{name}: still reading after {WATCHDOG:?}", target.name())
                }
                Err(mpsc::RecvTimeoutError::Disconnected) => {
                    let payload = reading.join().err();
                    let message = payload.as_ref().and_then(|p| {
                        p.downcast_ref::<String>().cloned().or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    });
                    panic!("{}/{name}: panicked: {}", target.name(), message.unwrap_or_default())
                }
            };
            println!("{}/{name}: {}", target.name(), outcome.as_ref().err().map_or("loaded", String::as_str));
            match (name.split('_').next(), outcome) {
                (Some("ok"), Err(e)) => panic!("{}/{name} was refused: {e}", target.name()),
                (Some("err"), Ok(())) => panic!("{}/{name} loaded", target.name()),
                (Some("err"), Err(e)) => assert!(!e.contains('\n'), "{}/{name}: {e}", target.name()),
                (Some("ok"), Ok(())) => {}
                _ => panic!("{}/{name}: a corpus file's name starts with ok_ or err_", target.name()),
            }
            count += 1;
        }
    }
    println!("{count} files in {:.2} s", start.elapsed().as_secs_f64());
}
