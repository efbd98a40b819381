//! Hardware ray queries (issue 48): which traversal the passes' rays take, and the
//! acceleration structures the hardware one walks.
//!
//! Every pass traces through one WGSL interface, `trace` / `occluded` in `bvh.wgsl`, over one
//! primitive, `traverse(o, d, t_min, t_max, skip_a, skip_b, skip_c, any_hit)`: the closest (or
//! any) triangle hit in the open interval (t_min, t_max) other than the three skipped, holes
//! or not. It has two implementations, chosen per pipeline when its module is composed
//! ([`crate::gpu::shader::for_rays`]):
//! * [`RayPath::Compute`]: `bvh_compute.wgsl`, the compressed 4-wide BVH walked by the compute
//!   shader (its CPU twin is `Bvh::intersect`);
//! * [`RayPath::Hardware`]: `bvh_hardware.wgsl`, a WGSL `ray_query` over a top-level
//!   acceleration structure ([`SceneAccel`]) with one instance (identity transform) of one
//!   bottom-level structure holding every triangle of the scene in the BVH's order, so that
//!   the query's `primitive_index` is the triangle index the rest of the code uses.
//!
//! The hardware traversal only proposes candidates: the geometry is built non-opaque
//! (no `OPAQUE` flag), so every candidate triangle comes back to the shader, which skips
//! `skip_a/b/c`, recomputes the intersection with the same Möller–Trumbore test as the compute
//! path (`intersect_triangle`) and commits it where that test accepts t ∈ (t_min, best t).
//! Both paths therefore report bit-identical t, b1, b2 for the same triangle; they can differ
//! only on rays that graze an edge, where the hardware's watertight test and Möller–Trumbore
//! round differently (counted as the CPU twin's comparison counts them, `rays::disagreements`).
//! Alpha holes stay with `trace`, shared by both paths: a hit on a hole re-traverses past it.

use crate::error::Result;
/// The choice of traversal and the device's ray-query support live with the device
/// ([`crate::gpu`]); re-exported here, where the traversals are.
pub use crate::gpu::{FEATURE, Rays, device_has_ray_queries, not_offered, parse_rays};

/// The traversal a scene's pipelines are built with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayPath {
    Compute,
    Hardware,
}

impl RayPath {
    pub fn name(self) -> &'static str {
        match self {
            RayPath::Compute => "compute",
            RayPath::Hardware => "hardware",
        }
    }
}

/// The scene's acceleration structures: one BLAS of every triangle, one TLAS with one
/// instance of it.
pub struct SceneAccel {
    pub tlas: wgpu::Tlas,
    /// Kept alive with the TLAS that refers to it.
    pub blas: wgpu::Blas,
    /// Device memory of the BLAS and the TLAS, bytes, from wgpu's allocator report; `None`
    /// where the backend gives none (the build's scratch memory is freed after it).
    pub memory: Option<u64>,
    /// Wall-clock time of the build, submission to completion, seconds.
    pub build_seconds: f64,
}

const BLAS_LABEL: &str = "scene blas";
const TLAS_LABEL: &str = "scene tlas";

/// The TLAS's binding in the scene's group (`gpu_scene::group`).
pub const TLAS_BINDING: u32 = 15;

/// Builds the acceleration structures over `triangles`, the scene's triangle buffer
/// (`GpuTriangle`: v0, v1, v2 each a vec3 in its own 16 bytes, 48 bytes a triangle, made with
/// `BLAS_INPUT`): read as `3 · count` vertices of stride 16, not indexed, vertex 3k + j is
/// corner j of triangle k, so primitive k is triangle k. Blocks until the build has finished.
pub fn build(gpu: &crate::gpu::Gpu, triangles: &wgpu::Buffer, count: u32) -> Result<SceneAccel> {
    let device = &gpu.device;
    let start = web_time::Instant::now();
    let size = wgpu::BlasTriangleGeometrySizeDescriptor {
        vertex_format: wgpu::VertexFormat::Float32x3,
        vertex_count: 3 * count,
        index_format: None,
        index_count: None,
        // Not OPAQUE: every candidate is offered to the shader (module docs).
        flags: wgpu::AccelerationStructureGeometryFlags::empty(),
    };
    let blas = device.create_blas(
        &wgpu::CreateBlasDescriptor {
            label: Some(BLAS_LABEL),
            flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
            update_mode: wgpu::AccelerationStructureUpdateMode::Build,
        },
        wgpu::BlasGeometrySizeDescriptors::Triangles { descriptors: vec![size.clone()] },
    );
    let mut tlas = device.create_tlas(&wgpu::CreateTlasDescriptor {
        label: Some(TLAS_LABEL),
        max_instances: 1,
        flags: wgpu::AccelerationStructureFlags::PREFER_FAST_TRACE,
        update_mode: wgpu::AccelerationStructureUpdateMode::Build,
    });
    // The identity transform, row-major 3 × 4; mask 0xff (every ray sees it).
    let identity = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0];
    tlas[0] = Some(wgpu::TlasInstance::new(&blas, identity, 0, 0xff));
    let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("scene accel") });
    enc.build_acceleration_structures(
        [&wgpu::BlasBuildEntry {
            blas: &blas,
            geometry: wgpu::BlasGeometries::TriangleGeometries(vec![wgpu::BlasTriangleGeometry {
                size: &size,
                vertex_buffer: triangles,
                first_vertex: 0,
                vertex_stride: 16,
                index_buffer: None,
                first_index: None,
                transform_buffer: None,
                transform_buffer_offset: None,
            }]),
        }],
        [&tlas],
    );
    gpu.queue.submit([enc.finish()]);
    gpu.wait()?;
    let build_seconds = start.elapsed().as_secs_f64();
    // The allocations of the two structures by their labels (the build's scratch is freed by
    // now; the TLAS's instance buffer, wgpu's own, holds 64 bytes an instance).
    let memory = device
        .generate_allocator_report()
        .map(|r| r.allocations.iter().filter(|a| a.name == BLAS_LABEL || a.name == TLAS_LABEL).map(|a| a.size).sum());
    Ok(SceneAccel { tlas, blas, memory, build_seconds })
}
