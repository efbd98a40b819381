//! The scene model: triangles with Lambertian materials, area emitters and a pinhole camera.
//!
//! Every surface is Lambertian with albedo ρ (linear RGB) and may emit a constant radiance
//! `Le` from its front face. The front face of a triangle `(v0, v1, v2)` is the one its
//! counter-clockwise winding faces: its geometric normal is `normalize((v1-v0) × (v2-v0))`.
//! Emitters are one-sided. Reflection is one-sided too unless the material is `two_sided`
//! (a ray reaching the back of a one-sided surface is absorbed, as in Mitsuba 3's `diffuse`).
//! The albedo may vary over a surface: a material's constant albedo times an sRGB texture read
//! at the triangle's interpolated texture coordinates.

pub mod budget;
mod camera;
mod cornell;
pub mod default_camera;
pub mod export;
pub mod files;
pub mod generate;
mod gltf;
mod light;
mod material;
mod mitsuba;
mod obj;
pub mod sky;
mod sky_sun_table;
mod tangents;
mod texture;

pub use crate::bvh::bounds::Aabb;
pub use budget::{Budget, Budgets, parse_budget};
pub use camera::Camera;
pub use cornell::cornell_box;
pub use files::{Files, MemoryFiles};
pub use gltf::{GltfOptions, load_gltf, load_gltf_in, load_gltf_with};
pub use light::{Light, SunAngles};
pub use material::{AlphaMode, MAX_TEXTURES, Material, Texels, TextureRef, UvTransform};
pub use mitsuba::{MitsubaOptions, MitsubaScene, load_mitsuba, load_mitsuba_in};
pub use obj::{load_obj, load_obj_in, load_obj_with};
pub use tangents::mikktspace;
pub use texture::{MAX_DECODED_SIDE, Texture};

use glam::{Vec2, Vec3, Vec4};

use crate::error::{Error, Result};

/// The largest radiance (W/(m²·sr)), intensity (W/sr) or irradiance (W/m²) a scene may hold:
/// far above any light's (the sun's disc is about 2·10⁷ W/(m²·sr)), and far enough below
/// f32's 3.4·10³⁸ that what the passes make of it (powers, sums over photons, iterations and
/// pixels) stays finite.
pub const MAX_LIGHT: f32 = 1e20;

/// Checks that a radiance, intensity or irradiance (`what`, for the message) is finite, ≥ 0
/// and at most [`MAX_LIGHT`].
pub fn check_light(v: Vec3, what: &str) -> std::result::Result<(), String> {
    if !(v.is_finite() && v.min_element() >= 0.0) {
        Err(format!("{what} {v} is negative or not finite"))
    } else if v.max_element() > MAX_LIGHT {
        Err(format!(
            "{what} {v} is beyond {MAX_LIGHT:e}, the most rastergi renders (the sun's disc is about 2e7 W/(m²·sr))"
        ))
    } else {
        Ok(())
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

    /// Checks what every pass relies on: at least one triangle, finite coordinates within a
    /// finite extent, valid material indices, every number a material hands the GPU finite
    /// and in its range (albedo in [0, 1], emission within [`check_light`], an index of
    /// refraction > 0, roughness, metalness, transmission, specular and clear-coat weights in
    /// [0, 1], attenuation ≥ 0), lights within [`check_light`], a finite total emitted power,
    /// a valid camera.
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
        let b = self.bounds();
        if !(b.max - b.min).is_finite() {
            return Err(Error::InvalidScene(format!(
                "the scene's extent {} is beyond what 32-bit floats hold; scale it down",
                b.max - b.min
            )));
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
            check_light(m.emission, "emission")
                .map_err(|e| Error::InvalidScene(format!("material '{}': {e}", m.name)))?;
            let unit = [
                ("roughness", m.roughness),
                ("metallic", m.metallic),
                ("transmission", m.transmission),
                ("specular", m.specular),
                ("clearcoat", m.clearcoat),
                ("clearcoat roughness", m.clearcoat_roughness),
            ];
            if let Some((what, v)) = unit.iter().find(|(_, v)| !(0.0..=1.0).contains(v)) {
                return Err(Error::InvalidScene(format!("material '{}' has a {what} of {v}, outside [0, 1]", m.name)));
            }
            if !(m.ior.is_finite() && m.ior > 0.0) {
                return Err(Error::InvalidScene(format!(
                    "material '{}' has an index of refraction of {}; it must be a positive number",
                    m.name, m.ior
                )));
            }
            let ok = |v: Vec3| v.is_finite() && v.min_element() >= 0.0;
            if !ok(m.specular_color) || !ok(m.attenuation) {
                return Err(Error::InvalidScene(format!(
                    "material '{}' has a negative or non-finite specular colour ({}) or attenuation ({})",
                    m.name, m.specular_color, m.attenuation
                )));
            }
        }
        let power = self.emitted_power();
        if !power.is_finite() {
            return Err(Error::InvalidScene(format!(
                "the scene's emitters give a power of {power} W, beyond what 32-bit floats hold; lower their emission or the scene's size"
            )));
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
