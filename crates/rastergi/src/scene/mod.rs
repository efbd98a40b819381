//! The scene model: triangles with Lambertian materials, area emitters and a pinhole camera.
//!
//! Every surface is Lambertian with albedo ρ (linear RGB) and may emit a constant radiance
//! `Le` from its front face. The front face of a triangle `(v0, v1, v2)` is the one its
//! counter-clockwise winding faces: its geometric normal is `normalize((v1-v0) × (v2-v0))`.
//! Emitters are one-sided. Reflection is one-sided too unless the material is `two_sided`
//! (a ray reaching the back of a one-sided surface is absorbed, as in Mitsuba 3's `diffuse`).
//! The albedo may vary over a surface: a material's constant albedo times an sRGB texture read
//! at the triangle's interpolated texture coordinates.

mod cornell;
pub mod default_camera;
pub mod export;
pub mod files;
pub mod generate;
mod gltf;
mod mitsuba;
mod obj;
mod tangents;
mod texture;

pub use cornell::cornell_box;
pub use files::{Files, MemoryFiles};
pub use gltf::{GltfOptions, load_gltf, load_gltf_in, load_gltf_with};
pub use mitsuba::{MitsubaOptions, MitsubaScene, load_mitsuba, load_mitsuba_in};
pub use obj::{load_obj, load_obj_in};
pub use tangents::mikktspace;
pub use texture::{MAX_DECODED_SIDE, Texture};

use glam::{Vec2, Vec3, Vec4};

use crate::error::{Error, Result};

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

/// A texture as a material reads it: an index into [`Scene::textures`] and the placement of
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
    /// Index into [`Scene::textures`] of an albedo texture (sRGB, decoded to linear), read at
    /// the triangle's texture coordinates ([`Scene::uvs`]) placed by `albedo_transform`.
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
    /// single scattering, the model of Mitsuba 3's `roughconductor` ([`Scene::single_scattering`]).
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

/// A pinhole camera. `fov_y_deg` is the full vertical field of view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    pub target: Vec3,
    pub up: Vec3,
    pub fov_y_deg: f32,
}

impl Camera {
    /// The camera's orthonormal frame: (right, up, forward), right-handed, looking along forward.
    pub fn frame(&self) -> (Vec3, Vec3, Vec3) {
        let forward = (self.target - self.eye).normalize();
        let right = forward.cross(self.up).normalize();
        let up = right.cross(forward);
        (right, up, forward)
    }

    /// Rejects cameras that define no view: coincident eye and target, an up vector along the
    /// view direction, non-finite values or a field of view outside (0, 180) degrees.
    pub fn validate(&self) -> Result<()> {
        let finite = self.eye.is_finite() && self.target.is_finite() && self.up.is_finite();
        let forward = self.target - self.eye;
        if !finite || forward.length_squared() <= 0.0 {
            return Err(Error::InvalidCamera("eye and target must be distinct finite points".into()));
        }
        if forward.normalize().cross(self.up).length_squared() < 1e-12 {
            return Err(Error::InvalidCamera("the up vector must not be parallel to the view direction".into()));
        }
        if !(self.fov_y_deg > 0.0 && self.fov_y_deg < 180.0) {
            return Err(Error::InvalidCamera(format!(
                "the field of view must lie strictly between 0 and 180 degrees, got {}",
                self.fov_y_deg
            )));
        }
        Ok(())
    }
}

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };

    pub fn grow(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    pub fn union(self, o: Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }

    pub fn extent(&self) -> Vec3 {
        (self.max - self.min).max(Vec3::ZERO)
    }

    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }

    /// Surface area (0 for an empty box).
    pub fn area(&self) -> f32 {
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
}

/// A sun's direction as `--sun`, the viewer and the web page turn it: degrees from +Z towards
/// +X about +Y (azimuth), and degrees above the XZ plane (elevation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunAngles {
    pub azimuth: f32,
    pub elevation: f32,
}

impl SunAngles {
    /// The angles of a distant light travelling along `direction`.
    pub fn of_direction(direction: Vec3) -> SunAngles {
        let towards = -direction.normalize();
        SunAngles {
            azimuth: towards.x.atan2(towards.z).to_degrees().rem_euclid(360.0),
            elevation: towards.y.clamp(-1.0, 1.0).asin().to_degrees(),
        }
    }

    /// The direction a sun at these angles shines along (as `--sun`).
    pub fn direction(self) -> Vec3 {
        let (a, e) = (self.azimuth.to_radians(), self.elevation.to_radians());
        -Vec3::new(a.sin() * e.cos(), e.sin(), a.cos() * e.cos())
    }
}

/// A light that is not a surface: glTF `KHR_lights_punctual` lights (values read 1:1 as
/// radiometric, as Mitsuba's `point`, `spot` and `directional` take them) and the sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Radiant intensity I (W/sr, RGB) from `position` into every direction: E = I cos θ / d².
    Point { position: Vec3, intensity: Vec3 },
    /// A point light within a cone about `direction` (unit, where it shines): intensity
    /// I · s(cos θ), s = clamp((cos θ − cos θ_o)/(cos θ_i − cos θ_o), 0, 1)² (glTF's smooth
    /// falloff between the inner and outer cone half-angles, radians, 0 ≤ θ_i ≤ θ_o ≤ π/2, θ_o > 0;
    /// equal angles are a hard-edged cone, as Blender exports a spot without blend).
    Spot { position: Vec3, direction: Vec3, intensity: Vec3, inner: f32, outer: f32 },
    /// Light from far away along `direction` (unit, the way it travels): irradiance E (W/m²,
    /// RGB) on a surface facing it, E cos θ on others, from a disc of `angular_radius` radians
    /// of uniform radiance (0: one direction; the sun's is 0.27°).
    Distant { direction: Vec3, irradiance: Vec3, angular_radius: f32 },
}

impl Light {
    /// Checks the values: finite, non-negative, unit directions, cone angles in order.
    pub fn validate(&self) -> std::result::Result<(), String> {
        let colour = |v: Vec3, what: &str| {
            if v.is_finite() && v.min_element() >= 0.0 {
                Ok(())
            } else {
                Err(format!("a light has a negative or non-finite {what} ({v})"))
            }
        };
        let unit = |d: Vec3| {
            if d.is_finite() && (d.length() - 1.0).abs() < 1e-3 {
                Ok(())
            } else {
                Err(format!("a light's direction {d} is not a unit vector"))
            }
        };
        let finite =
            |p: Vec3| if p.is_finite() { Ok(()) } else { Err(format!("a light's position {p} is not finite")) };
        match *self {
            Light::Point { position, intensity } => finite(position).and(colour(intensity, "intensity")),
            Light::Spot { position, direction, intensity, inner, outer } => {
                finite(position)?;
                unit(direction)?;
                colour(intensity, "intensity")?;
                if !(inner >= 0.0 && inner <= outer && outer > 0.0 && outer <= std::f32::consts::FRAC_PI_2 + 1e-6) {
                    return Err(format!(
                        "a spot light's cone angles (inner {inner}, outer {outer} radians) must satisfy 0 ≤ inner ≤ outer ≤ π/2 and outer > 0"
                    ));
                }
                Ok(())
            }
            Light::Distant { direction, irradiance, angular_radius } => {
                unit(direction)?;
                colour(irradiance, "irradiance")?;
                if !(0.0..=0.5).contains(&angular_radius) {
                    return Err(format!("a distant light's angular radius {angular_radius} rad is not in [0, 0.5]"));
                }
                Ok(())
            }
        }
    }
}

/// A triangle soup with one material per triangle, and its lights.
#[derive(Clone, Debug)]
pub struct Scene {
    /// Lights that are not surfaces (glTF punctual lights, the sun); emissive triangles are
    /// lights too.
    pub lights: Vec<Light>,
    /// Radiance from every direction at infinity (`--env`), if any.
    pub environment: Option<std::sync::Arc<crate::environment::Environment>>,
    /// Triangle corners, counter-clockwise about the front face.
    pub triangles: Vec<[Vec3; 3]>,
    /// Index into `materials` for each triangle.
    pub material_ids: Vec<u32>,
    pub materials: Vec<Material>,
    /// Texture coordinates of each triangle's corners, in the order of `triangles`: empty when
    /// no triangle has any, else one entry per triangle (zero where a triangle has none).
    pub uvs: Vec<[Vec2; 3]>,
    /// Shading normals at the triangles' corners (glTF NORMAL, OBJ vn), unit, in the order of
    /// `triangles`: empty when no triangle has any, else one entry per triangle (zero where a
    /// triangle has none: it shades with its geometric normal).
    pub normals: Vec<[Vec3; 3]>,
    /// Tangents at the triangles' corners for normal maps (glTF TANGENT, or MikkTSpace's): xyz
    /// a unit tangent along increasing u, w = ±1 the handedness (bitangent = w · n × t, glTF's
    /// convention); empty or one entry per triangle like `normals` (zero: none).
    pub tangents: Vec<[Vec4; 3]>,
    /// Textures, referred to by the materials.
    pub textures: Vec<Texture>,
    pub camera: Camera,
    /// The image its file frames (a Mitsuba film and sampler), if it says: what `render`
    /// makes when not told otherwise.
    pub framing: Option<Framing>,
}

/// The image a scene file frames: its film's size and its sample count per pixel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Framing {
    pub width: u32,
    pub height: u32,
    pub samples: Option<u32>,
}

impl Scene {
    pub fn new(camera: Camera) -> Self {
        Self {
            lights: Vec::new(),
            environment: None,
            triangles: Vec::new(),
            material_ids: Vec::new(),
            materials: Vec::new(),
            uvs: Vec::new(),
            normals: Vec::new(),
            tangents: Vec::new(),
            textures: Vec::new(),
            camera,
            framing: None,
        }
    }

    /// A 64-bit hash (XXH3) of everything that is rendered: geometry, shading normals,
    /// tangents, texture coordinates, materials, textures, lights, the sky and the camera. Two
    /// scenes with the same hash render the same image (checkpoints compare it); it is the
    /// same on every machine and build that reads the scene the same way.
    pub fn content_hash(&self) -> u64 {
        let mut h = xxhash_rust::xxh3::Xxh3::new();
        let mut section = |name: &str, bytes: &[u8]| {
            h.update(name.as_bytes());
            h.update(&(bytes.len() as u64).to_le_bytes());
            h.update(bytes);
        };
        section("triangles", bytemuck::cast_slice(&self.triangles));
        section("material ids", bytemuck::cast_slice(&self.material_ids));
        section("uvs", bytemuck::cast_slice(&self.uvs));
        section("normals", bytemuck::cast_slice(&self.normals));
        section("tangents", bytemuck::cast_slice(&self.tangents));
        // Materials, lights and the camera by their field values (f32s print exactly).
        section("materials", format!("{:?}", self.materials).as_bytes());
        section("lights", format!("{:?}", self.lights).as_bytes());
        section("camera", format!("{:?}", self.camera).as_bytes());
        for t in &self.textures {
            section("texture", format!("{} {}x{} {}", t.name, t.width, t.height, t.linear).as_bytes());
            section("texels", bytemuck::cast_slice(&t.texels));
        }
        if let Some(env) = &self.environment {
            section("environment", format!("{}x{}", env.width, env.height).as_bytes());
            section("sky", bytemuck::cast_slice(&env.texels));
        }
        h.digest()
    }

    /// Lights a scene that has no light of its own as glTF viewers light models: with
    /// [`crate::environment::Environment::neutral`], where it has no lights, no environment
    /// that gives light, and either no emissive surface or (`model`: a glTF file, whose
    /// emission is rarely meant to light it) only emissive surfaces. Returns what it found
    /// ("no lights", "no lights but its emissive surfaces") where it lit the scene.
    pub fn light_if_unlit(&mut self, model: bool) -> Option<&'static str> {
        let lit_by_env = self.environment.as_ref().is_some_and(|e| !e.is_dark());
        let emissive = !self.emissive_triangles().is_empty();
        if !self.lights.is_empty() || lit_by_env || (emissive && !model) {
            return None;
        }
        self.environment = Some(std::sync::Arc::new(crate::environment::Environment::neutral()));
        Some(if emissive { "no lights but its emissive surfaces" } else { "no lights" })
    }

    /// Every material without the rough metal's multiple-scattering compensation: the
    /// single-scattering model of Mitsuba 3's `roughconductor`, for comparisons with it.
    pub fn single_scattering(&mut self) {
        self.materials.iter_mut().for_each(|m| m.multiple_scattering = false);
    }

    /// Adds a material and returns its index.
    pub fn add_material(&mut self, material: Material) -> u32 {
        self.materials.push(material);
        (self.materials.len() - 1) as u32
    }

    pub fn add_triangle(&mut self, tri: [Vec3; 3], material: u32) {
        self.triangles.push(tri);
        self.material_ids.push(material);
        if !self.uvs.is_empty() {
            self.uvs.push([Vec2::ZERO; 3]);
        }
        if !self.normals.is_empty() {
            self.normals.push([Vec3::ZERO; 3]);
        }
        if !self.tangents.is_empty() {
            self.tangents.push([Vec4::ZERO; 3]);
        }
    }

    /// Gives the last triangle added the tangents `t` at its corners (see [`Scene::tangents`]).
    pub fn set_last_tangents(&mut self, t: [Vec4; 3]) {
        let count = self.triangles.len();
        self.tangents.resize(count, [Vec4::ZERO; 3]);
        self.tangents[count - 1] = t;
    }

    /// Adds a triangle with texture coordinates `uv` at its corners.
    pub fn add_textured_triangle(&mut self, tri: [Vec3; 3], uv: [Vec2; 3], material: u32) {
        self.add_triangle(tri, material);
        // The earlier triangles (and this one, if it is the first with any) get zeros first.
        self.uvs.resize(self.triangles.len(), [Vec2::ZERO; 3]);
        *self.uvs.last_mut().expect("the triangle's texture coordinates") = uv;
    }

    /// Gives the last triangle added the shading normals `n` at its corners (normalised;
    /// a zero or non-finite one makes the triangle shade flat).
    pub fn set_last_normals(&mut self, n: [Vec3; 3]) {
        let count = self.triangles.len();
        self.normals.resize(count, [Vec3::ZERO; 3]);
        // Unit vectors are kept bit for bit (an exported file loads back the same normals).
        let n = n.map(|v| if (v.length_squared() - 1.0).abs() < 1e-6 { v } else { v.normalize_or_zero() });
        self.normals[count - 1] = if n.iter().all(|v| *v != Vec3::ZERO) { n } else { [Vec3::ZERO; 3] };
    }

    /// Adds a texture and returns its index.
    pub fn add_texture(&mut self, texture: Texture) -> usize {
        self.textures.push(texture);
        self.textures.len() - 1
    }

    /// Adds the quad `a, b, c, d` (counter-clockwise about its front face) as two triangles.
    pub fn add_quad(&mut self, [a, b, c, d]: [Vec3; 4], material: u32) {
        self.add_triangle([a, b, c], material);
        self.add_triangle([a, c, d], material);
    }

    /// The direction of the scene's sun: its last distant light, which the viewer and the web
    /// page turn.
    pub fn sun(&self) -> Option<Vec3> {
        self.lights.iter().rev().find_map(|l| match l {
            Light::Distant { direction, .. } => Some(*direction),
            _ => None,
        })
    }

    /// Turns the scene's sun (its last distant light, if it has one) to `to`.
    pub fn turn_sun(&mut self, to: SunAngles) {
        if let Some(Light::Distant { direction, .. }) =
            self.lights.iter_mut().rev().find(|l| matches!(l, Light::Distant { .. }))
        {
            *direction = to.direction();
        }
    }

    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for t in &self.triangles {
            t.iter().for_each(|&p| b.grow(p));
        }
        b
    }

    pub fn material_of(&self, tri: usize) -> &Material {
        &self.materials[self.material_ids[tri] as usize]
    }

    /// The fraction of triangle `tri`'s surface that is there at barycentrics (b1, b2): 1 where
    /// it is opaque, 0 or 1 on a cut-out (α ≥ cutoff), α on a stochastic surface — the
    /// probability that a ray meeting it there stops. α is read from the image as decoded
    /// ([`Texture::alpha_at`]; the renderer reads its resampled twin).
    pub fn coverage_at(&self, tri: usize, b1: f32, b2: f32) -> f32 {
        let m = self.material_of(tri);
        if !m.has_holes() {
            return 1.0;
        }
        let alpha = m.opacity
            * m.opacity_texture.map_or(1.0, |t| {
                let uv = self.uvs.get(tri).map_or(Vec2::ZERO, |c| c[0] * (1.0 - b1 - b2) + c[1] * b1 + c[2] * b2);
                self.textures[t.texture].alpha_at(t.transform.apply(uv))
            });
        match m.alpha_mode {
            AlphaMode::Opaque => 1.0,
            AlphaMode::Mask { cutoff } => (alpha >= cutoff) as u32 as f32,
            AlphaMode::Blend => alpha,
        }
    }

    /// Indices of the triangles that emit light and have a non-zero area.
    pub fn emissive_triangles(&self) -> Vec<u32> {
        (0..self.triangles.len())
            .filter(|&i| self.material_of(i).is_emitter() && triangle_area(&self.triangles[i]) > 0.0)
            .map(|i| i as u32)
            .collect()
    }

    /// Total emitted power Φ = Σ π · Le · A over the emitters (one-sided Lambertian emission).
    pub fn emitted_power(&self) -> Vec3 {
        self.emissive_triangles()
            .iter()
            .map(|&i| {
                std::f32::consts::PI
                    * self.material_of(i as usize).emission
                    * triangle_area(&self.triangles[i as usize])
            })
            .sum()
    }

    /// Checks what every pass relies on: at least one triangle, finite coordinates, valid
    /// material indices, finite non-negative albedo and emission, a valid camera.
    pub fn validate(&self) -> Result<()> {
        if self.triangles.is_empty() {
            return Err(Error::InvalidScene("the scene has no triangles".into()));
        }
        if self.material_ids.len() != self.triangles.len() {
            return Err(Error::InvalidScene("one material index per triangle is required".into()));
        }
        if let Some(i) = self.triangles.iter().position(|t| !t.iter().all(|p| p.is_finite())) {
            return Err(Error::InvalidScene(format!("triangle {i} has a non-finite coordinate")));
        }
        if let Some(&m) = self.material_ids.iter().find(|&&m| m as usize >= self.materials.len()) {
            return Err(Error::InvalidScene(format!("material index {m} is out of range")));
        }
        if !self.uvs.is_empty() && self.uvs.len() != self.triangles.len() {
            return Err(Error::InvalidScene("texture coordinates must be given for every triangle or none".into()));
        }
        if let Some(i) = self.uvs.iter().position(|t| !t.iter().all(|uv| uv.is_finite())) {
            return Err(Error::InvalidScene(format!("triangle {i} has a non-finite texture coordinate")));
        }
        if !self.normals.is_empty() && self.normals.len() != self.triangles.len() {
            return Err(Error::InvalidScene("shading normals must be given for every triangle or none".into()));
        }
        if !self.tangents.is_empty() && self.tangents.len() != self.triangles.len() {
            return Err(Error::InvalidScene("tangents must be given for every triangle or none".into()));
        }
        if let Some(i) = self.tangents.iter().position(|t| !t.iter().all(|v| v.is_finite())) {
            return Err(Error::InvalidScene(format!("triangle {i} has a non-finite tangent")));
        }
        if self.textures.len() > MAX_TEXTURES {
            return Err(Error::InvalidScene(format!(
                "the scene has {} textures, more than the {MAX_TEXTURES} supported",
                self.textures.len()
            )));
        }
        for t in &self.textures {
            t.validate().map_err(Error::InvalidScene)?;
        }
        for l in &self.lights {
            l.validate().map_err(Error::InvalidScene)?;
        }
        for m in &self.materials {
            let ok = |v: Vec3| v.is_finite() && v.min_element() >= 0.0;
            if !ok(m.albedo) || !ok(m.emission) {
                return Err(Error::InvalidScene(format!(
                    "material '{}' has a negative or non-finite albedo or emission",
                    m.name
                )));
            }
            if let Some(t) = m.texture_refs().find(|t| t.texture >= self.textures.len()) {
                return Err(Error::InvalidScene(format!(
                    "material '{}' refers to texture {}, but the scene has {}",
                    m.name,
                    t.texture,
                    self.textures.len()
                )));
            }
            if !m.texture_refs().all(|t| t.transform.is_finite()) || !m.albedo_transform.is_finite() {
                return Err(Error::InvalidScene(format!("material '{}' has a non-finite texture transform", m.name)));
            }
            let cutoff_ok = match m.alpha_mode {
                AlphaMode::Mask { cutoff } => cutoff.is_finite() && cutoff >= 0.0,
                _ => true,
            };
            if !(0.0..=1.0).contains(&m.opacity) || !cutoff_ok || !m.normal_scale.is_finite() {
                return Err(Error::InvalidScene(format!(
                    "material '{}' has an opacity outside [0, 1], a negative alpha cutoff or a non-finite normal scale",
                    m.name
                )));
            }
            if m.albedo.max_element() > 1.0 {
                return Err(Error::InvalidScene(format!(
                    "material '{}' has an albedo above 1 ({}), which would create energy; scale it into [0, 1]",
                    m.name, m.albedo
                )));
            }
        }
        self.camera.validate()
    }

    /// A camera that frames the whole scene from its +z side, looking at the centre of its
    /// bounds with a 45° vertical field of view ([`Scene::default_camera`] keeps it where its
    /// view shows the scene).
    pub fn framing_camera(bounds: &Aabb) -> Camera {
        let fov_y_deg = 45.0f32;
        let radius = 0.5 * bounds.extent().length().max(1e-6);
        let distance = radius / (0.5 * fov_y_deg.to_radians()).sin();
        Camera { eye: bounds.center() + Vec3::Z * distance, target: bounds.center(), up: Vec3::Y, fov_y_deg }
    }
}

/// Area of a triangle.
pub fn triangle_area(t: &[Vec3; 3]) -> f32 {
    0.5 * (t[1] - t[0]).cross(t[2] - t[0]).length()
}

/// Geometric (front-face) normal of a triangle; zero for a degenerate one.
pub fn triangle_normal(t: &[Vec3; 3]) -> Vec3 {
    (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero()
}
