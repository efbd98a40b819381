//! `rastergi compare`: how an image differs from a reference, in the metrics of DESIGN.md
//! ("Validation"), and where, as a false-colour difference image.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use rastergi::image_io::{LinearImage, read_image, write_png};
use rastergi::metrics::{BLOCK, difference_image};
pub use rastergi::metrics::{Metrics, check_finite, check_mask_threshold, metrics};

/// Reference values above which `--mask-emitters` without a value treats a pixel as an emitter.
pub(crate) const DEFAULT_EMITTER_THRESHOLD: &str = "3";

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image to check: .exr (linear radiance) or .png (display-encoded sRGB).
    image: PathBuf,
    /// The reference it is measured against: .exr or .png.
    reference: PathBuf,
    /// Write a false-colour difference image (.png): blue where IMAGE is darker than REFERENCE,
    /// white where equal, red where brighter; emitter pixels left out by --mask-emitters are black.
    #[arg(long, value_name = "DIFF.png")]
    diff: Option<PathBuf>,
    /// Relative difference shown at full colour in the --diff image: a pixel is fully blue or red
    /// where the mean over its channels of (image − reference) reaches this fraction of the
    /// reference mean.
    #[arg(long, value_name = "FRACTION", default_value_t = 0.1)]
    diff_scale: f64,
    /// Leave emitters out of the metrics: reference pixels above THRESHOLD in any channel
    /// (default 3) and their 8 neighbours. Give it after the file names or with a value.
    #[arg(long, value_name = "THRESHOLD", num_args = 0..=1, default_missing_value = DEFAULT_EMITTER_THRESHOLD)]
    mask_emitters: Option<f32>,
}

fn is_png(path: &Path) -> bool {
    path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("png"))
}

/// Refuses, before reading anything, a difference image path that could not be written.
fn check_diff_path(diff: &Path) -> Result<()> {
    if !is_png(diff) {
        bail!("{}: the difference image is a PNG; give --diff a file name ending in .png", diff.display());
    }
    if diff.is_dir() {
        bail!("{}: is a directory; give --diff a file name ending in .png", diff.display());
    }
    let dir = match diff.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        bail!(
            "{}: the directory {} does not exist; create it first or choose another --diff",
            diff.display(),
            dir.display()
        );
    }
    Ok(())
}

/// Reads an image and checks that every pixel is a finite number.
pub fn read(path: &Path) -> Result<LinearImage> {
    let image = read_image(path)?;
    check_finite(path.display(), &image)?;
    Ok(image)
}

fn describe(path: &Path, image: &LinearImage) -> String {
    let encoding = if is_png(path) { "PNG, display-encoded sRGB decoded to linear" } else { "EXR, linear" };
    format!("{}  ({} x {}, {encoding})", path.display(), image.width, image.height)
}

pub fn run(args: &CompareArgs) -> Result<()> {
    if !(args.diff_scale.is_finite() && args.diff_scale > 0.0) {
        bail!("--diff-scale must be a positive number, got {}", args.diff_scale);
    }
    check_mask_threshold(args.mask_emitters)?;
    if let Some(diff) = &args.diff {
        check_diff_path(diff)?;
    }
    let image = read(&args.image)?;
    let reference = read(&args.reference)?;
    let m = metrics(&image, args.image.display(), &reference, args.reference.display(), args.mask_emitters)?;
    let (c, mask, kept, total, mean_ref) =
        (m.comparison, m.mask.as_deref(), m.compared_pixels, m.total_pixels, m.reference_mean);

    println!("image:            {}", describe(&args.image, &image));
    println!("reference:        {}", describe(&args.reference, &reference));
    if is_png(&args.image) || is_png(&args.reference) {
        println!(
            "note: PNG values are display-encoded (exposure, clamped to [0, 1], 8-bit sRGB); decoded to \
             linear they only approximate the radiance, so this comparison is approximate; compare .exr \
             renders for exact numbers"
        );
    }
    match args.mask_emitters {
        Some(t) => {
            println!(
                "compared pixels:  {kept} of {total} (emitter mask: reference above {t} in a channel, and neighbours)"
            );
            if kept == total {
                println!("note: no reference pixel exceeds {t}, so the emitter mask left nothing out");
            }
        }
        None => println!("compared pixels:  {kept} of {total}"),
    }
    println!(
        "relative RMSE:    {:.6}  (sqrt(mean((image - reference)^2)) / mean(reference), all channels)",
        c.relative_rmse
    );
    println!(
        "block-mean error: {:.6}  (mean |difference of {BLOCK}x{BLOCK}-block means| / mean(reference); \
         noise averages out, bias remains)",
        c.block_mean_error
    );
    if c.psnr.is_infinite() {
        println!("PSNR:             inf dB  (the images are identical over the compared pixels)");
    } else {
        println!("PSNR:             {:.2} dB  (peak = reference maximum {})", c.psnr, m.peak);
    }
    let [r, g, b] = c.mean_ratio;
    println!("mean ratio R G B: {r:.6} {g:.6} {b:.6}  (mean(image) / mean(reference) per channel)");
    println!("RMSE:             {:.6}  (absolute, linear units)", m.rmse);
    println!("reference mean:   {mean_ref:.6}");

    if let Some(path) = &args.diff {
        write_png(path, &difference_image(&image, &reference, mask, args.diff_scale))?;
        let masked = if mask.is_some() { "; black: left out by the emitter mask" } else { "" };
        println!(
            "difference image: {}  (per pixel d = mean over channels of (image - reference) / mean(reference); \
             blue: darker, white: equal, red: brighter; full colour at |d| >= {} (--diff-scale){masked})",
            path.display(),
            args.diff_scale
        );
    }
    Ok(())
}
