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
pub mod gpu_check;
pub use albedo::ggx_albedo;

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

fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's Fresnel with reflectance f₀ at normal incidence and 1 at grazing.
pub fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * schlick_weight(cos)
}

/// The exact unpolarised Fresnel reflectance of a dielectric interface for a ray arriving at
/// cosine `cos_i` to the normal on the side of relative index `eta` (η_t/η_i for cos_i > 0;
/// from below, 1/eta); 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_i < 0.0 { (-cos_i, 1.0 / eta) } else { (cos_i, eta) };
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

/// A slab's reflectance from one face's R, with the light reflected back and forth inside:
/// R + T²R/(1 − R²) = 2R/(1 + R).
fn slab_reflectance(r: f32) -> f32 {
    if r >= 1.0 { 1.0 } else { 2.0 * r / (1.0 + r) }
}

/// GGX's normal distribution D(h) for α (h in the upper hemisphere).
pub fn ggx_d(h: Vec3, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = h.z * h.z * (a2 - 1.0) + 1.0;
    a2 / (std::f32::consts::PI * t * t)
}

/// Smith's masking G₁(w, h) for GGX: 0 where w sees the back of the microfacet h.
pub fn ggx_g1(w: Vec3, h: Vec3, alpha: f32) -> f32 {
    if w.dot(h) * w.z <= 0.0 {
        return 0.0;
    }
    let c2 = w.z * w.z;
    let a2 = alpha * alpha;
    2.0 * w.z.abs() / (w.z.abs() + (a2 + (1.0 - a2) * c2).sqrt())
}

/// The density of the microfacet normal h visible from w (Heitz 2018):
/// G₁(w) |w·h| D(h) / |cos θ_w|.
pub fn vndf_pdf(w: Vec3, h: Vec3, alpha: f32) -> f32 {
    if w.z == 0.0 {
        return 0.0;
    }
    ggx_g1(w, h, alpha) * w.dot(h).abs() * ggx_d(h, alpha) / w.z.abs()
}

/// A microfacet normal visible from w (either hemisphere; h in the upper one), Heitz's
/// "Sampling the GGX distribution of visible normals" (2018).
pub fn vndf_sample(w: Vec3, alpha: f32, u1: f32, u2: f32) -> Vec3 {
    let flip = w.z < 0.0;
    let w = if flip { -w } else { w };
    let vh = Vec3::new(alpha * w.x, alpha * w.y, w.z).normalize();
    let len2 = vh.x * vh.x + vh.y * vh.y;
    let t1 = if len2 > 0.0 { Vec3::new(-vh.y, vh.x, 0.0) / len2.sqrt() } else { Vec3::X };
    let t2 = vh.cross(t1);
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let p1 = r * phi.cos();
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
    let nh = t1 * p1 + t2 * p2 + vh * (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
    Vec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(1e-6)).normalize()
}

fn reflect(w: Vec3, h: Vec3) -> Vec3 {
    2.0 * w.dot(h) * h - w
}

/// w refracted through the microfacet h (h on w's side or not) for the relative index `eta`
/// of the side h faces; with the relative index η' = η_t/η_i it used; None under total
/// internal reflection.
fn refract(w: Vec3, h: Vec3, eta: f32) -> Option<(Vec3, f32)> {
    let mut cos_i = h.dot(w);
    let (mut eta, mut h) = (eta, h);
    if cos_i < 0.0 {
        eta = 1.0 / eta;
        cos_i = -cos_i;
        h = -h;
    }
    let sin2_t = (1.0 - cos_i * cos_i).max(0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((-w / eta + (cos_i / eta - cos_t) * h, eta))
}

fn mirror_z(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

impl Bsdf {
    /// A Lambertian surface of albedo ρ.
    pub fn diffuse(albedo: Vec3) -> Self {
        Self {
            base: albedo,
            metallic: 0.0,
            alpha: 1.0,
            specular: 0.0,
            specular_color: Vec3::ONE,
            ior: 1.5,
            transmission: 0.0,
            thin: false,
            multiple_scattering: true,
            clearcoat: 0.0,
            clearcoat_alpha: 0.0,
        }
    }

    /// The albedo of a Lambertian surface standing in for this model where the photon map is
    /// read at a visible point (the photon-map view, the caustics pass; the gather's hits
    /// follow the glossy lobes instead, [`Self::lambertian_albedo`]), seen from ω_o at cosine
    /// `cos_o` (an approximation, stated in docs/design.md): the model's directional albedo ∫f·cos θ_i dω_i
    /// towards ω_o — what it reflects towards ω_o under uniform incident light — for the metal
    /// (Schlick's F₀ = c: c·E₁ + (1 − c)·E₅, [`albedo`], plus F_ms·(1 − E₁) compensated) and the opaque dielectric
    /// (E_L(μ_o) + (1 − E_L(μ_o))·c, exact for the energy-conserving layer); the
    /// hemispherical reflectance F̄ = f₀ + (1 − f₀)/21 for glass (the light it transmits is
    /// not seen there). Until issue 34 this was c for the metal and the dielectric, which
    /// counted a rough white metal's lost energy as reflected (0.31 at roughness 1).
    pub fn diffuse_equivalent(&self, cos_o: f32) -> Vec3 {
        let cos_o = cos_o.abs().min(1.0);
        let f0 = self.ior_f0();
        let mean_f = f0 + (1.0 - f0) / 21.0;
        let opaque = (1.0 - self.metallic) * (1.0 - self.transmission);
        let metal = if self.smooth() {
            schlick(self.base, cos_o)
        } else {
            let [e1, e5] = ggx_albedo().at(cos_o, self.alpha);
            self.base * e1 + (Vec3::ONE - self.base) * e5 + self.ms_fresnel() * self.ms_loss(cos_o)
        };
        let layer = self.layer_albedo(cos_o);
        let dielectric = layer + (Vec3::ONE - layer) * self.base;
        let under = self.metallic * metal
            + opaque * dielectric
            + Vec3::splat((1.0 - self.metallic) * self.transmission * mean_f);
        let coat = self.coat_albedo(cos_o);
        Vec3::splat(coat) + (1.0 - coat) * under
    }

    /// The albedo a(μ_o) of the model's Lambertian part f_L(ω_o, ω_i) = a(μ_o)/π, which the
    /// photon map answers for exactly where the final gather's rays meet the surface (its
    /// irradiance E gives ∫f_L L cos θ_i dω_i = a/π·E); the gather follows the rest, f − f_L,
    /// by sampling the model (docs/design.md). a is the albedo of the cosine lobes: the
    /// diffuse base under the layer, (1 − m)(1 − t)·(1 − E_L(μ_o))·c, and the metal's
    /// multiple scattering, m·F_ms·(1 − E₁(μ_o)) — each lobe's ∫·cos θ_i dω_i, since
    /// ∫(1 − E(μ))2μ dμ = 1 − Ē — under a coat scaled by what it leaves, 1 − k·E_k(μ_o). The
    /// rest then reflects nothing on average where the light is uniform; on a Lambertian
    /// surface it is zero.
    pub fn lambertian_albedo(&self, cos_o: f32) -> Vec3 {
        let cos_o = cos_o.abs().min(1.0);
        let opaque = (1.0 - self.metallic) * (1.0 - self.transmission);
        let base = if self.specular == 0.0 { Vec3::ONE } else { Vec3::ONE - self.layer_albedo(cos_o) };
        (opaque * base * self.base + self.metallic * self.ms_fresnel() * self.ms_loss(cos_o))
            * (1.0 - self.coat_albedo(cos_o))
    }

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

    fn coat_smooth(&self) -> bool {
        self.clearcoat_alpha < SMOOTH_ALPHA
    }

    /// Whether a coat with a glossy (not perfectly specular) lobe lies on top.
    fn rough_coat(&self) -> bool {
        self.clearcoat > 0.0 && !self.coat_smooth()
    }

    /// What the coat reflects in all for a direction at cosine `cos`, its directional albedo
    /// k·E_k(μ) = k(F₀E₁(μ, α_c) + (1 − F₀)E₅(μ, α_c)), F₀ = [`COAT_F0`]; kF_k(μ) when smooth.
    /// Zero without a coat.
    fn coat_albedo(&self, cos: f32) -> f32 {
        if self.clearcoat <= 0.0 {
            return 0.0;
        }
        let cos = cos.abs().min(1.0);
        if self.coat_smooth() {
            return self.clearcoat * schlick(Vec3::splat(COAT_F0), cos).x;
        }
        let [e1, e5] = ggx_albedo().at(cos, self.clearcoat_alpha);
        self.clearcoat * (COAT_F0 * e1 + (1.0 - COAT_F0) * e5)
    }

    /// The share of the model under the coat, 1 − k·E_k(μ_v), μ_v the cosine of the direction
    /// the light leaves by: ω_o for radiance, ω_i for importance (the adjoint; module docs).
    fn coat_scale(&self, wo: Vec3, wi: Vec3, transport: Transport) -> f32 {
        let view = if transport == Transport::Radiance { wo } else { wi };
        1.0 - self.coat_albedo(view.z)
    }

    /// The coat's glossy lobe k·F_k(ω_o·h)·D G₁ G₁/(4 cos θ_o cos θ_i), on ω_o's side; zero
    /// when smooth (a delta, sampled only) or absent.
    fn coat_eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
        if !self.rough_coat() {
            return Vec3::ZERO;
        }
        let (o, i) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if o.z <= 0.0 || i.z <= 0.0 {
            return Vec3::ZERO;
        }
        let h = (o + i).normalize();
        let a = self.clearcoat_alpha;
        let spec = ggx_d(h, a) * ggx_g1(o, h, a) * ggx_g1(i, h, a) / (4.0 * o.z * i.z);
        Vec3::splat(self.clearcoat * schlick(Vec3::splat(COAT_F0), o.dot(h)).x * spec)
    }

    /// Whether rough glass's lobes are scaled by 1/E_g of the direction the light leaves by
    /// (module docs).
    fn glass_compensates(&self) -> bool {
        self.multiple_scattering && !self.smooth() && self.transmission > 0.0
    }

    /// The single-scattering albedo of white rough glass for flux arriving from `w`
    /// ([`albedo::GlassAlbedo`]: a solid from either side; a thin slab's is the reflection
    /// lobe's, E₁(|cos θ|), since it passes what it does not reflect along the mirrored lobe).
    /// A relative index below 1 is the same glass seen from inside (the renderers turn the
    /// frame towards the arriving ray and invert η there).
    fn glass_single_albedo(&self, w: Vec3) -> f32 {
        if self.thin {
            ggx_albedo().at(w.z.abs(), self.alpha)[0]
        } else {
            let (eta, inside) = if self.ior < 1.0 { (1.0 / self.ior, w.z >= 0.0) } else { (self.ior, w.z < 0.0) };
            albedo::glass_albedo().at(w.z.abs(), self.alpha, eta, inside)
        }
    }

    /// Whether the metal lobe has its multiple-scattering lobe (module docs): compensated,
    /// rough and partly metallic.
    fn compensates(&self) -> bool {
        self.multiple_scattering && !self.smooth() && self.metallic > 0.0
    }

    /// F_ms = F̄²Ē/(1 − F̄(1 − Ē)) of the multiple-scattering lobe, F̄ = c + (1 − c)/21 and
    /// Ē = Ē₁(α): the albedo it adds is F_ms·(1 − E₁(μ_o)). Zero where it is off.
    fn ms_fresnel(&self) -> Vec3 {
        if !self.compensates() {
            return Vec3::ZERO;
        }
        let e_avg = ggx_albedo().mean_at(self.alpha)[0];
        let f_avg = self.base + (Vec3::ONE - self.base) / 21.0;
        f_avg * f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg))
    }

    /// 1 − E₁(μ, α): what single scattering loses for a direction at cosine `cos`.
    fn ms_loss(&self, cos: f32) -> f32 {
        (1.0 - ggx_albedo().at(cos, self.alpha)[0]).max(0.0)
    }

    /// M_ms(ω_o, ω_i) = F_ms(1 − E₁(μ_o))(1 − E₁(μ_i)) / (π(1 − Ē₁)), for cosines on the lobe's side.
    fn ms_eval(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        if !self.compensates() {
            return Vec3::ZERO;
        }
        let e_avg = ggx_albedo().mean_at(self.alpha)[0];
        self.ms_fresnel()
            * (self.ms_loss(cos_o) * self.ms_loss(cos_i) / (std::f32::consts::PI * (1.0 - e_avg).max(1e-6)))
    }

    /// f₀ of the dielectric, ((η − 1)/(η + 1))².
    fn ior_f0(&self) -> f32 {
        let r = (self.ior - 1.0) / (self.ior + 1.0);
        r * r
    }

    /// F₀ of the layer, min(f₀·colour, 1) per channel (`KHR_materials_specular`).
    fn layer_f0(&self) -> Vec3 {
        (self.ior_f0() * self.specular_color).min(Vec3::ONE)
    }

    /// The layer's Fresnel weight s·F_s(cos), F_s = F₀ + (1 − F₀)(1 − cos)⁵.
    fn layer_fresnel(&self, cos: f32) -> Vec3 {
        self.specular * schlick(self.layer_f0(), cos)
    }

    /// What the specular layer reflects in all for ω_o at cosine `cos`, its directional albedo
    /// E_L(μ) = s·(F₀E₁(μ, α) + (1 − F₀)E₅(μ, α)) ([`albedo`]) per channel; sF(μ) when smooth
    /// (a mirror reflects its Fresnel term).
    fn layer_albedo(&self, cos: f32) -> Vec3 {
        if self.smooth() {
            return self.layer_fresnel(cos);
        }
        let f0 = self.layer_f0();
        let [e1, e5] = ggx_albedo().at(cos, self.alpha);
        self.specular * (f0 * e1 + (Vec3::ONE - f0) * e5)
    }

    /// The layer's cosine-weighted mean albedo Ē_L = 2∫E_L(μ)μ dμ; sF̄ = s(F₀ + (1 − F₀)/21)
    /// when smooth.
    fn layer_mean_albedo(&self) -> Vec3 {
        let f0 = self.layer_f0();
        if self.smooth() {
            return self.specular * (f0 + (Vec3::ONE - f0) / 21.0);
        }
        let [m1, m5] = ggx_albedo().mean_at(self.alpha);
        self.specular * (f0 * m1 + (Vec3::ONE - f0) * m5)
    }

    /// The share of the light that the specular layer leaves to the diffuse base, for the
    /// directions at cosines `cos_o` and `cos_i`: (1 − E_L(cos θ_o))(1 − E_L(cos θ_i)) / (1 − Ē_L),
    /// E_L the layer's directional albedo and Ē_L its cosine-weighted mean. Reciprocal and
    /// energy-conserving at every roughness: the base receives exactly what the layer does not
    /// reflect, so a white surface reflects E_L(μ_o) + (1 − E_L(μ_o)) = 1 in all (Kulla & Conty
    /// 2017). Rough GGX's single scattering reflects less than its Fresnel term (E_L < sF); a
    /// base that gave up sF(cos θ) in both directions, as before, lost the difference: a white
    /// glTF dielectric of roughness 1 reflected 0.974 at normal incidence and 0.62 at 80°, and
    /// a room of such walls came out 10 % darker than Lambertian ones (issue 34). glTF's own
    /// form, (1 − sF(ω_o·h)), gains up to 22 % at grazing angles.
    fn diffuse_share(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        if self.specular == 0.0 {
            return Vec3::ONE;
        }
        (Vec3::ONE - self.layer_albedo(cos_o)) * (Vec3::ONE - self.layer_albedo(cos_i))
            / (Vec3::ONE - self.layer_mean_albedo())
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

    /// A thin slab's pair (ω_o, ω_i) on ω_o's side: ω_o, ω_i reflected through the surface where
    /// it is transmitted, their half vector, whether ω_i is reflected, and the slab's
    /// reflectance R' at the half vector.
    fn thin_pair(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3, Vec3, bool, f32) {
        let (o, i) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        let reflected = i.z > 0.0;
        let ir = if reflected { i } else { mirror_z(i) };
        let h = (o + ir).normalize();
        (o, ir, h, reflected, slab_reflectance(fresnel_dielectric(o.dot(h), self.ior)))
    }

    /// A solid's generalized half vector h (upper hemisphere) of (ω_o, ω_i) and the relative
    /// index η' of the refraction (1 for a reflection); None where no microfacet pairs them.
    fn solid_half(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
        let etap = if wo.z * wi.z > 0.0 {
            1.0
        } else if wo.z > 0.0 {
            self.ior
        } else {
            1.0 / self.ior
        };
        let h = wi * etap + wo;
        if h.length_squared() == 0.0 {
            return None;
        }
        let h = h.normalize();
        let h = if h.z < 0.0 { -h } else { h };
        if h.dot(wi) * wi.z < 0.0 || h.dot(wo) * wo.z < 0.0 {
            return None;
        }
        Some((h, etap))
    }

    /// The glass's f: a thin slab alike from both sides, a solid entered from the front;
    /// compensated, divided by the single-scattering albedo E_g of the direction the light
    /// leaves by (ω_o for radiance, ω_i for importance: module docs).
    fn glass_eval(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Vec3 {
        let f = self.glass_single_eval(wo, wi, transport);
        if !self.glass_compensates() || f == Vec3::ZERO {
            return f;
        }
        let view = if transport == Transport::Radiance { wo } else { wi };
        f / self.glass_single_albedo(view).max(1e-3)
    }

    /// Walter et al.'s single-scattering glass.
    fn glass_single_eval(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Vec3 {
        if self.smooth() || wo.z == 0.0 || wi.z == 0.0 {
            return Vec3::ZERO;
        }
        let a = self.alpha;
        if self.thin {
            let (o, ir, h, reflected, r) = self.thin_pair(wo, wi);
            let weight = if reflected { Vec3::splat(r) } else { (1.0 - r) * self.base };
            return weight * ggx_d(h, a) * ggx_g1(o, h, a) * ggx_g1(ir, h, a) / (4.0 * o.z * ir.z);
        }
        let Some((h, etap)) = self.solid_half(wo, wi) else { return Vec3::ZERO };
        let reflected = wo.z * wi.z > 0.0;
        let f = fresnel_dielectric(wo.dot(h), self.ior);
        let dg = ggx_d(h, a) * ggx_g1(wo, h, a) * ggx_g1(wi, h, a);
        if reflected {
            return Vec3::splat(dg * f / (4.0 * wo.z * wi.z).abs());
        }
        let denom = (wi.dot(h) + wo.dot(h) / etap).powi(2) * wi.z * wo.z;
        let mut ft = dg * (1.0 - f) * (wi.dot(h) * wo.dot(h) / denom).abs();
        if transport == Transport::Radiance {
            ft /= etap * etap;
        }
        ft * self.base
    }

    /// The glass's density of ω_i (its rough lobes; 0 when smooth).
    fn glass_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.smooth() || wo.z == 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let a = self.alpha;
        if self.thin {
            let (o, _, h, reflected, r) = self.thin_pair(wo, wi);
            let choice = if reflected { r } else { 1.0 - r };
            return vndf_pdf(o, h, a) / (4.0 * o.dot(h).abs()) * choice;
        }
        let Some((h, etap)) = self.solid_half(wo, wi) else { return 0.0 };
        let reflected = wo.z * wi.z > 0.0;
        let r = fresnel_dielectric(wo.dot(h), self.ior);
        if reflected {
            vndf_pdf(wo, h, a) / (4.0 * wo.dot(h).abs()) * r
        } else {
            let denom = (wi.dot(h) + wo.dot(h) / etap).powi(2);
            vndf_pdf(wo, h, a) * wi.dot(h).abs() / denom * (1.0 - r)
        }
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

    /// f_base(ω_o, ω_i): the non-specular lobes under the coat.
    fn eval_under_coat(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Vec3 {
        let mut f = Vec3::ZERO;
        let opaque = (1.0 - self.metallic) * (1.0 - self.transmission);
        if self.transmission > 0.0 && self.metallic < 1.0 {
            f += (1.0 - self.metallic) * self.transmission * self.glass_eval(wo, wi, transport);
        }
        // The opaque lobes reflect on ω_o's side.
        let (o, i) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        if o.z <= 0.0 || i.z <= 0.0 {
            return f;
        }
        let h = (o + i).normalize();
        let vh = o.dot(h);
        f += opaque * self.base * self.diffuse_share(o.z, i.z) / std::f32::consts::PI;
        f += self.metallic * self.ms_eval(o.z, i.z);
        let fs = self.layer_fresnel(vh);
        if !self.smooth() {
            let a = self.alpha;
            let spec = ggx_d(h, a) * ggx_g1(o, h, a) * ggx_g1(i, h, a) / (4.0 * o.z * i.z);
            f += spec * (self.metallic * schlick(self.base, vh) + opaque * fs);
        }
        f
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

    fn sample_glass(&self, wo: Vec3, u0: f32, u1: f32, u2: f32, p: f32, transport: Transport) -> Option<BsdfSample> {
        let scale = (1.0 - self.metallic) * self.transmission;
        if self.smooth() {
            let cos_o = wo.z;
            // The coat's share is alike for ω_o and the mirrored or passing ω_i (|cos| equal).
            let reflected = scale * self.coat_scale(wo, wo, transport);
            if self.thin {
                let r = slab_reflectance(fresnel_dielectric(cos_o.abs(), self.ior));
                return Some(if u0 < r {
                    BsdfSample { wi: mirror_z(-wo), weight: Vec3::splat(reflected / p), pdf: p * r, delta: true }
                } else {
                    BsdfSample { wi: -wo, weight: reflected * self.base / p, pdf: p * (1.0 - r), delta: true }
                });
            }
            let r = fresnel_dielectric(cos_o, self.ior);
            if u0 < r {
                return Some(BsdfSample {
                    wi: mirror_z(-wo),
                    weight: Vec3::splat(reflected / p),
                    pdf: p * r,
                    delta: true,
                });
            }
            let (wi, etap) = refract(wo, Vec3::Z, self.ior)?;
            let mut weight = scale * self.coat_scale(wo, wi, transport) * self.base / p;
            if transport == Transport::Radiance {
                weight /= etap * etap;
            }
            return Some(BsdfSample { wi, weight, pdf: p * (1.0 - r), delta: true });
        }
        let wi = if self.thin {
            let side = if wo.z < 0.0 { -1.0 } else { 1.0 };
            let o = wo * side;
            let h = vndf_sample(o, self.alpha, u1, u2);
            let ir = reflect(o, h);
            if ir.z <= 0.0 {
                return None;
            }
            let r = slab_reflectance(fresnel_dielectric(o.dot(h), self.ior));
            (if u0 < r { ir } else { mirror_z(ir) }) * side
        } else {
            let h = vndf_sample(wo, self.alpha, u1, u2);
            let r = fresnel_dielectric(wo.dot(h), self.ior);
            if u0 < r {
                let wi = reflect(wo, h);
                if wi.z * wo.z <= 0.0 {
                    return None;
                }
                wi
            } else {
                let (wi, _) = refract(wo, h, self.ior)?;
                if wi.z * wo.z >= 0.0 {
                    return None;
                }
                wi
            }
        };
        self.finish_sample(wo, wi, transport)
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
