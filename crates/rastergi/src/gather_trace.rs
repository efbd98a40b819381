//! Final gather by ray casting: the nearest surface along ω from every visible point, found by
//! traversing the BVH in a compute shader (`gather_trace.wgsl`); the estimate is the raster
//! gather's ([`crate::gather`]). One dispatch per direction, no ray-view textures and no
//! read-back, so directions queue up without synchronisation. It is exact where the raster
//! gather quantises to ray-view texels, and costs O(log n) per pixel where rasterising costs
//! O(n) per layer; rasterization wins where fragment work is cheap and the scene shallow.

use crate::film::Film;
use crate::frame::FrameBinding;
use crate::gbuffer::GBufferPass;
use crate::gpu::{Gpu, compute_pipeline, dispatch_pixels, storage_entry, uint_texture_entry, uniform_entry};
use crate::gpu_scene::GpuScene;
use crate::photons::gpu::GpuPhotonMap;
use crate::profile::{Profiler, compute_pass};
use crate::shader;

pub struct TraceGather {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    profiler: Option<Profiler>,
}

impl TraceGather {
    /// `uniforms` holds [`crate::gather::GatherUniforms`].
    pub fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        frame: &FrameBinding,
        gbuffer: &GBufferPass,
        film: &Film,
        map: &GpuPhotonMap,
        uniforms: &wgpu::Buffer,
    ) -> TraceGather {
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
                wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&gbuffer.view) },
                wgpu::BindGroupEntry { binding: 2, resource: film.accumulation.as_entire_binding() },
            ],
        });
        let source = shader::with_scene(
            &[include_str!("photon_map.wgsl"), include_str!("gather.wgsl"), include_str!("gather_trace.wgsl")]
                .join("\n"),
        );
        let module = shader::module(device, "gather trace", &source);
        let pipeline = compute_pipeline(
            device,
            "gather trace",
            &module,
            "main",
            &[&scene.layout, &frame.layout, &layout, &map.layout],
        );
        TraceGather { pipeline, bind_group, profiler: gpu.profiler.clone() }
    }

    /// Reads: scene, frame, G-buffer, photon map, gather uniforms. Adds to: the film's
    /// indirect component.
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        scene: &GpuScene,
        frame: &FrameBinding,
        map: &GpuPhotonMap,
        width: u32,
        height: u32,
    ) {
        let mut pass = compute_pass(enc, self.profiler.as_ref(), "gather trace");
        let bind_groups = [&scene.bind_group, &frame.bind_group, &self.bind_group, &map.bind_group];
        dispatch_pixels(&mut pass, &self.pipeline, &bind_groups, width, height);
    }
}
