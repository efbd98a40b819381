//! The scene on the GPU: triangles in BVH order, materials, BVH nodes and the light table,
//! bound together as bind group 0 of every pass that reads the scene (`gpu_scene.wgsl`).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::bvh::{Bvh, BvhNode};
use crate::gpu::{Gpu, buffer_bind_group, storage_entry};
use crate::lights::{LightEntry, LightTable};
use crate::scene::{Aabb, Scene};

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

/// `Material` in `gpu_scene.wgsl`. Bit 0 of `flags`: the back face reflects too.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GpuMaterial {
    pub albedo: [f32; 3],
    pub flags: u32,
    pub emission: [f32; 3],
    pub _pad: u32,
}

pub const MATERIAL_TWO_SIDED: u32 = 1;

/// A scene prepared for rendering: triangles permuted into BVH order, with the BVH and the
/// light table over them. CPU twins use this directly; [`GpuScene`] uploads it.
#[derive(Clone, Debug)]
pub struct PreparedScene {
    pub scene: Scene,
    pub bvh: Bvh,
    pub lights: LightTable,
    pub bounds: Aabb,
}

impl PreparedScene {
    pub fn new(scene: &Scene) -> PreparedScene {
        let bvh = Bvh::build(&scene.triangles);
        let mut scene = scene.clone();
        scene.triangles = bvh.permute(&scene.triangles);
        scene.material_ids = bvh.permute(&scene.material_ids);
        let bvh = Bvh { order: (0..scene.triangles.len() as u32).collect(), ..bvh };
        let lights = LightTable::new(&scene);
        let bounds = scene.bounds();
        PreparedScene { scene, bvh, lights, bounds }
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
}

impl GpuScene {
    pub fn new(gpu: &Gpu, prepared: &PreparedScene) -> GpuScene {
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
                _pad: 0,
            })
            .collect();
        let lights: Vec<LightEntry> = prepared.lights.entries.clone();
        let nodes: &[BvhNode] = &prepared.bvh.nodes;
        let none = wgpu::BufferUsages::empty();
        let buffers = [
            gpu.storage_buffer("scene triangles", bytemuck::cast_slice(&triangles), none),
            gpu.storage_buffer("scene materials", bytemuck::cast_slice(&materials), none),
            gpu.storage_buffer("scene bvh nodes", bytemuck::cast_slice(nodes), none),
            gpu.storage_buffer("scene lights", bytemuck::cast_slice(&lights), none),
        ];
        let vis = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT | wgpu::ShaderStages::COMPUTE;
        let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("scene"),
            entries: &[
                storage_entry(0, vis, true),
                storage_entry(1, vis, true),
                storage_entry(2, vis, true),
                storage_entry(3, vis, true),
            ],
        });
        let refs: Vec<&wgpu::Buffer> = buffers.iter().collect();
        let bind_group = buffer_bind_group(&gpu.device, "scene", &layout, &refs);
        GpuScene {
            layout,
            bind_group,
            triangle_count: triangles.len() as u32,
            light_count: lights.len() as u32,
            bounds: prepared.bounds,
            ray_epsilon: prepared.ray_epsilon(),
            emitted_power: prepared.lights.power,
        }
    }
}
