//! Eye pass: rasterizes the scene from the camera (jittered per iteration) into a visibility
//! G-buffer. Each pixel stores `(triangle + 1, b1, b2, λ)` — 0 where nothing is seen — from
//! which later passes reconstruct the visible point exactly (`surface_at` in WGSL): position
//! by barycentric interpolation, geometric normal, material. λ is the albedo texture's level
//! of detail over the pixel's footprint, log2 of the texture coordinates' screen-space change
//! in texels (`texture_lod`), so that the passes read the texture filtered like a fragment
//! shader would.

use crate::error::Result;
use crate::film::Film;
use crate::frame::FrameBinding;
use crate::gpu::{Gpu, storage_entry, uint_texture_entry};
use crate::gpu_scene::GpuScene;
use crate::shader;

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
    profiler: Option<crate::profile::Profiler>,
}

impl GBufferPass {
    pub fn new(gpu: &Gpu, scene: &GpuScene, frame: &FrameBinding, width: u32, height: u32) -> Self {
        let device = &gpu.device;
        let module = shader::module(device, "gbuffer", &source());
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("gbuffer"),
            bind_group_layouts: &[Some(&scene.layout), Some(&frame.layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("gbuffer"),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                // Reversed Z: nearer is larger.
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(FORMAT.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
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
        let size = self.texture.size();
        let (w, h) = (size.width, size.height);
        let row = (w * 16).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = gpu.zeroed_buffer(
            "gbuffer readback",
            (row * h) as u64,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            self.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(h) },
            },
            size,
        );
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.read_buffer(&buffer, buffer.size())?;
        let mut out = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            let r: &[[u32; 4]] = bytemuck::cast_slice(&bytes[y * row as usize..y * row as usize + w as usize * 16]);
            out.extend_from_slice(r);
        }
        Ok(out)
    }
}

/// Layout of a per-pixel pass's own group: the G-buffer (binding 0) and the film (binding 1).
pub fn gbuffer_film_layout(device: &wgpu::Device, label: &str) -> wgpu::BindGroupLayout {
    device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[
            uint_texture_entry(0, wgpu::ShaderStages::COMPUTE),
            storage_entry::<[f32; 4]>(1, wgpu::ShaderStages::COMPUTE, false),
        ],
    })
}

pub fn gbuffer_film_bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    gbuffer: &GBufferPass,
    film: &Film,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some(label),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&gbuffer.view) },
            wgpu::BindGroupEntry { binding: 1, resource: film.accumulation.as_entire_binding() },
        ],
    })
}
