//! The directional albedo of the GGX microfacet lobe, tabulated once: what a rough specular
//! lobe reflects in all, so that the diffuse base under glTF's dielectric layer takes exactly
//! the energy the layer leaves (energy-conserving layering, Kulla & Conty 2017, "Revisiting
//! Physically Based Shading at Imageworks", §"Energy conservation of layered materials").
//!
//! With Schlick's Fresnel F(μ_h) = f₀ + (1 − f₀)(1 − μ_h)⁵ (μ_h = ω_o·h), the lobe's albedo
//! for ω_o at cos θ_o = μ is linear in f₀:
//!
//! ```text
//! E(μ) = ∫ F(ω_o·h) D(h) G₁(ω_o) G₁(ω_i) / (4 μ cos θ_i) cos θ_i dω_i = f₀·E₁(μ, α) + (1 − f₀)·E₅(μ, α)
//! E₁ = ∫ D G₁ G₁ / (4 μ) dω_i,   E₅ = ∫ (1 − ω_o·h)⁵ D G₁ G₁ / (4 μ) dω_i
//! ```
//!
//! and its cosine-weighted mean Ē = 2∫₀¹ E(μ) μ dμ likewise. Both integrals are computed by
//! sampling the distribution of visible normals (Heitz 2018), whose weight for the reflected
//! direction is exactly F·G₁(ω_i), on a stratified 64 × 64 grid of (u₁, u₂) per table cell (in parallel over the cells).
//! The tables hold [`N`] × [`N`] cells, μ and the roughness √α each uniform on [0, 1] (α = 0
//! is the mirror limit: E₁ = 1, E₅ = (1 − μ)⁵; cells uniform in α instead left the metal's
//! energy compensation 1.2 % off at roughness 0.1 and 85°, where E₁ changes fastest), read
//! bilinearly; Ē is integrated from the interpolated
//! table itself, so that ∫(1 − E(μ_i))·cos θ_i/π dω_i / (1 − Ē) is exactly 1 and the layer's
//! white furnace errs only by the interpolation at μ_o. The WGSL twin reads the same numbers
//! from the scene's textures at bindings 13 and 14 (filled from [`GpuGgxAlbedo`], gpu_scene.rs).

use std::sync::OnceLock;

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use super::{fresnel_dielectric, ggx_g1, reflect, refract, vndf_sample};
use crate::par::prelude::*;

/// Cells along μ and along α.
pub use crate::gpu::consts::GGX_ALBEDO_N as N;
/// Strata per axis of the (u₁, u₂) grid of each cell's integral.
const STRATA: usize = 64;

/// E₁ and E₅ at every (μ, √α) cell (index √α·N + μ), and their cosine-weighted means at every √α.
pub struct GgxAlbedo {
    pub e: Vec<[f32; 2]>,
    pub mean: Vec<[f32; 2]>,
}

/// μ or √α of grid index i: i/(N − 1).
fn grid(i: usize) -> f32 {
    i as f32 / (N - 1) as f32
}

/// (E₁, E₅) for cos θ_o = μ and α by VNDF sampling (f32 throughout, summed in f64).
fn integrate(mu: f32, alpha: f32) -> [f32; 2] {
    // Just off the grazing and the mirror limits, where the integrands are continuous.
    let mu = mu.max(1e-4);
    let alpha = alpha.max(1e-4);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu);
    let (mut e1, mut e5) = (0.0f64, 0.0f64);
    for a in 0..STRATA {
        for b in 0..STRATA {
            let u1 = (a as f32 + 0.5) / STRATA as f32;
            let u2 = (b as f32 + 0.5) / STRATA as f32;
            let h = vndf_sample(wo, alpha, u1, u2);
            let wi = 2.0 * wo.dot(h) * h - wo;
            if wi.z <= 0.0 {
                continue;
            }
            let g = ggx_g1(wi, h, alpha) as f64;
            let m = (1.0 - wo.dot(h)).clamp(0.0, 1.0) as f64;
            e1 += g;
            e5 += g * m.powi(5);
        }
    }
    let n = (STRATA * STRATA) as f64;
    [(e1 / n) as f32, (e5 / n) as f32]
}

/// Cell k = √α·N + μ of the GGX table, integrated: (E₁, E₅).
pub fn ggx_cell(k: usize) -> [f32; 2] {
    let (i, j) = (k % N, k / N);
    if j == 0 {
        // The mirror limit: every ray reflects, F at μ itself.
        [1.0, (1.0 - grid(i)).powi(5)]
    } else {
        integrate(grid(i), grid(j) * grid(j))
    }
}

/// The GGX table as committed (`ggx_albedo.bin`, little-endian f32 pairs (E₁, E₅) in
/// [`GgxAlbedo::e`]'s order), written by `cargo run --release -p rastergi --example
/// albedo_tables` from [`ggx_cell`]: 4 M microfacet samples, which took every process 0.08 s
/// of start-up on two cores (0.3–0.4 s on a loaded machine) when integrated there
/// (`the_committed_ggx_table_is_what_the_integral_gives` integrates every cell again).
const GGX_TABLE: &[u8] = include_bytes!("ggx_albedo.bin");

impl GgxAlbedo {
    /// Every cell integrated (in parallel): what the committed table holds.
    pub fn compute() -> Self {
        GgxAlbedo::with_cells((0..N * N).into_par_iter().map(ggx_cell).collect())
    }

    fn committed() -> Self {
        assert_eq!(GGX_TABLE.len(), N * N * 8, "ggx_albedo.bin holds {} cells", N * N);
        let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
        GgxAlbedo::with_cells(GGX_TABLE.chunks_exact(8).map(|b| [f(&b[..4]), f(&b[4..])]).collect())
    }

    /// The table of cells `e` with its cosine-weighted means.
    fn with_cells(e: Vec<[f32; 2]>) -> Self {
        let mut table = GgxAlbedo { e, mean: vec![[0.0; 2]; N] };
        // 2∫ E(μ) μ dμ of the interpolated table, by the midpoint rule on a fine grid.
        const STEPS: usize = 4096;
        for j in 0..N {
            let (mut m1, mut m5) = (0.0f64, 0.0f64);
            for k in 0..STEPS {
                let mu = (k as f32 + 0.5) / STEPS as f32;
                let [a, b] = table.at(mu, grid(j) * grid(j));
                m1 += a as f64 * mu as f64;
                m5 += b as f64 * mu as f64;
            }
            let scale = 2.0 / STEPS as f64;
            table.mean[j] = [(m1 * scale) as f32, (m5 * scale) as f32];
        }
        table
    }

    /// (E₁, E₅) at cos θ_o = `mu` and `alpha`, bilinear in (μ, √α) between cells (clamped to [0, 1]).
    pub fn at(&self, mu: f32, alpha: f32) -> [f32; 2] {
        let (i, fx) = cell(mu);
        let (j, fy) = cell(alpha.max(0.0).sqrt());
        let lerp = |a: [f32; 2], b: [f32; 2], t: f32| [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t];
        let lo = lerp(self.e[j * N + i], self.e[j * N + i + 1], fx);
        let hi = lerp(self.e[(j + 1) * N + i], self.e[(j + 1) * N + i + 1], fx);
        lerp(lo, hi, fy)
    }

    /// (Ē₁, Ē₅) at `alpha`, linear in √α between cells: exactly the mean of [`Self::at`] over μ.
    pub fn mean_at(&self, alpha: f32) -> [f32; 2] {
        let (j, t) = cell(alpha.max(0.0).sqrt());
        let (a, b) = (self.mean[j], self.mean[j + 1]);
        [a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t]
    }

    /// The GPU form, bsdf.wgsl's `GgxAlbedoTable` (bound as the scene's `ggx_table`), with the
    /// glass's table where `glass` (read on first use), zeros elsewhere. Boxed: with the glass
    /// table it is 272 KiB, too large for a worker thread's stack to copy around.
    pub fn gpu(&self, glass: bool) -> Box<GpuGgxAlbedo> {
        let mut g: Box<GpuGgxAlbedo> = bytemuck::zeroed_box();
        if glass {
            g.glass.copy_from_slice(&glass_albedo().e);
        }
        for k in 0..N * N {
            let next = if k % N < N - 1 { k + 1 } else { k };
            let (a, b) = (self.e[k], self.e[next]);
            g.cells[k] = [a[0], a[1], b[0], b[1]];
        }
        for j in 0..N {
            let (a, b) = (self.mean[j], self.mean[(j + 1).min(N - 1)]);
            g.means[j] = [a[0], a[1], b[0], b[1]];
        }
        g
    }
}

/// The tables as the GPU reads them (the scene's two textures, gpu_scene.rs; a storage buffer
/// in the GPU twin's test): cell k = √α·N + μ holds (E₁, E₅) at k and at k + 1 (the next μ,
/// the pair a bilinear read needs from one row), mean j (Ē₁, Ē₅) at √α cells j and j + 1.
/// `glass` holds the rough solid glass's albedo ([`GlassAlbedo`]), all zeros where the scene
/// has no rough solid glass with its compensation (its kernels never read it).
#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
pub struct GpuGgxAlbedo {
    pub cells: [[f32; 4]; N * N],
    pub means: [[f32; 4]; N],
    pub glass: [f32; GLASS_CELLS],
}

/// The cell of x ∈ [0, 1] on the grid and the fraction within it.
fn cell(x: f32) -> (usize, f32) {
    let t = x.clamp(0.0, 1.0) * (N - 1) as f32;
    let i = (t as usize).min(N - 2);
    (i, t - i as f32)
}

/// The GGX tables (the committed cells, read on first use).
pub fn ggx_albedo() -> &'static GgxAlbedo {
    static TABLE: OnceLock<GgxAlbedo> = OnceLock::new();
    TABLE.get_or_init(GgxAlbedo::committed)
}

pub use crate::gpu::consts::{GLASS_CELLS, GLASS_ETA_MAX, GLASS_ETAS};
/// Strata per axis of each glass cell's integral: the integrand jumps where total internal
/// reflection begins, and 24 × 24 midpoints left the albedo from inside 1.5 % off at roughness
/// 1 (64 × 64: within 0.1 % of a quadrature of `eval` and of sampling).
const GLASS_STRATA: usize = 64;

/// The single-scattering albedo of rough solid glass (Walter et al.'s model, white, η the
/// relative index across the surface): the share E_g(μ, α, η, side) of the flux arriving from
/// a direction at cosine μ on either side (outside: η; inside: 1/η, with total internal
/// reflection) that one microfacet reflects or refracts, E_h[F·G₁(ω_r) + (1 − F)·G₁(ω_t)] over
/// the visible normals (the importance weights of VNDF sampling: the refracted radiance's
/// 1/η'² is not flux). Tabulated on μ and √α uniform on [0, 1] (N × N) and η uniform on
/// [1, [`GLASS_ETA_MAX`]] ([`GLASS_ETAS`]), read trilinearly. The glass's energy
/// compensation divides its lobes by it (`Bsdf::glass_eval`).
pub struct GlassAlbedo {
    /// Index ((side·GLASS_ETAS + η)·N + √α)·N + μ; side 0 outside, 1 inside.
    pub e: Vec<f32>,
}

/// η of glass grid index k.
fn glass_eta(k: usize) -> f32 {
    1.0 + (GLASS_ETA_MAX - 1.0) * k as f32 / (GLASS_ETAS - 1) as f32
}

fn integrate_glass(mu: f32, alpha: f32, eta: f32, inside: bool) -> f32 {
    let mu = mu.max(1e-4);
    let alpha = alpha.max(1e-4);
    let wo = Vec3::new((1.0 - mu * mu).max(0.0).sqrt(), 0.0, if inside { -mu } else { mu });
    let mut e = 0.0f64;
    for a in 0..GLASS_STRATA {
        for b in 0..GLASS_STRATA {
            let u1 = (a as f32 + 0.5) / GLASS_STRATA as f32;
            let u2 = (b as f32 + 0.5) / GLASS_STRATA as f32;
            let h = vndf_sample(wo, alpha, u1, u2);
            let f = fresnel_dielectric(wo.dot(h), eta);
            let wr = reflect(wo, h);
            if wr.z * wo.z > 0.0 {
                e += (f * ggx_g1(wr, h, alpha)) as f64;
            }
            if let Some((wt, _)) = refract(wo, h, eta)
                && wt.z * wo.z < 0.0
            {
                e += ((1.0 - f) * ggx_g1(wt, h, alpha)) as f64;
            }
        }
    }
    (e / (GLASS_STRATA * GLASS_STRATA) as f64) as f32
}

/// Cell k of the glass table, integrated.
pub fn glass_cell(k: usize) -> f32 {
    let (i, j, eta, side) = (k % N, (k / N) % N, (k / (N * N)) % GLASS_ETAS, k / (N * N * GLASS_ETAS));
    if j == 0 {
        // Smooth glass loses nothing.
        return 1.0;
    }
    integrate_glass(grid(i), grid(j) * grid(j), glass_eta(eta), side == 1)
}

/// The glass table as committed (`glass_albedo.bin`, little-endian f32 in [`GlassAlbedo::e`]'s
/// order), written by `cargo run --release -p rastergi --example albedo_tables` from
/// [`glass_cell`] (`cargo run --release -p rastergi --example albedo_tables`): 134 M microfacet samples, too slow to integrate at every start
/// (`the_committed_glass_table_is_what_the_integral_gives` recomputes cells of it).
const GLASS_TABLE: &[u8] = include_bytes!("glass_albedo.bin");

impl GlassAlbedo {
    /// All cells integrated (in parallel): what the committed table holds.
    pub fn compute() -> Self {
        GlassAlbedo { e: (0..GLASS_CELLS).into_par_iter().map(glass_cell).collect() }
    }

    fn committed() -> Self {
        assert_eq!(GLASS_TABLE.len(), GLASS_CELLS * 4, "glass_albedo.bin holds {GLASS_CELLS} cells");
        GlassAlbedo { e: GLASS_TABLE.chunks_exact(4).map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect() }
    }

    /// E_g for a direction at cosine `mu` on the inside (`inside`) or the outside, α and η:
    /// trilinear between cells (each coordinate clamped to the table).
    pub fn at(&self, mu: f32, alpha: f32, eta: f32, inside: bool) -> f32 {
        let (i, fx) = cell(mu);
        let (j, fy) = cell(alpha.max(0.0).sqrt());
        let t = ((eta - 1.0) / (GLASS_ETA_MAX - 1.0)).clamp(0.0, 1.0) * (GLASS_ETAS - 1) as f32;
        let k = (t as usize).min(GLASS_ETAS - 2);
        let fz = t - k as f32;
        let side = if inside { GLASS_ETAS } else { 0 };
        let at = |k: usize, j: usize| {
            let row = ((side + k) * N + j) * N + i;
            self.e[row] + (self.e[row + 1] - self.e[row]) * fx
        };
        let plane = |k: usize| at(k, j) + (at(k, j + 1) - at(k, j)) * fy;
        plane(k) + (plane(k + 1) - plane(k)) * fz
    }
}

/// The glass table (the committed one, read on first use).
pub fn glass_albedo() -> &'static GlassAlbedo {
    static TABLE: OnceLock<GlassAlbedo> = OnceLock::new();
    TABLE.get_or_init(GlassAlbedo::committed)
}
