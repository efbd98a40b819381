//! Photons aimed where they are read (`RenderSettings::photon_guiding`, issue 57).
//!
//! A room lit through its windows reads the photon map in the room and on the ground the
//! gather sees through the windows; the sun's and the sky's photons start on a disc across the
//! whole scene (aimed at the photon region: [`crate::lights::disc_start`]), and most of them
//! land on walls from outside, on the roof, on the ground far away. Worse, the photons that do
//! reach the room after a bounce on the ground come from the disc's sparse outer parts and
//! carry many times the flux of those that come in through a window: measured in the sky-lit
//! `sunroom`, the map's brightest slots held 25–58 times the median photon's flux, and the
//! worst 1 % of the pixels held half of the squared error (more photons around the room,
//! same count: a quarter).
//!
//! **Where the map is read.** Every lookup marks its cell in a bit array over the cells of
//! the render's first grid (`mark_read` in `map/map.wgsl`): the gather's hits, the glossy
//! chains' stops, the caustics at the visible points. Marks accumulate over the render.
//!
//! **Where photons are emitted to land there.** For the sun and the sky (each distant light
//! and the environment), the photon's start on its disc is drawn from a one-sample mixture of
//! the fixed aim ([`crate::lights::disc_start`], density p₀) and a learned table q:
//!
//! ```text
//!   p(x | ω) = (1 − g_d)·p₀(x) + g_d·q_d(x),   q_d(x) = pmf_d(b(x)) · P² / (π R_g²),
//! ```
//!
//! d the direction's bin ([`ENV_DIRECTIONS`] equal-area bins of the sphere for the sky, one
//! for a distant light), b(x) the bin of x among P × P ([`POSITIONS`]²) equal-area bins of the
//! guide disc (radius R_g: the aim's surroundings, [`crate::gpu::consts::NEAR_SCALE`] times the
//! photon region's radius, or the whole disc without a region; the bins are the squares of
//! Shirley and Chiu's concentric map, which keeps areas), g_d = [`GUIDED_FRACTION`] where
//! direction bin d has been learned, else 0. The photon carries L(ω)/(pdf(ω)·pmf·p(x|ω))
//! whichever part drew it, so every map stays unbiased for any table; the defensive p₀ keeps
//! every start possible and bounds the flux at 1/(1 − g) of the unguided one's.
//!
//! **Learned from the photons.** Each guided photon counts its deposits in marked cells (it
//! is useful where the map is read) and adds them, and itself, to its start's bin
//! (`trace.wgsl`). After each pass the counts are read back and summed over the passes; the
//! table takes pmf_d(b) ∝ ū(b), the mean useful deposits of the photons started in bin b
//! (the photons' expected usefulness per unit area of the disc, whatever density drew them),
//! so the density goes where photons land where the map is read, in proportion to how much of
//! it they reach: through a window, and onto the ground the gather sees through it. A bin
//! no photon has started from yet has pmf 0 (the p₀ part still starts photons there).

use glam::Vec3;

use crate::error::Result;
use crate::gpu::Gpu;
use crate::photons::map::GridSpec;

pub use crate::gpu::consts::{GUIDE_POSITIONS as POSITIONS, GUIDED_FRACTION};
/// Direction bins of the sky (8 of cos θ about +Y × 8 of φ: equal solid angles).
pub const ENV_DIRECTIONS: u32 = ENV_BANDS * ENV_BANDS;
const ENV_BANDS: u32 = crate::gpu::consts::GUIDE_ENV_BANDS;
/// The most lights guided (the sky and up to three distant lights).
pub const MAX_GUIDED_LIGHTS: usize = crate::gpu::consts::MAX_GUIDED_LIGHTS as usize;
/// Photons of the direction's mean usefulness each bin's estimate starts from.
pub const PRIOR_PHOTONS: f64 = 4.0;
/// Useful deposits a direction bin needs before its table is used.
pub const MIN_USEFUL: f64 = 32.0;
/// Words of a guided light's header in the table ([`GuideTable::words`]).
pub const HEADER_WORDS: u32 = crate::gpu::consts::GUIDE_HEADER_WORDS;
/// No bin (a photon of a light that is not guided).
pub const NO_BIN: u32 = u32::MAX;

/// Shirley and Chiu's concentric map of the unit square onto the unit disc: area-preserving
/// (a uniform point on the square is uniform on the disc). Mirrors `concentric` in `emit.wgsl`.
pub fn concentric(u: f32, v: f32) -> (f32, f32) {
    use std::f32::consts::FRAC_PI_4;
    let (a, b) = (2.0 * u - 1.0, 2.0 * v - 1.0);
    if a == 0.0 && b == 0.0 {
        return (0.0, 0.0);
    }
    let (r, phi) =
        if a.abs() > b.abs() { (a, FRAC_PI_4 * (b / a)) } else { (b, 2.0 * FRAC_PI_4 - FRAC_PI_4 * (a / b)) };
    (r * phi.cos(), r * phi.sin())
}

/// The inverse of [`concentric`]: the square's point of a point of the unit disc. Mirrors
/// `concentric_inverse` in `emit.wgsl`.
pub fn concentric_inverse(x: f32, y: f32) -> (f32, f32) {
    use std::f32::consts::{FRAC_PI_4, PI};
    let r = (x * x + y * y).sqrt();
    let mut phi = y.atan2(x);
    if phi < -FRAC_PI_4 {
        phi += 2.0 * PI;
    }
    let (a, b) = if phi < FRAC_PI_4 {
        (r, r * phi / FRAC_PI_4)
    } else if phi < 3.0 * FRAC_PI_4 {
        (-r * (phi - 2.0 * FRAC_PI_4) / FRAC_PI_4, r)
    } else if phi < 5.0 * FRAC_PI_4 {
        (-r, -r * (phi - PI) / FRAC_PI_4)
    } else {
        (r * (phi - 6.0 * FRAC_PI_4) / FRAC_PI_4, -r)
    };
    (((a + 1.0) * 0.5).clamp(0.0, 1.0), ((b + 1.0) * 0.5).clamp(0.0, 1.0))
}

/// The sky's direction bin of the unit direction towards the sky `to_sky`: 8 bands of equal
/// solid angle in cos θ = y, 8 sectors of φ = atan2(x, −z). Mirrors `env_direction_bin` in
/// `emit.wgsl`.
pub fn env_direction_bin(to_sky: Vec3) -> u32 {
    let band = (((to_sky.y + 1.0) * 0.5 * ENV_BANDS as f32) as u32).min(ENV_BANDS - 1);
    let u = to_sky.x.atan2(-to_sky.z) / (2.0 * std::f32::consts::PI);
    let sector = (((u - u.floor()) * ENV_BANDS as f32) as u32).min(ENV_BANDS - 1);
    band * ENV_BANDS + sector
}

/// The guide disc's position bin of a point at disc coordinates (x, y) (in units of the guide
/// disc's radius, about its centre), `None` outside it. Mirrors `position_bin` in `emit.wgsl`.
pub fn position_bin(x: f32, y: f32) -> Option<u32> {
    if x * x + y * y > 1.0 {
        return None;
    }
    let (u, v) = concentric_inverse(x, y);
    let (i, j) =
        (((u * POSITIONS as f32) as u32).min(POSITIONS - 1), ((v * POSITIONS as f32) as u32).min(POSITIONS - 1));
    Some(j * POSITIONS + i)
}

/// One guided light's part of the [`GuideTable`].
#[derive(Clone, Debug, PartialEq)]
pub struct GuidedLight {
    /// Its light-table entry and direction bins (one for a distant light).
    pub entry: u32,
    pub directions: u32,
    /// The first of its bins among the counters (direction-major, P² positions each).
    pub first_bin: u32,
    /// Per direction bin: its weight and its cdf over the P² position bins; empty where the
    /// direction is not learned yet.
    pub cdfs: Vec<(f32, Vec<f32>)>,
}

/// The learned emission tables, as the GPU reads them (f32 bits in the guide buffer).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GuideTable {
    pub lights: Vec<GuidedLight>,
}

impl GuideTable {
    /// The tables of `lights` ((entry, direction bins)), none learned yet.
    pub fn unlearned(lights: &[(u32, u32)]) -> GuideTable {
        let mut first_bin = 0;
        let lights = (lights.iter().take(MAX_GUIDED_LIGHTS))
            .map(|&(entry, directions)| {
                let l =
                    GuidedLight { entry, directions, first_bin, cdfs: vec![(0.0, Vec::new()); directions as usize] };
                first_bin += directions * POSITIONS * POSITIONS;
                l
            })
            .collect();
        GuideTable { lights }
    }

    /// Bins counted: every guided light's direction × position bins.
    pub fn bins(&self) -> u32 {
        self.lights.iter().map(|l| l.directions * POSITIONS * POSITIONS).sum()
    }

    /// Its words (`guide_data` in `emit.wgsl` reads them): [`MAX_GUIDED_LIGHTS`] headers of
    /// [`HEADER_WORDS`] (light entry, u32::MAX where none; direction bins; the first word of
    /// its data; its first bin), then each light's data: per direction bin its weight (0: not
    /// learned) and the cdf over its P² position bins.
    pub fn words(&self) -> Vec<u32> {
        let mut header = vec![u32::MAX; MAX_GUIDED_LIGHTS * HEADER_WORDS as usize];
        let mut data = Vec::new();
        let first = header.len() as u32;
        let n = (POSITIONS * POSITIONS) as usize;
        for (k, l) in self.lights.iter().enumerate().take(MAX_GUIDED_LIGHTS) {
            let h = k * HEADER_WORDS as usize;
            header[h..h + 4].copy_from_slice(&[l.entry, l.directions, first + data.len() as u32, l.first_bin]);
            for d in 0..l.directions as usize {
                match l.cdfs.get(d) {
                    Some((w, cdf)) if *w > 0.0 && cdf.len() == n => {
                        data.push(w.to_bits());
                        data.extend(cdf.iter().map(|c| c.to_bits()));
                    }
                    _ => data.extend(std::iter::repeat_n(0u32, 1 + n)),
                }
            }
        }
        header.extend(data);
        header
    }

    /// Light entry `entry`'s part, if it is guided.
    pub fn light(&self, entry: u32) -> Option<&GuidedLight> {
        self.lights.iter().find(|l| l.entry == entry)
    }
}

impl GuidedLight {
    /// Direction bin d's cdf, where learned.
    pub fn cdf(&self, d: u32) -> Option<&[f32]> {
        self.cdfs.get(d as usize).filter(|(w, c)| *w > 0.0 && !c.is_empty()).map(|(_, c)| c.as_slice())
    }

    /// The counter bin of direction d and position bin `position` ([`NO_BIN`] for none).
    pub fn bin(&self, d: u32, position: u32) -> u32 {
        if position == NO_BIN { NO_BIN } else { self.first_bin + d * POSITIONS * POSITIONS + position }
    }
}

/// The start of a guided light's photon on its disc (the CPU twin of `guided_start` in
/// `emit.wgsl`): from (u1, u2), with `cdf` the direction's learned table (None: p₀ alone), the
/// origin, 1/p(x|ω), and the photon's position bin ([`NO_BIN`] outside the guide disc). `disc`
/// is the light's disc (centre, radius) across the scene, `axis` the photon's direction,
/// `aim` the fixed aim, `guide_radius` R_g.
pub fn guided_start(
    axis: Vec3,
    disc: (Vec3, f32),
    aim: Option<crate::lights::PhotonAim>,
    cdf: Option<&[f32]>,
    (u1, u2): (f32, f32),
) -> (Vec3, f32, u32) {
    use std::f32::consts::PI;
    let (centre, radius) = disc;
    let (t, b) = crate::sampling::orthonormal_basis(axis);
    let (towards, guide_radius) = guide_disc(axis, disc, aim);
    let start = centre - axis * radius;
    let Some(cdf) = cdf else {
        let (origin, inv_p) = crate::lights::disc_start(axis, centre, radius, aim, u1, u2);
        let rel = origin - start - towards;
        let bin = position_bin(rel.dot(t) / guide_radius, rel.dot(b) / guide_radius);
        return (origin, inv_p, bin.unwrap_or(NO_BIN));
    };
    let g = GUIDED_FRACTION;
    // The fixed aim's density where it drew x (its own branch's term always counted, as
    // disc_start counts it), else by where x lies.
    // The position bin: the table's where it drew x (its own term counted, as the disc's
    // branches count theirs: rounding at a bin's edge never moves x into a bin of another
    // weight), else x's.
    let (offset, p0, drawn) = if u1 < g {
        let u = u1 / g;
        let bin = cdf.partition_point(|&c| c <= u).min(cdf.len() - 1);
        let lo = if bin > 0 { cdf[bin - 1] } else { 0.0 };
        let s = ((u - lo) / (cdf[bin] - lo).max(1e-30)).clamp(0.0, 0.999_999_9);
        let (i, j) = (bin as u32 % POSITIONS, bin as u32 / POSITIONS);
        let (x, y) = concentric((i as f32 + s) / POSITIONS as f32, (j as f32 + u2) / POSITIONS as f32);
        let offset = towards + (t * x + b * y) * guide_radius;
        (offset, crate::lights::disc_density(axis, centre, radius, aim, offset), Some(bin as u32))
    } else {
        let u = ((u1 - g) / (1.0 - g)).min(0.999_999_9);
        let (origin, inv_p) = crate::lights::disc_start(axis, centre, radius, aim, u, u2);
        (origin - start, 1.0 / inv_p, None)
    };
    let rel = offset - towards;
    let bin = drawn.or_else(|| position_bin(rel.dot(t) / guide_radius, rel.dot(b) / guide_radius));
    let q = match bin {
        Some(bin) => {
            let lo = if bin > 0 { cdf[bin as usize - 1] } else { 0.0 };
            (cdf[bin as usize] - lo) * (POSITIONS * POSITIONS) as f32 / (PI * guide_radius * guide_radius)
        }
        None => 0.0,
    };
    let p = (1.0 - g) * p0 + g * q;
    (start + offset, 1.0 / p, bin.unwrap_or(NO_BIN))
}

/// The guide disc of a photon along `axis` from the light's `disc`: the offset of its centre
/// from the disc's centre (the aim's projection, or none) and its radius R_g (the aim's
/// surroundings, or the whole disc). Mirrors `guide_disc` in `emit.wgsl`.
pub fn guide_disc(axis: Vec3, disc: (Vec3, f32), aim: Option<crate::lights::PhotonAim>) -> (Vec3, f32) {
    match aim.filter(|a| a.radius > 0.0) {
        Some(a) => {
            let d = a.centre - disc.0;
            (d - axis * d.dot(axis), a.radius * crate::gpu::consts::NEAR_SCALE)
        }
        None => (Vec3::ZERO, disc.1),
    }
}

/// The guide buffer of a render and the photon guide's part of it: on the GPU one buffer (a
/// browser grants 10 storage buffers per shader stage, and the passes that read the map had
/// used them all) holding a header ([`GUIDE_MARKS`] words: the gather guide's grid,
/// [`crate::gather::guide::GuideField::header`]), the marks (one bit per cell of `marks`), the
/// useful deposits and the photons per bin, the learned emission tables, and the gather
/// guide's cells; on the CPU the counts summed over the passes.
pub struct PhotonGuide {
    pub buffer: wgpu::Buffer,
    /// The grid whose cells are marked (the render's first).
    pub marks: GridSpec,
    pub mark_words: u32,
    /// Useful deposits and photons per bin, summed over the passes.
    useful: Vec<f64>,
    emitted: Vec<f64>,
    table: GuideTable,
    /// Whether emission is guided (else no cell is marked, no photon counted, nothing learned).
    pub enabled: bool,
    /// The gather guide's grid, where the gather is guided.
    pub field: Option<crate::gather::guide::GuideField>,
}

pub use crate::gpu::consts::GUIDE_MARKS;

/// The counters' first word and the table's in a guide buffer of `mark_words` marks and `bins`
/// bins.
pub fn guide_offsets(mark_words: u32, bins: u32) -> (u32, u32) {
    (GUIDE_MARKS + mark_words, GUIDE_MARKS + mark_words + 2 * bins)
}

impl PhotonGuide {
    /// For the guided lights `lights` ((light-table entry, direction bins): the environment and
    /// the distant lights, [`guided_lights`]), marking the cells of `marks`; with the gather
    /// guide's cells over `field` where the gather is guided.
    pub fn new(
        gpu: &Gpu,
        marks: GridSpec,
        lights: &[(u32, u32)],
        enabled: bool,
        field: Option<crate::gather::guide::GuideField>,
    ) -> PhotonGuide {
        let mark_words = (marks.cell_count() as u32).div_ceil(32).max(1);
        // Unguided: no light's photons are counted, no cell is marked (the lookups' and the
        // tracer's atomics on the marks cost nothing then: on SwiftShader they made a
        // 101 054-triangle scene's iterations minutes long).
        let table = GuideTable::unlearned(if enabled { lights } else { &[] });
        let bins = table.bins();
        let words = table.words();
        let (_, table_start) = guide_offsets(mark_words, bins);
        let field_start = table_start as u64 + words.len() as u64;
        let size = (field_start + field.as_ref().map_or(0, |f| f.words())) * 4;
        let buffer = gpu.zeroed_buffer(
            "guide",
            size,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        );
        let header = field.as_ref().map_or([0u32; 16], |f| f.header(field_start as u32));
        gpu.queue.write_buffer(&buffer, crate::gpu::consts::GUIDE_HEADER as u64 * 4, bytemuck::cast_slice(&header));
        if let Some(f) = &field {
            let lead = f.leading_words();
            if !lead.is_empty() {
                gpu.queue.write_buffer(&buffer, field_start * 4, bytemuck::cast_slice(&lead));
            }
        }
        let (useful, emitted) = (vec![0.0; bins as usize], vec![0.0; bins as usize]);
        let guide = PhotonGuide { buffer, marks, mark_words, useful, emitted, table, enabled, field };
        guide.upload_table(gpu);
        guide
    }

    /// The grid whose cells the lookups mark, as the shaders read it: none (no cells) where
    /// emission is not guided, so that `mark_read` and `is_read` touch no memory.
    pub fn marked_grid(&self) -> super::gpu::GridLevels {
        let grid = super::gpu::GridLevels::from(&self.marks);
        match self.enabled {
            true => grid,
            false => super::gpu::GridLevels { dims: [0; 3], ..grid },
        }
    }

    /// The cells marked so far (read back: waits for the GPU).
    pub fn marked_cells(&self, gpu: &Gpu) -> Result<u64> {
        let bytes = read_range(gpu, &self.buffer, GUIDE_MARKS as u64 * 4, self.mark_words as u64 * 4)?;
        Ok(bytemuck::cast_slice::<u8, u32>(&bytes).iter().map(|w| w.count_ones() as u64).sum())
    }

    /// Bins counted.
    pub fn bins(&self) -> u32 {
        self.table.bins()
    }

    /// The table as learned so far.
    pub fn table(&self) -> &GuideTable {
        &self.table
    }

    /// Replaces the learned table by `table` (for the tests that trace with a table of their
    /// own): it must guide the same lights, with their direction bins and counter bins.
    pub fn set_table(&mut self, gpu: &Gpu, table: GuideTable) {
        let shape = |t: &GuideTable| t.lights.iter().map(|l| (l.entry, l.directions, l.first_bin)).collect::<Vec<_>>();
        assert_eq!(shape(&table), shape(&self.table), "a table for other lights");
        self.table = table;
        self.upload_table(gpu);
    }

    fn upload_table(&self, gpu: &Gpu) {
        let (_, table) = guide_offsets(self.mark_words, self.bins());
        gpu.queue.write_buffer(&self.buffer, table as u64 * 4, bytemuck::cast_slice(&self.table.words()));
    }

    /// After a pass: its counts are read back (waits for the GPU) and added to the sums, the
    /// counters cleared, and the table learned anew (where enabled). Returns the pass's photons
    /// started from guided lights and their useful deposits.
    pub fn learn(&mut self, gpu: &Gpu) -> Result<(u64, u64)> {
        let bins = self.bins();
        if bins == 0 {
            return Ok((0, 0));
        }
        let (counters, _) = guide_offsets(self.mark_words, bins);
        let bytes = read_range(gpu, &self.buffer, counters as u64 * 4, 2 * bins as u64 * 4)?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        let (useful, emitted) = words.split_at(bins as usize);
        let (mut photons, mut deposits) = (0u64, 0u64);
        for (b, (&u, &e)) in useful.iter().zip(emitted).enumerate() {
            self.useful[b] += u as f64;
            self.emitted[b] += e as f64;
            photons += e as u64;
            deposits += u as u64;
        }
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.buffer, counters as u64 * 4, Some(2 * bins as u64 * 4));
        gpu.queue.submit([enc.finish()]);
        if self.enabled {
            learn_table(&mut self.table, &self.useful, &self.emitted);
            self.upload_table(gpu);
        }
        Ok((photons, deposits))
    }
}

/// The guided lights of `lights`: the environment ([`ENV_DIRECTIONS`] direction bins) and the
/// distant lights (one), by light-table entry.
pub fn guided_lights(lights: &crate::lights::LightTable) -> Vec<(u32, u32)> {
    use crate::gpu::consts::{ENVIRONMENT_LIGHT, LIGHT_DISTANT, PUNCTUAL_LIGHT};
    (lights.entries.iter().enumerate())
        .filter_map(|(i, e)| {
            if e.triangle == ENVIRONMENT_LIGHT {
                Some((i as u32, ENV_DIRECTIONS))
            } else if e.triangle != ENVIRONMENT_LIGHT
                && e.triangle & PUNCTUAL_LIGHT != 0
                && lights.punctual[(e.triangle & !PUNCTUAL_LIGHT) as usize].kind == LIGHT_DISTANT
            {
                Some((i as u32, 1))
            } else {
                None
            }
        })
        .take(MAX_GUIDED_LIGHTS)
        .collect()
}

/// A direction's table entry of position-bin `weights` (not all zero): their sum and their
/// cumulative distribution, its last entry exactly 1.
pub fn cumulative(weights: &[f64]) -> (f32, Vec<f32>) {
    let sum: f64 = weights.iter().sum();
    let mut acc = 0.0;
    let mut cdf: Vec<f32> = weights
        .iter()
        .map(|w| {
            acc += w / sum;
            acc as f32
        })
        .collect();
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    (sum as f32, cdf)
}

/// The table learned from the summed counts: per light and direction bin, pmf ∝ the mean
/// useful deposits per photon started in each position bin, where the direction has
/// [`MIN_USEFUL`] useful deposits.
pub fn learn_table(table: &mut GuideTable, useful: &[f64], emitted: &[f64]) {
    let n = (POSITIONS * POSITIONS) as usize;
    for l in &mut table.lights {
        for d in 0..l.directions as usize {
            let range = l.first_bin as usize + d * n..l.first_bin as usize + (d + 1) * n;
            let total: f64 = useful[range.clone()].iter().sum();
            if total < MIN_USEFUL {
                l.cdfs[d] = (0.0, Vec::new());
                continue;
            }
            // The direction's mean usefulness, and each bin's shrunk towards it by PRIOR_PHOTONS
            // photons of that mean (a bin few photons started from is not trusted alone).
            let started: f64 = emitted[range.clone()].iter().sum();
            let m = total / started.max(1.0);
            let mean: Vec<f64> = (useful[range.clone()].iter().zip(&emitted[range]))
                .map(|(&u, &e)| ((u + PRIOR_PHOTONS * m) / (e + PRIOR_PHOTONS)).sqrt())
                .collect();
            l.cdfs[d] = cumulative(&mean);
        }
    }
}

/// `size` bytes of `buffer` from `offset`, read back.
fn read_range(gpu: &Gpu, buffer: &wgpu::Buffer, offset: u64, size: u64) -> Result<Vec<u8>> {
    let staging = gpu.zeroed_buffer(
        "photon guide read",
        size,
        wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::STORAGE,
    );
    let mut enc = gpu.device.create_command_encoder(&Default::default());
    enc.copy_buffer_to_buffer(buffer, offset, &staging, 0, size);
    gpu.queue.submit([enc.finish()]);
    gpu.read_buffer(&staging, size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_concentric_map_keeps_areas_and_its_inverse_undoes_it() {
        let mut rng = crate::sampling::Rng::new(5, 0, 0);
        // Uniform on the square → uniform on the disc: the fraction within radius ρ is ρ².
        let n = 200_000;
        let mut inside = [0u32; 4];
        for _ in 0..n {
            let (u, v) = (rng.next_f32(), rng.next_f32());
            let (x, y) = concentric(u, v);
            let r2 = x * x + y * y;
            assert!(r2 <= 1.0 + 1e-5);
            for (k, c) in inside.iter_mut().enumerate() {
                if r2 <= ((k + 1) as f32 * 0.25).powi(2) {
                    *c += 1;
                }
            }
            let (a, b) = concentric_inverse(x, y);
            assert!((a - u).abs() < 2e-4 && (b - v).abs() < 2e-4, "({u}, {v}) → ({x}, {y}) → ({a}, {b})");
        }
        for (k, &c) in inside.iter().enumerate() {
            let expected = ((k + 1) as f64 * 0.25).powi(2);
            let se = (expected * (1.0 - expected) / n as f64).sqrt().max(1e-9);
            assert!((c as f64 / n as f64 - expected).abs() < 5.0 * se, "radius {}: {c}", (k + 1) as f32 * 0.25);
        }
    }

    #[test]
    fn the_skys_direction_bins_have_equal_solid_angles() {
        let mut rng = crate::sampling::Rng::new(9, 0, 0);
        let n = 256_000;
        let mut count = vec![0u32; ENV_DIRECTIONS as usize];
        for _ in 0..n {
            let d = crate::sampling::uniform_sphere(rng.next_f32(), rng.next_f32());
            count[env_direction_bin(d) as usize] += 1;
        }
        let expected = n as f64 / ENV_DIRECTIONS as f64;
        for c in count {
            assert!((c as f64 - expected).abs() < 5.0 * expected.sqrt(), "{c} against {expected}");
        }
    }

    /// Whatever the table, E[1/p(x)·f(x)] over the guided starts is ∫ f over the disc: the flux
    /// through patches inside, beside and far from the guide disc, against their areas.
    #[test]
    fn guided_starts_are_unbiased_for_any_table() {
        let axis = Vec3::new(0.2, -1.0, 0.1).normalize();
        let disc = (Vec3::ZERO, 100.0);
        let aim = Some(crate::lights::PhotonAim { centre: Vec3::new(3.0, 1.0, -2.0), radius: 4.0 });
        // A table that likes a few bins (some inside the aim, some in its surroundings) and
        // ignores the rest.
        let n = (POSITIONS * POSITIONS) as usize;
        let mut rng = crate::sampling::Rng::new(11, 0, 0);
        let weights: Vec<f64> =
            (0..n).map(|_| if rng.next_f32() < 0.05 { rng.next_f32() as f64 * 10.0 } else { 0.0 }).collect();
        let (_, cdf) = cumulative(&weights);
        let (t, b) = crate::sampling::orthonormal_basis(axis);
        let (towards, rg) = guide_disc(axis, disc, aim);
        // Patches (centre offset in disc coordinates, half size), area in the disc's plane.
        let patches = [(towards, 2.0f32), (towards + t * (0.6 * rg), 3.0), (t * 60.0 + b * 20.0, 10.0)];
        for (centre, half) in patches {
            let mut rng = crate::sampling::Rng::new(17, 0, 0);
            let m = 1 << 20;
            let (mut s1, mut s2) = (0.0f64, 0.0f64);
            for _ in 0..m {
                let (o, inv_p, _) = guided_start(axis, disc, aim, Some(&cdf), (rng.next_f32(), rng.next_f32()));
                let rel = o - (disc.0 - axis * disc.1) - centre;
                if rel.dot(t).abs() < half && rel.dot(b).abs() < half {
                    let f = inv_p as f64 / m as f64;
                    s1 += f;
                    s2 += f * f;
                }
            }
            let se = (s2 - s1 * s1 / m as f64).max(0.0).sqrt();
            let area = (2.0 * half as f64).powi(2);
            assert!((s1 - area).abs() < 4.0 * se + 1e-3 * area, "patch at {centre}: {s1} against {area} (se {se})");
        }
    }
}
