//! Eye pass: rasterizes the scene from the camera (jittered per iteration) into a visibility
//! G-buffer. Each pixel stores `(triangle + 1, b1, b2, λ)` — 0 where nothing is seen — from
//! which later passes reconstruct the visible point exactly (`surface_at` in WGSL): position
//! by barycentric interpolation, geometric normal, material. λ is the albedo texture's level
//! of detail over the pixel's footprint, log2 of the texture coordinates' screen-space change
//! in texels (`texture_lod`), so that the passes read the texture filtered like a fragment
//! shader would.

use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::profile::{Profiler, compute_pass, render_pass};
use crate::gpu::{Gpu, dispatch_pixels, scene_raster_pipeline, shader};
use crate::gpu_scene::GpuScene;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;
use crate::passes::{FrameContext, IterationPass};
use crate::photons::gpu::GpuPhotonMap;

/// The pass's composed shader.
pub fn source() -> String {
    crate::passes::with_scene(include_str!("gbuffer.wgsl"))
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

    /// Raw texels `(triangle + 1, b1 bits, b2 bits, texture level of detail bits)`, row by row
    /// (for tests and tools).
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<[u32; 4]>> {
        Ok(bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.texture, 16)?))
    }
}

impl IterationPass for GBufferPass {
    /// Reads: scene, frame. Writes: the G-buffer.
    fn encode(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext) -> Result<()> {
        let (scene, frame) = (ctx.scene, ctx.frame);
        let clear =
            wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT), store: wgpu::StoreOp::Store };
        let mut pass = render_pass(enc, self.profiler.as_ref(), "gbuffer", (&self.view, clear), Some(&self.depth_view));
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &scene.bind_group, &[]);
        pass.set_bind_group(1, &frame.bind_group, &[]);
        pass.draw(0..3 * scene.triangle_count, 0..1);
        Ok(())
    }
}

/// The WGSL of a [`PixelPass`]'s bind group 2 (`gbuffer`, `film`).
pub const GBUFFER_FILM_WGSL: &str = include_str!("gbuffer_film.wgsl");

/// A [`PixelPass`]'s bind group 2: the G-buffer read, the film written.
pub fn pixel_group() -> Group {
    Group::compute("gbuffer film", &[Slot::uint_texture(0, "gbuffer"), Slot::write::<[f32; 4]>(1, "film")])
}

/// A compute pass run once per eye pixel, in 8×8 workgroups (`begin_pixel` in `frame.wgsl`):
/// bind group 0 is the scene, 1 the frame, 2 the G-buffer and the film (`gbuffer_film.wgsl`),
/// 3 whatever else its shader declares ([`GroupThree`]). The direct light, the specular
/// chains, the photon view, the caustic term and the denoiser's guides are such passes.
pub struct PixelPass {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    third: Third,
    profiler: Option<Profiler>,
    label: &'static str,
}

/// What a [`PixelPass`] binds as group 3.
pub enum GroupThree<'a> {
    None,
    /// The current photon map's lookup group, from the frame context at each iteration.
    PhotonMap(&'a GpuPhotonMap),
    /// A group of the pass's own, on its layout.
    Own(&'a wgpu::BindGroupLayout, wgpu::BindGroup),
}

/// [`GroupThree`] as the pass keeps it.
enum Third {
    None,
    PhotonMap,
    Own(wgpu::BindGroup),
}

/// A [`PixelPass`]'s shader: the composed `source`, its entry point `entry`, and the label of
/// its pipeline and of its timings (`--profile`).
pub struct PixelShader<'a> {
    pub label: &'static str,
    pub source: &'a str,
    pub entry: &'a str,
}

impl PixelPass {
    /// `third`: what `shader` binds as group 3.
    pub fn new(
        gpu: &Gpu,
        (scene, frame): (&GpuScene, &FrameBinding),
        (gbuffer, film): (&GBufferPass, &Film),
        shader: PixelShader,
        third: GroupThree,
    ) -> PixelPass {
        let device = &gpu.device;
        let label = shader.label;
        let module = scene.module(device, label, shader.source, crate::gpu_scene::RayUse::Eye);
        let resources = [
            ("gbuffer", wgpu::BindingResource::TextureView(&gbuffer.view)),
            ("film", film.accumulation.as_entire_binding()),
        ];
        let (layout, bind_group) = pixel_group().layout_and_bind(device, &resources);
        let (third_layout, third) = match third {
            GroupThree::None => (None, Third::None),
            GroupThree::PhotonMap(map) => (Some(&map.bind_layout), Third::PhotonMap),
            GroupThree::Own(layout, group) => (Some(layout), Third::Own(group)),
        };
        let layouts: Vec<&wgpu::BindGroupLayout> =
            [&scene.layout, &frame.layout, &layout].into_iter().chain(third_layout).collect();
        let pipeline = scene.compute_pipeline(device, label, &module, shader.entry, &layouts);
        PixelPass { pipeline, bind_group, third, profiler: gpu.profiler.clone(), label }
    }
}

impl IterationPass for PixelPass {
    /// Runs the pass over the frame's image (nothing where it reads a photon map and the
    /// render has none).
    fn encode(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext) -> Result<()> {
        let third = match (&self.third, ctx.map) {
            (Third::None, _) => None,
            (Third::PhotonMap, Some(map)) => Some(&map.bind_group),
            (Third::PhotonMap, None) => return Ok(()),
            (Third::Own(group), _) => Some(group),
        };
        let mut pass = compute_pass(enc, self.profiler.as_ref(), self.label);
        let groups: Vec<&wgpu::BindGroup> =
            [&ctx.scene.bind_group, &ctx.frame.bind_group, &self.bind_group].into_iter().chain(third).collect();
        dispatch_pixels(&mut pass, &self.pipeline, &groups, ctx.width, ctx.rows);
        Ok(())
    }
}
