//! Materials: the scattering model's parameters per surface, their textures and how a texture is
//! placed and read.

use glam::{Vec2, Vec3};

/// Most textures a scene may hold: one texture-array layer each, and 256 layers is what every
/// WebGPU device supports.
pub const MAX_TEXTURES: usize = 256;

/// An affine map of texture coordinates, (u', v') = (a·u + b·v + c, d·u + e·v + f), stored as
/// its two rows `[[a, b, c], [d, e, f]]`: a texture's placement (glTF `KHR_texture_transform`,
/// MTL `-o`/`-s`), in the scene's convention (v down the image).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvTransform(pub [[f32; 3]; 2]);

impl UvTransform {
    pub const IDENTITY: UvTransform = UvTransform([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);

    pub fn apply(&self, uv: Vec2) -> Vec2 {
        let [r, s] = self.0;
        Vec2::new(r[0] * uv.x + r[1] * uv.y + r[2], s[0] * uv.x + s[1] * uv.y + s[2])
    }

    /// `self` after `first`: uv ↦ self(first(uv)).
    pub fn after(&self, first: &UvTransform) -> UvTransform {
        let ([a, b, c], [d, e, f]) = (self.0[0], self.0[1]);
        let ([p, q, r], [s, t, w]) = (first.0[0], first.0[1]);
        UvTransform([
            [a * p + b * s, a * q + b * t, a * r + b * w + c],
            [d * p + e * s, d * q + e * t, d * r + e * w + f],
        ])
    }

    pub fn is_finite(&self) -> bool {
        self.0.iter().flatten().all(|x| x.is_finite())
    }
}

impl Default for UvTransform {
    fn default() -> Self {
        Self::IDENTITY
    }
}

/// A texture as a material reads it: an index into [`Scene::textures`](super::Scene::textures) and the placement of
/// the triangle's texture coordinates on it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TextureRef {
    pub texture: usize,
    pub transform: UvTransform,
}

impl TextureRef {
    pub fn new(texture: usize) -> TextureRef {
        TextureRef { texture, transform: UvTransform::IDENTITY }
    }
}

/// How a material's opacity α (its factor × its texture's alpha) cuts the surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// α is ignored: the surface is everywhere.
    Opaque,
    /// A cut-out: the surface is where α ≥ the cutoff, a hole elsewhere (glTF MASK).
    Mask { cutoff: f32 },
    /// Stochastic opacity (glTF BLEND, OBJ `d`/`map_d`): each ray, camera sample and photon
    /// meets the surface with probability α and passes through it otherwise, so every image is
    /// α × the surface + (1 − α) × what lies behind, in expectation (without sorting).
    Blend,
}

/// A Lambertian material with optional one-sided emission, opacity and a normal map.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    pub name: String,
    /// Diffuse albedo ρ in linear RGB; the BRDF is ρ/π. With a texture, ρ = albedo × texel.
    pub albedo: Vec3,
    /// Index into [`Scene::textures`](super::Scene::textures) of an albedo texture (sRGB, decoded to linear), read at
    /// the triangle's texture coordinates ([`Scene::uvs`](super::Scene::uvs)) placed by `albedo_transform`.
    pub albedo_texture: Option<usize>,
    pub albedo_transform: UvTransform,
    /// Radiance emitted from the front face, linear RGB; with a texture, Le = emission × texel.
    pub emission: Vec3,
    pub emission_texture: Option<TextureRef>,
    /// Opacity α = `opacity` × the alpha channel of `opacity_texture` (if any), used as
    /// `alpha_mode` says.
    pub opacity: f32,
    pub opacity_texture: Option<TextureRef>,
    pub alpha_mode: AlphaMode,
    /// A tangent-space normal map (linear RGB, glTF's convention: n = (2c − 1) scaled by
    /// (scale, scale, 1) in the frame (tangent, bitangent, shading normal)).
    pub normal_texture: Option<TextureRef>,
    pub normal_scale: f32,
    /// Whether the back face reflects too (it never emits).
    pub two_sided: bool,
    /// The scattering model's parameters ([`crate::bsdf::Bsdf`]): `albedo` is its base colour.
    /// glTF's metallic factor (× the blue channel of `metal_rough_texture`).
    pub metallic: f32,
    /// Perceptual roughness r (× the green channel of `metal_rough_texture`): GGX α = r².
    pub roughness: f32,
    /// glTF's `metallicRoughnessTexture` (linear): roughness in G, metallic in B.
    pub metal_rough_texture: Option<TextureRef>,
    /// Weight of the dielectric specular layer (`KHR_materials_specular`'s specularFactor):
    /// 1 for glTF materials, 0 for a plain Lambertian surface.
    pub specular: f32,
    /// The layer's colour at normal incidence (`KHR_materials_specular`'s
    /// specularColorFactor; [`crate::bsdf::Bsdf::specular_color`]): white by default.
    pub specular_color: Vec3,
    /// `KHR_materials_specular`'s specularTexture (linear, A × `specular`) and
    /// specularColorTexture (sRGB, RGB × `specular_color`).
    pub specular_texture: Option<TextureRef>,
    pub specular_color_texture: Option<TextureRef>,
    /// Index of refraction (`KHR_materials_ior`, MTL `Ni`).
    pub ior: f32,
    /// `KHR_materials_transmission`'s factor: the share of the dielectric that is glass.
    pub transmission: f32,
    /// `KHR_materials_transmission`'s transmissionTexture (linear, R × `transmission`).
    pub transmission_texture: Option<TextureRef>,
    /// Thin-walled glass (glTF transmission without `KHR_materials_volume`): no refraction.
    pub thin: bool,
    /// The attenuation coefficient σ (per unit length, per channel) inside solid glass
    /// (`KHR_materials_volume`: σ = −ln(attenuationColor)/attenuationDistance): light that
    /// crosses a length t of it is scaled by exp(−σt) (Beer–Lambert). Zero: clear. Read where
    /// the glass is a solid (not `thin`) and transmits; media do not nest.
    pub attenuation: Vec3,
    /// Rough metal with its multiple-scattering energy compensation ([`crate::bsdf`]); false:
    /// single scattering, the model of Mitsuba 3's `roughconductor` ([`Scene::single_scattering`](super::Scene::single_scattering)).
    pub multiple_scattering: bool,
    /// The clear coat's weight k (`KHR_materials_clearcoat`'s clearcoatFactor, MTL `Pc`; 0:
    /// none) and perceptual roughness (clearcoatRoughnessFactor, MTL `Pcr`; its GGX α is the
    /// square): a dielectric layer of η 1.5 over the rest ([`crate::bsdf`]).
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    /// clearcoatTexture (linear, R × `clearcoat`) and clearcoatRoughnessTexture (linear, G ×
    /// `clearcoat_roughness`).
    pub clearcoat_texture: Option<TextureRef>,
    pub clearcoat_roughness_texture: Option<TextureRef>,
}

impl Material {
    pub fn diffuse(name: &str, albedo: Vec3) -> Self {
        Self {
            name: name.to_owned(),
            albedo,
            albedo_texture: None,
            albedo_transform: UvTransform::IDENTITY,
            emission: Vec3::ZERO,
            emission_texture: None,
            opacity: 1.0,
            opacity_texture: None,
            alpha_mode: AlphaMode::Opaque,
            normal_texture: None,
            normal_scale: 1.0,
            two_sided: false,
            metallic: 0.0,
            roughness: 1.0,
            metal_rough_texture: None,
            specular: 0.0,
            specular_color: Vec3::ONE,
            specular_texture: None,
            specular_color_texture: None,
            ior: 1.5,
            transmission: 0.0,
            transmission_texture: None,
            thin: false,
            attenuation: Vec3::ZERO,
            multiple_scattering: true,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            clearcoat_texture: None,
            clearcoat_roughness_texture: None,
        }
    }

    /// The attenuation coefficient that applies inside this material ([`Self::attenuation`]
    /// where it is solid glass, else zero).
    pub fn medium(&self) -> Vec3 {
        if self.thin || self.transmission <= 0.0 { Vec3::ZERO } else { self.attenuation.max(Vec3::ZERO) }
    }

    /// Beer–Lambert along a segment of length `t` that ends on a surface of this material
    /// arriving along `d` at geometric normal `n`: exp(−σt) where the segment ran inside the
    /// solid it bounds (it meets the back face), else 1 (`segment_transmittance` in WGSL).
    pub fn segment_transmittance(&self, d: Vec3, n: Vec3, t: f32) -> Vec3 {
        let sigma = self.medium();
        if sigma == Vec3::ZERO || d.dot(n) <= 0.0 {
            return Vec3::ONE;
        }
        (-sigma * t).exp()
    }

    /// The scattering model with base colour `base` (the albedo × its texel) and the texels
    /// of its other textures at the point ([`Texels`]: ones without them).
    pub fn bsdf(&self, base: Vec3, t: &Texels) -> crate::bsdf::Bsdf {
        let r = (self.roughness * t.metal_rough.y).clamp(0.0, 1.0);
        crate::bsdf::Bsdf {
            base,
            metallic: (self.metallic * t.metal_rough.z).clamp(0.0, 1.0),
            alpha: r * r,
            specular: (self.specular * t.specular).clamp(0.0, 1.0),
            specular_color: self.specular_color * t.specular_color,
            ior: self.ior,
            transmission: (self.transmission * t.transmission).clamp(0.0, 1.0),
            thin: self.thin,
            multiple_scattering: self.multiple_scattering,
            clearcoat: (self.clearcoat * t.clearcoat).clamp(0.0, 1.0),
            clearcoat_alpha: (self.clearcoat_roughness * t.clearcoat_roughness).clamp(0.0, 1.0).powi(2),
        }
    }

    /// Whether eye and gather rays go on through it rather than stop (`surface_passes_rays` in
    /// WGSL, [`crate::passes::specular`]): no diffuse base, and perfectly specular — a smooth metal — or
    /// glass, rough or smooth; or one whose roughness a texture sets (a transmissionTexture only
    /// lowers the transmission below its factor, so the factor decides); not a smooth metal
    /// under a rough clear coat. Scenes with such materials get the eye's specular chains and
    /// the photon map's caustic twins.
    pub fn passes_rays(&self) -> bool {
        let opaque = (1.0 - self.metallic.clamp(0.0, 1.0)) * (1.0 - self.transmission);
        let rough_coat = self.clearcoat > 0.0
            && self.clearcoat_texture.is_none()
            && self.clearcoat_roughness.powi(2) >= crate::bsdf::SMOOTH_ALPHA
            && self.clearcoat_roughness_texture.is_none();
        opaque <= 0.0
            && (self.transmission > 0.0
                || ((self.roughness * self.roughness < crate::bsdf::SMOOTH_ALPHA
                    || self.metal_rough_texture.is_some())
                    && !rough_coat))
    }

    /// Whether it has a perfectly specular lobe besides others (polished plastic: a smooth
    /// specular layer over a diffuse base; a smooth, partly metallic surface): the eye's
    /// chains follow that lobe stochastically ([`crate::passes::specular`]). Or may have, where a
    /// texture sets the roughness; or a smooth clear coat (or one a texture may make smooth).
    pub fn has_delta_lobe(&self) -> bool {
        let smooth = self.roughness * self.roughness < crate::bsdf::SMOOTH_ALPHA || self.metal_rough_texture.is_some();
        let smooth_coat = self.clearcoat > 0.0
            && (self.clearcoat_roughness.powi(2) < crate::bsdf::SMOOTH_ALPHA
                || self.clearcoat_roughness_texture.is_some());
        smooth_coat || (smooth && (self.metallic > 0.0 || self.transmission > 0.0 || self.specular > 0.0))
    }

    /// Whether its BSDF reads the rough solid glass's albedo table (its energy compensation:
    /// glass, rough or roughened by a texture, solid, compensated).
    pub fn needs_glass_table(&self) -> bool {
        self.transmission > 0.0
            && !self.thin
            && self.multiple_scattering
            && (self.roughness * self.roughness >= crate::bsdf::SMOOTH_ALPHA || self.metal_rough_texture.is_some())
    }

    /// Whether it scatters as a plain Lambertian surface (f = ρ/π).
    pub fn is_lambertian(&self) -> bool {
        self.metallic == 0.0 && self.transmission == 0.0 && self.specular == 0.0 && self.clearcoat <= 0.0
    }

    pub fn is_emitter(&self) -> bool {
        self.emission.max_element() > 0.0
    }

    /// Whether some of the surface may let rays through.
    pub fn has_holes(&self) -> bool {
        match self.alpha_mode {
            AlphaMode::Opaque => false,
            AlphaMode::Mask { cutoff } => cutoff > 0.0 && (self.opacity < cutoff || self.opacity_texture.is_some()),
            AlphaMode::Blend => self.opacity < 1.0 || self.opacity_texture.is_some(),
        }
    }

    /// The textures the material reads.
    pub fn texture_refs(&self) -> impl Iterator<Item = TextureRef> + '_ {
        let albedo = self.albedo_texture.map(|texture| TextureRef { texture, transform: self.albedo_transform });
        albedo
            .into_iter()
            .chain(self.emission_texture)
            .chain(self.opacity_texture)
            .chain(self.normal_texture)
            .chain(self.metal_rough_texture)
            .chain(self.transmission_texture)
            .chain(self.specular_texture)
            .chain(self.specular_color_texture)
            .chain(self.clearcoat_texture)
            .chain(self.clearcoat_roughness_texture)
    }
}

/// What a material's textures other than the base colour's say at a point, each the factor its
/// texture multiplies (ones where it has none): the metallic-roughness texel (G roughness, B
/// metallic), transmissionTexture's R, specularTexture's A, specularColorTexture's RGB,
/// clearcoatTexture's R and clearcoatRoughnessTexture's G.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Texels {
    pub metal_rough: Vec3,
    pub transmission: f32,
    pub specular: f32,
    pub specular_color: Vec3,
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
}

impl Default for Texels {
    fn default() -> Self {
        Self {
            metal_rough: Vec3::ONE,
            transmission: 1.0,
            specular: 1.0,
            specular_color: Vec3::ONE,
            clearcoat: 1.0,
            clearcoat_roughness: 1.0,
        }
    }
}
