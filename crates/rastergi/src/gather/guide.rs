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
//! corner cell are two tables), the radiance the gather's rays found, in
//! [`BINS`] = 16 × 16 directions of equal solid angle (bands of w_y, sectors of φ): each ray
//! adds the luminance of what it brought back — the photon map's light at its hit, the sky
//! where it escaped, zero where it found nothing — to its direction's bin, and counts itself
//! there (fixed point: the sums do not depend on the order the rays add them, so a seed still
//! gives one image). At the start of iterations 1, 2, 4, 8 … a pass ([`build_source`],
//! [`GuideBuild`]) makes each cell's table — a bin's weight is its mean radiance; cells whose
//! counts reach [`DECAY`] are halved first — so every row band of an iteration reads one table
//! and each aligned run of 2^m iterations one warp. The same pass makes the guided sky's tables
//! ([`crate::passes::sky_guide`]), which share the cells.
//!
//! **How it samples.** The traced gather's per-pixel direction is drawn from the one-sample
//! mixture
//!
//! ```text
//!   p(w) = (1 − g)·p_s(w) + g·q(w),   q(w) = weight(b(w)) / Σ weights · BINS / 4π,
//! ```
//!
//! p_s the visible point's own scattering (cosine on a Lambertian surface, the BSDF's
//! sampling elsewhere), g = [`FRACTION`] where the point's cell has learned something, else 0;
//! the estimate is f(w)·cos θ·L / p(w), unbiased for any table (every direction the scattering
//! reaches keeps a density of at least (1 − g)·p_s). The gather's escaping rays and the direct
//! pass's environment samples are weighed against each other with this density
//! (`guided_gather_density`, read by both passes), so the sky through a window, which the
//! table learns like any light, is sampled where the window is by the gather and counted once.

use glam::Vec3;

use crate::gpu::binding::{Group, Slot};
pub use crate::gpu::consts::{
    GATHER_GUIDE_BANDS as BANDS, GATHER_GUIDE_BINS as BINS, GATHER_GUIDE_DECAY as DECAY,
    GATHER_GUIDE_FRACTION as FRACTION,
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

/// The direction bin of unit direction w (`gather_guide_bin` in `guide.wgsl`).
pub fn direction_bin(w: Vec3) -> u32 {
    let band = (((w.y + 1.0) * 0.5 * BANDS as f32) as u32).min(BANDS - 1);
    let u = w.x.atan2(-w.z) / (2.0 * std::f32::consts::PI);
    let sector = (((u - u.floor()) * BANDS as f32) as u32).min(BANDS - 1);
    band * BANDS + sector
}

/// A direction uniform in bin b from two uniforms (`gather_guide_direction` in `guide.wgsl`).
pub fn bin_direction(b: u32, u: [f32; 2]) -> Vec3 {
    let y = -1.0 + ((b / BANDS) as f32 + u[0]) * 2.0 / BANDS as f32;
    let phi = ((b % BANDS) as f32 + u[1]) * 2.0 * std::f32::consts::PI / BANDS as f32;
    let s = (1.0 - y * y).max(0.0).sqrt();
    Vec3::new(phi.sin() * s, y, -phi.cos() * s)
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

    #[test]
    fn direction_bins_have_equal_solid_angles_and_bin_directions_fall_in_their_bin() {
        let mut rng = crate::sampling::Rng::new(2, 0, 0);
        let n = 512_000;
        let mut count = vec![0u32; BINS as usize];
        for _ in 0..n {
            let d = crate::sampling::uniform_sphere(rng.next_f32(), rng.next_f32());
            count[direction_bin(d) as usize] += 1;
        }
        let expected = n as f64 / BINS as f64;
        for c in count {
            assert!((c as f64 - expected).abs() < 5.0 * expected.sqrt(), "{c} against {expected}");
        }
        for b in 0..BINS {
            for _ in 0..16 {
                let w = bin_direction(b, [rng.next_f32() * 0.998 + 0.001, rng.next_f32() * 0.998 + 0.001]);
                assert!((w.length() - 1.0).abs() < 1e-5);
                assert_eq!(direction_bin(w), b);
            }
        }
    }
}
