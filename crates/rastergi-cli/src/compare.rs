//! `rastergi compare`: how an image differs from a reference, in the metrics of DESIGN.md
//! ("Validation"), and where, as a false-colour difference image.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use clap::Args;
use rastergi::image_io::{LinearImage, read_image, validate_finite, write_png};
use rastergi::metrics::{BLOCK, Comparison, compare, difference_image, emitter_mask, masked_mean, rmse};

/// Reference values above which `--mask-emitters` without a value treats a pixel as an emitter.
const DEFAULT_EMITTER_THRESHOLD: &str = "3";

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

/// Refuses an image with a NaN or infinite pixel; `name` says which (its path).
pub fn check_finite(name: impl std::fmt::Display, image: &LinearImage) -> Result<()> {
    validate_finite(image).map_err(|e| anyhow::anyhow!("{name}: {e}; compare needs finite pixel values"))
}

/// Refuses a `--mask-emitters` threshold that is not a finite number.
pub fn check_mask_threshold(mask_emitters: Option<f32>) -> Result<()> {
    if let Some(t) = mask_emitters.filter(|t| !t.is_finite()) {
        bail!("--mask-emitters needs a finite threshold, got {t}");
    }
    Ok(())
}

/// What `rastergi compare` prints: the metrics over the compared pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Metrics {
    pub comparison: Comparison,
    /// The emitter mask of `--mask-emitters` (`None`: every pixel compared).
    pub mask: Option<Vec<bool>>,
    /// Absolute RMSE, linear units.
    pub rmse: f64,
    /// The reference's mean over the compared pixels.
    pub reference_mean: f64,
    /// The reference's maximum over the compared pixels and channels (the PSNR's peak).
    pub peak: f32,
    pub compared_pixels: usize,
    pub total_pixels: usize,
}

/// Compares `image` with `reference` as `rastergi compare` does, refusing images of different
/// sizes, a mask that leaves nothing and a black reference; the names (their paths) are for
/// the messages.
pub fn metrics(
    image: &LinearImage,
    image_name: impl std::fmt::Display,
    reference: &LinearImage,
    reference_name: impl std::fmt::Display,
    mask_emitters: Option<f32>,
) -> Result<Metrics> {
    check_mask_threshold(mask_emitters)?;
    if (image.width, image.height) != (reference.width, reference.height) {
        bail!(
            "the images differ in size: {image_name} is {} x {} but {reference_name} is {} x {}; compare needs images of the same size",
            image.width,
            image.height,
            reference.width,
            reference.height
        );
    }
    let mask = mask_emitters.map(|t| emitter_mask(reference, t));
    let m = mask.as_deref();
    let total = image.pixels.len();
    let kept = m.map_or(total, |m| m.iter().filter(|&&k| k).count());
    if kept == 0 {
        bail!("--mask-emitters leaves no pixel to compare; raise its threshold");
    }
    let mean_ref = masked_mean(reference, m);
    if mean_ref <= 0.0 {
        bail!(
            "{reference_name}: the reference is black over the compared pixels (mean {mean_ref}), so relative errors are undefined"
        );
    }
    let comparison = compare(image, reference, m);
    let peak = reference.pixels.iter().enumerate().filter(|(i, _)| m.is_none_or(|m| m[*i]));
    let peak = peak.flat_map(|(_, p)| *p).fold(0.0f32, f32::max);
    Ok(Metrics {
        comparison,
        rmse: rmse(image, reference, m),
        reference_mean: mean_ref,
        peak,
        compared_pixels: kept,
        total_pixels: total,
        mask,
    })
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
