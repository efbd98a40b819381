//! The guided gather (`RenderSettings::gather_guiding`, issue 57): the traced gather's
//! directions drawn towards where the light comes from, as its own rays found it.
//!
//! In a room lit through its windows most of a shadowed point's indirect light comes from a
//! few bright patches: the sunlit floor, the sky-lit ground and walls seen through a window.
//! Drawn by the cosine alone, few of the gather's rays find them, and those carry the light
//! of the whole hemisphere: measured in the sky-lit `sunroom`, the worst 1 % of the pixels held
//! 80 % of the indirect light's squared error, single pixels 2000 times a ray's typical value,
//! and 128 fresh photon maps (one an iteration) did not lower it — the gather's sampling, not
//! the map.
//!
//! **What it learns.** Per cell of a grid over the part of the scene the camera reads (the
//! photon region, or the scene; [`GRID`] cells along its longest side) and per side (the
//! dominant axis and sign of the visible point's shading normal: the floor and a wall in one
//! corner cell are two tables), the radiance the gather's rays found, in [`BINS`] = 16 × 16
//! bins of the cosine warp's square in the side's [`frame`] (rows of sin²θ, columns of φ:
//! bins of equal projected solid angle): each ray adds the luminance of what it brought back
//! — the photon map's light at its hit, zero where it escaped (the sky is direct light, which
//! the direct pass's samples and the guided sky look after) — to its direction's bin, and
//! counts itself there (fixed point: the sums do not depend on the order the rays add them, so a seed still
//! gives one image). At the start of iterations 1, 2, 4, 8 … a pass ([`build_source`],
//! [`GuideBuild`]) makes each cell's table — a bin's weight is its mean radiance smoothed
//! towards the cell's mean by [`PRIOR`] pseudo-samples (a bin of two rays, one of which met a
//! bright patch by chance, would otherwise draw a sixth of the cell's directions; measured:
//! without it the guided gather's per-pixel variance was 1.4 times the cosine's), and a cell
//! guides only once it has counted [`MIN_SAMPLES`]; cells whose counts reach [`DECAY`] are
//! halved first — so every row band of an iteration reads one table
//! and each aligned run of 2^m iterations one warp. The same pass makes the guided sky's tables
//! ([`crate::passes::sky_guide`]), which share the cells.
//!
//! **How it samples.** On a Lambertian visible point whose cell has learned, the traced
//! gather's per-pixel direction is drawn from the one-sample mixture
//!
//! ```text
//!   p(w) = F_b(w) · cos θ/π,   F_b = (1 − g) + g · BINS · weight_b / Σ weights,
//! ```
//!
//! the cosine's density reweighted per bin b(w), g = [`FRACTION`] — by **one warp** of the
//! pixel's Sobol' point ([`GuidedGather::sample`]): its first uniform picks the square's row by
//! the mixture's row masses, its second the bin along the row, the remainders the point in the
//! bin, which the cosine warp maps to a direction. Both steps are monotone, so the pixel's
//! Owen-scrambled Sobol' points stay stratified (with a uniform table it is the cosine warp
//! itself). The estimate f(w)·cos θ·L/p(w) = ρ·L/F_b is unbiased for any table: every
//! direction keeps at least (1 − g) of the cosine's density. The gather's escaping rays and the
//! direct pass's environment samples are weighed against each other with this density
//! (`guided_gather_density`, read by both passes). Elsewhere (glossy and layered surfaces)
//! the BSDF's own sampling draws the directions; their rays still teach the table.
//!
//! The first guided gather (stop 60) drew every other direction from the table instead — a
//! coin between two strategies, each with half the Sobol' points: that lost more stratification
//! than the table gained (worse everywhere it was measured, docs/measurements.md).

use glam::Vec3;

use crate::gpu::binding::{Group, Slot};
pub use crate::gpu::consts::{
    GATHER_GUIDE_BANDS as BANDS, GATHER_GUIDE_BINS as BINS, GATHER_GUIDE_DECAY as DECAY,
    GATHER_GUIDE_FRACTION as FRACTION, GATHER_GUIDE_MIN_SAMPLES as MIN_SAMPLES, GATHER_GUIDE_PRIOR as PRIOR,
};
use crate::gpu::{Gpu, compute_pipeline, shader};

/// Cells of the guide's grid along its box's longest side.
pub const GRID: u32 = 32;
/// Cells the guide holds at most (a power of two): a table per cell and side the camera
/// sees; more are not guided.
pub const CAPACITY: u32 = 4096;
/// Words of one guide's table in a cell: its bins' sums, counts and cumulative weights.
pub const TABLE_WORDS: u32 = 3 * BINS;
/// A guide that is off has its table at this offset (`GUIDE_NO_TABLE` in `guide.wgsl`).
pub const NO_TABLE: u32 = u32::MAX;

/// Where the guide's cells lie and what its fixed point counts: written into the guide
/// buffer's header ([`crate::photons::guide::PhotonGuide`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GuideField {
    pub origin: Vec3,
    pub cell: f32,
    pub dims: [u32; 3],
    pub capacity: u32,
    /// Fixed-point units per unit of luminance: 256 per the scene's typical radiance.
    pub scale: f32,
    /// Whether the cells hold the gather guide's tables.
    pub gather: bool,
    /// The guided sky's blocks of the environment, where its cells hold the sky's tables
    /// ([`crate::passes::sky_guide`]).
    pub sky: Option<crate::passes::sky_guide::SkyBlocks>,
}

impl GuideField {
    /// Over `bounds` (the photon region's, or the scene's), for a scene whose lights emit
    /// `power` (RGB watts) onto `area` m² of surface: the typical radiance is the mean
    /// irradiance's reflection by a white surface, Φ/(π·A).
    pub fn new(bounds: &crate::scene::Aabb, power: Vec3, area: f64) -> GuideField {
        let extent = bounds.extent().max(Vec3::splat(1e-6));
        let cell = extent.max_element() / GRID as f32 * (1.0 + 1e-4);
        let dims = (extent / cell).ceil().as_uvec3().max(glam::UVec3::ONE).min(glam::UVec3::splat(GRID));
        let typical = ((power.x + power.y + power.z) as f64 / 3.0 / (std::f64::consts::PI * area.max(1e-12))) as f32;
        let scale = if typical > 0.0 && typical.is_finite() { 256.0 / typical } else { 256.0 };
        GuideField { origin: bounds.min, cell, dims: dims.into(), capacity: CAPACITY, scale, gather: true, sky: None }
    }

    /// The offsets in a cell's entry of the gather guide's table and the sky's ([`NO_TABLE`]
    /// where off), and the words of an entry (its key and its tables).
    pub fn tables(&self) -> (u32, u32, u32) {
        let gather = if self.gather { 1 } else { NO_TABLE };
        let sky = match (&self.sky, self.gather) {
            (None, _) => NO_TABLE,
            (Some(_), true) => 1 + TABLE_WORDS,
            (Some(_), false) => 1,
        };
        let words = 1 + TABLE_WORDS * (self.gather as u32 + self.sky.is_some() as u32);
        (gather, sky, words)
    }

    /// Its words in the guide buffer's header (`guide.wgsl`: `guide_header_*`) where its part
    /// of the buffer begins at word `start`: the sky's block masses there, then the cells.
    pub fn header(&self, start: u32) -> [u32; 16] {
        let (gather, sky, entry) = self.tables();
        let (columns, rows) = self.sky.as_ref().map_or((0, 0), |b| (b.columns, b.rows));
        let lead = self.leading_words().len() as u32;
        [
            self.origin.x.to_bits(),
            self.origin.y.to_bits(),
            self.origin.z.to_bits(),
            self.cell.to_bits(),
            self.dims[0],
            self.dims[1],
            self.dims[2],
            self.capacity,
            start + lead,
            self.scale.to_bits(),
            entry,
            gather,
            sky,
            columns,
            rows,
            start,
        ]
    }

    /// The words that follow the header: the sky's block tables (none without it).
    pub fn leading_words(&self) -> Vec<u32> {
        self.sky.as_ref().map_or(Vec::new(), |b| b.words().iter().map(|m| m.to_bits()).collect())
    }

    /// The words its part of the buffer takes: the block masses and the cells.
    pub fn words(&self) -> u64 {
        self.leading_words().len() as u64 + self.capacity as u64 * self.tables().2 as u64
    }
}

/// The guide's frame at a surface of shading normal n (`gather_guide_frame` in `guide.wgsl`):
/// (t, b, n), the tangent t from a world axis across the side's dominant axis (z where x
/// dominates, else x; never within 45° of n), b = n × t. Every point of a cell's side whose
/// normals agree shares it, so their rays fill the same bins.
pub fn frame(n: Vec3) -> [Vec3; 3] {
    let a = n.abs();
    let r = if a.x > a.y.max(a.z) { Vec3::Z } else { Vec3::X };
    let t = (r - n * n.dot(r)).normalize();
    [t, n.cross(t), n]
}

/// The cosine warp about n (`gather_guide_warp`): v = (sin²θ, φ/2π) in the unit square ↦ the
/// direction of polar angle θ to n and azimuth φ from t; v uniform gives density cos θ/π.
pub fn warp(n: Vec3, v: [f32; 2]) -> Vec3 {
    let [t, b, n] = frame(n);
    let r = v[0].sqrt();
    let phi = 2.0 * std::f32::consts::PI * v[1];
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - v[0]).max(0.0).sqrt()).normalize()
}

/// The direction bin of w about n (`gather_guide_bin`): the cell of the warp's square holding
/// the point that warps to w — [`BANDS`] rows of sin²θ by as many columns of φ, bins of equal
/// projected solid angle (each 1/[`BINS`] of the cosine's measure).
pub fn direction_bin(n: Vec3, w: Vec3) -> u32 {
    let [t, b, _] = frame(n);
    let (x, y) = (w.dot(t), w.dot(b));
    let k = BANDS as f32;
    let row = (((x * x + y * y).clamp(0.0, 1.0) * k) as u32).min(BANDS - 1);
    let a = y.atan2(x) / (2.0 * std::f32::consts::PI);
    let column = (((a - a.floor()) * k) as u32).min(BANDS - 1);
    row * BANDS + column
}

/// The guided mixture over one cell's table, `cdf` its cumulative bin weights
/// (`guide_build.wgsl`; the last is the total, > 0): the CPU twin of `gather_guide_factor`,
/// `gather_guide_mixture_cdf` and `gather_guide_sample`.
pub struct GuidedGather<'a> {
    pub cdf: &'a [f32],
}

impl GuidedGather<'_> {
    fn total(&self) -> f32 {
        self.cdf[BINS as usize - 1]
    }

    fn weight(&self, b: u32) -> f32 {
        let b = b as usize;
        self.cdf[b] - if b > 0 { self.cdf[b - 1] } else { 0.0 }
    }

    /// F_b = p/p_cos on bin b: (1 − g) + g·BINS·weight_b/total, g = [`FRACTION`].
    pub fn factor(&self, b: u32) -> f32 {
        (1.0 - FRACTION) + FRACTION * BINS as f32 * self.weight(b) / self.total()
    }

    /// The mixture's probability of bins 0 to b together.
    fn mixture_cdf(&self, b: u32) -> f32 {
        (1.0 - FRACTION) * (b + 1) as f32 / BINS as f32 + FRACTION * self.cdf[b as usize] / self.total()
    }

    /// The density (per steradian) of direction w about n: F_b·cos θ/π, 0 below the surface.
    pub fn density(&self, n: Vec3, w: Vec3) -> f32 {
        let c = n.dot(w);
        if c <= 0.0 { 0.0 } else { self.factor(direction_bin(n, w)) * c / std::f32::consts::PI }
    }

    /// A direction about n from two uniforms by one warp: u₀ picks the warp square's row by
    /// the mixture's row masses, u₁ the bin along it, each remainder the point in the bin,
    /// which [`warp`] maps to a direction. Monotone in each uniform (stratified points stay
    /// stratified); density [`Self::density`].
    pub fn sample(&self, n: Vec3, u: [f32; 2]) -> Vec3 {
        let k = BANDS;
        let search = |mut lo: u32, mut hi: u32, goal: f32, at: &dyn Fn(u32) -> u32| {
            while lo < hi {
                let mid = (lo + hi) / 2;
                if self.mixture_cdf(at(mid)) <= goal { lo = mid + 1 } else { hi = mid }
            }
            lo
        };
        let row = search(0, k - 1, u[0], &|r| r * k + k - 1);
        let below = if row > 0 { self.mixture_cdf(row * k - 1) } else { 0.0 };
        let row_mass = (self.mixture_cdf(row * k + k - 1) - below).max(1e-30);
        let v0 = ((u[0] - below) / row_mass).clamp(0.0, 0.999_999_94);
        let goal = below + u[1] * row_mass;
        let b = search(row * k, row * k + k - 1, goal, &|b| b);
        let before = if b > row * k { self.mixture_cdf(b - 1) } else { below };
        let v1 = ((goal - before) / (self.mixture_cdf(b) - before).max(1e-30)).clamp(0.0, 0.999_999_94);
        warp(n, [(row as f32 + v0) / k as f32, ((b - row * k) as f32 + v1) / k as f32])
    }
}

/// The guide's WGSL: its accessors, sampling and learning, for a shader that binds the guide
/// buffer as `photon_guide`.
pub const WGSL: &str = include_str!("guide.wgsl");
/// The guided density (`guided_gather_density`), for a shader that also knows the visible
/// point (`passes/visible_point.wgsl`) and the gather's estimators.
pub const DENSITY_WGSL: &str = include_str!("guided_density.wgsl");

/// The table-making pass's bind group: the guide buffer.
pub fn build_group() -> Group {
    Group::compute("gather guide build", &[Slot::write::<u32>(0, "photon_guide")])
}

/// The table-making pass's composed shader.
pub fn build_source() -> String {
    shader::compose(&[shader::SAMPLING, WGSL, include_str!("guide_build.wgsl")])
}

/// The pass that makes the cells' tables from what the passes learned (`guide_build.wgsl`):
/// the gather guide's and the guided sky's, at the start of iterations 1, 2, 4, 8 …
pub struct GuideBuild {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    groups: (u32, u32),
}

impl GuideBuild {
    /// Over `buffer`, the guide buffer of a guide of `capacity` cells.
    pub fn new(gpu: &Gpu, buffer: &wgpu::Buffer, capacity: u32) -> GuideBuild {
        let device = &gpu.device;
        let (layout, bind_group) =
            build_group().layout_and_bind(device, &[("photon_guide", buffer.as_entire_binding())]);
        let module = shader::module(device, "gather guide build", &build_source());
        let pipeline = compute_pipeline(device, "gather guide build", &module, "build_guide", &[&layout], &[]);
        let n = capacity.div_ceil(64).max(1);
        GuideBuild { pipeline, bind_group, groups: (n.min(65535), n.div_ceil(65535)) }
    }

    /// Encodes the pass.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, profiler: Option<&crate::gpu::profile::Profiler>) {
        let mut pass = crate::gpu::profile::compute_pass(enc, profiler, "gather guide");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.groups.0, self.groups.1, 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn normals() -> [Vec3; 4] {
        [Vec3::Y, -Vec3::X, Vec3::new(0.3, 0.2, -0.93).normalize(), Vec3::new(-0.7, 0.69, 0.1).normalize()]
    }

    /// Each bin holds 1/BINS of the cosine's measure (cosine-distributed directions fill the
    /// bins evenly), and the warp of a point of a bin's square falls in that bin.
    #[test]
    fn direction_bins_hold_equal_cosine_measure_and_the_warp_inverts_them() {
        let mut rng = crate::sampling::Rng::new(2, 0, 0);
        for n in normals() {
            let samples = 256_000;
            let mut count = vec![0u32; BINS as usize];
            let [t, b, _] = frame(n);
            assert!(t.dot(n).abs() < 1e-6 && (t.length() - 1.0).abs() < 1e-6 && (b.length() - 1.0).abs() < 1e-6);
            for _ in 0..samples {
                let w = crate::sampling::cosine_hemisphere(n, rng.next_f32(), rng.next_f32());
                count[direction_bin(n, w) as usize] += 1;
            }
            let expected = samples as f64 / BINS as f64;
            for c in count {
                assert!((c as f64 - expected).abs() < 5.0 * expected.sqrt(), "{c} against {expected}");
            }
            for bin in 0..BINS {
                for _ in 0..8 {
                    let v = [rng.next_f32() * 0.98 + 0.01, rng.next_f32() * 0.98 + 0.01];
                    let w = warp(
                        n,
                        [((bin / BANDS) as f32 + v[0]) / BANDS as f32, ((bin % BANDS) as f32 + v[1]) / BANDS as f32],
                    );
                    assert!((w.length() - 1.0).abs() < 1e-5 && w.dot(n) >= 0.0);
                    assert_eq!(direction_bin(n, w), bin);
                }
            }
        }
    }

    /// A table with bright bins and empty ones.
    fn table() -> Vec<f32> {
        let mut rng = crate::sampling::Rng::new(5, 0, 0);
        let mut acc = 0.0;
        (0..BINS)
            .map(|b| {
                let w = match b {
                    37 | 38 | 200 => 40.0,
                    b if b % 7 == 0 => 0.0,
                    _ => rng.next_f32(),
                };
                acc += w;
                acc
            })
            .collect()
    }

    /// χ² of the guided warp's samples in the bins against the mixture's probabilities F_b/BINS,
    /// and its density integrating to one over the hemisphere (uniform directions, pdf 1/2π).
    #[test]
    fn the_guided_gathers_warp_draws_its_density() {
        let cdf = table();
        let g = GuidedGather { cdf: &cdf };
        let mut rng = crate::sampling::Rng::new(9, 0, 0);
        for n in normals() {
            let samples = 1u32 << 20;
            let mut count = vec![0u32; BINS as usize];
            for _ in 0..samples {
                let w = g.sample(n, [rng.next_f32(), rng.next_f32()]);
                assert!((w.length() - 1.0).abs() < 1e-5 && w.dot(n) >= 0.0);
                count[direction_bin(n, w) as usize] += 1;
            }
            let mut chi2 = 0.0;
            for (b, &c) in count.iter().enumerate() {
                let expected = samples as f64 * g.factor(b as u32) as f64 / BINS as f64;
                chi2 += (c as f64 - expected).powi(2) / expected;
            }
            // 255 degrees of freedom: mean 255, standard deviation 22.6; 350 is p ≈ 1e-4.
            assert!(chi2 < 350.0, "χ² {chi2:.1} for n = {n}");
            let m = 400_000;
            let mut integral = 0.0;
            for _ in 0..m {
                let mut w = crate::sampling::uniform_sphere(rng.next_f32(), rng.next_f32());
                if w.dot(n) < 0.0 {
                    w = -w;
                }
                integral += g.density(n, w) as f64 * 2.0 * std::f64::consts::PI;
            }
            let integral = integral / m as f64;
            assert!((integral - 1.0).abs() < 0.02, "∫ p = {integral:.4} for n = {n}");
        }
    }

    /// With a uniform table the mixture is the cosine warp itself, point for point.
    #[test]
    fn a_uniform_table_is_the_cosine_warp() {
        let cdf: Vec<f32> = (1..=BINS).map(|b| b as f32).collect();
        let g = GuidedGather { cdf: &cdf };
        let mut rng = crate::sampling::Rng::new(3, 0, 0);
        let n = normals()[2];
        for _ in 0..10_000 {
            let u = [rng.next_f32(), rng.next_f32()];
            assert!(g.sample(n, u).distance(warp(n, u)) < 1e-4);
            assert!((g.factor(direction_bin(n, warp(n, u))) - 1.0).abs() < 1e-5);
        }
    }
}
