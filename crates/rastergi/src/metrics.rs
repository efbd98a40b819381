//! Image error metrics of DESIGN.md ("Validation"): relative RMSE over pixels and channels,
//! and the error of 16×16 block means, where Monte Carlo noise averages out and bias remains;
//! and a false-colour picture of where two images differ; [`metrics`] is `rastergi compare`'s
//! whole comparison, with its refusals; [`seed_noise`] is `rastergi noise`'s: one render's noise
//! from renders of independent seeds, without a reference.

use crate::error::{Error, Result};
use crate::image_io::{DisplayImage, LinearImage};

/// Block side of [`Comparison::block_mean_error`].
pub const BLOCK: u32 = 16;

/// How an image differs from a reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Comparison {
    /// sqrt(mean((a − r)²)) / mean(r), over the kept pixels and all channels.
    pub relative_rmse: f64,
    /// Mean over 16×16 blocks and channels of |mean_block(a) − mean_block(r)|, divided by
    /// mean(r). Blocks with fewer than half their pixels kept are skipped.
    pub block_mean_error: f64,
    /// mean(a_c) / mean(r_c) per channel.
    pub mean_ratio: [f64; 3],
    /// 10·log10(max(r)² / mean((a − r)²)) in dB, the peak max(r) taken over the kept pixels
    /// and channels; infinite when the images are equal there.
    pub psnr: f64,
    /// Pixels kept by the mask.
    pub pixels: usize,
}

/// Keeps every pixel except emitters: those whose reference value exceeds `threshold` in
/// any channel, and their 8 neighbours (pixels partly covering an emitter).
pub fn emitter_mask(reference: &LinearImage, threshold: f32) -> Vec<bool> {
    let (w, h) = (reference.width as i64, reference.height as i64);
    let hot: Vec<bool> = reference.pixels.iter().map(|p| p.iter().any(|&c| c > threshold)).collect();
    let mut keep = vec![true; hot.len()];
    for y in 0..h {
        for x in 0..w {
            if hot[(y * w + x) as usize] {
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        let (nx, ny) = (x + dx, y + dy);
                        if nx >= 0 && ny >= 0 && nx < w && ny < h {
                            keep[(ny * w + nx) as usize] = false;
                        }
                    }
                }
            }
        }
    }
    keep
}

/// Compares `image` with `reference` over the pixels `mask` keeps (all when `None`).
/// Panics if the sizes differ (callers check first).
pub fn compare(image: &LinearImage, reference: &LinearImage, mask: Option<&[bool]>) -> Comparison {
    assert_eq!((image.width, image.height), (reference.width, reference.height), "image sizes differ");
    let keep = |i: usize| mask.is_none_or(|m| m[i]);
    let (mut sum_sq, mut sum_a, mut sum_r, mut max_r, mut n) = (0.0f64, [0.0f64; 3], [0.0f64; 3], 0.0f64, 0usize);
    for (i, (a, r)) in image.pixels.iter().zip(&reference.pixels).enumerate() {
        if !keep(i) {
            continue;
        }
        n += 1;
        for c in 0..3 {
            let (a, r) = (a[c] as f64, r[c] as f64);
            sum_sq += (a - r) * (a - r);
            sum_a[c] += a;
            sum_r[c] += r;
            max_r = max_r.max(r);
        }
    }
    let mean_r = (sum_r.iter().sum::<f64>() / (3 * n.max(1)) as f64).max(f64::MIN_POSITIVE);
    let mse = sum_sq / (3 * n.max(1)) as f64;

    let (bw, bh) = (image.width.div_ceil(BLOCK), image.height.div_ceil(BLOCK));
    let (mut block_err, mut blocks) = (0.0f64, 0usize);
    for by in 0..bh {
        for bx in 0..bw {
            let (mut sa, mut sr, mut k, mut total) = ([0.0f64; 3], [0.0f64; 3], 0usize, 0usize);
            for y in by * BLOCK..((by + 1) * BLOCK).min(image.height) {
                for x in bx * BLOCK..((bx + 1) * BLOCK).min(image.width) {
                    let i = (y * image.width + x) as usize;
                    total += 1;
                    if keep(i) {
                        k += 1;
                        for c in 0..3 {
                            sa[c] += image.pixels[i][c] as f64;
                            sr[c] += reference.pixels[i][c] as f64;
                        }
                    }
                }
            }
            if 2 * k >= total && k > 0 {
                blocks += 1;
                block_err += (0..3).map(|c| (sa[c] - sr[c]).abs() / k as f64).sum::<f64>() / 3.0;
            }
        }
    }
    Comparison {
        relative_rmse: mse.sqrt() / mean_r,
        block_mean_error: block_err / blocks.max(1) as f64 / mean_r,
        mean_ratio: [0, 1, 2].map(|c| sum_a[c] / sum_r[c].max(f64::MIN_POSITIVE)),
        psnr: if mse > 0.0 { 10.0 * (max_r * max_r / mse).log10() } else { f64::INFINITY },
        pixels: n,
    }
}

/// Mean over the kept pixels and all channels.
pub fn masked_mean(image: &LinearImage, mask: Option<&[bool]>) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for (i, p) in image.pixels.iter().enumerate() {
        if mask.is_none_or(|m| m[i]) {
            n += 3;
            s += p.iter().map(|&v| v as f64).sum::<f64>();
        }
    }
    s / n.max(1) as f64
}

/// Root-mean-square difference of two images over the kept pixels (absolute units).
pub fn rmse(a: &LinearImage, b: &LinearImage, mask: Option<&[bool]>) -> f64 {
    let (mut s, mut n) = (0.0f64, 0usize);
    for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        if mask.is_none_or(|m| m[i]) {
            n += 3;
            s += (0..3).map(|c| (p[c] as f64 - q[c] as f64).powi(2)).sum::<f64>();
        }
    }
    (s / n.max(1) as f64).sqrt()
}

/// Colour of [`difference_image`] where the image is darker than the reference by the full
/// scale or more (sRGB; the blue end of ColorBrewer's RdBu).
pub const DIFF_DARKER: [u8; 3] = [33, 102, 172];
/// Colour where the image equals the reference.
pub const DIFF_EQUAL: [u8; 3] = [247, 247, 247];
/// Colour where the image is brighter than the reference by the full scale or more (RdBu's red).
pub const DIFF_BRIGHTER: [u8; 3] = [178, 24, 43];
/// Colour of pixels the mask leaves out.
pub const DIFF_MASKED: [u8; 3] = [0, 0, 0];

/// A false-colour picture of `image − reference` on a diverging colour map. Each pixel's
/// relative difference is
///
/// d = (mean_c a_c − mean_c r_c) / mean(r),
///
/// the pixel's error in units of the reference mean over the kept pixels and channels (the
/// normalisation of [`Comparison::relative_rmse`]). Its colour runs linearly in sRGB from
/// [`DIFF_EQUAL`] at d = 0 to [`DIFF_DARKER`] at d ≤ −`scale` and to [`DIFF_BRIGHTER`] at
/// d ≥ `scale`; pixels the mask leaves out are [`DIFF_MASKED`]. Panics if the sizes differ.
pub fn difference_image(
    image: &LinearImage,
    reference: &LinearImage,
    mask: Option<&[bool]>,
    scale: f64,
) -> DisplayImage {
    assert_eq!((image.width, image.height), (reference.width, reference.height), "image sizes differ");
    let norm = masked_mean(reference, mask).max(f64::MIN_POSITIVE) * scale.max(f64::MIN_POSITIVE);
    let mut rgba = Vec::with_capacity(4 * image.pixels.len());
    for (i, (a, r)) in image.pixels.iter().zip(&reference.pixels).enumerate() {
        let colour = if mask.is_none_or(|m| m[i]) {
            let d = (0..3).map(|c| a[c] as f64 - r[c] as f64).sum::<f64>() / 3.0;
            let t = (d / norm).clamp(-1.0, 1.0);
            let end = if t < 0.0 { DIFF_DARKER } else { DIFF_BRIGHTER };
            [0, 1, 2].map(|c| (DIFF_EQUAL[c] as f64 + t.abs() * (end[c] as f64 - DIFF_EQUAL[c] as f64)).round() as u8)
        } else {
            DIFF_MASKED
        };
        rgba.extend_from_slice(&colour);
        rgba.push(255);
    }
    DisplayImage { width: image.width, height: image.height, rgba }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// k renders of `base` plus independent normal noise of standard deviation σ_p per pixel
    /// (every channel), from `seed`.
    fn noisy_renders(base: &LinearImage, sigma: impl Fn(usize) -> f64, k: usize, seed: u64) -> Vec<LinearImage> {
        let mut normal = crate::sampling::gaussian_deviates(seed);
        (0..k)
            .map(|_| LinearImage {
                width: base.width,
                height: base.height,
                pixels: base
                    .pixels
                    .iter()
                    .enumerate()
                    .map(|(p, v)| v.map(|v| v + (sigma(p) * normal()) as f32))
                    .collect(),
            })
            .collect()
    }

    fn names(k: usize) -> Vec<String> {
        (0..k).map(|i| format!("r{i}.exr")).collect()
    }

    #[test]
    fn seed_noise_of_known_gaussian_noise_is_its_level_within_sampling_error() {
        let (w, h, sigma, k) = (64u32, 64u32, 0.05, 4);
        let base = LinearImage {
            width: w,
            height: h,
            pixels: (0..w * h).map(|i| [0.5 + 0.5 * (i % 7) as f32 / 7.0; 3]).collect(),
        };
        let mean = masked_mean(&base, None);
        let n = f64::from(3 * w * h);
        let s = seed_noise(&noisy_renders(&base, |_| sigma, k, 7), &names(k), None).unwrap();
        // mean s²/σ² is a mean of n·(k − 1) squared deviates: sd √(2/(n(k − 1))), half that
        // in its root.
        let sd = sigma / mean * (2.0 / (n * (k - 1) as f64)).sqrt() / 2.0;
        assert!((s.relative - sigma / mean).abs() < 4.0 * sd, "{} against {} ± {sd}", s.relative, sigma / mean);
        // Each pair alone: n deviates, sd √(2/n)/2 relative.
        let pair_sd = sigma / mean * (2.0 / n).sqrt() / 2.0;
        assert_eq!(s.pairs.len(), 2);
        for p in &s.pairs {
            assert!((p - sigma / mean).abs() < 4.0 * pair_sd, "pair {p} against {}", sigma / mean);
        }
        assert!((s.mean - mean).abs() < 1e-3 * mean);
        assert_eq!((s.renders, s.compared_pixels, s.total_pixels), (k, (w * h) as usize, (w * h) as usize));
        // Homoscedastic: the worst 1 % hold little more than 1 %.
        assert!(s.tail_share > 0.01 && s.tail_share < 0.05, "tail {}", s.tail_share);
    }

    #[test]
    fn seed_noise_finds_the_tail_and_the_body() {
        // 41 of 4096 pixels ten times as noisy: they hold 41·100 / (41·100 + 4055) = 50.3 % of
        // the variance; the body is the rest's σ.
        let (w, h, sigma, k) = (64u32, 64u32, 0.02, 4);
        let base = LinearImage { width: w, height: h, pixels: vec![[1.0; 3]; (w * h) as usize] };
        let loud = |p: usize| p.is_multiple_of(100);
        let renders = noisy_renders(&base, |p| if loud(p) { 10.0 * sigma } else { sigma }, k, 11);
        let s = seed_noise(&renders, &names(k), None).unwrap();
        let want = 41.0 * 100.0 / (41.0 * 100.0 + 4055.0);
        // The worst 40 by their estimates are 40 of the 41 loud pixels (s² of 9 degrees of
        // freedom: their sum's sd is 7 % of it, the share's about 2 points).
        assert!((s.tail_share - want).abs() < 0.06, "tail {} against {want}", s.tail_share);
        assert!((s.body - sigma).abs() < 0.05 * sigma, "body {} against {sigma}", s.body);
        let all = ((41.0 * 100.0 + 4055.0) / 4096.0f64).sqrt() * sigma;
        assert!((s.relative - all).abs() < 0.05 * all, "{} against {all}", s.relative);
    }

    #[test]
    fn seed_noise_leaves_out_emitters_and_refuses_what_it_cannot_measure() {
        let (w, h) = (32u32, 32u32);
        let mut base = LinearImage { width: w, height: h, pixels: vec![[0.5; 3]; (w * h) as usize] };
        base.pixels[(10 * w + 10) as usize] = [100.0; 3];
        let renders = noisy_renders(&base, |_| 0.01, 3, 5);
        let s = seed_noise(&renders, &names(3), Some(3.0)).unwrap();
        assert_eq!((s.compared_pixels, s.total_pixels), ((w * h - 9) as usize, (w * h) as usize));
        assert_eq!(s.pairs.len(), 1);
        let e = |r: Result<SeedNoise>| r.expect_err("refused").to_string();
        assert!(e(seed_noise(&renders[..1], &names(1), None)).contains("at least two"));
        let small = LinearImage { width: 8, height: 8, pixels: vec![[0.5; 3]; 64] };
        let msg = e(seed_noise(&[renders[0].clone(), small], &names(2), None));
        assert!(msg.contains("differ in size") && msg.contains("r1.exr"), "{msg}");
        let black = vec![LinearImage { width: 4, height: 4, pixels: vec![[0.0; 3]; 16] }; 2];
        assert!(e(seed_noise(&black, &names(2), None)).contains("black"));
        assert!(e(seed_noise(&renders, &names(3), Some(0.1))).contains("leaves no pixel"));
    }

    fn constant(w: u32, h: u32, v: f32) -> LinearImage {
        LinearImage { width: w, height: h, pixels: vec![[v; 3]; (w * h) as usize] }
    }

    #[test]
    fn identical_images_have_zero_error_and_offsets_are_measured() {
        let r = constant(32, 32, 0.5);
        let c = compare(&r, &r, None);
        assert_eq!((c.relative_rmse, c.block_mean_error), (0.0, 0.0));
        let a = constant(32, 32, 0.55);
        let c = compare(&a, &r, None);
        assert!((c.relative_rmse - 0.1).abs() < 1e-6 && (c.block_mean_error - 0.1).abs() < 1e-6);
        assert!((c.mean_ratio[0] - 1.1).abs() < 1e-6);
    }

    #[test]
    fn zero_mean_noise_shows_in_rmse_but_not_in_block_means() {
        let r = constant(64, 64, 1.0);
        // ±0.2 in a checkerboard: RMSE 0.2, every block mean exact.
        let a = LinearImage {
            width: 64,
            height: 64,
            pixels: (0..64 * 64).map(|i| [if (i % 64 + i / 64) % 2 == 0 { 1.2 } else { 0.8 }; 3]).collect(),
        };
        let c = compare(&a, &r, None);
        assert!((c.relative_rmse - 0.2).abs() < 1e-6);
        assert!(c.block_mean_error < 1e-6);
    }

    #[test]
    fn emitter_mask_drops_hot_pixels_and_their_neighbours() {
        let mut r = constant(8, 8, 0.1);
        r.pixels[3 * 8 + 3] = [10.0; 3];
        let keep = emitter_mask(&r, 1.0);
        assert_eq!(keep.iter().filter(|&&k| !k).count(), 9);
        assert!(!keep[2 * 8 + 2] && keep[0]);
    }

    /// r(x, y, c) = k_c · (i + 1) / n for the pixel index i = y·w + x of n = w·h pixels: channel
    /// means k_c · (n + 1) / (2n), peak k_0 = 1.
    const K: [f32; 3] = [1.0, 0.5, 0.25];
    fn ramp(w: u32, h: u32) -> LinearImage {
        let n = (w * h) as f32;
        LinearImage { width: w, height: h, pixels: (0..w * h).map(|i| K.map(|k| k * (i as f32 + 1.0) / n)).collect() }
    }

    fn ramp_mean(w: u32, h: u32) -> f64 {
        let n = (w * h) as f64;
        K.iter().map(|&k| k as f64).sum::<f64>() / 3.0 * (n + 1.0) / (2.0 * n)
    }

    fn map(image: &LinearImage, f: impl FnMut(&[f32; 3]) -> [f32; 3]) -> LinearImage {
        LinearImage { width: image.width, height: image.height, pixels: image.pixels.iter().map(f).collect() }
    }

    #[test]
    fn identical_images_have_zero_error_unit_ratio_and_infinite_psnr() {
        let r = ramp(40, 24);
        let c = compare(&r, &r, None);
        assert_eq!((c.relative_rmse, c.block_mean_error, c.mean_ratio), (0.0, 0.0, [1.0; 3]));
        assert_eq!(c.psnr, f64::INFINITY);
        assert_eq!(c.pixels, 40 * 24);
    }

    #[test]
    fn constant_offset_gives_the_closed_form_errors() {
        // 40 x 24: partial blocks at the right and bottom edges.
        let (w, h, delta) = (40, 24, 0.05f32);
        let r = ramp(w, h);
        let a = map(&r, |p| p.map(|v| v + delta));
        let c = compare(&a, &r, None);
        let mean = ramp_mean(w, h);
        let d = delta as f64;
        assert!((c.relative_rmse - d / mean).abs() < 1e-5 * d / mean, "{c:?}");
        // Every block mean is off by exactly delta.
        assert!((c.block_mean_error - d / mean).abs() < 1e-5 * d / mean, "{c:?}");
        let n = (w * h) as f64;
        for ch in 0..3 {
            let mean_c = K[ch] as f64 * (n + 1.0) / (2.0 * n);
            assert!((c.mean_ratio[ch] - (mean_c + d) / mean_c).abs() < 1e-5, "channel {ch}: {c:?}");
        }
        // PSNR = 20·log10(peak / delta) with peak 1.
        assert!((c.psnr - 20.0 * (1.0 / d).log10()).abs() < 1e-4, "{c:?}");
        assert!((rmse(&a, &r, None) - d).abs() < 1e-6);
    }

    #[test]
    fn gaussian_noise_of_known_level_is_measured_within_sampling_error() {
        let (w, h, sigma) = (64u32, 64u32, 0.05f64);
        let r = ramp(w, h);
        let mut normal = crate::sampling::gaussian_deviates(7);
        let a = map(&r, |p| p.map(|v| v + (sigma * normal()) as f32));
        let c = compare(&a, &r, None);
        let mean = ramp_mean(w, h);
        let samples = (3 * w * h) as f64;

        // The RMS of N deviates of std σ has standard deviation ≈ σ/√(2N).
        let rms_sd = sigma / (2.0 * samples).sqrt();
        assert!((c.relative_rmse * mean - sigma).abs() < 4.0 * rms_sd, "rmse {} vs σ {sigma}", c.relative_rmse * mean);
        // PSNR = 20·log10(peak/σ), peak 1; its sd is (20/ln 10)·rms_sd/σ.
        let psnr_sd = 20.0 / std::f64::consts::LN_10 * rms_sd / sigma;
        assert!((c.psnr - 20.0 * (1.0 / sigma).log10()).abs() < 4.0 * psnr_sd, "psnr {}", c.psnr);

        // A block mean of 256 pixels has sd σ_b = σ/16; |N(0, σ_b²)| has mean σ_b·√(2/π) and sd
        // σ_b·√(1 − 2/π), and the error averages 16 blocks × 3 channels of them.
        let sigma_b = sigma / 16.0;
        let expected = sigma_b * (2.0 / std::f64::consts::PI).sqrt();
        let sd = sigma_b * (1.0 - 2.0 / std::f64::consts::PI).sqrt() / 48f64.sqrt();
        let block = c.block_mean_error * mean;
        assert!((block - expected).abs() < 4.0 * sd, "block error {block} vs {expected} ± {sd}");
        assert!(block < 0.1 * sigma, "noise averages out in block means");

        // A channel mean of 4096 pixels has sd σ/64.
        let n = (w * h) as f64;
        for ch in 0..3 {
            let mean_c = K[ch] as f64 * (n + 1.0) / (2.0 * n);
            assert!((c.mean_ratio[ch] - 1.0).abs() < 4.0 * sigma / 64.0 / mean_c, "channel {ch}: {c:?}");
        }
    }

    #[test]
    fn masked_pixels_do_not_count() {
        let r = ramp(32, 32);
        let mut a = r.clone();
        a.pixels[5] = [100.0; 3];
        let mut keep = vec![true; 32 * 32];
        keep[5] = false;
        let c = compare(&a, &r, Some(&keep));
        assert_eq!((c.relative_rmse, c.block_mean_error, c.pixels), (0.0, 0.0, 32 * 32 - 1));
        assert!(compare(&a, &r, None).relative_rmse > 0.0);
    }

    #[test]
    fn difference_image_is_blue_where_darker_red_where_brighter_white_where_equal() {
        // Reference mean 0.5; scale 0.1, so full colour at a difference of 0.05.
        let r = constant(6, 1, 0.5);
        let mut a = r.clone();
        a.pixels[1] = [0.40; 3]; // d = −0.2: saturated blue
        a.pixels[2] = [0.60; 3]; // d = +0.2: saturated red
        a.pixels[3] = [0.525; 3]; // d = +0.05, half the scale: half-way to red
        a.pixels[4] = [0.6, 0.5, 0.4]; // channel differences cancel: white
        let keep = [true, true, true, true, true, false];
        let diff = difference_image(&a, &r, Some(&keep), 0.1);
        let px = |i: usize| [diff.rgba[4 * i], diff.rgba[4 * i + 1], diff.rgba[4 * i + 2]];
        assert_eq!((diff.width, diff.height, diff.rgba.len()), (6, 1, 24));
        assert_eq!(px(0), DIFF_EQUAL);
        assert_eq!(px(1), DIFF_DARKER);
        assert_eq!(px(2), DIFF_BRIGHTER);
        let half = [0, 1, 2].map(|c| ((DIFF_EQUAL[c] as f64 + DIFF_BRIGHTER[c] as f64) / 2.0).round() as u8);
        assert_eq!(px(3), half);
        assert_eq!(px(4), DIFF_EQUAL);
        assert_eq!(px(5), DIFF_MASKED);
        assert!(diff.rgba.chunks(4).all(|p| p[3] == 255));
    }
}

/// Refuses an image with a NaN or infinite pixel; `name` says which (its path).
pub fn check_finite(name: impl std::fmt::Display, image: &LinearImage) -> Result<()> {
    crate::image_io::validate_finite(image)
        .map_err(|e| Error::Invalid(format!("{name}: {e}; compare needs finite pixel values")))
}

/// Refuses a `--mask-emitters` threshold that is not a finite number.
pub fn check_mask_threshold(mask_emitters: Option<f32>) -> Result<()> {
    if let Some(t) = mask_emitters.filter(|t| !t.is_finite()) {
        return Err(Error::Invalid(format!("--mask-emitters needs a finite threshold, got {t}")));
    }
    Ok(())
}

/// What `rastergi compare` prints (and the Python package's `compare` returns): the metrics
/// over the compared pixels.
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
        return Err(Error::Invalid(format!(
            "the images differ in size: {image_name} is {} x {} but {reference_name} is {} x {}; compare needs images of the same size",
            image.width, image.height, reference.width, reference.height
        )));
    }
    let mask = mask_emitters.map(|t| emitter_mask(reference, t));
    let m = mask.as_deref();
    let total = image.pixels.len();
    let kept = m.map_or(total, |m| m.iter().filter(|&&k| k).count());
    if kept == 0 {
        return Err(Error::Invalid("--mask-emitters leaves no pixel to compare; raise its threshold".into()));
    }
    let mean_ref = masked_mean(reference, m);
    if mean_ref <= 0.0 {
        return Err(Error::Invalid(format!(
            "{reference_name}: the reference is black over the compared pixels (mean {mean_ref}), so relative errors are undefined"
        )));
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

/// The noise of one render, measured from renders of the same settings with independent seeds
/// (`rastergi noise`): for k renders x_1 … x_k, per pixel and channel the unbiased sample
/// variance s² = Σ_i (x_i − x̄)² / (k − 1), whose expectation is one render's variance σ²
/// whatever the image's expectation is. Over the kept pixels, with m the renders' mean:
///
/// ```text
///   relative = √(mean s²) / m      (one render's relative RMSE against its expectation)
/// ```
///
/// what `rastergi compare` would give against a noise-free reference, less the bias. Where
/// the noise has a heavy tail, a few pixels hold most of Σ s² and two renders tell little (the
/// shared classroom: 17.5 % from one pair of seeds, 23.1 % from the next, docs/measurements.md):
/// the pairs' own estimates are reported beside it.
#[derive(Clone, Debug, PartialEq)]
pub struct SeedNoise {
    /// √(mean s²) / m over the kept pixels and channels.
    pub relative: f64,
    /// The same over the best 99 % of the kept pixels (by s² averaged over the channels): the
    /// body of the noise.
    pub body: f64,
    /// The share of Σ s² in the worst 1 % of the kept pixels (at least one): the tail.
    pub tail_share: f64,
    /// `relative` from each disjoint pair of renders alone, (1, 2), (3, 4) …:
    /// √(mean (a − b)²/2) / m.
    pub pairs: Vec<f64>,
    /// The renders' mean over the kept pixels and channels.
    pub mean: f64,
    pub renders: usize,
    pub compared_pixels: usize,
    pub total_pixels: usize,
}

/// [`SeedNoise`] of `images` (at least two, one size; `names` for the messages) over the pixels
/// that the emitter mask of their mean leaves (`mask_emitters`, as `rastergi compare`'s of its
/// reference), refusing fewer than two images, images of different sizes, a mask that leaves
/// nothing and a black mean.
pub fn seed_noise(images: &[LinearImage], names: &[String], mask_emitters: Option<f32>) -> Result<SeedNoise> {
    check_mask_threshold(mask_emitters)?;
    if images.len() < 2 {
        return Err(Error::Invalid(
            "noise needs at least two renders of the same settings with different seeds; give two or more images"
                .into(),
        ));
    }
    let first = &images[0];
    for (image, name) in images.iter().zip(names).skip(1) {
        if (image.width, image.height) != (first.width, first.height) {
            return Err(Error::Invalid(format!(
                "the images differ in size: {} is {} x {} but {name} is {} x {}; noise needs renders of the same size",
                names[0], first.width, first.height, image.width, image.height
            )));
        }
    }
    let k = images.len() as f64;
    let pixels = first.pixels.len();
    // x̄ per pixel and channel, once: for the emitter mask, the mean and the variances.
    let means: Vec<[f64; 3]> = (0..pixels)
        .map(|p| [0, 1, 2].map(|c| images.iter().map(|i| f64::from(i.pixels[p][c])).sum::<f64>() / k))
        .collect();
    let mask = mask_emitters.map(|t| {
        let pixels = means.iter().map(|m| m.map(|v| v as f32)).collect();
        emitter_mask(&LinearImage { width: first.width, height: first.height, pixels }, t)
    });
    let kept: Vec<usize> = (0..pixels).filter(|&p| mask.as_ref().is_none_or(|m| m[p])).collect();
    if kept.is_empty() {
        return Err(Error::Invalid("--mask-emitters leaves no pixel to measure; raise its threshold".into()));
    }
    let mean = kept.iter().map(|&p| means[p].iter().sum::<f64>()).sum::<f64>() / (3.0 * kept.len() as f64);
    if mean <= 0.0 {
        return Err(Error::Invalid(format!(
            "the renders are black over the measured pixels (mean {mean}), so relative noise is undefined"
        )));
    }
    // s² per kept pixel, averaged over its channels.
    let mut variance: Vec<f64> = kept
        .iter()
        .map(|&p| {
            (0..3)
                .map(|c| images.iter().map(|i| (f64::from(i.pixels[p][c]) - means[p][c]).powi(2)).sum::<f64>())
                .sum::<f64>()
                / (3.0 * (k - 1.0))
        })
        .collect();
    let total: f64 = variance.iter().sum();
    variance.sort_by(|a, b| b.total_cmp(a));
    let worst = (kept.len() / 100).max(1);
    let tail: f64 = variance[..worst].iter().sum();
    let n = kept.len() as f64;
    let relative = (total / n).sqrt() / mean;
    let body = if kept.len() > worst { ((total - tail) / (n - worst as f64)).sqrt() / mean } else { 0.0 };
    let pairs = images
        .chunks_exact(2)
        .map(|pair| {
            let s: f64 = kept
                .iter()
                .map(|&p| {
                    (0..3)
                        .map(|c| (f64::from(pair[0].pixels[p][c]) - f64::from(pair[1].pixels[p][c])).powi(2) / 2.0)
                        .sum::<f64>()
                })
                .sum();
            (s / (3.0 * n)).sqrt() / mean
        })
        .collect();
    Ok(SeedNoise {
        relative,
        body,
        tail_share: if total > 0.0 { tail / total } else { 0.0 },
        pairs,
        mean,
        renders: images.len(),
        compared_pixels: kept.len(),
        total_pixels: pixels,
    })
}
