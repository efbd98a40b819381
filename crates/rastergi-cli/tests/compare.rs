//! `rastergi compare` on image pairs whose differences are known in closed form (identical,
//! a constant offset, Gaussian noise of a known level, PNG values), and on the inputs it must
//! refuse with one clear error line: missing, corrupt, mismatched, non-finite; `rastergi noise`
//! on renders of a known noise level, and on what it must refuse.

mod common;

use std::path::Path;
use std::time::Duration;

use common::Run;
use rastergi::image_io::{DisplayImage, LinearImage, read_image, write_exr, write_png};
use rastergi::metrics::{DIFF_BRIGHTER, DIFF_DARKER, DIFF_EQUAL, DIFF_MASKED};

/// Far longer than a comparison takes; a run past it is killed and fails the test.
const TIMEOUT: Duration = Duration::from_secs(120);

impl Run {
    fn assert_success(&self) {
        assert!(self.status.success(), "the run failed:\n{}", self.stderr);
        assert!(self.our_stderr().is_empty(), "unexpected stderr:\n{}", self.stderr);
    }

    /// The one `error: ` line of a failed run, after checking that the run failed with exit
    /// code 1, printed exactly one such line, nothing else, and did not panic.
    fn error_line(&self) -> &str {
        assert_eq!(self.status.code(), Some(1), "stdout:\n{}\nstderr:\n{}", self.stdout, self.stderr);
        self.sole_error_line()
    }

    /// The numbers after `key:` on the line of stdout that starts with it, up to the first
    /// that is not a number ("inf" included).
    fn numbers(&self, key: &str) -> Vec<f64> {
        let line = self
            .stdout
            .lines()
            .find_map(|l| l.strip_prefix(&format!("{key}:")))
            .unwrap_or_else(|| panic!("no '{key}:' line in:\n{}", self.stdout));
        line.split_whitespace().map_while(|w| w.parse().ok()).collect()
    }

    fn number(&self, key: &str) -> f64 {
        self.numbers(key)[0]
    }
}

fn rastergi(dir: &Path, args: &[&str]) -> Run {
    common::rastergi(dir, args, TIMEOUT)
}

/// r(x, y, c) = k_c · (i + 1) / n for pixel index i of n pixels: channel means
/// k_c · (n + 1) / (2n), peak 1.
const K: [f64; 3] = [1.0, 0.5, 0.25];

fn ramp(w: u32, h: u32) -> LinearImage {
    let n = (w * h) as f64;
    LinearImage {
        width: w,
        height: h,
        pixels: (0..w * h).map(|i| K.map(|k| (k * (i as f64 + 1.0) / n) as f32)).collect(),
    }
}

fn ramp_channel_means(w: u32, h: u32) -> [f64; 3] {
    let n = (w * h) as f64;
    K.map(|k| k * (n + 1.0) / (2.0 * n))
}

fn map(image: &LinearImage, f: impl FnMut(&[f32; 3]) -> [f32; 3]) -> LinearImage {
    LinearImage { width: image.width, height: image.height, pixels: image.pixels.iter().map(f).collect() }
}

fn write(dir: &Path, name: &str, image: &LinearImage) {
    write_exr(&dir.join(name), image).unwrap();
}

/// Writes `image` and `reference`, each a file name and its image, as EXR files in `dir` and
/// runs `rastergi compare IMAGE REFERENCE options…` there.
fn compare(dir: &Path, image: (&str, &LinearImage), reference: (&str, &LinearImage), options: &[&str]) -> Run {
    write(dir, image.0, image.1);
    write(dir, reference.0, reference.1);
    rastergi(dir, &[&["compare", image.0, reference.0], options].concat())
}

#[test]
fn identical_images_have_zero_error_and_infinite_psnr() {
    let dir = tempfile::tempdir().unwrap();
    let run = compare(dir.path(), ("a.exr", &ramp(40, 24)), ("b.exr", &ramp(40, 24)), &[]);
    run.assert_success();
    assert_eq!(run.number("relative RMSE"), 0.0);
    assert_eq!(run.number("block-mean error"), 0.0);
    assert_eq!(run.number("PSNR"), f64::INFINITY);
    assert_eq!(run.numbers("mean ratio R G B"), [1.0; 3]);
    assert!(run.stdout.contains("compared pixels:  960 of 960"), "{}", run.stdout);
    assert!(!run.stdout.contains("PNG"), "no PNG note for EXR files:\n{}", run.stdout);
}

#[test]
fn constant_offset_is_reported_exactly() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h, delta) = (40, 24, 0.05);
    let reference = ramp(w, h);
    let image = map(&reference, |p| p.map(|v| v + delta as f32));
    let run = compare(dir.path(), ("img.exr", &image), ("ref.exr", &reference), &[]);
    run.assert_success();

    let means = ramp_channel_means(w, h);
    let mean = means.iter().sum::<f64>() / 3.0;
    // Printed with 6 decimals; f32 pixels add a few 1e-8.
    let close = |got: f64, want: f64| (got - want).abs() < 2e-6;
    assert!(close(run.number("relative RMSE"), delta / mean), "{}", run.stdout);
    assert!(close(run.number("block-mean error"), delta / mean), "{}", run.stdout);
    assert!(close(run.number("RMSE"), delta), "{}", run.stdout);
    for (c, ratio) in run.numbers("mean ratio R G B").into_iter().enumerate() {
        assert!(close(ratio, (means[c] + delta) / means[c]), "channel {c}: {}", run.stdout);
    }
    // PSNR = 20·log10(peak / delta), peak 1; printed with 2 decimals.
    assert!((run.number("PSNR") - 20.0 * (1.0 / delta).log10()).abs() < 0.006, "{}", run.stdout);
}

#[test]
fn gaussian_noise_of_known_level_is_reported_within_sampling_error() {
    let dir = tempfile::tempdir().unwrap();
    let (w, h, sigma) = (64u32, 64u32, 0.05f64);
    let reference = ramp(w, h);
    let mut normal = rastergi::sampling::gaussian_deviates(12345);
    let noisy = map(&reference, |p| p.map(|v| v + (sigma * normal()) as f32));
    let run = compare(dir.path(), ("noisy.exr", &noisy), ("ref.exr", &reference), &[]);
    run.assert_success();

    let mean = ramp_channel_means(w, h).iter().sum::<f64>() / 3.0;
    // The RMS of N normal deviates of std σ has sd ≈ σ/√(2N).
    let rms_sd = sigma / (2.0 * (3 * w * h) as f64).sqrt();
    let rmse = run.number("relative RMSE") * mean;
    assert!((rmse - sigma).abs() < 4.0 * rms_sd, "RMSE {rmse} vs σ = {sigma} ± {rms_sd}");
    // Block means of 256 pixels have sd σ/16; the mean of 48 |N(0, (σ/16)²)| is about
    // 0.8·σ/16 ≈ 0.05·σ, far below the per-pixel error.
    let block = run.number("block-mean error") * mean;
    assert!(block > 0.02 * sigma && block < 0.08 * sigma, "block error {block} for σ = {sigma}");
}

/// The sRGB transfer function's inverse, written out from IEC 61966-2-1.
fn srgb_to_linear(v: u8) -> f64 {
    let v = v as f64 / 255.0;
    if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}

fn grey_png(dir: &Path, name: &str, w: u32, h: u32, v: u8) {
    let rgba = (0..w * h).flat_map(|_| [v, v, v, 255]).collect();
    write_png(&dir.join(name), &DisplayImage { width: w, height: h, rgba }).unwrap();
}

#[test]
fn png_values_are_decoded_to_linear_and_flagged_as_approximate() {
    let dir = tempfile::tempdir().unwrap();
    grey_png(dir.path(), "ref.png", 16, 8, 128);
    grey_png(dir.path(), "img.png", 16, 8, 140);
    let run = rastergi(dir.path(), &["compare", "img.png", "ref.png"]);
    run.assert_success();
    assert!(run.stdout.contains("note: PNG values are display-encoded"), "{}", run.stdout);
    assert!(run.stdout.contains("clamped") && run.stdout.contains("approximate"), "{}", run.stdout);
    let (a, r) = (srgb_to_linear(140), srgb_to_linear(128));
    assert!((run.number("relative RMSE") - (a - r) / r).abs() < 2e-6, "{}", run.stdout);
    assert!((run.number("mean ratio R G B") - a / r).abs() < 2e-6, "{}", run.stdout);

    // An EXR image against a PNG reference: the EXR holding the reference's linear values exactly.
    let exact = LinearImage { width: 16, height: 8, pixels: vec![[r as f32; 3]; 128] };
    write(dir.path(), "img.exr", &exact);
    let run = rastergi(dir.path(), &["compare", "img.exr", "ref.png"]);
    run.assert_success();
    assert!(run.stdout.contains("note: PNG"), "{}", run.stdout);
    assert!(run.number("relative RMSE") < 1e-6, "{}", run.stdout);
}

#[test]
fn emitter_mask_leaves_out_hot_reference_pixels_and_their_neighbours() {
    let dir = tempfile::tempdir().unwrap();
    let mut reference = LinearImage { width: 8, height: 8, pixels: vec![[0.5; 3]; 64] };
    reference.pixels[3 * 8 + 4] = [20.0, 10.0, 5.0];
    let mut image = reference.clone();
    image.pixels[3 * 8 + 4] = [15.0, 10.0, 5.0]; // the emitter
    image.pixels[2 * 8 + 5] = [0.7; 3]; // its neighbour, partly covering it

    let run = compare(dir.path(), ("img.exr", &image), ("ref.exr", &reference), &["--mask-emitters"]);
    run.assert_success();
    assert!(run.stdout.contains("compared pixels:  55 of 64"), "{}", run.stdout);
    assert_eq!(run.number("relative RMSE"), 0.0, "{}", run.stdout);

    // Above the emitter's brightest channel nothing is left out.
    let run = rastergi(dir.path(), &["compare", "img.exr", "ref.exr", "--mask-emitters", "25"]);
    run.assert_success();
    assert!(run.stdout.contains("compared pixels:  64 of 64"), "{}", run.stdout);
    assert!(run.stdout.contains("no reference pixel exceeds 25"), "{}", run.stdout);
    assert!(run.number("relative RMSE") > 0.0);

    let run = rastergi(dir.path(), &["compare", "img.exr", "ref.exr", "--mask-emitters", "0.1"]);
    assert!(run.error_line().contains("leaves no pixel"), "{}", run.stderr);
}

#[test]
fn difference_image_is_red_where_brighter_blue_where_darker() {
    let dir = tempfile::tempdir().unwrap();
    let reference = LinearImage { width: 4, height: 2, pixels: vec![[1.0; 3]; 8] };
    let mut image = reference.clone();
    image.pixels[1] = [1.5; 3]; // +50 % of the reference mean
    image.pixels[2] = [0.5; 3]; // −50 %
    image.pixels[7] = [30.0; 3];
    let mut masked_reference = reference.clone();
    masked_reference.pixels[7] = [30.0; 3];
    write(dir.path(), "hot.exr", &masked_reference);
    let run = compare(dir.path(), ("img.exr", &image), ("ref.exr", &reference), &["--diff", "d.png"]);
    run.assert_success();
    assert!(run.stdout.contains("full colour at |d| >= 0.1"), "the scale is printed:\n{}", run.stdout);

    // The PNG read back as linear; each pixel should be one of the colour map's 8-bit colours.
    let is = |p: [f32; 3], c: [u8; 3]| (0..3).all(|i| (p[i] as f64 - srgb_to_linear(c[i])).abs() < 1e-6);
    let diff = read_image(&dir.path().join("d.png")).unwrap();
    assert_eq!((diff.width, diff.height), (4, 2));
    // The reference mean is 1 and the scale 0.1: ±0.5 saturates; a pixel at 30 is red too.
    assert!(is(diff.pixels[0], DIFF_EQUAL), "{:?}", diff.pixels[0]);
    assert!(is(diff.pixels[1], DIFF_BRIGHTER), "{:?}", diff.pixels[1]);
    assert!(is(diff.pixels[2], DIFF_DARKER), "{:?}", diff.pixels[2]);
    assert!(is(diff.pixels[7], DIFF_BRIGHTER), "{:?}", diff.pixels[7]);

    // With the emitter at pixel 7 masked, it and its neighbours are black.
    let run = rastergi(dir.path(), &["compare", "img.exr", "hot.exr", "--diff", "m.png", "--mask-emitters"]);
    run.assert_success();
    let diff = read_image(&dir.path().join("m.png")).unwrap();
    for i in [2, 3, 6, 7] {
        assert!(is(diff.pixels[i], DIFF_MASKED), "pixel {i}: {:?}", diff.pixels[i]);
    }
    assert!(is(diff.pixels[1], DIFF_BRIGHTER), "{:?}", diff.pixels[1]);
}

#[test]
fn missing_and_corrupt_files_are_one_error_line_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "ref.exr", &ramp(8, 8));
    let run = rastergi(dir.path(), &["compare", "missing.exr", "ref.exr"]);
    let line = run.error_line();
    assert!(line.contains("missing.exr") && line.contains("no such file"), "{line}");
    let run = rastergi(dir.path(), &["compare", "ref.exr", "missing.png"]);
    assert!(run.error_line().contains("missing.png"), "{}", run.stderr);

    for name in ["corrupt.exr", "corrupt.png"] {
        std::fs::write(dir.path().join(name), b"these bytes are not an image").unwrap();
        let run = rastergi(dir.path(), &["compare", name, "ref.exr"]);
        let line = run.error_line();
        assert!(line.contains(name) && line.contains("cannot read"), "{line}");
    }
    std::fs::write(dir.path().join("image.jpg"), b"").unwrap();
    let run = rastergi(dir.path(), &["compare", "image.jpg", "ref.exr"]);
    let line = run.error_line();
    assert!(line.contains("image.jpg") && line.contains(".exr") && line.contains(".png"), "{line}");
}

#[test]
fn images_of_different_sizes_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let run = compare(dir.path(), ("a.exr", &ramp(32, 32)), ("b.exr", &ramp(32, 24)), &[]);
    let line = run.error_line();
    assert!(line.contains("a.exr is 32 x 32") && line.contains("b.exr is 32 x 24"), "{line}");
    assert!(run.stdout.is_empty(), "no metrics printed:\n{}", run.stdout);
}

#[test]
fn nan_and_infinite_pixels_are_counted_and_located() {
    let dir = tempfile::tempdir().unwrap();
    let reference = ramp(16, 8);
    let mut image = reference.clone();
    image.pixels[5 * 16 + 3][1] = f32::NAN; // x 3, y 5: the first
    image.pixels[6 * 16][0] = f32::INFINITY;
    let run = compare(dir.path(), ("nan.exr", &image), ("ref.exr", &reference), &[]);
    let line = run.error_line();
    assert!(line.contains("nan.exr") && line.contains("2 pixels are NaN or infinite"), "{line}");
    assert!(line.contains("x = 3, y = 5"), "{line}");
    // In the reference just the same.
    let run = rastergi(dir.path(), &["compare", "ref.exr", "nan.exr"]);
    assert!(run.error_line().contains("nan.exr: 2 pixels"), "{}", run.stderr);
}

#[test]
fn diff_to_a_non_png_path_is_refused_before_anything_is_written() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "a.exr", &ramp(8, 8));
    let run = rastergi(dir.path(), &["compare", "a.exr", "a.exr", "--diff", "diff.exr"]);
    let line = run.error_line();
    assert!(line.contains("diff.exr") && line.contains(".png"), "{line}");
    let run = rastergi(dir.path(), &["compare", "a.exr", "a.exr", "--diff", "no/such/dir/d.png"]);
    assert!(run.error_line().contains("does not exist"), "{}", run.stderr);
    assert_eq!(common::files_in(dir.path()), ["a.exr"]);
}

#[test]
fn black_reference_makes_relative_errors_undefined() {
    let dir = tempfile::tempdir().unwrap();
    let black = LinearImage { width: 4, height: 4, pixels: vec![[0.0; 3]; 16] };
    let run = compare(dir.path(), ("a.exr", &ramp(4, 4)), ("black.exr", &black), &[]);
    let line = run.error_line();
    assert!(line.contains("black.exr") && line.contains("undefined"), "{line}");
}

/// Renders of a ramp with independent normal noise of a known level, as EXR files in `dir`.
fn noisy_renders(dir: &Path, k: usize, sigma: f64) -> Vec<String> {
    let reference = ramp(64, 64);
    let mut normal = rastergi::sampling::gaussian_deviates(99);
    (0..k)
        .map(|i| {
            let name = format!("seed{i}.exr");
            write(dir, &name, &map(&reference, |p| p.map(|v| v + (sigma * normal()) as f32)));
            name
        })
        .collect()
}

#[test]
fn noise_of_renders_of_known_gaussian_noise_is_its_level_within_sampling_error() {
    let dir = tempfile::tempdir().unwrap();
    let (sigma, k) = (0.05, 4);
    let names = noisy_renders(dir.path(), k, sigma);
    let args: Vec<&str> = std::iter::once("noise").chain(names.iter().map(String::as_str)).collect();
    let run = rastergi(dir.path(), &args);
    run.assert_success();
    let mean = ramp_channel_means(64, 64).iter().sum::<f64>() / 3.0;
    // mean s²/σ² over n = 3·64² values of k − 1 degrees of freedom: sd √(2/(n(k − 1))), half
    // that in the root.
    let n = 3.0 * 64.0 * 64.0;
    let sd = sigma / mean * (2.0 / (n * (k - 1) as f64)).sqrt() / 2.0;
    let noise = run.number("noise");
    assert!((noise - sigma / mean).abs() < 4.0 * sd, "{noise} against {} ± {sd}\n{}", sigma / mean, run.stdout);
    assert!((run.number("noise of mean") - noise / 2.0).abs() < 2e-6, "{}", run.stdout);
    assert_eq!(run.numbers("pairs").len(), 2, "{}", run.stdout);
    assert!(run.stdout.contains("renders:          4 of 64 x 64"), "{}", run.stdout);
}

#[test]
fn noise_refuses_one_render_and_renders_of_different_sizes() {
    let dir = tempfile::tempdir().unwrap();
    let names = noisy_renders(dir.path(), 1, 0.05);
    let run = rastergi(dir.path(), &["noise", &names[0]]);
    assert!(run.error_line().contains("at least two"), "{}", run.stderr);
    write(dir.path(), "small.exr", &ramp(8, 8));
    let run = rastergi(dir.path(), &["noise", &names[0], "small.exr"]);
    let line = run.error_line();
    assert!(line.contains("differ in size") && line.contains("small.exr"), "{line}");
    let run = rastergi(dir.path(), &["noise", &names[0], "missing.exr"]);
    assert!(run.error_line().contains("missing.exr"), "{}", run.stderr);
}
