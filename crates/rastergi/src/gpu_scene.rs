//! The scene on the GPU: triangles in BVH order, materials, BVH nodes, the light table, the
//! environment map and the albedo textures with the triangles' texture coordinates, bound together as bind group 0 of
//! every pass that reads the scene (`gpu_scene.wgsl`).

use bytemuck::{Pod, Zeroable};
use glam::{Vec2, Vec3};

use crate::bvh::{Bvh, BvhNode};
use crate::error::Result;
use wgpu::util::DeviceExt;

use crate::environment::{Environment, GpuEnvironment};
use crate::gpu::{Gpu, storage_entry, uniform_entry};
use crate::lights::{LightEntry, LightTable};
use crate::scene::{Aabb, Scene};
use crate::textures::TextureArray;

/// `Triangle` in `gpu_scene.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuTriangle {
    pub v0: [f32; 3],
    pub material: u32,
    pub v1: [f32; 3],
    pub _pad0: u32,
    pub v2: [f32; 3],
    pub _pad1: u32,
}

/// `Material` in `gpu_scene.wgsl`. Bit 0 of `flags`: the back face reflects too. `texture`:
/// the layer of the albedo texture in the texture array, [`NO_TEXTURE`] for none.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub albedo: [f32; 3],
    pub flags: u32,
    pub emission: [f32; 3],
    pub texture: u32,
}

pub use crate::consts::{MATERIAL_TWO_SIDED, NO_TEXTURE};

/// A scene prepared for rendering: triangles permuted into BVH order, with the BVH and the
/// light table over them and the textures as the GPU samples them. CPU twins use this
/// directly; [`GpuScene`] uploads it.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    pub scene: Scene,
    pub bvh: Bvh,
    pub lights: LightTable,
    pub bounds: Aabb,
    pub textures: TextureArray,
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
        let bvh = Bvh { order: (0..scene.triangles.len() as u32).collect(), ..bvh };
        let lights = LightTable::new(&scene);
        let bounds = scene.bounds();
        let textures = TextureArray::new(&scene.textures);
        PreparedScene { scene, bvh, lights, bounds, textures }
    }

    /// Texture coordinates at barycentrics (b1, b2) of triangle `tri` (`surface_uv` in WGSL).
    pub fn uv_at(&self, tri: usize, b1: f32, b2: f32) -> Vec2 {
        match self.scene.uvs.get(tri) {
            Some(uv) => uv[0] * (1.0 - b1 - b2) + uv[1] * b1 + uv[2] * b2,
            None => Vec2::ZERO,
        }
    }

    /// The shading normal at barycentrics (b1, b2) of triangle `tri`: the corners' normals
    /// interpolated and normalised, turned into the geometric normal's hemisphere; the
    /// geometric normal where the triangle has none (`shading_normal` in WGSL).
    pub fn shading_normal_at(&self, tri: usize, b1: f32, b2: f32) -> Vec3 {
        let n = crate::scene::triangle_normal(&self.scene.triangles[tri]);
        let Some(c) = self.scene.normals.get(tri) else { return n };
        let v = c[0] * (1.0 - b1 - b2) + c[1] * b1 + c[2] * b2;
        if v.length() < 1e-6 {
            return n;
        }
        let v = v.normalize();
        if v.dot(n) >= 0.0 { v } else { -v }
    }

    /// The albedo at barycentrics (b1, b2) of triangle `tri`, its texture read at level of
    /// detail `lod`: the twin of `surface_at(…).albedo` in WGSL.
    pub fn albedo_at(&self, tri: usize, b1: f32, b2: f32, lod: f32) -> Vec3 {
        let m = self.scene.material_of(tri);
        match m.albedo_texture {
            Some(layer) => m.albedo * self.textures.sample(layer as u32, self.uv_at(tri, b1, b2), lod),
            None => m.albedo,
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

pub struct GpuScene {
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    pub triangle_count: u32,
    pub light_count: u32,
    pub bounds: Aabb,
    pub ray_epsilon: f32,
    pub emitted_power: Vec3,
    /// Σ area and Σ perimeter of the triangles (bounds on what a projection of them covers).
    pub total_area: f64,
    pub total_perimeter: f64,
}

impl GpuScene {
    /// Uploads `prepared`, after checking that its buffers fit the device (see [`crate::limits`]).
    pub fn new(gpu: &Gpu, prepared: &PreparedScene) -> Result<GpuScene> {
        let limits = gpu.device.limits();
        crate::limits::check_scene(&limits, &prepared.scene)?;
        crate::limits::check_bvh_nodes(&limits, prepared.bvh.nodes.len())?;
        let s = &prepared.scene;
        let triangles: Vec<GpuTriangle> = s
            .triangles
            .iter()
            .zip(&s.material_ids)
            .map(|(t, &m)| GpuTriangle {
                v0: t[0].into(),
                material: m,
                v1: t[1].into(),
                _pad0: 0,
                v2: t[2].into(),
                _pad1: 0,
            })
            .collect();
        let materials: Vec<GpuMaterial> = s
            .materials
            .iter()
            .map(|m| GpuMaterial {
                albedo: m.albedo.into(),
                flags: if m.two_sided { MATERIAL_TWO_SIDED } else { 0 },
                emission: m.emission.into(),
                texture: m.albedo_texture.map_or(NO_TEXTURE, |t| t as u32),
            })
            .collect();
        // One triangle's worth of zeros when the scene has no texture coordinates: a binding
        // cannot be empty, and `surface_uv` clamps its index into the buffer.
        let uvs: Vec<[f32; 2]> = if s.uvs.is_empty() {
            vec![[0.0; 2]; 3]
        } else {
            s.uvs.iter().flat_map(|t| t.map(|uv| uv.to_array())).collect()
        };
        // Nine zeros (one flat triangle) when the scene has no shading normals.
        let normals: Vec<f32> = if s.normals.is_empty() {
            vec![0.0; 9]
        } else {
            s.normals.iter().flat_map(|t| t.iter().flat_map(|n| n.to_array())).collect()
        };
        let (texture_view, sampler) = prepared.textures.upload(gpu);
        let lights: Vec<LightEntry> = prepared.lights.entries.clone();
        // A binding cannot be empty: one zero light where the scene has none.
        let mut punctual = prepared.lights.punctual.clone();
        if punctual.is_empty() {
            punctual.push(bytemuck::Zeroable::zeroed());
        }
        let nodes: &[BvhNode] = &prepared.bvh.nodes;
        let env = s.environment.as_deref();
        let env_data = env.map_or(vec![0.0f32; 4], Environment::gpu_data);
        crate::limits::check_storage_buffer(
            &limits,
            "the environment map",
            env_data.len() as u64,
            4,
            "use a smaller --env image",
        )?;
        let (disc_centre, disc_radius) = prepared.lights.disc;
        let env_uniform = GpuEnvironment::new(env, disc_centre, disc_radius, prepared.lights.environment_pmf);
        let none = wgpu::BufferUsages::empty();
        let buffers = [
            gpu.storage_buffer("scene triangles", bytemuck::cast_slice(&triangles), none),
            gpu.storage_buffer("scene materials", bytemuck::cast_slice(&materials), none),
            gpu.storage_buffer("scene bvh nodes", bytemuck::cast_slice(nodes), none),
            gpu.storage_buffer("scene lights", bytemuck::cast_slice(&lights), none),
            gpu.storage_buffer("scene texture coordinates", bytemuck::cast_slice(&uvs), none),
            gpu.storage_buffer("scene punctual lights", bytemuck::cast_slice(&punctual), none),
            gpu.storage_buffer("scene environment map", bytemuck::cast_slice(&env_data), none),
            gpu.storage_buffer("scene shading normals", bytemuck::cast_slice(&normals), none),
        ];
        let env_uniform_buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene environment"),
            contents: bytemuck::bytes_of(&env_uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let vis = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[
                storage_entry::<GpuTriangle>(0, vis, true),
                storage_entry::<GpuMaterial>(1, vis, true),
                storage_entry::<crate::bvh::BvhNode>(2, vis, true),
                storage_entry::<crate::lights::LightEntry>(3, vis, true),
                storage_entry::<[f32; 2]>(4, vis, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: vis,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2Array,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 6,
                    visibility: vis,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
                storage_entry::<crate::lights::PunctualLight>(7, vis, true),
                // The environment and the shading normals are read by compute passes only, and
                // hidden from the raster stages: lavapipe (Mesa 22.3) silently loses fragment
                // writes once a fragment stage sees 11 storage buffers (it reports 32): with
                // them visible, the fragment lists' gather lost 10 % of its estimates
                // (tests/gather.rs).
                storage_entry::<f32>(8, wgpu::ShaderStages::COMPUTE, true),
                uniform_entry::<GpuEnvironment>(9, wgpu::ShaderStages::COMPUTE),
                storage_entry::<[f32; 9]>(10, wgpu::ShaderStages::COMPUTE, true),
            ],
        });
        // The buffers' bindings, in the order of `buffers`.
        const BUFFER_BINDINGS: [u32; 8] = [0, 1, 2, 3, 4, 7, 8, 10];
        let mut entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .zip(BUFFER_BINDINGS)
            .map(|(b, binding)| wgpu::BindGroupEntry { binding, resource: b.as_entire_binding() })
            .collect();
        entries.push(wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&texture_view) });
        entries.push(wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::Sampler(&sampler) });
        entries.push(wgpu::BindGroupEntry { binding: 9, resource: env_uniform_buffer.as_entire_binding() });
        let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("scene"),
            layout: &layout,
            entries: &entries,
        });
        Ok(GpuScene {
            layout,
            bind_group,
            triangle_count: triangles.len() as u32,
            light_count: lights.len() as u32,
            bounds: prepared.bounds,
            ray_epsilon: prepared.ray_epsilon(),
            emitted_power: prepared.lights.power,
            total_area: s.triangles.iter().map(|t| crate::scene::triangle_area(t) as f64).sum(),
            total_perimeter: s
                .triangles
                .iter()
                .map(|t| (t[0].distance(t[1]) + t[1].distance(t[2]) + t[2].distance(t[0])) as f64)
                .sum(),
        })
    }
}
