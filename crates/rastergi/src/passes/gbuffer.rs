//! Eye pass: rasterizes the scene from the camera (jittered per iteration) into a visibility
//! G-buffer. Each pixel stores `(triangle + 1, b1, b2, λ)` — 0 where nothing is seen — from
//! which later passes reconstruct the visible point exactly (`surface_at` in WGSL): position
//! by barycentric interpolation, geometric normal, material. λ is the albedo texture's level
//! of detail over the pixel's footprint, log2 of the texture coordinates' screen-space change
//! in texels (`texture_lod`), so that the passes read the texture filtered like a fragment
//! shader would.
//!
//! The same texels can be found by casting a camera ray per pixel into the BVH instead
//! (`gbuffer_trace.wgsl`, [`EyeMethod::Trace`]; λ by ray differentials), which is cheaper where
//! the pixels are few and the triangles many: drawing the staircase's 262 k triangles took
//! 31.6 ms of lavapipe's time for a 40 × 23 preview, 70 % of its iteration, where 920 rays take
//! about 1 ms. A viewer's previews measure both ([`EyeMethod::Auto`]: [`EYE_TRIALS`]
//! G-buffers each way, each alone on the GPU, the faster kept by the least of its times).

use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::profile::{Profiler, compute_pass, render_pass};
use crate::gpu::{Gpu, dispatch_pixels, scene_raster_pipeline, shader};
use crate::gpu_scene::GpuScene;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;
use crate::passes::{FrameContext, IterationPass};
use crate::photons::gpu::GpuPhotonMap;
use crate::settings::EyeMethod;

/// The pass's composed shader.
pub fn source() -> String {
    crate::passes::with_scene(include_str!("gbuffer.wgsl"))
}

/// The ray-cast eye pass's composed shader.
pub fn trace_source() -> String {
    crate::passes::with_scene(&[crate::passes::EYE_RAY, include_str!("gbuffer_trace.wgsl")].join("\n"))
}

/// The ray-cast eye pass's bind group 2: the G-buffer written.
pub fn trace_group() -> Group {
    Group::compute("gbuffer trace", &[Slot::uint_storage_texture(0, "visibility")])
}

/// G-buffers timed each way before [`EyeMethod::Auto`] chooses.
pub const EYE_TRIALS: usize = 2;

/// The ray-cast eye pass.
struct TracedEye {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
}

/// How the pass makes its G-buffer: one way, or still timing both ([`EyeMethod::Auto`]).
#[derive(Clone, Debug, PartialEq)]
enum EyeChoice {
    Fixed(EyeMethod),
    /// Seconds of each G-buffer made so far: rasterized, traced.
    Timing([Vec<f64>; 2]),
}

pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

pub struct GBufferPass {
    pipeline: wgpu::RenderPipeline,
    pub texture: wgpu::Texture,
    pub view: wgpu::TextureView,
    depth_view: wgpu::TextureView,
    profiler: Option<crate::gpu::profile::Profiler>,
    traced: Option<TracedEye>,
    choice: EyeChoice,
}

impl GBufferPass {
    /// The eye pass of a `width` × `height` image, by `method`: `Auto` times both ways where
    /// the GPU can be waited for ([`crate::gpu::READ_BACK_BLOCKS`]), else rasterizes.
    pub fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        frame: &FrameBinding,
        (width, height): (u32, u32),
        method: EyeMethod,
    ) -> Self {
        let device = &gpu.device;
        let choice = match method {
            EyeMethod::Auto if crate::gpu::READ_BACK_BLOCKS => EyeChoice::Timing([Vec::new(), Vec::new()]),
            EyeMethod::Auto | EyeMethod::Raster => EyeChoice::Fixed(EyeMethod::Raster),
            EyeMethod::Trace => EyeChoice::Fixed(EyeMethod::Trace),
        };
        // The ray-cast pass and the texture's storage use, only where it may trace.
        let traces = choice != EyeChoice::Fixed(EyeMethod::Raster);
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
                | wgpu::TextureUsages::COPY_SRC
                | if traces { wgpu::TextureUsages::STORAGE_BINDING } else { wgpu::TextureUsages::empty() },
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
        let traced = traces.then(|| {
            let module = scene.module(device, "gbuffer trace", &trace_source(), crate::gpu_scene::RayUse::Eye);
            let (layout, bind_group) =
                trace_group().layout_and_bind(device, &[("visibility", wgpu::BindingResource::TextureView(&view))]);
            let pipeline = scene.compute_pipeline(
                device,
                "gbuffer trace",
                &module,
                "main",
                &[&scene.layout, &frame.layout, &layout],
            );
            TracedEye { pipeline, bind_group }
        });
        Self { pipeline, texture, view, depth_view, profiler: gpu.profiler.clone(), traced, choice }
    }

    /// How the G-buffers are made now: `Auto` while both ways are still being timed.
    pub fn method(&self) -> EyeMethod {
        match self.choice {
            EyeChoice::Fixed(m) => m,
            EyeChoice::Timing(_) => EyeMethod::Auto,
        }
    }

    /// Makes the G-buffer of the frame `ctx` as [`encode`](IterationPass::encode) does, but
    /// alone on the GPU and timed, where both ways are still being timed (returns false and
    /// does nothing otherwise): by turns each way, until each has made [`EYE_TRIALS`]; then
    /// the way of the least time is kept. The frame's uniforms must be written already.
    pub fn timed(&mut self, ctx: &FrameContext) -> Result<bool> {
        let EyeChoice::Timing(times) = &self.choice else { return Ok(false) };
        let k = usize::from(times[0].len() > times[1].len());
        let gpu = ctx.gpu;
        gpu.wait()?;
        let began = web_time::Instant::now();
        let mut enc =
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("gbuffer timed") });
        self.encode_as(&mut enc, ctx, if k == 0 { EyeMethod::Raster } else { EyeMethod::Trace });
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        let seconds = began.elapsed().as_secs_f64();
        let EyeChoice::Timing(times) = &mut self.choice else { unreachable!() };
        times[k].push(seconds);
        if times.iter().all(|t| t.len() >= EYE_TRIALS) {
            let least = |t: &[f64]| t.iter().copied().fold(f64::INFINITY, f64::min);
            let (raster, trace) = (least(&times[0]), least(&times[1]));
            let method = if trace < raster { EyeMethod::Trace } else { EyeMethod::Raster };
            log::info!(
                "eye pass at {}x{}: rasterized {:.1} ms, traced {:.1} ms: {method:?}",
                self.texture.width(),
                self.texture.height(),
                raster * 1e3,
                trace * 1e3
            );
            self.choice = EyeChoice::Fixed(method);
        }
        Ok(true)
    }

    fn encode_as(&self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext, method: EyeMethod) {
        let (scene, frame) = (ctx.scene, ctx.frame);
        match (method, &self.traced) {
            (EyeMethod::Trace, Some(t)) => {
                let mut pass = compute_pass(enc, self.profiler.as_ref(), "gbuffer trace");
                let groups = [&scene.bind_group, &frame.bind_group, &t.bind_group];
                dispatch_pixels(&mut pass, &t.pipeline, &groups, ctx.width, ctx.height);
            }
            _ => {
                let clear = wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                };
                let mut pass =
                    render_pass(enc, self.profiler.as_ref(), "gbuffer", (&self.view, clear), Some(&self.depth_view));
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &scene.bind_group, &[]);
                pass.set_bind_group(1, &frame.bind_group, &[]);
                pass.draw(0..3 * scene.triangle_count, 0..1);
            }
        }
    }

    /// Raw texels `(triangle + 1, b1 bits, b2 bits, texture level of detail bits)`, row by row
    /// (for tests and tools).
    pub fn read(&self, gpu: &Gpu) -> Result<Vec<[u32; 4]>> {
        Ok(bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.texture, 16)?))
    }
}

impl IterationPass for GBufferPass {
    /// Reads: scene, frame. Writes: the G-buffer, whole whatever the band's rows: rasterized,
    /// or traced where that was chosen.
    fn encode(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext) -> Result<()> {
        self.encode_as(enc, ctx, self.method());
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
