//! An environment light: radiance from every direction at infinity, stored as an
//! equirectangular (latitude–longitude) image, importance-sampled by luminance
//! (`environment.wgsl` is its GPU twin).
//!
//! # Mapping (Mitsuba 3's `envmap` with the identity `to_world`)
//! A direction d = (x, y, z) has texture coordinates
//!   u = atan2(x, −z) / 2π  (wrapped to [0, 1)),   v = acos(y) / π,
//! so +Y is the zenith (v = 0, the image's top row), u = 0 looks along −Z and u = ¼ along +X;
//! conversely d(u, v) = (sin φ sin θ, cos θ, −cos φ sin θ) with φ = 2πu, θ = πv.
//! Pixel (i, j) of a W × H image sits at u = (i + ½)/W, θ = j·π/(H − 1): the columns at pixel
//! centres, wrapping around, the rows at the poles inclusive (row 0 at the zenith, row H − 1
//! at the nadir). Radiance between them is bilinear in (u, v) over the four nearest pixels:
//! Mitsuba's `eval_spectrum` with its extra periodic column. The same file gives the same
//! light in both renderers.
//!
//! # Sampling
//! The cells between four neighbouring pixels — W columns (the last wraps to column 0) by
//! H − 1 rows — form a 2D discrete distribution with weights ℓ̄·Ω: ℓ̄ the mean luminance of the
//! cell's corners, Ω = (2π/W)(cos θ_j − cos θ_{j+1}) its solid angle (the sin θ weighting,
//! integrated). A cell is picked by its row (marginal) and then its column (conditional), and
//! a direction uniformly in solid angle within it (φ uniform, cos θ uniform), so
//! pdf(ω) = pmf(cell)/Ω(cell). Wherever the radiance is non-zero some corner is, so the pdf
//! is too: the estimator L/pdf is unbiased for any image.

use std::path::Path;
use std::sync::Arc;

use bytemuck::Zeroable;
use glam::{Vec2, Vec3};

use crate::error::{Error, Result};
use crate::gpu::structs::gpu_struct;

/// Rec. 709 luminance, the weight of the sampling distribution (Mitsuba's `luminance`).
pub fn luminance(c: Vec3) -> f32 {
    0.212671 * c.x + 0.715160 * c.y + 0.072169 * c.z
}

/// An environment map: W × H pixels of radiance (the `--env-scale` already applied) and its
/// sampling distribution.
#[derive(Clone, Debug, PartialEq)]
pub struct Environment {
    pub width: u32,
    pub height: u32,
    /// Row-major, row 0 at the zenith.
    pub texels: Vec<Vec3>,
    /// Cumulative probability of the cell rows 0 … j (H − 1 rows).
    pub row_cdf: Vec<f32>,
    /// Per cell row, the cumulative conditional probability of columns 0 … i (W per row).
    pub column_cdf: Vec<f32>,
    /// Joint probability of each cell (row-major, W per row).
    pub cell_pmf: Vec<f32>,
    /// ∫ L dω over the sphere (RGB), from the cells' mean corner radiance × their solid angle.
    pub integral: Vec3,
}

impl Environment {
    /// An environment of `width × height` radiance values (row 0 at the zenith). Mitsuba's
    /// minimum size is 2 × 3; values must be finite, negative ones are clamped to zero.
    pub fn new(width: u32, height: u32, texels: Vec<Vec3>) -> Result<Environment> {
        let bad = |m: String| Error::InvalidScene(format!("environment map: {m}"));
        if width < 2 || height < 3 {
            return Err(bad(format!("{width}x{height} pixels is too small; it needs at least 2x3")));
        }
        if texels.len() as u64 != width as u64 * height as u64 {
            return Err(bad(format!("{} values for {width}x{height} pixels", texels.len())));
        }
        if let Some(i) = texels.iter().position(|t| !t.is_finite()) {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(bad(format!("pixel ({x}, {y}) is not finite ({}); repair the image", texels[i])));
        }
        if let Some(i) = texels.iter().position(|t| t.max_element() > crate::scene::MAX_LIGHT) {
            let (x, y) = (i as u32 % width, i as u32 / width);
            return Err(bad(format!(
                "pixel ({x}, {y}) is {}, beyond the largest radiance rastergi renders ({:e}); scale the image down",
                texels[i],
                crate::scene::MAX_LIGHT
            )));
        }
        if texels.iter().any(|t| t.min_element() < 0.0) {
            log::warn!("environment map: negative values clamped to zero");
        }
        let texels: Vec<Vec3> = texels.into_iter().map(|t| t.max(Vec3::ZERO)).collect();
        let (w, h) = (width as usize, height as usize);
        let rows = h - 1;
        let texel = |i: usize, j: usize| texels[j * w + i % w];
        let mut weights = vec![0.0f64; w * rows];
        let mut integral = glam::DVec3::ZERO;
        for j in 0..rows {
            let omega = cell_solid_angle(width, height, j as u32) as f64;
            for i in 0..w {
                let mean = 0.25 * (texel(i, j) + texel(i + 1, j) + texel(i, j + 1) + texel(i + 1, j + 1));
                integral += mean.as_dvec3() * omega;
                weights[j * w + i] = luminance(mean) as f64 * omega;
            }
        }
        let total: f64 = weights.iter().sum();
        let (mut row_cdf, mut column_cdf, mut cell_pmf) = (vec![0.0; rows], vec![0.0; w * rows], vec![0.0; w * rows]);
        if total > 0.0 {
            let mut acc = 0.0;
            for j in 0..rows {
                let row = &weights[j * w..(j + 1) * w];
                let row_total: f64 = row.iter().sum();
                acc += row_total;
                row_cdf[j] = (acc / total) as f32;
                let mut c = 0.0;
                for i in 0..w {
                    c += row[i];
                    column_cdf[j * w + i] = if row_total > 0.0 { (c / row_total) as f32 } else { 0.0 };
                    cell_pmf[j * w + i] = (row[i] / total) as f32;
                }
                if row_total > 0.0 {
                    column_cdf[j * w + w - 1] = 1.0;
                }
            }
            // The last row with any weight ends the cdf at exactly 1.
            let last = (0..rows).rev().find(|&j| row_cdf[j] > row_cdf.get(j.wrapping_sub(1)).copied().unwrap_or(0.0));
            for v in &mut row_cdf[last.unwrap_or(0)..] {
                *v = 1.0;
            }
        }
        Ok(Environment { width, height, texels, row_cdf, column_cdf, cell_pmf, integral: integral.as_vec3() })
    }

    /// The environment of `width × height` texels whose texel in column `i`, row `j` (row 0
    /// at the zenith) is `radiance(i, j)`, called row by row; checked as [`Environment::new`].
    pub fn from_fn(width: u32, height: u32, mut radiance: impl FnMut(u32, u32) -> Vec3) -> Result<Environment> {
        let texels = (0..height).flat_map(|j| (0..width).map(move |i| (i, j))).map(|(i, j)| radiance(i, j)).collect();
        Environment::new(width, height, texels)
    }

    /// This environment with its radiance scaled by `factor` (finite, ≥ 0): the sampling
    /// distribution is unchanged (it is proportional to the radiance), the texels and the
    /// integral are × `factor`; × 0 gives a black environment with no distribution, as
    /// [`Environment::new`] builds it.
    pub fn scaled(&self, factor: f32) -> Environment {
        if factor > 0.0 && self.integral.max_element() > 0.0 {
            let texels = self.texels.iter().map(|t| *t * factor).collect();
            return Environment { texels, integral: self.integral * factor, ..self.clone() };
        }
        let texels = self.texels.iter().map(|t| *t * factor.max(0.0)).collect();
        Environment::new(self.width, self.height, texels).expect("the same size and finite values")
    }

    /// A constant environment of radiance `l` (a uniform sky), for radiances the program
    /// chooses: it panics where `l` is not finite, negative or beyond
    /// [`MAX_LIGHT`](crate::scene::MAX_LIGHT). A file's radiance goes through
    /// [`Environment::checked_constant`].
    pub fn constant(l: Vec3) -> Environment {
        Environment::checked_constant(l).expect("a finite radiance ≥ 0 within MAX_LIGHT")
    }

    /// A constant environment of radiance `l`, or why `l` cannot be one (not finite, negative
    /// or beyond [`MAX_LIGHT`](crate::scene::MAX_LIGHT)).
    pub fn checked_constant(l: Vec3) -> std::result::Result<Environment, String> {
        crate::scene::check_light(l, "radiance")?;
        Environment::new(2, 3, vec![l; 6]).map_err(|e| e.to_string())
    }

    /// The neutral light that models without lights are shown in, as glTF viewers show them
    /// (their default image-based light is a grey studio): a grey dome, radiance 1 from the
    /// zenith down to 30° above the horizon, falling smoothly to 0.3 at 10° below it and below
    /// — light from everywhere, with enough above-versus-below to show a model's shape. No
    /// colour, so the model's own colours are what the image shows. 64 × 33 texels.
    pub fn neutral() -> Environment {
        let (w, h) = (64u32, 33u32);
        let texels = (0..h)
            .flat_map(|j| {
                // Row j's elevation: +90° at row 0, −90° at the last.
                let elevation = 90.0 - 180.0 * j as f32 / (h - 1) as f32;
                let t = ((elevation + 10.0) / 40.0).clamp(0.0, 1.0);
                let l = 0.3 + 0.7 * t * t * (3.0 - 2.0 * t);
                std::iter::repeat_n(Vec3::splat(l), w as usize)
            })
            .collect();
        Environment::new(w, h, texels).expect("a valid neutral environment")
    }

    /// Reads an equirectangular image (`.exr` linear RGB, or Radiance `.hdr`) and scales its
    /// radiance by `scale`, within the default budgets.
    pub fn load(path: &Path, scale: f32) -> Result<Arc<Environment>> {
        Environment::load_with(path, scale, &crate::scene::Budgets::default())
    }

    /// [`Environment::load`] of an image of at most `budgets.texels` pixels.
    pub fn load_with(path: &Path, scale: f32, budgets: &crate::scene::Budgets) -> Result<Arc<Environment>> {
        Environment::load_in(crate::scene::Files::Disk, path, scale, budgets)
    }

    /// [`Environment::load_with`] of the file at `path` of `files`.
    pub fn load_in(
        files: crate::scene::Files,
        path: &Path,
        scale: f32,
        budgets: &crate::scene::Budgets,
    ) -> Result<Arc<Environment>> {
        let bad = |m: String| Error::ImageFile { path: path.to_path_buf(), message: m };
        if !scale.is_finite() || scale < 0.0 {
            return Err(Error::InvalidScene(format!("--env-scale {scale} must be a finite number ≥ 0")));
        }
        if files.missing(path).is_some() {
            return Err(bad("no such environment map; give an .exr or .hdr file".into()));
        }
        if files.is_special(path) {
            return Err(bad("is not a regular file".into()));
        }
        let ext = path.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()).unwrap_or_default();
        if !matches!(ext.as_str(), "exr" | "hdr") {
            return Err(bad("unsupported environment map format; use an .exr or .hdr file".into()));
        }
        let bytes = files.read(path).map_err(|e| bad(format!("cannot be read: {e}")))?;
        Environment::decode(&ext, &bytes, scale, budgets.texels).map(Arc::new).map_err(bad)
    }

    /// Decodes an equirectangular image (`ext`: `exr`, linear RGB, or `hdr`, Radiance) of at
    /// most `max_pixels` pixels (its header's size is checked before its pixels are read) and
    /// scales its radiance by `scale`; each texel must then be finite and within
    /// [`MAX_LIGHT`](crate::scene::MAX_LIGHT). Errors say what is wrong without naming the
    /// file.
    pub fn decode(ext: &str, bytes: &[u8], scale: f32, max_pixels: u64) -> std::result::Result<Environment, String> {
        let (width, height, pixels) = match ext {
            "exr" => {
                let img = crate::image_io::decode_exr(std::io::Cursor::new(bytes), max_pixels)?;
                (img.width, img.height, img.pixels)
            }
            "hdr" => {
                let reader = || image::ImageReader::with_format(std::io::Cursor::new(bytes), image::ImageFormat::Hdr);
                let hdr_error =
                    |e: image::ImageError| format!("cannot read Radiance HDR: {}", crate::error::one_line(e));
                let (w, h) = reader().into_dimensions().map_err(hdr_error)?;
                let pixels = w as u64 * h as u64;
                let budgets = crate::scene::Budgets { texels: max_pixels, ..Default::default() };
                let check = budgets.check(crate::scene::Budget::Texels, pixels, &format!("{w}x{h}"));
                check.map_err(|m| format!("its header {m}"))?;
                let mut limits = image::Limits::default();
                limits.max_alloc = Some(pixels.saturating_mul(16).max(1 << 20));
                let mut reader = reader();
                reader.limits(limits);
                let img = reader.decode().map_err(hdr_error)?.into_rgb32f();
                let (w, h) = img.dimensions();
                let pixels: Vec<[f32; 3]> = bytemuck::allocation::try_cast_vec(img.into_raw())
                    .unwrap_or_else(|(_, raw)| raw.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect());
                (w, h, pixels)
            }
            _ => return Err("unsupported environment map format; use an .exr or .hdr file".into()),
        };
        let texels = pixels.into_iter().map(|p| Vec3::from(p) * scale).collect();
        Environment::new(width, height, texels)
            .map_err(|e| e.to_string().trim_start_matches("invalid scene: ").to_string())
    }

    /// The radiance arriving from direction `d` (unit, pointing away from the scene): bilinear
    /// between the four nearest pixels (module docs).
    pub fn eval(&self, d: Vec3) -> Vec3 {
        let (w, h) = (self.width as usize, self.height as usize);
        let uv = direction_to_uv(d);
        let x = (uv.x - 0.5 / w as f32).rem_euclid(1.0) * w as f32;
        let y = uv.y * (h - 1) as f32;
        let (i, j) = ((x as usize).min(w - 1), (y as usize).min(h - 2));
        let (fx, fy) = (x - i as f32, y - j as f32);
        let t = |i: usize, j: usize| self.texels[j * w + i % w];
        let top = t(i, j) * (1.0 - fx) + t(i + 1, j) * fx;
        let bottom = t(i, j + 1) * (1.0 - fx) + t(i + 1, j + 1) * fx;
        top * (1.0 - fy) + bottom * fy
    }

    /// Whether any direction has radiance.
    pub fn is_dark(&self) -> bool {
        self.row_cdf.last().is_none_or(|&c| c == 0.0)
    }

    /// The cell (column, row) holding direction `d`.
    pub(crate) fn cell_of(&self, d: Vec3) -> (usize, usize) {
        let (w, h) = (self.width as usize, self.height as usize);
        let uv = direction_to_uv(d);
        let x = (uv.x - 0.5 / w as f32).rem_euclid(1.0) * w as f32;
        ((x as usize).min(w - 1), ((uv.y * (h - 1) as f32) as usize).min(h - 2))
    }

    /// The solid-angle density with which [`sample`](Self::sample) returns direction `d`.
    pub fn pdf(&self, d: Vec3) -> f32 {
        let (i, j) = self.cell_of(d);
        self.cell_pmf[j * self.width as usize + i] / cell_solid_angle(self.width, self.height, j as u32)
    }

    /// A direction from uniforms (u1, u2) ∈ [0, 1)² and its solid-angle density: the row by
    /// u1, the column by u2, each uniform's position within the chosen interval for the
    /// position within the cell (module docs).
    pub fn sample(&self, u1: f32, u2: f32) -> (Vec3, f32) {
        let w = self.width as usize;
        let j = self.row_cdf.partition_point(|&c| c <= u1).min(self.row_cdf.len() - 1);
        let lo = if j > 0 { self.row_cdf[j - 1] } else { 0.0 };
        let r1 = ((u1 - lo) / (self.row_cdf[j] - lo).max(f32::MIN_POSITIVE)).clamp(0.0, 0.99999994);
        let row = &self.column_cdf[j * w..(j + 1) * w];
        let i = row.partition_point(|&c| c <= u2).min(w - 1);
        let lo = if i > 0 { row[i - 1] } else { 0.0 };
        let r2 = ((u2 - lo) / (row[i] - lo).max(f32::MIN_POSITIVE)).clamp(0.0, 0.99999994);
        let d = self.cell_direction(i as u32, j as u32, r2, r1);
        let omega = cell_solid_angle(self.width, self.height, j as u32);
        (d, self.cell_pmf[j * w + i] / omega)
    }

    /// The direction at fractions (a, b) ∈ [0, 1)² across cell (i, j): φ uniform over the
    /// cell's columns, cos θ uniform over its rows.
    pub(crate) fn cell_direction(&self, i: u32, j: u32, a: f32, b: f32) -> Vec3 {
        let u = (i as f32 + 0.5 + a) / self.width as f32;
        let (c0, c1) = row_cosines(self.height, j);
        let cos_t = c0 - b * (c0 - c1);
        let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
        let phi = 2.0 * std::f32::consts::PI * u;
        Vec3::new(phi.sin() * sin_t, cos_t, -phi.cos() * sin_t)
    }

    /// The most radiance × 1/pdf over directions, per channel's maximum: a bound on L/pdf
    /// (bilinear radiance is at most the cell's largest corner).
    pub fn max_radiance_over_pdf(&self) -> f64 {
        let (w, h) = (self.width as usize, self.height as usize);
        let t = |i: usize, j: usize| self.texels[j * w + i % w].max_element();
        let mut m = 0.0f64;
        for j in 0..h - 1 {
            let omega = cell_solid_angle(self.width, self.height, j as u32) as f64;
            for i in 0..w {
                let corner = t(i, j).max(t(i + 1, j)).max(t(i, j + 1)).max(t(i + 1, j + 1)) as f64;
                let pmf = self.cell_pmf[j * w + i] as f64;
                if corner > 0.0 && pmf > 0.0 {
                    m = m.max(corner * omega / pmf);
                }
            }
        }
        m
    }

    /// The GPU form: [`GpuEnvironment`] (without the light-table fields) and the data buffer
    /// (`environment.wgsl`): texels as RGB triples, then the row cdf, the column cdfs and the
    /// cells' pmfs.
    pub fn gpu_data(&self) -> Vec<f32> {
        let mut data = Vec::with_capacity(self.texels.len() * 3 + self.row_cdf.len() + 2 * self.cell_pmf.len());
        data.extend(self.texels.iter().flat_map(|t| t.to_array()));
        data.extend_from_slice(&self.row_cdf);
        data.extend_from_slice(&self.column_cdf);
        data.extend_from_slice(&self.cell_pmf);
        data
    }
}

/// (cos θ_j, cos θ_{j+1}): the cosines bounding cell row j of an image of `height` rows.
fn row_cosines(height: u32, j: u32) -> (f32, f32) {
    let step = std::f32::consts::PI / (height - 1) as f32;
    ((j as f32 * step).cos(), ((j + 1) as f32 * step).cos())
}

/// The solid angle of a cell of row j: (2π/W)(cos θ_j − cos θ_{j+1}).
pub fn cell_solid_angle(width: u32, height: u32, j: u32) -> f32 {
    let (c0, c1) = row_cosines(height, j);
    2.0 * std::f32::consts::PI / width as f32 * (c0 - c1)
}

/// Texture coordinates (u, v) of unit direction `d` (module docs).
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let u = d.x.atan2(-d.z) / (2.0 * std::f32::consts::PI);
    Vec2::new(u.rem_euclid(1.0), d.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI)
}

/// The unit direction of texture coordinates (u, v) (module docs).
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let (phi, theta) = (2.0 * std::f32::consts::PI * uv.x, std::f32::consts::PI * uv.y);
    Vec3::new(phi.sin() * theta.sin(), theta.cos(), -phi.cos() * theta.sin())
}

gpu_struct! {
    /// `Environment` in WGSL (`environment.wgsl`): the map's size, where its sections start in the
    /// data buffer, its light-table probability and the photon disc.
    #[derive(PartialEq)]
    pub struct GpuEnvironment as "Environment" {
        /// The centre of the scene's bounding sphere, which photons cross from a disc.
        pub disc_centre: [f32; 3],
        /// The photon disc's radius (the bounding sphere's, enlarged by 1 %).
        pub disc_radius: f32,
        /// W and H; 0 × 0 where the scene has no environment.
        pub width: u32,
        pub height: u32,
        /// The probability that the light table picks the environment.
        pub pmf: f32,
        pub _pad0: u32,
        /// Offsets (in floats) of the row cdf, the column cdfs and the cell pmfs in the data.
        pub row_cdf: u32,
        pub column_cdf: u32,
        pub cell_pmf: u32,
        pub _pad1: u32,
    }
}

impl GpuEnvironment {
    /// The uniform of `env` (None: no environment) with the photon disc (centre, radius),
    /// picked by the light table with probability `pmf`.
    pub fn new(env: Option<&Environment>, centre: Vec3, radius: f32, pmf: f32) -> GpuEnvironment {
        let Some(env) = env else { return GpuEnvironment::zeroed() };
        let texels = 3 * env.texels.len() as u32;
        let cells = env.cell_pmf.len() as u32;
        GpuEnvironment {
            disc_centre: centre.into(),
            disc_radius: radius,
            width: env.width,
            height: env.height,
            pmf,
            _pad0: 0,
            row_cdf: texels,
            column_cdf: texels + env.height - 1,
            cell_pmf: texels + env.height - 1 + cells,
            _pad1: 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// A small sky with structure: a gradient, a dark ground and one bright pixel.
    fn sky() -> Environment {
        let (w, h) = (16u32, 9u32);
        Environment::from_fn(w, h, |i, j| {
            let theta = j as f32 * std::f32::consts::PI / (h - 1) as f32;
            let v = if theta < 1.5 { Vec3::new(0.3, 0.5, 1.0) * (0.4 + 0.6 * theta.cos()) } else { Vec3::splat(0.05) };
            if (i, j) == (3, 2) { Vec3::new(200.0, 180.0, 160.0) } else { v + Vec3::splat(i as f32 * 0.01) }
        })
        .unwrap()
    }

    #[test]
    fn a_scaled_environment_is_the_one_built_from_scaled_radiance() {
        let e = sky();
        for factor in [0.0f32, 0.25, 3.0] {
            let texels = e.texels.iter().map(|t| *t * factor).collect();
            let built = Environment::new(e.width, e.height, texels).unwrap();
            let scaled = e.scaled(factor);
            assert_eq!(scaled.texels, built.texels, "× {factor}");
            assert!(scaled.integral.abs_diff_eq(built.integral, 1e-5 * built.integral.max_element()), "× {factor}");
            for (a, b) in [
                (&scaled.row_cdf, &built.row_cdf),
                (&scaled.column_cdf, &built.column_cdf),
                (&scaled.cell_pmf, &built.cell_pmf),
            ] {
                assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 1e-6), "× {factor}");
            }
        }
    }

    #[test]
    fn mapping_is_mitsubas() {
        // Mitsuba's uv_to_direction: u = 0 looks along −Z, u = ¼ along +X, v = 0 is +Y.
        assert!(uv_to_direction(Vec2::new(0.0, 0.5)).abs_diff_eq(Vec3::NEG_Z, 1e-6));
        assert!(uv_to_direction(Vec2::new(0.25, 0.5)).abs_diff_eq(Vec3::X, 1e-6));
        assert!(uv_to_direction(Vec2::new(0.5, 0.5)).abs_diff_eq(Vec3::Z, 1e-6));
        assert!(uv_to_direction(Vec2::new(0.3, 0.0)).abs_diff_eq(Vec3::Y, 1e-6));
        let mut rng = Rng::new(1, 2, 3);
        for _ in 0..1000 {
            let uv = Vec2::new(rng.next_f32(), 0.001 + 0.998 * rng.next_f32());
            let back = direction_to_uv(uv_to_direction(uv));
            assert!((back - uv).abs().max_element() < 1e-4 || (back.x - uv.x).abs() > 0.9999, "{uv} → {back}");
        }
    }

    #[test]
    fn pixels_sit_at_column_centres_and_pole_inclusive_rows() {
        let e = sky();
        let (w, h) = (e.width, e.height);
        for j in 0..h {
            for i in 0..w {
                let uv = Vec2::new((i as f32 + 0.5) / w as f32, j as f32 / (h - 1) as f32);
                let got = e.eval(uv_to_direction(uv));
                let want = e.texels[(j * w + i) as usize];
                // At the poles every column meets: any azimuth gives the row's value there only
                // when the row is constant, so skip the pole rows' azimuth dependence.
                if j == 0 || j == h - 1 {
                    continue;
                }
                assert!(
                    (got - want).abs().max_element() < 1e-3 * want.max_element().max(1.0),
                    "({i},{j}): {got} vs {want}"
                );
            }
        }
        // Halfway between columns 15 and 0 (the wrap) and between rows 4 and 5: the mean.
        let uv = Vec2::new(0.0, 4.5 / 8.0);
        let t = |i: usize, j: usize| e.texels[j * 16 + i];
        let want = 0.25 * (t(15, 4) + t(0, 4) + t(15, 5) + t(0, 5));
        assert!((e.eval(uv_to_direction(uv)) - want).abs().max_element() < 1e-4);
    }

    /// ∫ pdf dω = 1 and E[L/pdf] = ∫ L dω, by sampling; and pdf(sample) = the returned pdf.
    #[test]
    fn sampling_agrees_with_its_pdf_and_the_integral() {
        let e = sky();
        let mut rng = Rng::new(4, 5, 6);
        let n = 200_000;
        let mut sum = glam::DVec3::ZERO;
        for _ in 0..n {
            let (d, pdf) = e.sample(rng.next_f32(), rng.next_f32());
            assert!(pdf > 0.0 && (d.length() - 1.0).abs() < 1e-4);
            let again = e.pdf(d);
            assert!((again - pdf).abs() <= 1e-3 * pdf, "pdf {pdf} vs {again} at {d}");
            sum += (e.eval(d) / pdf).as_dvec3();
        }
        let mc = sum / n as f64;
        // The bilinear integral by a fine uniform quadrature in (u, cos θ).
        let m = 800;
        let mut quad = glam::DVec3::ZERO;
        for a in 0..m {
            for b in 0..m {
                let cos_t = 1.0 - 2.0 * (b as f32 + 0.5) / m as f32;
                let phi = 2.0 * std::f32::consts::PI * (a as f32 + 0.5) / m as f32;
                let s = (1.0 - cos_t * cos_t).sqrt();
                quad += e.eval(Vec3::new(phi.sin() * s, cos_t, -phi.cos() * s)).as_dvec3();
            }
        }
        quad *= 4.0 * std::f64::consts::PI / (m * m) as f64;
        let rel = ((mc - quad) / quad).abs().max_element();
        assert!(rel < 0.01, "E[L/pdf] {mc} vs ∫L {quad}");
        // The cells' mean-corner integral is close to the bilinear one (used for light power).
        assert!(((e.integral.as_dvec3() - quad) / quad).abs().max_element() < 0.05);
        // ∫ pdf dω cell by cell (the pdf is constant on each): the pdf looked up at points
        // inside each cell, times the cell's solid angle.
        let mut p = 0.0f64;
        for j in 0..e.height - 1 {
            for i in 0..e.width {
                for (a, b) in [(0.5, 0.5), (0.01, 0.99), (0.99, 0.01)] {
                    let d = e.cell_direction(i, j, a, b);
                    p += e.pdf(d) as f64 * cell_solid_angle(e.width, e.height, j) as f64 / 3.0;
                }
            }
        }
        assert!((p - 1.0).abs() < 1e-5, "∫ pdf = {p}");
    }

    /// The neutral light: grey, 1 at the zenith, 0.3 below the horizon, in between at it.
    #[test]
    fn the_neutral_light_is_a_grey_dome() {
        let e = Environment::neutral();
        let at = |d: Vec3| e.eval(d.normalize());
        assert!((at(Vec3::Y) - Vec3::ONE).abs().max_element() < 1e-5, "{}", at(Vec3::Y));
        assert!((at(-Vec3::Y) - Vec3::splat(0.3)).abs().max_element() < 1e-5, "{}", at(-Vec3::Y));
        let horizon = at(Vec3::X);
        assert!(horizon.x > 0.35 && horizon.x < 0.95 && horizon.x == horizon.y && horizon.y == horizon.z, "{horizon}");
        // 2π sr above at ≥ 0.3 and ≤ 1, and the same below.
        assert!(
            e.integral.x > 0.3 * 4.0 * std::f32::consts::PI && e.integral.x < 1.3 * 2.0 * std::f32::consts::PI,
            "{}",
            e.integral
        );
    }

    #[test]
    fn constant_environment_is_uniform() {
        let e = Environment::constant(Vec3::new(1.0, 2.0, 3.0));
        assert!((e.integral - 4.0 * std::f32::consts::PI * Vec3::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-4);
        let mut rng = Rng::new(7, 8, 9);
        for _ in 0..100 {
            let (d, pdf) = e.sample(rng.next_f32(), rng.next_f32());
            assert!((pdf - 1.0 / (4.0 * std::f32::consts::PI)).abs() < 1e-5);
            assert!((e.eval(d) - Vec3::new(1.0, 2.0, 3.0)).abs().max_element() < 1e-5);
        }
        assert!(e.max_radiance_over_pdf() > 0.0);
    }

    #[test]
    fn hostile_images_are_refused() {
        assert!(Environment::new(1, 3, vec![Vec3::ONE; 3]).is_err());
        assert!(Environment::new(2, 2, vec![Vec3::ONE; 4]).is_err());
        assert!(Environment::new(2, 3, vec![Vec3::ONE; 5]).is_err());
        let mut t = vec![Vec3::ONE; 6];
        t[4] = Vec3::new(f32::NAN, 0.0, 0.0);
        let err = Environment::new(2, 3, t).unwrap_err().to_string();
        assert!(err.contains("(0, 2)") && err.contains("not finite"), "{err}");
        let dark = Environment::new(2, 3, vec![Vec3::splat(-1.0); 6]).unwrap();
        assert!(dark.is_dark());
        let err = Environment::load(Path::new("/nonexistent/sky.exr"), 1.0).unwrap_err().to_string();
        assert!(err.contains("no such environment map"), "{err}");
        let err = Environment::load(Path::new("Cargo.toml"), 1.0).unwrap_err().to_string();
        assert!(err.contains("use an .exr or .hdr"), "{err}");
        assert!(Environment::load(Path::new("x.exr"), f32::NAN).is_err());
    }
}
