//! The GPU side of the twins' tests: `bsdf.wgsl` run on queries in a compute shader, for the
//! tests to hold against the Rust model (`tests/materials.rs`).

use super::{Bsdf, BsdfSample, Transport, albedo, ggx_albedo};
use glam::Vec3;

/// What the GPU twin (`bsdf.wgsl`) computes for one query: f, the density, and a sample.
#[derive(Clone, Copy, Debug)]
pub struct GpuAnswer {
    pub eval: Vec3,
    pub pdf: f32,
    pub sample: Option<BsdfSample>,
    /// `bsdf_lambertian_albedo(b, ω_o.z)`.
    pub lambertian_albedo: Vec3,
}

/// `bsdf_eval`, `bsdf_pdf` and `bsdf_sample` of `bsdf.wgsl` for each (model, ω_o, ω_i,
/// uniforms, transport), in a compute shader (for tests: the twins must agree).
pub fn on_gpu(
    gpu: &crate::gpu::Gpu,
    queries: &[(Bsdf, Vec3, Vec3, [f32; 3], Transport)],
) -> crate::Result<Vec<GpuAnswer>> {
    use crate::gpu::binding::{Group, Slot};
    let device = &gpu.device;
    let input: Vec<[f32; 25]> = queries
        .iter()
        .map(|(b, wo, wi, u, t)| {
            [
                b.base.x,
                b.base.y,
                b.base.z,
                b.metallic,
                b.alpha,
                b.specular,
                b.ior,
                b.transmission,
                if b.thin { 1.0 } else { 0.0 },
                wo.x,
                wo.y,
                wo.z,
                wi.x,
                wi.y,
                wi.z,
                u[0],
                u[1],
                u[2],
                if *t == Transport::Radiance { 0.0 } else { 1.0 },
                if b.multiple_scattering { 1.0 } else { 0.0 },
                b.specular_color.x,
                b.specular_color.y,
                b.specular_color.z,
                b.clearcoat,
                b.clearcoat_alpha,
            ]
        })
        .collect();
    let input = gpu.storage_buffer("bsdf queries", bytemuck::cast_slice(&input), wgpu::BufferUsages::empty());
    let table = gpu.storage_buffer(
        "bsdf ggx albedo",
        bytemuck::bytes_of(&*ggx_albedo().gpu(true)),
        wgpu::BufferUsages::empty(),
    );
    let main = "
        struct Query { v: array<f32, 25> }
        struct Answer { v: array<f32, 16> }
        @group(0) @binding(0) var<storage, read> queries: array<Query>;
        @group(0) @binding(1) var<storage, read_write> answers: array<Answer>;
        @group(0) @binding(2) var<storage, read> ggx_table: GgxAlbedoTable;
        fn ggx_cell(k: u32) -> vec4f { return ggx_table.cells[k]; }
        fn ggx_mean(j: u32) -> vec4f { return ggx_table.means[j]; }
        fn glass_cell(r: u32) -> f32 { return ggx_table.glass[r]; }
        @compute @workgroup_size(64)
        fn main(@builtin(global_invocation_id) gid: vec3u) {
            if gid.x >= arrayLength(&queries) {
                return;
            }
            let q = queries[gid.x].v;
            let b = Bsdf(vec3f(q[0], q[1], q[2]), q[3], q[4], q[5], vec3f(q[20], q[21], q[22]), q[6], q[7], q[8] > 0.5, q[19] > 0.5,
                q[23], q[24]);
            let wo = vec3f(q[9], q[10], q[11]);
            let wi = vec3f(q[12], q[13], q[14]);
            let t = u32(q[18]);
            let f = bsdf_eval(b, wo, wi, t);
            let s = bsdf_sample(b, wo, vec3f(q[15], q[16], q[17]), t);
            var a: array<f32, 16>;
            a[0] = f.x; a[1] = f.y; a[2] = f.z; a[3] = bsdf_pdf(b, wo, wi);
            a[4] = s.wi.x; a[5] = s.wi.y; a[6] = s.wi.z;
            a[7] = s.weight.x; a[8] = s.weight.y; a[9] = s.weight.z; a[10] = s.pdf;
            a[11] = select(0.0, 1.0, s.delta); a[12] = select(0.0, 1.0, s.ok);
            let la = bsdf_lambertian_albedo(b, wo.z);
            a[13] = la.x; a[14] = la.y; a[15] = la.z;
            answers[gid.x] = Answer(a);
        }";
    let source = crate::gpu::shader::compose(&[crate::gpu::shader::SAMPLING, crate::gpu::shader::BSDF, main]);
    let module = crate::gpu::shader::module(device, "bsdf", &source);
    let answers: Vec<[f32; 16]> = gpu.run_once_read(
        "bsdf",
        &module,
        &Group::compute(
            "bsdf",
            &[
                Slot::read::<[f32; 25]>(0, "queries"),
                Slot::write::<[f32; 16]>(1, "answers"),
                Slot::read::<albedo::GpuGgxAlbedo>(2, "ggx_table"),
            ],
        ),
        &[("queries", input.as_entire_binding()), ("ggx_table", table.as_entire_binding())],
        "answers",
        queries.len(),
    )?;
    Ok(answers
        .iter()
        .map(|a| GpuAnswer {
            eval: Vec3::new(a[0], a[1], a[2]),
            pdf: a[3],
            sample: (a[12] > 0.5).then(|| BsdfSample {
                wi: Vec3::new(a[4], a[5], a[6]),
                weight: Vec3::new(a[7], a[8], a[9]),
                pdf: a[10],
                delta: a[11] > 0.5,
            }),
            lambertian_albedo: Vec3::new(a[13], a[14], a[15]),
        })
        .collect())
}
