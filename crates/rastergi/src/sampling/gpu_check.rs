//! The GPU side of the sampler's tests: `sampling.wgsl`'s `sobol_owen_2d` run in a compute shader,
//! for the tests to hold against the Rust twin (`tests/gather.rs`).

use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu::binding::{Group, Slot};

/// [`sobol_owen_2d`](super::sobol_owen_2d) of each (index, seed) evaluated by its WGSL twin in a compute shader (for
/// tests: the two must agree bit for bit).
pub fn sobol_owen_on_gpu(gpu: &Gpu, queries: &[(u32, u32)]) -> Result<Vec<[u32; 2]>> {
    let device = &gpu.device;
    let input: Vec<[u32; 2]> = queries.iter().map(|&(i, s)| [i, s]).collect();
    let input = gpu.storage_buffer("sobol queries", bytemuck::cast_slice(&input), wgpu::BufferUsages::empty());
    let main = "
        @group(0) @binding(0) var<storage, read> queries: array<vec2u>;
        @group(0) @binding(1) var<storage, read_write> points: array<vec2u>;
        @compute @workgroup_size(64)
        fn main(@builtin(global_invocation_id) gid: vec3u) {
            if gid.x >= arrayLength(&queries) {
                return;
            }
            points[gid.x] = sobol_owen_2d(queries[gid.x].x, queries[gid.x].y);
        }";
    let source = crate::gpu::shader::compose(&[crate::gpu::shader::SAMPLING, main]);
    let module = crate::gpu::shader::module(device, "sobol points", &source);
    gpu.run_once_read(
        "sobol points",
        &module,
        &Group::compute("sobol points", &[Slot::read::<[u32; 2]>(0, "queries"), Slot::write::<[u32; 2]>(1, "points")]),
        &[("queries", input.as_entire_binding())],
        "points",
        queries.len(),
    )
}
