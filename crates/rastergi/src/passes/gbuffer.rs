//! Eye pass: rasterizes the scene from the camera (jittered per iteration) into a visibility
//! G-buffer. Each pixel stores `(triangle + 1, b1, b2, λ)` — 0 where nothing is seen — from
//! which later passes reconstruct the visible point exactly (`surface_at` in WGSL): position
//! by barycentric interpolation, geometric normal, material. λ is the albedo texture's level
//! of detail over the pixel's footprint, log2 of the texture coordinates' screen-space change
//! in texels (`texture_lod`), so that the passes read the texture filtered like a fragment
//! shader would.

use crate::error::Result;
use crate::gpu::profile::{Profiler, compute_pass};
use crate::gpu::shader;
use crate::gpu::{
    Gpu, bind_group, bind_group_layout, dispatch_pixels, scene_raster_pipeline, storage_entry, uint_texture_entry,
};
use crate::gpu_scene::GpuScene;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;

/// The pass's composed shader.
pub fn source() -> String {
    shader::with_scene(include_str!("gbuffer.wgsl"))
}

pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

pub struct GBufferPass {
    pipeline: wgpu::RenderPipeline,
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    profiler: Option<crate::gpu::profile::Profiler>,
}

impl GBufferPass {
    pub fn new(gpu: &Gpu, scene: &GpuScene, frame: &FrameBinding, width: u32, height: u32) -> Self {
        let device = &gpu.device;
        let module = shader::module(device, "gbuffer", &source());
        let layouts = [&scene.layout, &frame.layout];
        // Reversed Z: the nearest surface has the largest depth.
        let pipeline =
            scene_raster_pipeline(device, "gbuffer", (&module, &layouts), "fs_main", FORMAT.into(), Some(DEPTH_FORMAT));
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("gbuffer"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let depth = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("gbuffer depth"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: DEPTH_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let depth_view = depth.create_view(&Default::default());
        Self { pipeline, texture, view, depth_view, profiler: gpu.profiler.clone() }
    }

    /// Reads: scene, frame. Writes: the G-buffer.
    pub fn encode(&self, enc: &mut wgpu::CommandEncoder, scene: &GpuScene, frame: &FrameBinding) {
        let mut pass = enc.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("gbuffer"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &self.depth_view,
                depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Discard }),
                stencil_ops: None,
            }),
            timestamp_writes: self.profiler.as_ref().and_then(|p| p.render("gbuffer")),
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.bind_group, &[]);
        pass.set_bind_group(1, &frame.bind_group, &[]);
        pass.draw(0..3 * scene.triangle_count, 0..1);
    }

    /// Raw texels `(triangle + 1, b1 bits, b2 bits, texture level of detail bits)`, row by row
    /// (for tests and tools).
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<[u32; 4]>> {
        Ok(bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.texture, 16)?))
    }
}

/// The WGSL of a [`PixelPass`]'s bind group 2 (`gbuffer`, `film`).
pub const GBUFFER_FILM_WGSL: &str = include_str!("gbuffer_film.wgsl");

/// A compute pass run once per eye pixel, in 8×8 workgroups (`begin_pixel` in `frame.wgsl`):
/// bind group 0 is the scene, 1 the frame, 2 the G-buffer and the film (`gbuffer_film.wgsl`),
/// 3, … whatever else its shader declares. The direct light, the specular chains, the photon
/// view and the caustic term are such passes.
pub struct PixelPass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    profiler: Option<Profiler>,
    label: &'static str,
}

/// A [`PixelPass`]'s shader: the composed `source`, its entry point `entry`, and the label of
/// its pipeline and of its timings (`--profile`).
pub struct PixelShader<'a> {
    pub label: &'static str,
    pub source: &'a str,
    pub entry: &'a str,
}

impl PixelPass {
    /// `more_layouts`: the layouts of bind groups 3, … of `shader`.
    pub fn new(
        gpu: &Gpu,
        (scene, frame): (&GpuScene, &FrameBinding),
        (gbuffer, film): (&GBufferPass, &Film),
        shader: PixelShader,
        more_layouts: &[&wgpu::BindGroupLayout],
    ) -> PixelPass {
        let device = &gpu.device;
        let label = shader.label;
        let module = scene.module(device, label, shader.source);
        let layout = bind_group_layout(
            device,
            label,
            &[
                uint_texture_entry(0, wgpu::ShaderStages::COMPUTE),
                storage_entry::<[f32; 4]>(1, wgpu::ShaderStages::COMPUTE, false),
            ],
        );
        let resources = [wgpu::BindingResource::TextureView(&gbuffer.view), film.accumulation.as_entire_binding()];
        let bind_group = bind_group(device, label, &layout, &resources);
        let layouts: Vec<&wgpu::BindGroupLayout> =
            [&scene.layout, &frame.layout, &layout].into_iter().chain(more_layouts.iter().copied()).collect();
        let pipeline = scene.compute_pipeline(device, label, &module, shader.entry, &layouts);
        PixelPass { pipeline, bind_group, profiler: gpu.profiler.clone(), label }
    }

    /// Runs the pass over a `width × height` image; `more_groups`: bind groups 3, ….
    pub fn encode(
        &self,
        enc: &mut wgpu::CommandEncoder,
        (scene, frame): (&GpuScene, &FrameBinding),
        more_groups: &[&wgpu::BindGroup],
        width: u32,
        height: u32,
    ) {
        let mut pass = compute_pass(enc, self.profiler.as_ref(), self.label);
        let groups: Vec<&wgpu::BindGroup> = [&scene.bind_group, &frame.bind_group, &self.bind_group]
            .into_iter()
            .chain(more_groups.iter().copied())
            .collect();
        dispatch_pixels(&mut pass, &self.pipeline, &groups, width, height);
    }
}
