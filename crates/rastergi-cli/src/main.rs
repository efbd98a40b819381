//! `rastergi`: the command-line front end. All rendering lives in the `rastergi` library.

mod bench;
mod render;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

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
        gpu: render::GpuArgs,
    },
    /// Render a scene progressively and write the image (.exr linear, .png display).
    Render(render::RenderArgs),
    /// Measure throughput: `bench photons`, `bench gather`.
    #[command(subcommand)]
    Bench(bench::BenchCommand),
}

fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Info { gpu } => render::gpu(&gpu).map(|g| println!("{}", g.describe())),
        Command::Render(args) => render::run(&args),
        Command::Bench(command) => bench::run(&command),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line, whatever the error's sources hold (driver messages can span several).
            let message = format!("{e:#}");
            let line: Vec<&str> = message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
            eprintln!("error: {}", line.join(" "));
            ExitCode::FAILURE
        }
    }
}
