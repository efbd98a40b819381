//! The guided sky (`RenderSettings::sky_guiding`, issue 57): the direct pass's environment
//! samples drawn towards the parts of the sky that are open from each visible point.
//!
//! In a room lit through its windows the environment's own sampling (by luminance × solid
//! angle, [`crate::environment::Environment::sample`]) sends most samples at the walls: from
//! a shaded point of the sky-lit `sunroom` about 1 % of them pass a window. **What it learns.**
//! Per cell and side of the guides' grid ([`crate::gather::guide`]: the cells of the visible
//! points, the dominant axis of their shading normal) and per *block* of the environment map —
//! [`SkyBlocks`]: up to 16 × 16 rectangles of its cells, aligned with its rows and columns —
//! the mean *openness* V(ω)·max(0, n·ω) of the directions that the direct pass's environment
//! samples and the traced gather's rays took from there (1 where a ray escaped along ω, 0 where
//! something was hit; fixed point, [`crate::gpu::consts::SKY_GUIDE_SCALE`]). The table's weight
//! of block b is W_b = P_b·V̄_b, P_b the environment's probability of the block (its cells'
//! pmfs summed): the share of the sky's light that arrives through b, up to the cosine.
//!
//! **How it samples.** An environment sample is drawn from the one-sample mixture
//!
//! ```text
//!   p(ω) = (1 − g)·p_env(ω) + g·q(ω),   q(ω) = W_b / ΣW · p_env(ω) / P_b   (ω in block b),
//! ```
//!
//! g = [`crate::gpu::consts::SKY_GUIDE_FRACTION`] where the point's cell has learned something,
//! else 0. Within a block the guided samples follow the sky's brightness (a sun in the map
//! stays as well sampled as before): q = p_env·V̄_b/ΣW, so p = p_env·((1 − g) + g·V̄_b/ΣW). The
//! mixture is drawn as *one* warp of the light sample's two uniforms, not by a coin between two
//! strategies: a block by its mixture probability (1 − g)·P_b + g·W_b/ΣW, then a cell of the
//! block by the environment's own pmf, then a point of the cell uniformly, exactly as the
//! environment's sampling places it. A coin would split each pixel's Owen-scrambled Sobol'
//! points between the strategies at random and lose their stratification — measured so in the
//! sky-lit `sunroom`: the direct light's noise 8.1 → 12.7 % at 128 iterations, 4× the variance
//! on the sunlit floor. The estimate f·L·cos θ/(pmf_env·p(ω)) is unbiased for any table (every
//! direction keeps at least (1 − g)·p_env). The gathers' escaping
//! rays, which also find the sky, are weighed against these samples with the same p
//! (`env_gather_weight`), so the sky through a window is counted once.
//!
//! The tables are made at the start of each iteration ([`crate::gather::guide::GuideBuild`]),
//! so the direct pass and the gather of one iteration (of each of its row bands) read the same
//! table: the power heuristic's two densities agree.

use glam::Vec3;

use crate::environment::Environment;
pub use crate::gpu::consts::{SKY_GUIDE_FRACTION as FRACTION, SKY_GUIDE_SCALE as SCALE};

/// Most blocks along a row and down a column of the environment map.
pub const MAX_BLOCKS: u32 = 16;

/// The guided sky's blocks of an environment map: `columns` × `rows` rectangles of its cells
/// (W columns, H − 1 rows of cells), block (k, l) holding the cells (i, j) with
/// ⌊i·columns/W⌋ = k and ⌊j·rows/(H − 1)⌋ = l; `masses` the environment's probability of each,
/// block l·columns + k; `rows_cdf` per cell row j and block column k the probability of the
/// block column's cells in the rows of j's block row up to j (what the guided warp searches).
#[derive(Clone, Debug, PartialEq)]
pub struct SkyBlocks {
    pub columns: u32,
    pub rows: u32,
    pub masses: Vec<f32>,
    pub rows_cdf: Vec<f32>,
}

impl SkyBlocks {
    /// The blocks of `env`.
    pub fn new(env: &Environment) -> SkyBlocks {
        let (w, cell_rows) = (env.width, env.height - 1);
        let (columns, rows) = (MAX_BLOCKS.min(w), MAX_BLOCKS.min(cell_rows));
        let mut masses = vec![0.0f64; (columns * rows) as usize];
        let mut rows_cdf = vec![0.0f32; (cell_rows * columns) as usize];
        let mut run = vec![0.0f64; columns as usize];
        for j in 0..cell_rows {
            let l = j * rows / cell_rows;
            if j == 0 || (j - 1) * rows / cell_rows != l {
                run.iter_mut().for_each(|r| *r = 0.0);
            }
            for i in 0..w {
                let k = i * columns / w;
                let m = env.cell_pmf[(j * w + i) as usize] as f64;
                masses[(l * columns + k) as usize] += m;
                run[k as usize] += m;
            }
            for k in 0..columns {
                rows_cdf[(j * columns + k) as usize] = run[k as usize] as f32;
            }
        }
        SkyBlocks { columns, rows, masses: masses.into_iter().map(|m| m as f32).collect(), rows_cdf }
    }

    /// The blocks' masses cumulated, then `rows_cdf`: the words the guide buffer holds
    /// (`sky_blocks_cdf`, `sky_rows_cdf`).
    pub fn words(&self) -> Vec<f32> {
        let mut acc = 0.0f64;
        let mut out: Vec<f32> = self
            .masses
            .iter()
            .map(|&m| {
                acc += m as f64;
                acc as f32
            })
            .collect();
        out.extend_from_slice(&self.rows_cdf);
        out
    }

    /// The block of direction d in `env` (`sky_block_of` in `sky_guide.wgsl`).
    pub fn block_of(&self, env: &Environment, d: Vec3) -> u32 {
        let (i, j) = env.cell_of(d);
        let (i, j) = (i as u32, j as u32);
        (j * self.rows / (env.height - 1)) * self.columns + i * self.columns / env.width
    }

    /// The first cell column of block column k and the first cell row of block row l (the
    /// next block's are the ends): ⌈k·W/columns⌉, ⌈l·(H − 1)/rows⌉.
    pub fn starts(&self, env: &Environment, k: u32, l: u32) -> (u32, u32) {
        ((k * env.width).div_ceil(self.columns), (l * (env.height - 1)).div_ceil(self.rows))
    }

    /// The mixture's factor F_b = p/p_env of each block for a table of block weights
    /// `weights` (W_b = P_b·V̄_b, ΣW > 0): (1 − g) + g·W_b/(P_b·ΣW), 0 where P_b = 0.
    pub fn factors(&self, weights: &[f32]) -> Vec<f32> {
        let total: f32 = weights.iter().sum();
        self.masses
            .iter()
            .zip(weights)
            .map(|(&m, &w)| if m > 0.0 { (1.0 - FRACTION) + FRACTION * w / (m * total) } else { 0.0 })
            .collect()
    }

    /// The guided sky's density of direction d (per steradian) for a table of block weights
    /// `weights`: p_env·F_b, or p_env where ΣW = 0 (`sky_density` in `sky_guide.wgsl`).
    pub fn density(&self, env: &Environment, weights: &[f32], d: Vec3) -> f32 {
        let p = env.pdf(d);
        if weights.iter().sum::<f32>() <= 0.0 {
            return p;
        }
        p * self.factors(weights)[self.block_of(env, d) as usize]
    }

    /// A direction from the guided mixture for a table of block weights `weights` (ΣW > 0)
    /// and two uniforms, and its density (`sky_guided_light` in `sky_guide.wgsl`): u1 picks
    /// the cell row by the mixture's row masses, u2 the cell along the row by the mixture's
    /// masses there, each remainder the point in the cell — the environment's own warp
    /// ([`Environment::sample`]) with each block's cells weighed by its factor.
    pub fn sample(&self, env: &Environment, weights: &[f32], u1: f32, u2: f32) -> (Vec3, f32) {
        let f = self.factors(weights);
        let cols = self.columns as usize;
        let cell_rows = env.height - 1;
        // The mixture's mass of cell row j in block column k, and of the whole row.
        let cell_row_mass = |j: u32, k: usize| {
            let first = j == 0 || (j - 1) * self.rows / cell_rows != j * self.rows / cell_rows;
            let prev = if first { 0.0 } else { self.rows_cdf[(j as usize - 1) * cols + k] };
            f[(j * self.rows / cell_rows) as usize * cols + k] * (self.rows_cdf[j as usize * cols + k] - prev)
        };
        let row_mass = |j: u32| (0..cols).map(|k| cell_row_mass(j, k)).sum::<f32>();
        let total: f32 = (0..cell_rows).map(row_mass).sum();
        let (mut j, mut acc) = (0u32, 0.0f32);
        let goal = u1 * total;
        loop {
            let m = row_mass(j);
            if (acc + m > goal && m > 0.0) || j + 1 == cell_rows {
                break;
            }
            acc += m;
            j += 1;
        }
        let m = row_mass(j);
        let v = ((goal - acc) / m.max(f32::MIN_POSITIVE)).clamp(0.0, 0.99999994);
        let goal2 = u2 * m;
        let (mut k, mut acc2) = (0usize, 0.0f32);
        loop {
            let mk = cell_row_mass(j, k);
            if (acc2 + mk > goal2 && mk > 0.0) || k + 1 == cols {
                break;
            }
            acc2 += mk;
            k += 1;
        }
        let rest = ((goal2 - acc2) / cell_row_mass(j, k).max(f32::MIN_POSITIVE)).clamp(0.0, 0.99999994);
        let (c0, _) = self.starts(env, k as u32, 0);
        let (c1, _) = self.starts(env, k as u32 + 1, 0);
        let w = env.width as usize;
        let row = &env.column_cdf[j as usize * w..(j as usize + 1) * w];
        let col = |i: u32| if i == 0 { 0.0 } else { row[i as usize - 1] };
        let at = col(c0) + rest * (col(c1) - col(c0));
        let i = (c0 as usize + row[c0 as usize..c1 as usize].partition_point(|&c| c <= at)).min(c1 as usize - 1);
        let below = col(i as u32);
        let s = ((at - below) / (row[i] - below).max(f32::MIN_POSITIVE)).clamp(0.0, 0.99999994);
        let d = env.cell_direction(i as u32, j, s, v);
        (d, self.density(env, weights, d))
    }
}

/// The guided warp of `sky_guide.wgsl` (`sky_guided_light`) run on the GPU for `env`, its
/// `blocks` and one cell whose table has block weights `weights`, at each (u1, u2) of
/// `queries`: the direction and its density (per steradian) — the GPU side of the CPU twin's
/// test ([`SkyBlocks::sample`]).
pub fn guided_sky_on_gpu(
    gpu: &crate::gpu::Gpu,
    env: &Environment,
    blocks: &SkyBlocks,
    weights: &[f32],
    queries: &[[f32; 2]],
) -> crate::error::Result<Vec<[f32; 4]>> {
    use crate::gpu::binding::{Group, Slot};
    use crate::gpu::shader;
    use crate::gpu::structs::GpuStruct;
    let uniform = crate::environment::GpuEnvironment::new(Some(env), Vec3::ZERO, 1.0, 1.0);
    let storage = wgpu::BufferUsages::empty();
    let uniform = gpu.storage_buffer("sky check environment", bytemuck::bytes_of(&uniform), storage);
    let data = gpu.storage_buffer("sky check data", bytemuck::cast_slice(&env.gpu_data()), storage);
    // The guide buffer: the header, the blocks' tables, one cell (key, then the sky's table:
    // sums and counts unused, the cumulative weights).
    let bins = crate::gpu::consts::GATHER_GUIDE_BINS as usize;
    let lead = blocks.words();
    let start = crate::gpu::consts::GUIDE_MARKS;
    let base = start + lead.len() as u32;
    let mut words = vec![0u32; base as usize + 1 + 3 * bins];
    let header =
        [0, 0, 0, 0, 1, 1, 1, 1, base, 0, 1 + 3 * bins as u32, u32::MAX, 1, blocks.columns, blocks.rows, start];
    words[..16].copy_from_slice(&header);
    for (k, w) in lead.iter().enumerate() {
        words[start as usize + k] = w.to_bits();
    }
    words[base as usize] = 1;
    let mut acc = 0.0f32;
    for b in 0..bins {
        acc += weights.get(b).copied().unwrap_or(0.0);
        words[base as usize + 1 + 2 * bins + b] = acc.to_bits();
    }
    let guide = gpu.storage_buffer("sky check guide", bytemuck::cast_slice(&words), storage);
    let input = gpu.storage_buffer("sky check queries", bytemuck::cast_slice(queries), storage);
    let environment = include_str!("../environment.wgsl")
        .replace("@group(0) @binding(9) var<uniform> environment: Environment;", "")
        .replace("scene_f32(scene_offset(DATA_ENVIRONMENT) + k)", "env_words[k]");
    let main = "
        @group(0) @binding(0) var<storage, read> environment: Environment;
        @group(0) @binding(1) var<storage, read> env_words: array<f32>;
        @group(0) @binding(2) var<storage, read_write> photon_guide: array<atomic<u32>>;
        @group(0) @binding(3) var<storage, read> queries: array<vec2f>;
        @group(0) @binding(4) var<storage, read_write> samples: array<vec4f>;
        struct Surface { pos: vec3f }
        struct VisiblePoint { x: Surface, ns: vec3f }
        struct LightRay { dir: vec3f, dist: f32, e: vec3f, tri: u32, pdf: f32 }
        @compute @workgroup_size(64)
        fn main(@builtin(global_invocation_id) gid: vec3u) {
            if gid.x >= arrayLength(&queries) {
                return;
            }
            var l: LightRay;
            l.pdf = 1.0;
            let r = sky_guided_light(l, queries[gid.x], 0u, guide_total(0u, sky_guide_table()));
            samples[gid.x] = vec4f(r.dir, r.pdf);
        }";
    let source = shader::compose(&[
        shader::SAMPLING,
        &crate::environment::GpuEnvironment::wgsl(),
        &environment,
        crate::gather::guide::WGSL,
        WGSL,
        main,
    ]);
    let module = shader::module(&gpu.device, "sky check", &source);
    gpu.run_once_read(
        "sky check",
        &module,
        &Group::compute(
            "sky check",
            &[
                Slot::read::<crate::environment::GpuEnvironment>(0, "environment"),
                Slot::read::<f32>(1, "env_words"),
                Slot::write::<u32>(2, "photon_guide"),
                Slot::read::<[f32; 2]>(3, "queries"),
                Slot::write::<[f32; 4]>(4, "samples"),
            ],
        ),
        &[
            ("environment", uniform.as_entire_binding()),
            ("env_words", data.as_entire_binding()),
            ("photon_guide", guide.as_entire_binding()),
            ("queries", input.as_entire_binding()),
        ],
        "samples",
        queries.len(),
    )
}

/// The guided sky's WGSL (`sky_guide.wgsl`): for a shader that binds the guide buffer and
/// knows the environment and the visible point.
pub const WGSL: &str = include_str!("sky_guide.wgsl");

/// Its stand-ins where no guide buffer is bound (the direct pass without a photon map): the
/// environment's own sampling, nothing learned.
pub const UNGUIDED_WGSL: &str = "
const NO_GUIDE: u32 = 0xffffffffu;
fn sky_guide_entry(p: VisiblePoint, insert: bool) -> u32 {
    return NO_GUIDE;
}
fn sky_guide_total(e: u32) -> f32 {
    return 0.0;
}
fn sky_guided_light(l: LightRay, u: vec2f, e: u32, total: f32) -> LightRay {
    return l;
}
fn sky_guide_learn(e: u32, w: vec3f, openness: f32) {}
";

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// A sky with a sun: a 64 × 32 map whose one bright texel holds most of its power, the
    /// rest smooth, the lower half dark.
    fn sky() -> Environment {
        Environment::from_fn(64, 32, |i, j| {
            if (i, j) == (8, 8) {
                Vec3::new(900.0, 800.0, 700.0)
            } else if j < 16 {
                Vec3::splat(0.3 + 0.5 * (j as f32 / 16.0)) * (1.0 + 0.3 * (i as f32 * 0.2).sin())
            } else {
                Vec3::splat(0.02)
            }
        })
        .unwrap()
    }

    /// A table that opens a few blocks (a window) and half of the sun's.
    fn table(blocks: &SkyBlocks) -> Vec<f32> {
        let mut openness = vec![0.0f32; blocks.masses.len()];
        for b in [3 * 16 + 5, 3 * 16 + 6, 4 * 16 + 5, 4 * 16 + 6, 2 * 16 + 12] {
            openness[b] = 0.8;
        }
        openness[3 * 16 + 2] = 0.5;
        openness.iter().zip(&blocks.masses).map(|(v, m)| v * m).collect()
    }

    #[test]
    fn the_blocks_cover_the_map_and_their_tables_sum_its_pmf() {
        let env = sky();
        let blocks = SkyBlocks::new(&env);
        assert_eq!((blocks.columns, blocks.rows), (16, 16));
        let total: f64 = blocks.masses.iter().map(|&m| m as f64).sum();
        assert!((total - 1.0).abs() < 1e-5, "{total}");
        // Each block row's last cell row holds the block row's masses.
        for l in 0..blocks.rows {
            let (_, next) = blocks.starts(&env, 0, l + 1);
            for k in 0..blocks.columns {
                let a = blocks.rows_cdf[((next - 1) * blocks.columns + k) as usize];
                let b = blocks.masses[(l * blocks.columns + k) as usize];
                assert!((a - b).abs() <= 1e-6 * b.max(1e-3), "block ({k}, {l}): {a} against {b}");
            }
        }
    }

    /// χ² of the guided warp against its density over the blocks' cells: the counts of 2^20
    /// samples in each cell of the map against N·∫_cell p (p = p_env·F_b is constant over a
    /// cell's solid angle times the cell's pmf), cells expecting under 5 pooled.
    #[test]
    fn the_guided_warp_draws_its_density() {
        let env = sky();
        let blocks = SkyBlocks::new(&env);
        let weights = table(&blocks);
        let f = blocks.factors(&weights);
        let (w, rows) = (env.width as usize, env.height as usize - 1);
        let n = 1usize << 20;
        let mut counts = vec![0u32; w * rows];
        let mut rng = Rng::new(7, 0, 0);
        for _ in 0..n {
            let (d, pdf) = blocks.sample(&env, &weights, rng.next_f32(), rng.next_f32());
            assert!(pdf > 0.0 && (pdf - blocks.density(&env, &weights, d)).abs() <= 1e-4 * pdf);
            let (i, j) = env.cell_of(d);
            counts[j * w + i] += 1;
        }
        let (mut chi2, mut dof, mut pooled_e, mut pooled_o) = (0.0f64, 0usize, 0.0f64, 0.0f64);
        for j in 0..rows {
            for i in 0..w {
                let b = blocks.block_of(&env, env.cell_direction(i as u32, j as u32, 0.5, 0.5)) as usize;
                let e = n as f64 * env.cell_pmf[j * w + i] as f64 * f[b] as f64;
                let o = counts[j * w + i] as f64;
                if e < 5.0 {
                    assert!(e > 0.0 || o == 0.0, "a sample in cell ({i}, {j}) of density 0");
                    pooled_e += e;
                    pooled_o += o;
                } else {
                    chi2 += (o - e).powi(2) / e;
                    dof += 1;
                }
            }
        }
        if pooled_e > 0.0 {
            chi2 += (pooled_o - pooled_e).powi(2) / pooled_e;
            dof += 1;
        }
        // The 0.999 quantile of χ²(dof) ≈ dof + 3.09·√(2·dof) (normal approximation).
        let bound = dof as f64 + 3.09 * (2.0 * dof as f64).sqrt();
        assert!(chi2 < bound, "χ² {chi2:.1} over {dof} cells (bound {bound:.1})");
    }

    #[test]
    fn with_every_factor_one_the_warp_is_the_environments_own() {
        let env = sky();
        let blocks = SkyBlocks::new(&env);
        // Weights equal to the masses: V̄ = 1 everywhere, F_b = 1.
        let weights = blocks.masses.clone();
        let mut rng = Rng::new(3, 0, 0);
        for _ in 0..2000 {
            let (u1, u2) = (rng.next_f32(), rng.next_f32());
            let (a, pa) = env.sample(u1, u2);
            let (b, pb) = blocks.sample(&env, &weights, u1, u2);
            assert!((a - b).length() < 2e-3 && (pa - pb).abs() <= 1e-3 * pa, "({u1}, {u2}): {a} {pa} against {b} {pb}");
        }
    }
}
