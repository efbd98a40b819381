//! Image error metrics of DESIGN.md ("Validation"): relative RMSE over pixels and channels,
//! and the error of 16×16 block means, where Monte Carlo noise averages out and bias remains.

use crate::image_io::LinearImage;

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
    /// 10·log10(max(r)² / mean((a − r)²)).
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
        psnr: 10.0 * (max_r * max_r / mse.max(f64::MIN_POSITIVE)).log10(),
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
