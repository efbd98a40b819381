//! The layers: the specular layer of a dielectric over its diffuse base (its F₀ from the IOR and
//! the specular factors, its albedo) and the clear coat over everything, with the scale they
//! leave for what lies beneath.

use glam::Vec3;

use super::*;

impl Bsdf {
    pub(super) fn coat_smooth(&self) -> bool {
        self.clearcoat_alpha < SMOOTH_ALPHA
    }

    /// Whether a coat with a glossy (not perfectly specular) lobe lies on top.
    pub(super) fn rough_coat(&self) -> bool {
        self.clearcoat > 0.0 && !self.coat_smooth()
    }

    /// What the coat reflects in all for a direction at cosine `cos`, its directional albedo
    /// k·E_k(μ) = k(F₀E₁(μ, α_c) + (1 − F₀)E₅(μ, α_c)), F₀ = [`COAT_F0`]; kF_k(μ) when smooth.
    /// Zero without a coat.
    pub(super) fn coat_albedo(&self, cos: f32) -> f32 {
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
    pub(super) fn coat_scale(&self, wo: Vec3, wi: Vec3, transport: Transport) -> f32 {
        let view = if transport == Transport::Radiance { wo } else { wi };
        1.0 - self.coat_albedo(view.z)
    }

    /// The coat's glossy lobe k·F_k(ω_o·h)·D G₁ G₁/(4 cos θ_o cos θ_i), on ω_o's side; zero
    /// when smooth (a delta, sampled only) or absent.
    pub(super) fn coat_eval(&self, wo: Vec3, wi: Vec3) -> Vec3 {
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

    /// f₀ of the dielectric, ((η − 1)/(η + 1))².
    pub(super) fn ior_f0(&self) -> f32 {
        let r = (self.ior - 1.0) / (self.ior + 1.0);
        r * r
    }

    /// F₀ of the layer, min(f₀·colour, 1) per channel (`KHR_materials_specular`).
    pub(super) fn layer_f0(&self) -> Vec3 {
        (self.ior_f0() * self.specular_color).min(Vec3::ONE)
    }

    /// The layer's Fresnel weight s·F_s(cos), F_s = F₀ + (1 − F₀)(1 − cos)⁵.
    pub(super) fn layer_fresnel(&self, cos: f32) -> Vec3 {
        self.specular * schlick(self.layer_f0(), cos)
    }

    /// What the specular layer reflects in all for ω_o at cosine `cos`, its directional albedo
    /// E_L(μ) = s·(F₀E₁(μ, α) + (1 − F₀)E₅(μ, α)) ([`albedo`]) per channel; sF(μ) when smooth
    /// (a mirror reflects its Fresnel term).
    pub(super) fn layer_albedo(&self, cos: f32) -> Vec3 {
        if self.smooth() {
            return self.layer_fresnel(cos);
        }
        let f0 = self.layer_f0();
        let [e1, e5] = ggx_albedo().at(cos, self.alpha);
        self.specular * (f0 * e1 + (Vec3::ONE - f0) * e5)
    }

    /// The layer's cosine-weighted mean albedo Ē_L = 2∫E_L(μ)μ dμ; sF̄ = s(F₀ + (1 − F₀)/21)
    /// when smooth.
    pub(super) fn layer_mean_albedo(&self) -> Vec3 {
        let f0 = self.layer_f0();
        if self.smooth() {
            return self.specular * (f0 + (Vec3::ONE - f0) / 21.0);
        }
        let [m1, m5] = ggx_albedo().mean_at(self.alpha);
        self.specular * (f0 * m1 + (Vec3::ONE - f0) * m5)
    }

    /// f_base(ω_o, ω_i): the non-specular lobes under the coat.
    pub(super) fn eval_under_coat(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Vec3 {
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
}
