//! `rastergi`: the command-line front end. All rendering lives in the `rastergi` library; the
//! subcommands live in this crate's library (`rastergi_cli`), which the Python package shares.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use rastergi_cli::{args, bench, compare, export, merge, noise, render, serve, view};

#[derive(Parser)]
#[command(
    name = "rastergi",
    version,
    about = "Global illumination on the GPU with photon maps and a rasterized final gather"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the GPU adapter, backend, driver and the limits that matter.
    Info {
        #[command(flatten)]
        gpu: args::GpuArgs,
    },
    /// Render a scene progressively and write the image (.exr linear, .png display).
    Render(render::RenderArgs),
    /// Merge checkpoints of one image rendered with different seeds into one image (and
    /// checkpoint), each weighted by its iterations.
    Merge(merge::MergeArgs),
    /// Measure throughput, convergence and memory: `bench photons`, `gather`, `converge`, `frames`, `bvh`, `memory`.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
    /// Compare an image with a reference: relative RMSE, block-mean error, PSNR, mean ratios.
    Compare(compare::CompareArgs),
    /// The noise of one render from renders of different seeds, no reference needed: its
    /// relative RMSE, its body and the share of its worst 1 % of pixels.
    Noise(noise::NoiseArgs),
    /// Write a scene (built in, e.g. `atrium` or `spheres:1000000`, or a file) as Wavefront OBJ + MTL.
    Export(export::ExportArgs),
    /// Open a window that shows the image converging; fly or orbit through the scene.
    #[command(after_help = view::AFTER_HELP)]
    View(view::ViewArgs),
    /// Serve the web page (web/, built by scripts/web-build.sh) on localhost for a browser with WebGPU.
    Serve(serve::ServeArgs),
}

/// Mesa's Vulkan drivers probe Wayland when they start and, where `XDG_RUNTIME_DIR` is unset
/// (root shells, CI, containers), print "error: XDG_RUNTIME_DIR is invalid" lines that look
/// like rastergi's own errors. Commands that open no window point the variable at a private
/// directory first; the window of `view` needs the real environment, so it is left alone.
fn quiet_wayland_probe() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_some() {
        return;
    }
    let dir = std::env::temp_dir().join("rastergi-runtime");
    let created = std::fs::create_dir_all(&dir).is_ok();
    #[cfg(unix)]
    let created =
        created && std::fs::set_permissions(&dir, std::os::unix::fs::PermissionsExt::from_mode(0o700)).is_ok();
    if created {
        // SAFETY: called at the start of main, before any other thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

/// Rust ignores SIGPIPE, so a reader that closes the pipe early (`rastergi compare … | head`)
/// made the next `println!` panic with a backtrace. As other Unix tools do, the process now
/// ends quietly there (the signal's default action).
fn default_sigpipe() {
    // SAFETY: called at the start of main, before any other thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    #[cfg(unix)]
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

impl Command {
    fn opens_window(&self) -> bool {
        matches!(self, Command::View(_))
    }
}

fn main() -> ExitCode {
    default_sigpipe();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    if !cli.command.opens_window() {
        quiet_wayland_probe();
    }
    let ok = |r: anyhow::Result<()>| r.map(|()| ExitCode::SUCCESS);
    let result = match cli.command {
        Command::Info { gpu } => ok(args::gpu(&gpu).map(|g| println!("{}", g.describe()))),
        Command::Render(args) => render::run(&args),
        Command::Merge(args) => ok(merge::run(&args)),
        Command::Bench(command) => ok(bench::run(&command)),
        Command::Compare(args) => ok(compare::run(&args)),
        Command::Noise(args) => ok(noise::run(&args)),
        Command::Export(args) => ok(export::run(&args)),
        Command::View(args) => ok(view::run(&args)),
        Command::Serve(args) => ok(serve::run(&args)),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            // One line, whatever the error's sources hold (driver messages can span several).
            let message = format!("{e:#}");
            let line: Vec<&str> = message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            eprintln!("error: {}", line.join(" "));
            ExitCode::FAILURE
        }
    }
}
