//! Final gather by ray casting: the nearest surface along ω from every visible point, found by
//! traversing the BVH in a compute shader (`gather_trace.wgsl`); the estimate is the raster
//! gather's ([`crate::gather`]). One dispatch per direction, no ray-view textures and no
//! read-back, so directions queue up without synchronisation. It is exact where the raster
//! gather quantises to ray-view texels, and costs O(log n) per pixel where rasterising costs
//! O(n) per layer; rasterization wins where fragment work is cheap and the scene shallow.

use crate::gather::{GatherInputs, GatherSetup};
use crate::gpu::{Gpu, dispatch_pixels, storage_entry, uint_texture_entry, uniform_entry};
use crate::profile::{Profiler, compute_pass};

pub struct TraceGather {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    profiler: Option<Profiler>,
}

impl TraceGather {
    pub fn new(gpu: &Gpu, setup: &GatherSetup) -> TraceGather {
        let device = &gpu.device;
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("gather trace"),
            entries: &[uniform_entry(0, c), uint_texture_entry(1, c), storage_entry(2, c, false)],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("gather trace"),
            layout: &layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: setup.uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&setup.gbuffer.view) },
                wgpu::BindGroupEntry { binding: 2, resource: setup.film.accumulation.as_entire_binding() },
            ],
        });
        let pipeline = setup.estimate_pipeline(device, "gather trace", include_str!("gather_trace.wgsl"), &layout);
        TraceGather { pipeline, bind_group, profiler: gpu.profiler.clone() }
    }

    /// Reads: scene, frame, G-buffer, photon map, gather uniforms. Adds to: the film's
    /// indirect component.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) {
        let mut pass = compute_pass(enc, self.profiler.as_ref(), "gather trace");
        dispatch_pixels(&mut pass, &self.pipeline, &inputs.groups(&self.bind_group), inputs.width, inputs.height);
    }
}
