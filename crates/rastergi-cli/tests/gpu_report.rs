//! `scripts/gpu-report.sh --quick` with this build's binary: it succeeds, and its report has
//! every section, each with the command it ran and a figure where it measures one. (The
//! full report is for real GPUs; this keeps the script from rotting.)

mod common;

use std::path::Path;
use std::time::Duration;

/// Far above the ~25 s the quick report takes on lavapipe with 2 cores; a hang fails here.
const TIMEOUT: Duration = Duration::from_secs(300);

/// The report's sections by heading, in order.
const SECTIONS: [&str; 10] =
    ["Adapter", "Photons", "Rays", "Gather", "Viewer loop", "Convergence", "Mitsuba", "Denoiser", "Memory", "Summary"];

/// The text of the section `## name` (up to the next heading).
fn section<'a>(report: &'a str, name: &str) -> &'a str {
    let start = report.find(&format!("\n## {name}\n")).unwrap_or_else(|| panic!("no section '{name}' in:\n{report}"));
    let body = &report[start + name.len() + 5..];
    &body[..body.find("\n## ").unwrap_or(body.len())]
}

/// The numbers written just before `unit` on the section's lines ("0.24 M photons/s").
fn figures(text: &str, unit: &str) -> Vec<f64> {
    text.lines()
        .filter_map(|l| l.find(unit).map(|i| &l[..i]))
        .filter_map(|before| before.split_whitespace().last()?.trim_start_matches("**").parse().ok())
        .collect()
}

/// Asserts `count` or more positive, finite figures before `unit` in the section `name`.
fn check_figures(report: &str, name: &str, unit: &str, count: usize) {
    let text = section(report, name);
    let found = figures(text, unit);
    assert!(
        found.len() >= count && found.iter().all(|v| v.is_finite() && *v > 0.0),
        "section '{name}': expected {count} positive figures before '{unit}', found {found:?} in:\n{text}"
    );
}

#[test]
fn quick_report_has_every_section_with_its_command_and_figures() {
    let dir = tempfile::tempdir().unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scripts/gpu-report.sh");
    let out = dir.path().join("report.md");
    let args = [
        script.to_str().unwrap(),
        "--quick",
        "--out",
        out.to_str().unwrap(),
        "--binary",
        env!("CARGO_BIN_EXE_rastergi"),
    ];
    let run = common::run(dir.path(), "bash", &args, &[], TIMEOUT);
    let report = std::fs::read_to_string(&out).unwrap_or_else(|e| panic!("no report ({e}); stderr:\n{}", run.stderr));
    assert!(run.status.success(), "exit {:?}; stderr:\n{}\nreport:\n{report}", run.status, run.stderr);
    assert!(!report.contains("FAILED"), "{report}");

    // The header: date, commit, host and mode.
    for field in ["- date: ", "- commit: ", "- host: ", "- mode: quick"] {
        assert!(report.contains(field), "no '{field}' in the header:\n{report}");
    }
    for name in SECTIONS {
        section(&report, name);
    }
    // Each measurement shows the command it ran.
    for (name, command) in [
        ("Adapter", "rastergi info"),
        ("Photons", "rastergi bench photons"),
        ("Rays", "rastergi bench rays cornell"),
        ("Gather", "rastergi bench gather"),
        ("Viewer loop", "rastergi bench frames"),
        ("Convergence", "rastergi render cornell --method path"),
        ("Convergence", "rastergi bench converge"),
        ("Denoiser", "rastergi bench denoise cornell"),
        ("Memory", "rastergi bench memory"),
    ] {
        assert!(section(&report, name).contains(&format!("```sh\n{command}")), "{name}: no `{command}` in:\n{report}");
    }

    assert!(section(&report, "Adapter").contains("backend:"), "{report}");
    check_figures(&report, "Photons", "M photons/s", 2);
    // Five kinds of rays in each of two scenes.
    check_figures(&report, "Rays", "M rays/s", 10);
    // Two sizes × three gathers.
    check_figures(&report, "Gather", "directions/s", 6);
    // Batched with the panel, without it, and one iteration per frame.
    check_figures(&report, "Viewer loop", "frames/s", 3);
    check_figures(&report, "Viewer loop", "iterations/s", 2);
    // The reference's noise and the last error of the renderer and of the path tracer.
    check_figures(&report, "Convergence", "%** of the converged image", 1);
    check_figures(&report, "Convergence", "% after", 2);
    assert!(dir.path().join("report-converge.png").is_file(), "no convergence plot beside the report");
    let mitsuba = section(&report, "Mitsuba");
    assert!(mitsuba.contains("Skipped: ") || !figures(mitsuba, "%:").is_empty(), "{mitsuba}");
    check_figures(&report, "Denoiser", "ms per application", 1);
    check_figures(&report, "Memory", "MiB allocated", 2);
}
