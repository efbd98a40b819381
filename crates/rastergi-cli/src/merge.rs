//! `rastergi merge`: checkpoints of one image rendered with different seeds (on several GPUs or
//! machines) combined into one image, each weighted by its iterations: in expectation the image
//! of one render with all their iterations (rastergi::checkpoint::merge).

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use rastergi::image_io::{ImageFormat, display_encode, write_exr, write_png};
use rastergi::{checkpoint, fit};

use crate::args::ShowArg;

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Checkpoints (`rastergi render … --checkpoint FILE`) of the same scene and settings,
    /// each rendered with its own --seed.
    #[arg(required = true, num_args = 1..)]
    checkpoints: Vec<PathBuf>,
    /// Output image: .exr (linear radiance) or .png (exposure, sRGB).
    #[arg(long)]
    out: PathBuf,
    /// Also write the merged checkpoint here (to merge further).
    #[arg(long, value_name = "FILE")]
    checkpoint: Option<PathBuf>,
    /// What the image shows.
    #[arg(long, value_enum, default_value_t = ShowArg::Full)]
    show: ShowArg,
    /// Exposure in stops for a .png (default: fitted to the image).
    #[arg(long, allow_hyphen_values = true)]
    exposure: Option<f32>,
}

pub fn run(args: &MergeArgs) -> Result<()> {
    let format = ImageFormat::from_path(&args.out)?;
    crate::render::check_output_path(&args.out, "--out")?;
    if let Some(path) = &args.checkpoint {
        crate::render::check_output_path(path, "--checkpoint")?;
    }
    let merged = checkpoint::merge(&args.checkpoints)?;
    let image = merged.film.image(args.show.show());
    match format {
        ImageFormat::Exr => write_exr(&args.out, &image)?,
        _ => {
            let exposure = args.exposure.unwrap_or_else(|| fit::exposure(&image));
            write_png(&args.out, &display_encode(&image, exposure))?;
        }
    }
    if let Some(path) = &args.checkpoint {
        merged.write(path)?;
    }
    let error = merged.film.error_estimate().map_or(String::new(), |e| format!(", estimated error {:.2} %", 100.0 * e));
    eprintln!("merged {} checkpoints: {} iterations{error}", args.checkpoints.len(), merged.film.samples);
    Ok(())
}
