//! The surface scattering model: glTF 2.0's metallic-roughness BRDF with
//! `KHR_materials_specular`'s layer weight and `KHR_materials_transmission` glass. Every pass
//! evaluates and samples it through `bsdf.wgsl`, this module's bit-for-bit-in-spirit twin
//! (tested against it on the GPU); the photon tracer's CPU twin and the tests use it here.
//!
//! With base colour c, metallic m, transmission t and specular-layer weight s, the BSDF is the
//! mix of three:
//!
//! ```text
//! f = m·M + (1 − m)·[(1 − t)·D + t·G]
//! M (metal)      = F_c(ω_o·h) · D(h) G₁(ω_o) G₁(ω_i) / (4 |cos θ_o| |cos θ_i|),  F_c = c + (1 − c)(1 − ω_o·h)⁵
//! D (dielectric) = s·F_s(ω_o·h) · [the same microfacet term]
//!                  + (1 − s·F_s(cos θ_o))(1 − s·F_s(cos θ_i)) / (1 − s·F̄_s) · c/π,
//!                  F_s(μ) = f₀ + (1 − f₀)(1 − μ)⁵, f₀ = ((η − 1)/(η + 1))², F̄_s = f₀ + (1 − f₀)/21
//! G (glass)      = Walter et al.'s rough dielectric (2007) with the exact unpolarised Fresnel
//!                  term, transmission tinted by c; thin-walled: a slab (below)
//! ```
//!
//! as glTF's specification writes it (its `fresnel_mix` and `conductor_fresnel`, Schlick's
//! Fresnel at ω_o·h), with two exceptions. The diffuse base under the specular layer takes
//! the share the layer transmits in both directions (`diffuse_share`, reciprocal and
//! energy-conserving; glTF's mix by (1 − sF(ω_o·h)) reflects up to 22 % more than a white
//! surface receives at grazing angles). Glass uses the exact Fresnel term: a refracting solid
//! needs total internal reflection, which Schlick's form at the outer angle does not give. The
//! microfacet distribution is GGX (Trowbridge–Reitz) with α = roughness², and the shadowing
//! is Smith's separable form G = G₁(ω_o)·G₁(ω_i), G₁ = 2 cos θ/(cos θ + √(α² + (1 − α²) cos² θ)),
//! which is glTF's `V_GGX` and Mitsuba 3's `ggx` microfacets.
//!
//! Rough GGX's single scattering loses the light that bounces between microfacets before it
//! leaves (a white metal of roughness 1 reflects 0.31 at normal incidence). The metal gets it
//! back by Kulla & Conty's energy compensation (2017, "Revisiting Physically Based Shading at
//! Imageworks"), a second, diffuse-like lobe
//!
//! ```text
//! M_ms = F_ms · (1 − E(μ_o))(1 − E(μ_i)) / (π (1 − Ē)),   F_ms = F̄² Ē / (1 − F̄ (1 − Ē)),   F̄ = c + (1 − c)/21
//! ```
//!
//! with E = E₁ the single-scattering albedo of a white metal ([`albedo`]), Ē its
//! cosine-weighted mean and F̄ the cosine-weighted mean of Schlick's Fresnel term: reciprocal,
//! and a white metal reflects E(μ_o) + (1 − E(μ_o)) = 1 at every angle and roughness; a
//! coloured one gains the light that the series of inner bounces F̄^k keeps. The layer needs
//! none (its base takes what it leaves, `diffuse_share`). Rough glass divides its lobes by its
//! single-scattering albedo E_g for the direction the light leaves by (Turquin 2019's scaling:
//! the lost energy returned in the shape of the lobes it was lost from),
//!
//! ```text
//! f_G,ms(ω_o, ω_i) = f_G(ω_o, ω_i) / E_g(ω_v),   ω_v = ω_o for radiance, ω_i for importance
//! ```
//!
//! with E_g(ω) the share of the flux arriving from ω that one microfacet reflects or refracts
//! (tabulated on μ, α, η and the side, [`albedo::GlassAlbedo`]; a thin slab's is E₁). By
//! reciprocity ∫ f_G(ω_o, ω_i) η(ω_i)² cos θ_i dω_i = η(ω_o)² E_g(ω_o), so uniform light — the
//! equilibrium radiance η² on each side — is kept exactly at every roughness, from outside and
//! from inside (where rough glass of η 1.5 keeps 0.42 at roughness 1 by single scattering, the
//! rest lost to total internal reflection between microfacets); a single beam, as with the
//! coat, is kept on average. The model is reciprocal no more; importance uses the adjoint.
//! [`Bsdf::multiple_scattering`] off is the single-scattering model (Mitsuba 3's
//! `roughconductor`, which the reference images use: `--single-scattering`).
//!
//! Below [`SMOOTH_ALPHA`] the microfacet lobes are perfectly specular (Dirac deltas):
//! [`Bsdf::eval`] and [`Bsdf::pdf`] leave them out and only [`Bsdf::sample`] produces them.
//!
//! A clear coat (`KHR_materials_clearcoat`: weight k, its own roughness α_c, η = 1.5) lies over
//! all of that, f_base above:
//!
//! ```text
//! f = k·F_k(ω_o·h)·D_c(h) G₁(ω_o) G₁(ω_i) / (4 |cos θ_o| |cos θ_i|) + (1 − k·E_k(μ_v))·f_base,
//!     F_k = 0.04 + 0.96 (1 − ω_o·h)⁵,   E_k(μ) = 0.04·E₁(μ, α_c) + 0.96·E₅(μ, α_c)
//! ```
//!
//! with μ_v the cosine of the direction the light leaves by (ω_o for radiance, ω_i for the
//! photons' importance: the adjoint). The model under the coat gets what the coat does not
//! reflect towards the viewer, its directional albedo k·E_k (Schlick's kF_k(μ_v) when smooth),
//! so a coat over any white model reflects k·E_k + (1 − k·E_k) = 1: energy is conserved at
//! every roughness, as in OpenPBR's and Cycles' albedo scaling. glTF's text scales the base
//! by (1 − k·F_k(N·V)), the same form with the Fresnel term in place of the albedo, which
//! loses what a rough coat's single scattering does not reflect. The factor depends on μ_v
//! alone, so the coated model is not reciprocal; importance transport uses the adjoint
//! (μ_v = μ_i), so photons scatter as the light does and every renderer solves the same
//! transport, and the coated base's Lambertian part keeps the form a(μ_o)/π the photon map
//! answers for. What albedo scaling gives up: a single beam of light is conserved only on
//! average — one at normal incidence loses k(Ē_k − E_k(1)) (about 5 % of k for a smooth
//! coat), one at grazing incidence, which the coat mostly reflects, gains up to k(1 − Ē_k).
//! Uniform light (the white furnace) returns exactly what it brings. A reciprocal form,
//! (1 − kE_k(μ_o))(1 − kE_k(μ_i))/(1 − kĒ_k), is exact only over a Lambertian base: over
//! glTF's layered default it lost 9 % at 80°. The coat shares the base's shading normal
//! (clearcoatNormalTexture is not read).
//!
//! Directions are unit vectors pointing away from the surface, in the shading frame
//! ([`Frame`]): z is the front face's shading normal. Opaque lobes and thin glass reflect on
//! the side ω_o lies on (the caller decides whether a back face reflects at all); solid glass
//! is entered from the front (relative index η) and left from the back (1/η).
//!
//! A thin-walled glass (glTF's transmission without `KHR_materials_volume`) is a slab: the
//! reflectance R' = 2R/(1 + R) of its two faces with their inter-reflections (as Mitsuba's
//! `thindielectric`), the rest passing straight through, tinted; rough, the transmitted lobe
//! is the reflected lobe mirrored through the surface plane.

use glam::Vec3;

pub mod albedo;
mod dielectric;
mod diffuse;
pub mod gpu_check;
mod layered;
mod microfacet;

pub use albedo::ggx_albedo;
pub use dielectric::fresnel_dielectric;
use dielectric::*;
use microfacet::*;
pub use microfacet::{ggx_d, ggx_g1, schlick, vndf_pdf, vndf_sample};

/// GGX α below which the microfacet lobes are perfectly specular (roughness < 0.032).
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// F₀ of the clear coat: η = 1.5, which `KHR_materials_clearcoat` fixes.
pub const COAT_F0: f32 = 0.04;

/// The scattering parameters at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bsdf {
    /// Base colour c (linear RGB): the diffuse albedo, a metal's reflectance at normal
    /// incidence, glass's transmission tint.
    pub base: Vec3,
    pub metallic: f32,
    /// GGX α = roughness².
    pub alpha: f32,
    /// Weight s of the dielectric specular layer (`KHR_materials_specular`'s specularFactor;
    /// 0: a plain Lambertian surface).
    pub specular: f32,
    /// The layer's colour at normal incidence (`KHR_materials_specular`'s specularColorFactor):
    /// its F₀ = min(f₀(η)·colour, 1) per channel, F₉₀ = 1 (white: glTF's default). Glass keeps
    /// its exact Fresnel term of η.
    pub specular_color: Vec3,
    /// Index of refraction η of the dielectric (layer and glass).
    pub ior: f32,
    pub transmission: f32,
    /// Thin-walled glass: no refraction, a slab.
    pub thin: bool,
    /// The rough metal's energy compensation (module docs); off: single scattering only.
    pub multiple_scattering: bool,
    /// Weight k of the clear coat over everything else (`KHR_materials_clearcoat`'s
    /// clearcoatFactor; 0: none).
    pub clearcoat: f32,
    /// The coat's GGX α = clearcoatRoughness².
    pub clearcoat_alpha: f32,
}

/// What a sampled or evaluated direction carries: radiance (eye paths; a refracted ray's
/// radiance scales by 1/η'²) or importance (photons: flux does not).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    Radiance,
    Importance,
}

/// A sampled direction ω_i and its weight f·|cos θ_i|/pdf; `pdf` is the solid-angle density
/// of the non-specular lobes' mixture (what MIS compares), or for a specular lobe the
/// probability of having picked it (`delta`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
    pub delta: bool,
}

/// The lobes under the coat, in the order [`Bsdf::sample`] picks from (after the coat).
const METAL: usize = 0;
const LAYER: usize = 1;
const DIFFUSE: usize = 2;
const GLASS: usize = 3;

fn mean(c: Vec3) -> f32 {
    (c.x + c.y + c.z) / 3.0
}

impl Bsdf {
    /// Whether eye and gather rays pass it rather than stop (`surface_passes_rays` in WGSL): no
    /// diffuse base, and glass, or smooth under a smooth coat or none.
    pub fn passes_rays(&self) -> bool {
        let opaque = (1.0 - self.metallic.clamp(0.0, 1.0)) * (1.0 - self.transmission);
        opaque <= 0.0 && (self.transmission > 0.0 || (self.alpha < SMOOTH_ALPHA && !self.rough_coat()))
    }

    /// Whether the model is plain Lambertian (f = c/π).
    pub fn is_lambertian(&self) -> bool {
        self.metallic == 0.0 && self.transmission == 0.0 && self.specular == 0.0 && self.clearcoat <= 0.0
    }

    fn smooth(&self) -> bool {
        self.alpha < SMOOTH_ALPHA
    }

    /// The probabilities of picking the coat and each lobe under it for ω_o at |cos θ_o| =
    /// `cos_o`, in lobe order; all zero when nothing scatters. They depend on ω_o alone, so
    /// [`Self::pdf`] can give the density of any ω_i. The cosine-distributed lobe serves the
    /// diffuse base and the metal's multiple-scattering lobe, weighted by what each reflects;
    /// the coat is weighted by its Fresnel term kF_k(cos θ_o), the lobes under it by what it
    /// leaves them.
    fn lobe_probabilities(&self, cos_o: f32) -> (f32, [f32; 4]) {
        let m = self.metallic;
        let opaque = (1.0 - m) * (1.0 - self.transmission);
        let fs = self.layer_fresnel(cos_o);
        let w = [
            m * mean(schlick(self.base, cos_o)),
            opaque * mean(fs),
            opaque * mean((Vec3::ONE - fs) * self.base) + m * mean(self.ms_fresnel()) * self.ms_loss(cos_o),
            (1.0 - m) * self.transmission,
        ];
        let coat = if self.clearcoat > 0.0 { self.clearcoat * schlick(Vec3::splat(COAT_F0), cos_o).x } else { 0.0 };
        let under: f32 = w.iter().sum::<f32>() * (1.0 - coat);
        let total = coat + under;
        if total <= 0.0 {
            return (0.0, [0.0; 4]);
        }
        let scale = under / total / w.iter().sum::<f32>().max(f32::MIN_POSITIVE);
        (coat / total, w.map(|x| x * scale))
    }

    /// f(ω_o, ω_i) of the non-specular lobes, in the shading frame: the coat's and, scaled by
    /// what it leaves, the model's under it.
    pub fn eval(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Vec3 {
        let under = self.eval_under_coat(wo, wi, transport);
        if self.clearcoat <= 0.0 {
            return under;
        }
        self.coat_eval(wo, wi) + under * self.coat_scale(wo, wi, transport)
    }

    /// The solid-angle density with which [`Self::sample`] draws ω_i (its non-specular lobes).
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let (p_coat, p) = self.lobe_probabilities(wo.z.abs());
        let mut pdf = p[GLASS] * self.glass_pdf(wo, wi);
        let (o, i) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if o.z <= 0.0 || i.z <= 0.0 {
            return pdf;
        }
        pdf += p[DIFFUSE] * i.z / std::f32::consts::PI;
        let h = (o + i).normalize();
        if !self.smooth() {
            pdf += (p[METAL] + p[LAYER]) * vndf_pdf(o, h, self.alpha) / (4.0 * o.dot(h));
        }
        if self.rough_coat() {
            pdf += p_coat * vndf_pdf(o, h, self.clearcoat_alpha) / (4.0 * o.dot(h));
        }
        pdf
    }

    /// A direction ω_i for ω_o from three uniforms: u0 picks the lobe (the coat where u0 <
    /// its probability; then, rescaled, glass's reflection or transmission), (u1, u2) the
    /// direction in it. None where nothing scatters or the sample leaves the lobe's support.
    pub fn sample(&self, wo: Vec3, u: [f32; 3], transport: Transport) -> Option<BsdfSample> {
        if wo.z == 0.0 {
            return None;
        }
        let (p_coat, p) = self.lobe_probabilities(wo.z.abs());
        let side = if wo.z < 0.0 { -1.0 } else { 1.0 };
        let o = wo * side;
        if u[0] < p_coat {
            if self.coat_smooth() {
                let weight = Vec3::splat(self.clearcoat * schlick(Vec3::splat(COAT_F0), o.z).x / p_coat);
                return Some(BsdfSample { wi: Vec3::new(-o.x, -o.y, o.z) * side, weight, pdf: p_coat, delta: true });
            }
            let wi = reflect(o, vndf_sample(o, self.clearcoat_alpha, u[1], u[2]));
            return if wi.z <= 0.0 { None } else { self.finish_sample(wo, wi * side, transport) };
        }
        // The lobe whose interval of [p_coat, 1) holds u0 (the last one that can scatter when
        // rounding leaves u0 past them all).
        let mut u0 = u[0] - p_coat;
        let mut lobe = usize::MAX;
        for (k, &pk) in p.iter().enumerate() {
            if pk > 0.0 {
                lobe = k;
                if u0 < pk {
                    break;
                }
                u0 -= pk;
            }
        }
        if lobe == usize::MAX {
            return None;
        }
        // u0 rescaled to a fresh uniform within the picked lobe's interval.
        let u0 = (u0 / p[lobe]).clamp(0.0, 0.999_999_94);
        if lobe == GLASS {
            return self.sample_glass(wo, u0, u[1], u[2], p[GLASS], transport);
        }
        let wi = if lobe == DIFFUSE {
            crate::sampling::cosine_hemisphere(Vec3::Z, u[1], u[2])
        } else if self.smooth() {
            let weight = if lobe == METAL {
                self.metallic * schlick(self.base, o.z)
            } else {
                (1.0 - self.metallic) * (1.0 - self.transmission) * self.layer_fresnel(o.z)
            };
            let wi = Vec3::new(-o.x, -o.y, o.z) * side;
            let weight = weight * self.coat_scale(wo, wi, transport) / p[lobe];
            return Some(BsdfSample { wi, weight, pdf: p[lobe], delta: true });
        } else {
            reflect(o, vndf_sample(o, self.alpha, u[1], u[2]))
        };
        if wi.z <= 0.0 {
            return None;
        }
        self.finish_sample(wo, wi * side, transport)
    }

    /// The sample of a non-specular direction ω_i: its weight f·|cos θ_i|/pdf.
    fn finish_sample(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Option<BsdfSample> {
        let pdf = self.pdf(wo, wi);
        if pdf <= 0.0 {
            return None;
        }
        let weight = self.eval(wo, wi, transport) * (wi.z.abs() / pdf);
        Some(BsdfSample { wi, weight, pdf, delta: false })
    }
}

/// An orthonormal shading frame about the unit normal n: world ↔ local (z = n).
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl Frame {
    pub fn new(n: Vec3) -> Self {
        let (t, b) = crate::sampling::orthonormal_basis(n);
        Self { t, b, n }
    }

    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }

    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.t * v.x + self.b * v.y + self.n * v.z
    }
}

#[cfg(test)]
mod tests;
