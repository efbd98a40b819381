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
//! **Aimed bounces.** Sun and sky photons are aimed at the photon region
//! ([`crate::lights::disc_start`]); the few that start far from it carry a thousand times an
//! aimed photon's flux, and those that reach the region after bouncing off distant ground (the
//! sky's light on the terrain, reflected through a window) made the worst fireflies of a room
//! lit through windows (measured: in the sky-lit sunroom with a fresh map each iteration,
//! ending such photons took the worst 1 % of the pixels' share of the indirect light's squared
//! error from 65 to 16 %). So a photon's first Lambertian bounce outside the aim's sphere is
//! drawn from the one-sample mixture (1 − β)·cos θ/π + β·U_cone, U_cone uniform in the cone the
//! sphere subtends (β = [`BOUNCE_AIM_FRACTION`]; [`lambertian_bounce`]), with the weight
//! ρ·(cos θ/π)/p: the light that goes towards the region is carried by many light photons
//! instead of a few heavy ones. Unbiased for any β (the mixture covers the cosine).
//!
//! Since ρ_c/max(ρ) ≤ 1, a photon's flux per channel never exceeds its initial flux, which is
//! at most [`PhotonSettings::max_photon_flux`], except by the shading-normal factors and the
//! one aimed bounce (at most 1/(1 − β) = 2): the
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
use glam::Vec3;

/// Safety cap on bounces (Russian roulette ends almost every path long before).
pub const MAX_BOUNCES: u32 = 256;
/// Stream constant of the photon pass's random numbers (`STREAM_PHOTON` in WGSL).
pub use crate::gpu::consts::BOUNCE_AIM_FRACTION;
pub use crate::sampling::stream::PHOTON as STREAM_PHOTON;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonSettings {
    /// Photons emitted in total.
    pub count: u32,
    pub seed: u32,
    /// Grid cells along the scene's longest axis.
    pub grid_resolution: u32,
    /// Whose photons deposit from their second surface on, their direct light being taken by
    /// the map's readers from a light sample ([`SampledDirect`]).
    pub sampled_direct: SampledDirect,
    /// Where the camera reads the map, in cells `factor` times finer than the rest's
    /// ([`crate::fit::photon_region`]); `None`: one level of cells over the whole scene.
    pub region: Option<map::PhotonRegion>,
    /// The sun's and the sky's photons guided to where the map is read, as learned over the
    /// passes ([`guide`]).
    pub guided: bool,
}

impl Default for PhotonSettings {
    fn default() -> Self {
        Self {
            count: 1 << 20,
            seed: 0,
            grid_resolution: 64,
            sampled_direct: SampledDirect::None,
            region: None,
            guided: false,
        }
    }
}

/// Which lights' direct light the map leaves to its readers, who take it at each hit from a
/// light sample with a shadow ray ([`crate::gather::HitLight`]): those lights' photons deposit
/// from their second surface on. The codes are the shaders' (`params.first_deposit` in
/// `trace.wgsl`, `photon_grid.sampled_direct` in the gather).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SampledDirect {
    /// None: the map holds all the light (`HitLight::Map`).
    #[default]
    None = 0,
    /// Every light's: the map holds indirect light only (`HitLight::Exact`).
    All = 1,
    /// The punctual lights' (points, spots and distant lights such as the sun): the map holds
    /// the rest (`HitLight::Punctual`).
    Punctual = 2,
}

impl SampledDirect {
    /// Whether a photon of `light` (a light table entry's `triangle` word) skips its first
    /// surface's deposit.
    pub fn skips_first(self, light: u32) -> bool {
        match self {
            SampledDirect::None => false,
            SampledDirect::All => true,
            SampledDirect::Punctual => crate::lights::is_punctual(light),
        }
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

/// A Lambertian bounce at x about the shading normal `ns` from two uniforms: the direction and
/// the factor (cos θ/π)/p by which its weight differs from the cosine's. Cosine-distributed
/// (factor 1) unless `aimed` — then from the mixture (1 − β)·cos θ/π + β·U_cone, U_cone uniform
/// in the cone in which the aim's sphere is seen from x (x outside it), v1 choosing the
/// strategy and then reused. Mirrors `lambertian_bounce` in `photons/trace.wgsl`.
pub fn lambertian_bounce(x: Vec3, ns: Vec3, aim: Option<&crate::lights::PhotonAim>, v1: f32, v2: f32) -> (Vec3, f32) {
    let beta = BOUNCE_AIM_FRACTION;
    let Some(aim) = aim.filter(|a| a.radius > 0.0 && (a.centre - x).length_squared() > a.radius * a.radius) else {
        return (crate::sampling::cosine_hemisphere(ns, v1, v2), 1.0);
    };
    let to = aim.centre - x;
    let d2 = to.length_squared();
    let axis = to / d2.sqrt();
    let s2 = aim.radius * aim.radius / d2;
    let one_minus_cos = s2 / (1.0 + (1.0 - s2).max(0.0).sqrt());
    let w = if v1 < beta {
        crate::sampling::uniform_cone(axis, one_minus_cos, v1 / beta, v2)
    } else {
        crate::sampling::cosine_hemisphere(ns, (v1 - beta) / (1.0 - beta), v2)
    };
    let c = to.cross(w);
    let in_cone = to.dot(w) > 0.0 && c.length_squared() <= aim.radius * aim.radius;
    let cosine = w.dot(ns).max(0.0) / std::f32::consts::PI;
    let cone = if in_cone { 1.0 / (2.0 * std::f32::consts::PI * one_minus_cos) } else { 0.0 };
    let p = (1.0 - beta) * cosine + beta * cone;
    (w, if p > 0.0 { cosine / p } else { 0.0 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lights::PhotonAim;

    /// The aimed bounce carries the cosine's light: for sets of directions A (the aim's cone,
    /// half-spaces, a band), E[factor·1{w ∈ A}] under the mixture equals P_cos(A), which
    /// cosine samples count independently; and the factor never exceeds 1/(1 − β).
    #[test]
    fn the_aimed_bounce_weighs_its_directions_as_the_cosine() {
        let aim = PhotonAim { centre: Vec3::new(0.0, 1.5, 0.0), radius: 2.0 };
        let mut rng = crate::sampling::Rng::new(17, 0, 0);
        for (x, ns) in [
            (Vec3::new(30.0, 0.0, 4.0), Vec3::Y),
            (Vec3::new(3.0, 0.5, -1.0), Vec3::new(-0.6, 0.8, 0.0)),
            (Vec3::new(-9.0, 2.0, 1.0), Vec3::new(0.2, 0.3, 0.93).normalize()),
        ] {
            let to = aim.centre - x;
            let sets: [&dyn Fn(Vec3) -> bool; 4] = [
                &|w: Vec3| to.cross(w).length_squared() <= aim.radius * aim.radius && to.dot(w) > 0.0,
                &|w: Vec3| w.x > 0.0,
                &|w: Vec3| w.z > 0.3,
                &|w: Vec3| w.dot(ns) < 0.5,
            ];
            let n = 1 << 20;
            let (mut aimed, mut aimed_sq, mut cosine) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
            for _ in 0..n {
                let (w, f) = lambertian_bounce(x, ns, Some(&aim), rng.next_f32(), rng.next_f32());
                assert!(f <= 1.0 / (1.0 - BOUNCE_AIM_FRACTION) + 1e-4, "factor {f}");
                let c = crate::sampling::cosine_hemisphere(ns, rng.next_f32(), rng.next_f32());
                for (k, set) in sets.iter().enumerate() {
                    if set(w) {
                        aimed[k] += f as f64;
                        aimed_sq[k] += (f as f64).powi(2);
                    }
                    cosine[k] += set(c) as u32 as f64;
                }
            }
            for k in 0..4 {
                let (a, c) = (aimed[k] / n as f64, cosine[k] / n as f64);
                let se = ((aimed_sq[k] / n as f64 - a * a) / n as f64 + c * (1.0 - c) / n as f64).sqrt();
                assert!((a - c).abs() < 4.0 * se + 1e-6, "set {k} at {x}: aimed {a:.5}, cosine {c:.5}, se {se:.6}");
            }
        }
    }

    /// Inside the aim's sphere, or without an aim, the bounce is the cosine's, point for point.
    #[test]
    fn without_an_aim_the_bounce_is_the_cosines() {
        let aim = PhotonAim { centre: Vec3::ZERO, radius: 2.0 };
        let ns = Vec3::new(0.0, 0.6, 0.8);
        for (v1, v2) in [(0.1, 0.2), (0.7, 0.9), (0.45, 0.01)] {
            let c = crate::sampling::cosine_hemisphere(ns, v1, v2);
            assert_eq!(lambertian_bounce(Vec3::new(1.0, 0.0, 0.5), ns, Some(&aim), v1, v2), (c, 1.0));
            assert_eq!(lambertian_bounce(Vec3::new(9.0, 0.0, 0.5), ns, None, v1, v2), (c, 1.0));
        }
    }
}
