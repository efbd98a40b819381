//! The dielectric lobe (glass): exact Fresnel, refraction, solid and thin glass, rough and
//! smooth, with the rough glass's energy compensation.

use glam::Vec3;

use super::*;

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
pub(super) fn slab_reflectance(r: f32) -> f32 {
    if r >= 1.0 { 1.0 } else { 2.0 * r / (1.0 + r) }
}

/// w refracted through the microfacet h (h on w's side or not) for the relative index `eta`
/// of the side h faces; with the relative index η' = η_t/η_i it used; None under total
/// internal reflection.
pub(super) fn refract(w: Vec3, h: Vec3, eta: f32) -> Option<(Vec3, f32)> {
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

impl Bsdf {
    /// Whether rough glass's lobes are scaled by 1/E_g of the direction the light leaves by
    /// (module docs).
    pub(super) fn glass_compensates(&self) -> bool {
        self.multiple_scattering && !self.smooth() && self.transmission > 0.0
    }

    /// The single-scattering albedo of white rough glass for flux arriving from `w`
    /// ([`albedo::GlassAlbedo`]: a solid from either side; a thin slab's is the reflection
    /// lobe's, E₁(|cos θ|), since it passes what it does not reflect along the mirrored lobe).
    /// A relative index below 1 is the same glass seen from inside (the renderers turn the
    /// frame towards the arriving ray and invert η there).
    pub(super) fn glass_single_albedo(&self, w: Vec3) -> f32 {
        if self.thin {
            ggx_albedo().at(w.z.abs(), self.alpha)[0]
        } else {
            let (eta, inside) = if self.ior < 1.0 { (1.0 / self.ior, w.z >= 0.0) } else { (self.ior, w.z < 0.0) };
            albedo::glass_albedo().at(w.z.abs(), self.alpha, eta, inside)
        }
    }

    /// A thin slab's pair (ω_o, ω_i) on ω_o's side: ω_o, ω_i reflected through the surface where
    /// it is transmitted, their half vector, whether ω_i is reflected, and the slab's
    /// reflectance R' at the half vector.
    pub(super) fn thin_pair(&self, wo: Vec3, wi: Vec3) -> (Vec3, Vec3, Vec3, bool, f32) {
        let (o, i) = if wo.z < 0.0 { (-wo, -wi) } else { (wo, wi) };
        let reflected = i.z > 0.0;
        let ir = if reflected { i } else { mirror_z(i) };
        let h = (o + ir).normalize();
        (o, ir, h, reflected, slab_reflectance(fresnel_dielectric(o.dot(h), self.ior)))
    }

    /// A solid's generalized half vector h (upper hemisphere) of (ω_o, ω_i) and the relative
    /// index η' of the refraction (1 for a reflection); None where no microfacet pairs them.
    pub(super) fn solid_half(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32)> {
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
    pub(super) fn glass_eval(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Vec3 {
        let f = self.glass_single_eval(wo, wi, transport);
        if !self.glass_compensates() || f == Vec3::ZERO {
            return f;
        }
        let view = if transport == Transport::Radiance { wo } else { wi };
        f / self.glass_single_albedo(view).max(1e-3)
    }

    /// Walter et al.'s single-scattering glass.
    pub(super) fn glass_single_eval(&self, wo: Vec3, wi: Vec3, transport: Transport) -> Vec3 {
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
    pub(super) fn glass_pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
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

    pub(super) fn sample_glass(
        &self,
        wo: Vec3,
        u0: f32,
        u1: f32,
        u2: f32,
        p: f32,
        transport: Transport,
    ) -> Option<BsdfSample> {
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
