//! The CPU's view of a prepared scene: triangles in BVH order with the BVH, the light table and
//! the textures over them, and what a point on a surface is (texture coordinates, shading
//! normal, albedo, scattering model, emission, opacity): the CPU twins' surface queries.

use glam::{Vec2, Vec3, Vec4};

use crate::bvh::Bvh;
use crate::lights::LightTable;
use crate::scene::{Aabb, AlphaMode, Scene, TextureRef};
use crate::textures::TextureAtlas;

/// A scene prepared for rendering: triangles permuted into BVH order, with the BVH and the
/// light table over them and the textures as the GPU samples them. CPU twins use this
/// directly; [`GpuScene`](crate::gpu_scene::GpuScene) uploads it.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    pub scene: Scene,
    pub bvh: Bvh,
    pub lights: LightTable,
    pub bounds: Aabb,
    pub textures: TextureAtlas,
}

impl PreparedScene {
    pub fn new(scene: &Scene) -> PreparedScene {
        let bvh = Bvh::build(&scene.triangles);
        let mut scene = scene.clone();
        scene.triangles = bvh.permute(&scene.triangles);
        scene.material_ids = bvh.permute(&scene.material_ids);
        if !scene.uvs.is_empty() {
            scene.uvs = bvh.permute(&scene.uvs);
        }
        if !scene.normals.is_empty() {
            scene.normals = bvh.permute(&scene.normals);
        }
        if !scene.tangents.is_empty() {
            scene.tangents = bvh.permute(&scene.tangents);
        }
        let bvh = Bvh { order: (0..scene.triangles.len() as u32).collect(), ..bvh };
        let lights = LightTable::new(&scene);
        let bounds = scene.bounds();
        let textures = TextureAtlas::new(&scene.textures);
        PreparedScene { scene, bvh, lights, bounds, textures }
    }

    /// Texture coordinates at barycentrics (b1, b2) of triangle `tri` (`surface_uv` in WGSL).
    pub fn uv_at(&self, tri: usize, b1: f32, b2: f32) -> Vec2 {
        match self.scene.uvs.get(tri) {
            Some(uv) => uv[0] * (1.0 - b1 - b2) + uv[1] * b1 + uv[2] * b2,
            None => Vec2::ZERO,
        }
    }

    /// The shading normal at barycentrics (b1, b2) of triangle `tri` (`shading_normal` in
    /// WGSL): the corners' normals interpolated and normalised, turned into the geometric
    /// normal's hemisphere (the geometric normal where the triangle has none), then perturbed
    /// by the material's normal map, if any ([`perturb_normal`]).
    pub fn shading_normal_at(&self, tri: usize, b1: f32, b2: f32) -> Vec3 {
        let n = crate::scene::triangle_normal(&self.scene.triangles[tri]);
        let interpolated = self.scene.normals.get(tri).map(|c| c[0] * (1.0 - b1 - b2) + c[1] * b1 + c[2] * b2);
        let ns = match interpolated {
            Some(v) if v.length() >= 1e-6 => {
                let v = v.normalize();
                if v.dot(n) >= 0.0 { v } else { -v }
            }
            _ => n,
        };
        let m = self.scene.material_of(tri);
        let (Some(map), Some(t)) = (m.normal_texture, self.scene.tangents.get(tri)) else { return ns };
        let t = t[0] * (1.0 - b1 - b2) + t[1] * b1 + t[2] * b2;
        let texel = self.textures.sample(map.texture as u32, map.transform.apply(self.uv_at(tri, b1, b2)), 0.0);
        perturb_normal(n, ns, t, texel, m.normal_scale)
    }

    /// A texture of the material of `tri` read at barycentrics (b1, b2) and level of detail
    /// `lod` (linear RGBA).
    fn texel(&self, slot: TextureRef, tri: usize, b1: f32, b2: f32, lod: f32) -> Vec4 {
        self.textures.sample_rgba(slot.texture as u32, slot.transform.apply(self.uv_at(tri, b1, b2)), lod)
    }

    /// The albedo at barycentrics (b1, b2) of triangle `tri`, its texture read at level of
    /// detail `lod`: the twin of `surface_at(…).albedo` in WGSL.
    pub fn albedo_at(&self, tri: usize, b1: f32, b2: f32, lod: f32) -> Vec3 {
        let m = self.scene.material_of(tri);
        match m.albedo_texture {
            Some(texture) => {
                m.albedo
                    * self.texel(TextureRef { texture, transform: m.albedo_transform }, tri, b1, b2, lod).truncate()
            }
            None => m.albedo,
        }
    }

    /// The scattering model at barycentrics (b1, b2) of triangle `tri`, its albedo texture read
    /// at `lod` (`surface_bsdf(surface_at(…))` in WGSL).
    pub fn bsdf_at(&self, tri: usize, b1: f32, b2: f32, lod: f32) -> crate::bsdf::Bsdf {
        let m = self.scene.material_of(tri);
        let texel = |t: Option<TextureRef>| t.map(|t| self.texel(t, tri, b1, b2, 0.0));
        let texels = crate::scene::Texels {
            metal_rough: texel(m.metal_rough_texture).map_or(Vec3::ONE, |t| t.truncate()),
            transmission: texel(m.transmission_texture).map_or(1.0, |t| t.x),
            specular: texel(m.specular_texture).map_or(1.0, |t| t.w),
            specular_color: texel(m.specular_color_texture).map_or(Vec3::ONE, |t| t.truncate()),
            clearcoat: texel(m.clearcoat_texture).map_or(1.0, |t| t.x),
            clearcoat_roughness: texel(m.clearcoat_roughness_texture).map_or(1.0, |t| t.y),
        };
        m.bsdf(self.albedo_at(tri, b1, b2, lod), &texels)
    }

    /// The emitted radiance at barycentrics (b1, b2) of triangle `tri` (`surface_at(…).emission`).
    pub fn emission_at(&self, tri: usize, b1: f32, b2: f32) -> Vec3 {
        let m = self.scene.material_of(tri);
        match m.emission_texture {
            Some(t) => m.emission * self.texel(t, tri, b1, b2, 0.0).truncate(),
            None => m.emission,
        }
    }

    /// The radiance an emitter sends from barycentrics (b1, b2) of triangle `tri` as a light
    /// sample or a photon sees it: its emission there, nothing from a cut-out's hole, α × it
    /// on a stochastic surface (the expectation of meeting it). `emitter_radiance` in WGSL.
    pub fn emitter_radiance(&self, tri: usize, b1: f32, b2: f32) -> Vec3 {
        let le = self.emission_at(tri, b1, b2);
        match self.scene.material_of(tri).alpha_mode {
            AlphaMode::Opaque => le,
            AlphaMode::Mask { .. } if self.passes_through(tri, b1, b2, 0.0) => Vec3::ZERO,
            AlphaMode::Mask { .. } => le,
            AlphaMode::Blend => le * self.opacity_at(tri, b1, b2, 0.0),
        }
    }

    /// The opacity α at barycentrics (b1, b2) of triangle `tri`, its texture read at `lod`
    /// (`surface_opacity` in WGSL).
    pub fn opacity_at(&self, tri: usize, b1: f32, b2: f32, lod: f32) -> f32 {
        let m = self.scene.material_of(tri);
        m.opacity * m.opacity_texture.map_or(1.0, |t| self.texel(t, tri, b1, b2, lod).w)
    }

    /// Whether a ray meeting triangle `tri` at (b1, b2) passes through it (`passes_through`
    /// in WGSL): through a cut-out's holes (α < cutoff), through a stochastic surface when
    /// the uniform `u` ≥ α; never through an opaque one.
    pub fn passes_through(&self, tri: usize, b1: f32, b2: f32, u: f32) -> bool {
        match self.scene.material_of(tri).alpha_mode {
            AlphaMode::Opaque => false,
            AlphaMode::Mask { cutoff } => self.opacity_at(tri, b1, b2, 0.0) < cutoff,
            AlphaMode::Blend => u >= self.opacity_at(tri, b1, b2, 0.0),
        }
    }

    /// Distance used to offset ray origins and as the minimum hit distance: a small multiple
    /// of float precision at the scene's scale.
    pub fn ray_epsilon(&self) -> f32 {
        let b = self.bounds;
        let scale = b.min.abs().max(b.max.abs()).max_element().max(b.extent().max_element());
        1e-5 * scale.max(1e-3)
    }
}

/// A shading normal `ns` (unit, on the side of the geometric normal `n`) perturbed by a
/// normal-map texel (linear RGB c): with the tangent t (xyz interpolated, w the handedness)
/// made orthogonal to ns, t' = normalize(t − (ns·t) ns), and the bitangent b = w · ns × t',
/// the tangent-space normal m = (2c − 1) · (scale, scale, 1) gives
/// normalize(m.x t' + m.y b + m.z ns), bent into n's hemisphere where it falls below the
/// surface ([`crate::sampling::bend_towards`] towards n). Without a usable tangent ns is kept.
/// `perturb_normal` in WGSL.
pub fn perturb_normal(n: Vec3, ns: Vec3, t: Vec4, texel: Vec3, scale: f32) -> Vec3 {
    let tangent = t.truncate() - ns * ns.dot(t.truncate());
    if tangent.length_squared() < 1e-12 {
        return ns;
    }
    let tangent = tangent.normalize();
    let bitangent = ns.cross(tangent) * if t.w < 0.0 { -1.0 } else { 1.0 };
    let m = (2.0 * texel - Vec3::ONE) * Vec3::new(scale, scale, 1.0);
    let v = tangent * m.x + bitangent * m.y + ns * m.z;
    if v.length_squared() < 1e-12 {
        return ns;
    }
    crate::sampling::bend_towards(v.normalize(), n)
}

/// The uniform that decides whether a ray meeting triangle `tri` at (b1, b2) passes through a
/// stochastic surface, hashed from the point and the stream's `seed` (as in `passes_through`
/// in WGSL).
pub fn alpha_uniform(tri: u32, b1: f32, b2: f32, seed: u32) -> f32 {
    use crate::sampling::{pcg_hash, unit_f32};
    unit_f32(pcg_hash(pcg_hash(pcg_hash(tri ^ seed) ^ b1.to_bits()) ^ b2.to_bits()))
}
