//! Final gather by ray casting: the nearest surface along ω from every visible point, found by
//! traversing the BVH in a compute shader (`trace.wgsl`). One dispatch per iteration, no
//! ray-view textures and no read-back, so iterations queue up without synchronisation.
//!
//! * Shared directions: the uniforms' ω_k, each cast along whichever of ±ω_k lies above x
//!   (pdf 1/2π), the raster gathers' estimate (ρ_x/π)·L(h→x)·(n·w)·2π ([`super::estimator`]).
//! * Per-pixel directions ([`super::GatherDirections::PerPixel`]): pixel (x, y) takes the
//!   Owen-scrambled Sobol' points u_j = [`crate::sampling::sobol_owen_2d`]`(j, s_xy)`,
//!   j = first_index + k, s_xy = [`crate::sampling::pixel_seed`]`(key, x, y)`, and casts
//!   ω = [`crate::sampling::cosine_hemisphere`]`(n_x, u_j)` (pdf cos θ/π): estimate ρ_x·L(h→x).
//!
//! It is exact where the raster gather quantises to ray-view texels, and costs O(log n) per
//! pixel where rasterising costs O(n) per layer; rasterization wins where fragment work is
//! cheap and the scene shallow.

use super::Gather;
use super::estimator::{GatherInputs, GatherSetup, estimate_group, estimate_resources};
use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::profile::{Profiler, compute_pass};
use crate::gpu::{Gpu, dispatch_pixels};

pub struct TraceGather {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    profiler: Option<Profiler>,
}

/// The traced gather's bind group 2: the G-buffer read, the film written.
pub fn group() -> Group {
    estimate_group("gather trace", &[Slot::write::<[f32; 4]>(2, "film")])
}

impl TraceGather {
    pub fn new(gpu: &Gpu, setup: &GatherSetup, uniforms: &wgpu::Buffer) -> TraceGather {
        let device = &gpu.device;
        let (layout, bind_group) = group().layout_and_bind(
            device,
            &[
                estimate_resources(uniforms, setup.gbuffer).as_slice(),
                &[("film", setup.film.accumulation.as_entire_binding())],
            ]
            .concat(),
        );
        let pipeline = setup.estimate_pipeline(device, "gather trace", &[include_str!("trace.wgsl")], &layout);
        TraceGather { pipeline, bind_group, profiler: gpu.profiler.clone() }
    }
}

impl Gather for TraceGather {
    /// All the iteration's directions in one dispatch: the uniforms hold them all.
    fn encode(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) -> Result<()> {
        inputs.write_uniforms(gpu, 0);
        {
            let mut pass = compute_pass(enc, self.profiler.as_ref(), "gather trace");
            dispatch_pixels(&mut pass, &self.pipeline, &inputs.groups(&self.bind_group), inputs.width, inputs.rows);
        }
        Ok(())
    }
}
