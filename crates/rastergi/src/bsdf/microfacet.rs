//! GGX microfacets: the distribution, Smith's masking, visible-normal sampling, Schlick's
//! Fresnel term, and the conductor's multiple-scattering compensation (the metal lobe).

use glam::Vec3;

use super::*;

pub(super) fn schlick_weight(cos: f32) -> f32 {
    let m = (1.0 - cos).clamp(0.0, 1.0);
    let m2 = m * m;
    m2 * m2 * m
}

/// Schlick's Fresnel with reflectance f₀ at normal incidence and 1 at grazing.
pub fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    f0 + (Vec3::ONE - f0) * schlick_weight(cos)
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

pub(super) fn reflect(w: Vec3, h: Vec3) -> Vec3 {
    2.0 * w.dot(h) * h - w
}

pub(super) fn mirror_z(w: Vec3) -> Vec3 {
    Vec3::new(w.x, w.y, -w.z)
}

impl Bsdf {
    /// Whether the metal lobe has its multiple-scattering lobe (module docs): compensated,
    /// rough and partly metallic.
    pub(super) fn compensates(&self) -> bool {
        self.multiple_scattering && !self.smooth() && self.metallic > 0.0
    }

    /// F_ms = F̄²Ē/(1 − F̄(1 − Ē)) of the multiple-scattering lobe, F̄ = c + (1 − c)/21 and
    /// Ē = Ē₁(α): the albedo it adds is F_ms·(1 − E₁(μ_o)). Zero where it is off.
    pub(super) fn ms_fresnel(&self) -> Vec3 {
        if !self.compensates() {
            return Vec3::ZERO;
        }
        let e_avg = ggx_albedo().mean_at(self.alpha)[0];
        let f_avg = self.base + (Vec3::ONE - self.base) / 21.0;
        f_avg * f_avg * e_avg / (Vec3::ONE - f_avg * (1.0 - e_avg))
    }

    /// 1 − E₁(μ, α): what single scattering loses for a direction at cosine `cos`.
    pub(super) fn ms_loss(&self, cos: f32) -> f32 {
        (1.0 - ggx_albedo().at(cos, self.alpha)[0]).max(0.0)
    }

    /// M_ms(ω_o, ω_i) = F_ms(1 − E₁(μ_o))(1 − E₁(μ_i)) / (π(1 − Ē₁)), for cosines on the lobe's side.
    pub(super) fn ms_eval(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        if !self.compensates() {
            return Vec3::ZERO;
        }
        let e_avg = ggx_albedo().mean_at(self.alpha)[0];
        self.ms_fresnel()
            * (self.ms_loss(cos_o) * self.ms_loss(cos_i) / (std::f32::consts::PI * (1.0 - e_avg).max(1e-6)))
    }
}
