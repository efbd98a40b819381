//! Photon pass: photons leave the lights and deposit their flux into the grid photon map
//! ([`map`]) at every diffuse hit.
//!
//! Emission: a light triangle is chosen with probability pmf ∝ its power, a point uniformly on
//! it (pdf 1/A) and a direction with pdf cos θ/π, so a photon carries
//!
//! ```text
//!   Φ = Le · cos θ / (pmf/A · cos θ/π) / N = π · Le · A / pmf / N
//! ```
//!
//! (= total emitted power / N when all lights share one colour). At each hit of a side that
//! reflects, Φ is deposited in the slot (cell of the hit, bin of the side's normal); the photon
//! then survives with probability p = max(ρ) (Russian roulette) carrying Φ·ρ/p, in a cosine
//! direction about the side's normal; ρ is the albedo at the hit point, a texture read there
//! unfiltered (level 0), so each photon takes the colour of the texel it hits. There is no depth limit, only a safety cap
//! ([`MAX_BOUNCES`]). Hitting the back of a one-sided surface absorbs the photon.
//!
//! Shading normals (Veach 1997, §5.3): at a hit with geometric normal n_g and shading normal
//! n_s (both on the side hit; n_s bent towards the arriving photon where it faces away), the
//! photon arriving from ω_o deposits Φ·|ω_o·n_s|/|ω_o·n_g| — the map then estimates the
//! irradiance that the shading normal sees, E_s = ∫ L |ω·n_s| dω, as the eye's passes use
//! it — and scatters cosine-distributed about n_s into ω_i with the adjoint weight
//! ρ·(|ω_o·n_s|/|ω_o·n_g|)·(|ω_i·n_g|/|ω_i·n_s|), so that the flux leaving through the geometric
//! surface is what radiance ρ/π·E_s carries. A direction below the geometric surface ends the
//! path. Without shading normals both factors are 1.
//!
//! Every random number comes from the stream (seed ⊕ [`STREAM_PHOTON`], photon index), so the
//! GPU tracer ([`gpu`]) and its CPU twin ([`cpu`]) draw identical samples for a photon.
//!
//! Since ρ_c/max(ρ) ≤ 1, a photon's flux per channel never exceeds its initial flux, which is
//! at most [`PhotonSettings::max_photon_flux`], except by the shading-normal factors: the
//! GPU's fixed-point tally maps that bound to 2²⁴ quanta of a 32-bit add and clamps a deposit
//! at 2³¹ (128 times the bound).

pub mod budget;
mod clip;
pub mod cpu;
pub mod gpu;
pub mod guide;
pub mod map;
pub mod passes;
pub mod separators;
pub mod table;

use crate::surface::PreparedScene;

/// Safety cap on bounces (Russian roulette ends almost every path long before).
pub const MAX_BOUNCES: u32 = 256;
/// Stream constant of the photon pass's random numbers (`STREAM_PHOTON` in WGSL).
pub use crate::sampling::stream::PHOTON as STREAM_PHOTON;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonSettings {
    /// Photons emitted in total.
    pub count: u32,
    pub seed: u32,
    /// Grid cells along the scene's longest axis.
    pub grid_resolution: u32,
    /// Deposit from a photon's second surface on: the map then holds indirect irradiance only,
    /// and its readers add the direct part exactly ([`crate::gather::HitLight::Exact`]).
    pub indirect_only: bool,
    /// Where the camera reads the map, in cells `factor` times finer than the rest's
    /// ([`crate::fit::photon_region`]); `None`: one level of cells over the whole scene.
    pub region: Option<map::PhotonRegion>,
    /// The sun's and the sky's photons guided to where the map is read, as learned over the
    /// passes ([`guide`]).
    pub guided: bool,
}

impl Default for PhotonSettings {
    fn default() -> Self {
        Self { count: 1 << 20, seed: 0, grid_resolution: 64, indirect_only: false, region: None, guided: false }
    }
}

impl PhotonSettings {
    /// The largest flux, over lights and channels, that a photon starts with
    /// ([`crate::lights::LightTable::max_photon_flux`] / N).
    pub fn max_photon_flux(&self, prepared: &PreparedScene) -> f64 {
        prepared.lights.max_photon_flux(&prepared.scene, self.region.is_some(), self.guided) / self.count.max(1) as f64
    }

    /// Where sun and sky photons are aimed: the photon region's bounding sphere.
    pub fn aim(&self) -> Option<crate::lights::PhotonAim> {
        self.region
            .map(|r| crate::lights::PhotonAim { centre: r.bounds.center(), radius: 0.5 * r.bounds.extent().length() })
    }
}
