//! The diffuse lobe: Lambertian reflection under the layers, the Lambertian stand-in the photon
//! map is read with, and the diffuse base's share beneath a specular layer.

use glam::Vec3;

use super::*;

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
    pub(super) fn diffuse_share(&self, cos_o: f32, cos_i: f32) -> Vec3 {
        if self.specular == 0.0 {
            return Vec3::ONE;
        }
        (Vec3::ONE - self.layer_albedo(cos_o)) * (Vec3::ONE - self.layer_albedo(cos_i))
            / (Vec3::ONE - self.layer_mean_albedo())
    }
}
