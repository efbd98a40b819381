//! The denoiser (`passes/denoise/`): the GPU filter against its CPU twin, the convergence rule on
//! a synthetic image, and the Cornell box against the committed Mitsuba reference.

mod common;

use rastergi::image_io::LinearImage;
use rastergi::metrics::{Comparison, compare, emitter_mask, rmse};
use rastergi::passes::denoise::{DenoiseParams, Denoiser, EXTRA_SLOTS, GUIDE_SLOTS, cpu};
use rastergi::passes::film::{COMPONENTS, Show};
use rastergi::progressive::Denoising;
use rastergi::renderer::Renderer;
use rastergi::sampling::{pcg_hash, unit_f32};
use rastergi::scene::cornell_box;
use rastergi::settings::RenderSettings;

/// A uniform number in [0, 1) from three indices.
fn hash(a: u32, b: u32, c: u32) -> f32 {
    unit_f32(pcg_hash(a ^ pcg_hash(b ^ pcg_hash(c))))
}

/// A synthetic scene of `w × h` pixels: two planes meeting at a vertical edge (different
/// normals and distances), a checker albedo on the left one, smooth light with a step, and a
/// small emitter on the right one (its emission 20 times the light around it).
struct Synthetic {
    w: u32,
    h: u32,
}

impl Synthetic {
    /// The CPU twin's input for `n` iterations of this image's sums.
    fn input<'a>(&self, n: u32, (film, guides, extra): (&'a [f32], &'a [f32], &'a [f32])) -> cpu::Input<'a> {
        cpu::Input {
            width: self.w,
            height: self.h,
            samples: n,
            guide_samples: n,
            film,
            guides,
            extra,
            pixel_angle: PIXEL_ANGLE,
        }
    }

    /// The emission seen at (x, y): a 3 × 2-pixel emitter on the right plane.
    fn emission(&self, x: u32, y: u32) -> [f32; 3] {
        let (ex, ey) = (3 * self.w / 4, self.h / 2);
        if (ex..ex + 3).contains(&x) && (ey..ey + 2).contains(&y) { [20.0, 18.0, 15.0] } else { [0.0; 3] }
    }

    /// Whether (x, y) is the emitter or one of its 8-neighbours.
    fn near_emitter(&self, x: u32, y: u32) -> bool {
        let (ex, ey) = (3 * self.w / 4, self.h / 2);
        (ex - 1..ex + 4).contains(&x) && (ey - 1..ey + 3).contains(&y)
    }

    fn albedo(&self, x: u32, y: u32) -> [f32; 3] {
        if x < self.w / 2 {
            if (x / 4 + y / 4).is_multiple_of(2) { [0.8, 0.2, 0.2] } else { [0.3, 0.7, 0.3] }
        } else {
            [0.6, 0.6, 0.6]
        }
    }

    fn normal(&self, x: u32) -> [f32; 3] {
        if x < self.w / 2 {
            [0.0, 0.0, 1.0]
        } else {
            [std::f32::consts::FRAC_1_SQRT_2, 0.0, std::f32::consts::FRAC_1_SQRT_2]
        }
    }

    fn depth(&self, x: u32, y: u32) -> f32 {
        if x < self.w / 2 { 3.0 + 0.002 * y as f32 } else { 2.0 + 0.01 * (x - self.w / 2) as f32 }
    }

    /// The expected (direct, indirect) light, before the albedo.
    fn light(&self, x: u32, y: u32) -> ([f32; 3], [f32; 3]) {
        let fx = x as f32 / self.w as f32;
        let fy = y as f32 / self.h as f32;
        let direct = if y < self.h / 3 { [0.1; 3] } else { [1.0 + fx, 1.0 + fx, 0.8 + fy] };
        (direct, [0.3 + 0.2 * fy, 0.25, 0.2 + 0.1 * fx])
    }

    /// Film and guide sums of `n` iterations: each adds the expected value times noise of
    /// relative spread `spread` (direct a tenth of it), and the emission, as the renderer's
    /// passes would.
    fn render(&self, n: u32, spread: f32, seed: u32) -> (Vec<f32>, Vec<f32>, Vec<f32>) {
        let pixels = (self.w * self.h) as usize;
        let mut film = vec![0.0f32; COMPONENTS as usize * pixels * 4];
        let mut guides = vec![0.0f32; GUIDE_SLOTS as usize * pixels * 4];
        let mut extra = vec![0.0f32; EXTRA_SLOTS as usize * pixels * 4];
        let lum = |c: [f32; 3]| c[0] * 0.2126 + c[1] * 0.7152 + c[2] * 0.0722;
        for y in 0..self.h {
            for x in 0..self.w {
                let p = (y * self.w + x) as usize;
                let a = self.albedo(x, y);
                let (d, i) = self.light(x, y);
                let nrm = self.normal(x);
                let z = self.depth(x, y);
                let e = self.emission(x, y);
                for k in 0..n {
                    let u = |s: u32| 2.0 * hash(seed ^ s, p as u32, k) - 1.0;
                    let (nd, ni) = (1.0 + 0.1 * spread * u(1) * 1.732, (1.0 + spread * u(2) * 1.732).max(0.0));
                    let dv = [0, 1, 2].map(|c| a[c] * d[c] * nd);
                    let iv = [0, 1, 2].map(|c| a[c] * i[c] * ni);
                    for c in 0..3 {
                        film[4 * p + c] += e[c] + dv[c];
                        extra[4 * (2 * pixels + p) + c] += e[c];
                        film[4 * (pixels + p) + c] += iv[c];
                        guides[4 * p + c] += a[c];
                        guides[4 * (pixels + p) + c] += nrm[c];
                    }
                    guides[4 * p + 3] += z;
                    guides[4 * (pixels + p) + 3] += 1.0;
                    let (ld, li) = (lum(d) * nd, lum(i) * ni);
                    let m = 4 * (2 * pixels + p);
                    guides[m] += ld;
                    guides[m + 1] += ld * ld;
                    guides[m + 2] += li;
                    guides[m + 3] += li * li;
                }
            }
        }
        (film, guides, extra)
    }

    /// The expected image.
    fn truth(&self) -> LinearImage {
        let mut pixels = Vec::new();
        for y in 0..self.h {
            for x in 0..self.w {
                let a = self.albedo(x, y);
                let (d, i) = self.light(x, y);
                let e = self.emission(x, y);
                pixels.push([0, 1, 2].map(|c| e[c] + a[c] * (d[c] + i[c])));
            }
        }
        LinearImage { width: self.w, height: self.h, pixels }
    }
}

const PIXEL_ANGLE: f32 = 0.02;

/// The pixels of `reference` (kept by `mask`) whose largest relative difference from a
/// 4-neighbour is among the highest tenth: edges, corners, shadow boundaries.
fn high_gradient_mask(reference: &LinearImage, mask: &[bool]) -> Vec<bool> {
    let (w, h) = (reference.width as i32, reference.height as i32);
    let lum = |x: i32, y: i32| {
        let p = reference.pixels[(y.clamp(0, h - 1) * w + x.clamp(0, w - 1)) as usize];
        0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]
    };
    let gradient: Vec<f32> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| {
            let c = lum(x, y);
            let d = [(1, 0), (-1, 0), (0, 1), (0, -1)].map(|(dx, dy)| (lum(x + dx, y + dy) - c).abs());
            d.into_iter().fold(0.0, f32::max) / c.max(1e-3)
        })
        .collect();
    let mut kept: Vec<f32> = gradient.iter().zip(mask).filter(|(_, m)| **m).map(|(g, _)| *g).collect();
    kept.sort_by(f32::total_cmp);
    let threshold = kept[kept.len() * 9 / 10];
    gradient.iter().zip(mask).map(|(g, m)| *m && *g >= threshold).collect()
}

fn max_abs_difference(a: &LinearImage, b: &LinearImage) -> f32 {
    a.pixels.iter().zip(&b.pixels).flat_map(|(p, q)| (0..3).map(move |c| (p[c] - q[c]).abs())).fold(0.0, f32::max)
}

#[test]
fn gpu_filter_matches_its_cpu_twin() {
    let gpu = common::gpu();
    let s = Synthetic { w: 32, h: 24 };
    let n = 16;
    let (film, guides, extra) = s.render(n, 0.5, 7);
    let params = DenoiseParams::default();
    let input = s.input(n, (&film, &guides, &extra));
    let expected = cpu::denoise(&input, &params);
    let raw = cpu::raw(&input);
    let usage = wgpu::BufferUsages::COPY_SRC;
    let film_buffer = gpu.storage_buffer("film", bytemuck::cast_slice(&film), usage);
    let guide_buffer = gpu.storage_buffer("guides", bytemuck::cast_slice(&guides), usage);
    let extra_buffer = gpu.storage_buffer("extra", bytemuck::cast_slice(&extra), usage);
    let denoiser = Denoiser::new(&gpu, (s.w, s.h), &film_buffer, (&guide_buffer, &extra_buffer), 3);
    let got = denoiser.apply(&gpu, (n, n), PIXEL_ANGLE, &params).unwrap();
    let diff = max_abs_difference(&got, &expected);
    let change = max_abs_difference(&raw, &expected);
    println!("GPU vs CPU twin: max |difference| {diff:e}; the filter changed pixels by up to {change:.3}");
    assert!(change > 0.05, "the filter did nothing on the test image ({change})");
    // f32 with exp/pow/sqrt of a few ulps' difference through the guide's levels and the
    // regression's solve: 1e-4 of the light's scale (about 1).
    assert!(diff < 1e-4, "GPU and CPU twin differ by {diff}");
    // Other levels and windows: also the same (3 levels, more than the default; none, the
    // regression guided by the unfiltered light).
    for other in [
        DenoiseParams { levels: 3, radius_direct: 2, radius_indirect: 4, ..params },
        DenoiseParams { levels: 0, sigma_g: 2.0, ridge: 1.0e-2, ..params },
    ] {
        let got = denoiser.apply(&gpu, (n, n), PIXEL_ANGLE, &other).unwrap();
        let diff = max_abs_difference(&got, &cpu::denoise(&input, &other));
        assert!(diff < 1e-4, "{other:?}: GPU and CPU twin differ by {diff}");
    }
}

/// The convergence rule on the synthetic image: at 16 iterations the denoised image is
/// closer to the expectation than the raw one, and next to the emitter no farther than
/// elsewhere (its light is not spread to its neighbours); as the iterations grow, the denoised image's difference from
/// the raw one shrinks relative to the raw image's own noise, far under it.
#[test]
fn denoised_image_converges_to_the_raw_one() {
    let s = Synthetic { w: 32, h: 32 };
    let truth = s.truth();
    let params = DenoiseParams::default();
    let mut ratios = Vec::new();
    for n in [16u32, 256, 4096] {
        let (film, guides, extra) = s.render(n, 1.0, 3);
        let input = s.input(n, (&film, &guides, &extra));
        let (raw, denoised) = (cpu::raw(&input), cpu::denoise(&input, &params));
        let (raw_err, den_err, change) =
            (rmse(&raw, &truth, None), rmse(&denoised, &truth, None), rmse(&denoised, &raw, None));
        println!(
            "n {n}: RMSE raw {raw_err:.5}, denoised {den_err:.5}; denoised − raw {change:.5} ({:.3} of the raw noise)",
            change / raw_err
        );
        if n == 16 {
            assert!(den_err < raw_err, "denoising did not lower the error at 16 iterations");
            let near: Vec<bool> =
                (0..s.h).flat_map(|y| (0..s.w).map(move |x| (x, y))).map(|(x, y)| s.near_emitter(x, y)).collect();
            let (raw_near, den_near) = (rmse(&raw, &truth, Some(&near)), rmse(&denoised, &truth, Some(&near)));
            println!("n {n}, the emitter and its neighbours: RMSE raw {raw_near:.5}, denoised {den_near:.5}");
            // The emitter's neighbours are denoised as well as the image as a whole (measured
            // 0.0120 against 0.0156; filtering the emission with the reflected light, as the
            // denoiser did before it took the emission out, gave 0.0189 there).
            assert!(den_near < den_err, "the emitter's light spreads: RMSE {den_near} near it, {den_err} overall");
        }
        ratios.push(change / raw_err);
    }
    assert!(ratios[2] < ratios[0], "the change relative to the noise does not fall: {ratios:?}");
    assert!(ratios[2] < 0.5, "at 4096 iterations the denoiser still changes the image by {} of its noise", ratios[2]);
}

/// The figures of one iteration count of [`against_reference`].
#[derive(Clone, Copy, Debug)]
struct Figures {
    raw: Comparison,
    denoised: Comparison,
    /// Relative RMSE of the denoised image against the raw one.
    change: f64,
    /// The raw image's own relative noise from the film's halves (once both hold blocks).
    noise: Option<f64>,
}

/// The Cornell box at `size`² (seed 5, traced gather), raw and denoised after each of
/// `iterations`, against the committed Mitsuba pair `stem` with the emitter's pixels masked
/// as in gather.rs; prints the figures, also for the high-gradient tenth of the pixels.
fn against_reference(size: u32, stem: &str, iterations: &[u32]) -> Vec<Figures> {
    let gpu = common::gpu();
    let scene = cornell_box();
    let settings = RenderSettings { seed: 5, ..common::fitted_settings(&scene, size, 5) };
    let probe = rastergi::image_io::read_exr(&common::data(&format!("{stem}_a.exr"))).unwrap();
    let mask = emitter_mask(&probe, 3.0);
    let (reference, ref_noise) = common::reference_pair(stem, Some(&mask));
    let edges = high_gradient_mask(&reference, &mask);
    let mut r = Renderer::new(&gpu, &scene, settings).unwrap();
    r.enable_denoiser().unwrap();
    let params = DenoiseParams::default();
    let c = |i: &LinearImage| compare(i, &reference, Some(&mask));
    let mean = rastergi::metrics::masked_mean(&reference, Some(&mask));
    println!("{size}²: the reference's own relative noise {:.4}", ref_noise / mean);
    let mut done = 0;
    let mut figures = Vec::new();
    for &n in iterations {
        while done < n {
            r.iterate().unwrap();
            done += 1;
            if done % 64 == 0 {
                r.wait().unwrap();
            }
        }
        let raw = r.read_linear(Show::Full).unwrap();
        let den = r.read_denoised(&params).unwrap();
        let f = Figures {
            raw: c(&raw),
            denoised: c(&den),
            change: rmse(&den, &raw, Some(&mask)) / mean,
            noise: r.film_state().unwrap().error_estimate(),
        };
        let (er, ed) = (compare(&raw, &reference, Some(&edges)), compare(&den, &reference, Some(&edges)));
        println!(
            "{size}², n {n}, high-gradient tenth: raw relative RMSE {:.4}, denoised {:.4}",
            er.relative_rmse, ed.relative_rmse
        );
        println!(
            "{size}², n {n}: raw relative RMSE {:.4} (block {:.4}), denoised {:.4} (block {:.4}, mean ratio {:.4?}); \
             denoised − raw {:.4}, raw noise (halves) {:.4?}",
            f.raw.relative_rmse,
            f.raw.block_mean_error,
            f.denoised.relative_rmse,
            f.denoised.block_mean_error,
            f.denoised.mean_ratio,
            f.change,
            f.noise
        );
        figures.push(f);
    }
    figures
}

/// The block means of 16 denoised iterations stay within 0.5 % of the reference: no
/// darkening of corners, no light spread across edges.
fn assert_block_means(den16: &Comparison) {
    assert!(den16.block_mean_error < 0.005, "denoised 16: block-mean error {}", den16.block_mean_error);
    for c in den16.mean_ratio {
        assert!((c - 1.0).abs() < 0.005, "denoised 16: mean ratio {:?}", den16.mean_ratio);
    }
}

/// The Cornell box at 128² against the committed Mitsuba pair: 16 iterations denoised against
/// 16, 64 and 256 raw; then the convergence rule: at 1024 iterations the denoised image
/// differs from the raw one by less than the raw image's own noise (the film halves'
/// estimate; at 256 iterations the render has had one photon pass, one block, and the halves
/// say nothing). About 140 s on lavapipe.
///
/// Measured (lavapipe, seed 5; the reference's own noise 0.0075): relative RMSE raw 16 0.0671,
/// 64 0.0282, 256 0.0164, 1024 0.0092; denoised 16 0.0236 (block-mean error 0.0044; raw 256:
/// 0.0028), 256 0.0134, 1024 0.0092; at 1024 denoised − raw 0.0050, the raw noise 0.0085.
/// The goal, denoised 16 no worse than raw 256, is not met: 16 denoised iterations
/// are worth about 100 raw.
#[test]
fn cornell_box_denoised_against_raw_and_the_convergence_rule() {
    let figures = against_reference(128, "cornell_path_128", &[16, 64, 256, 1024]);
    let (raw16, den16, raw64) = (figures[0].raw, figures[0].denoised, figures[1].raw);
    // Denoising 16 iterations cuts their error to a third (measured 0.35×) and below 64 raw
    // iterations' (measured 0.84×).
    assert!(den16.relative_rmse < 0.4 * raw16.relative_rmse, "denoised 16 {den16:?} vs raw {raw16:?}");
    assert!(den16.relative_rmse < raw64.relative_rmse, "denoised 16 {den16:?} vs raw 64 {raw64:?}");
    assert_block_means(&den16);
    // At 256 iterations the denoised image is closer to the reference than the raw one
    // (measured 0.0134 vs 0.0164).
    let (raw256, den256) = (figures[2].raw, figures[2].denoised);
    assert!(den256.relative_rmse < raw256.relative_rmse, "256: denoised {den256:?} vs raw {raw256:?}");
    // The convergence rule: at 1024 iterations denoised − raw is under the raw noise, and the
    // denoised image is no farther from the reference than the raw one (measured 0.00918 vs
    // 0.00919; 1.02× allows for the last digit).
    let f = figures[3];
    let noise = f.noise.expect("both halves hold iterations at 1024");
    assert!(f.change < noise, "1024: the denoiser changes the image by {}, the raw noise is {noise}", f.change);
    assert!(f.denoised.relative_rmse < 1.02 * f.raw.relative_rmse, "1024: {f:?}");
}

/// The issue's own comparison, the Cornell box at 256² against the committed 256² Mitsuba
/// pair: 16 iterations denoised against 64 raw. About 25 s on lavapipe.
///
/// Measured (lavapipe, seed 5): see the tables in docs/denoiser.md. 16 denoised iterations are
/// closer to the reference than 64 raw ones, not yet than 256 raw ones (the goal; the
/// tables hold that figure, which nothing here asserts, so the render stops at 64).
#[test]
fn cornell_box_at_256_denoised_16_against_raw_64() {
    let figures = against_reference(256, "cornell_path_256", &[16, 64]);
    let (den16, raw64) = (figures[0].denoised, figures[1].raw);
    assert!(den16.relative_rmse < raw64.relative_rmse, "denoised 16 {den16:?} vs raw 64 {raw64:?}");
    assert_block_means(&den16);
}

/// The display encoding computed here, independently of the GPU's: 2^exposure · value,
/// clamped to [0, 1], the sRGB transfer function (IEC 61966-2-1), rounded to 8 bits.
fn srgb_bytes(image: &LinearImage, exposure: f32) -> Vec<[u8; 3]> {
    let scale = 2f64.powf(exposure as f64);
    let byte = |v: f32| {
        let c = (v as f64 * scale).clamp(0.0, 1.0);
        let e = if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 };
        (e * 255.0).round() as u8
    };
    image.pixels.iter().map(|p| p.map(byte)).collect()
}

/// The largest difference per channel between a display image's bytes and `expected`, and
/// how many pixels differ at all.
fn display_difference(shown: &rastergi::image_io::DisplayImage, expected: &[[u8; 3]]) -> (u8, usize) {
    let mut worst = 0;
    let mut differing = 0;
    for (px, e) in shown.rgba.chunks_exact(4).zip(expected) {
        let d = (0..3).map(|c| px[c].abs_diff(e[c])).max().unwrap();
        worst = worst.max(d);
        differing += (d > 0) as usize;
    }
    (worst, differing)
}

/// What `rastergi view` draws with the denoiser on: the film's display buffer after
/// `encode_denoise` + `encode_resolve_denoised` is the display encoding of `read_denoised`'s
/// image (computed on the CPU here) within 1/255 per channel, at exposures that clamp and that
/// do not, also when only the exposure changes (no new filter); and it is not the raw image's.
/// Then the raw resolve draws the raw image again.
#[test]
fn denoised_display_is_the_display_encoding_of_the_denoised_image() {
    let gpu = common::gpu();
    let scene = cornell_box();
    let mut r = Renderer::new(&gpu, &scene, common::fitted_settings(&scene, 64, 2)).unwrap();
    r.enable_denoiser().unwrap();
    for _ in 0..4 {
        r.iterate().unwrap();
    }
    let params = DenoiseParams::default();
    let denoised = r.read_denoised(&params).unwrap();
    let raw = r.read_linear(Show::Full).unwrap();
    for exposure in [0.0f32, 1.5, -2.0] {
        let shown = r.read_display_denoised(&params, exposure).unwrap();
        assert_eq!((shown.width, shown.height), (64, 64));
        let (worst, differing) = display_difference(&shown, &srgb_bytes(&denoised, exposure));
        let (_, from_raw) = display_difference(&shown, &srgb_bytes(&raw, exposure));
        println!(
            "exposure {exposure}: denoised display vs CPU encoding: max {worst}/255, {differing} of 4096 pixels \
             differ; {from_raw} pixels differ from the raw image's encoding"
        );
        assert!(worst <= 1, "exposure {exposure}: the denoised display is {worst}/255 off its CPU encoding");
        assert!(from_raw > 1000, "exposure {exposure}: the display shows the raw image ({from_raw} pixels differ)");
    }
    // A new exposure alone: the resolve of the image as last filtered, in one encoder.
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    r.encode_resolve_denoised(&mut enc, 1.0).unwrap();
    gpu.queue.submit([enc.finish()]);
    let shown = r.film().read_display_buffer(&gpu).unwrap();
    let (worst, _) = display_difference(&shown, &srgb_bytes(&denoised, 1.0));
    assert!(worst <= 1, "re-exposed without a new filter: {worst}/255 off");
    // The raw resolve takes the display buffer back.
    let shown = r.read_display(Show::Full, 0.0).unwrap();
    let (worst, _) = display_difference(&shown, &srgb_bytes(&raw, 0.0));
    assert!(worst <= 1, "the raw display after the denoised one: {worst}/255 off");
}

/// Texture sharpness: the textured room (a checker floor, a striped back wall, a textured cube
/// and panels: common/textured_room.rs) at 128², 16 iterations raw and denoised against 256
/// raw iterations at another seed. In the pixels of the reference's highest tenth of
/// gradients, the checker's and the stripes' edges among them, the denoised image is closer
/// than the raw one, and over all pixels much closer: demodulating by the albedo keeps the
/// textures out of the filter. About 35 s on lavapipe.
///
/// Measured (lavapipe): relative RMSE raw 0.0469, denoised 0.0267 (0.57×); in the high-gradient
/// tenth raw 0.0738, denoised 0.0642 (the reference's own noise about 0.008).
#[test]
fn textures_stay_sharp() {
    use common::textured_room::{self as room, Variant};
    let gpu = common::gpu();
    let dir = tempfile::tempdir().unwrap();
    let path = room::room_gltf(Variant::Binary).write(dir.path(), "room.glb");
    let scene = rastergi::scene::load_gltf(&path).unwrap();
    let settings = |seed| RenderSettings { seed, ..common::fitted_settings(&scene, 128, seed) };
    // 256 iterations (512 until issue 44): its own noise about 0.011 instead of 0.008, which adds
    // to both comparisons alike (measured denoised/raw 0.57 with 512, against the 0.65 bound).
    let reference = common::render(&gpu, &scene, settings(9), 256, Show::Full);
    let mask = emitter_mask(&reference, 3.0);
    let edges = high_gradient_mask(&reference, &mask);
    let mut r = Renderer::new(&gpu, &scene, settings(5)).unwrap();
    r.enable_denoiser().unwrap();
    for _ in 0..16 {
        r.iterate().unwrap();
    }
    let raw = r.read_linear(Show::Full).unwrap();
    let den = r.read_denoised(&DenoiseParams::default()).unwrap();
    let (all_raw, all_den) = (compare(&raw, &reference, Some(&mask)), compare(&den, &reference, Some(&mask)));
    let (edge_raw, edge_den) = (compare(&raw, &reference, Some(&edges)), compare(&den, &reference, Some(&edges)));
    println!(
        "textured room, 16 iterations: relative RMSE raw {:.4}, denoised {:.4}; high-gradient tenth raw {:.4}, \
         denoised {:.4}",
        all_raw.relative_rmse, all_den.relative_rmse, edge_raw.relative_rmse, edge_den.relative_rmse
    );
    assert!(edge_den.relative_rmse < edge_raw.relative_rmse, "edges: denoised {edge_den:?}, raw {edge_raw:?}");
    assert!(all_den.relative_rmse < 0.65 * all_raw.relative_rmse, "denoised {all_den:?}, raw {all_raw:?}");
    assert_block_means(&all_den);
}
