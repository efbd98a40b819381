//! Final gather by rasterization (Hachisuka, GPU Gems 2, ch. 38): the nearest surface along ω
//! for all visible points at once, by depth peeling the ray view. The estimator is the one in
//! [`super::estimator`].
//!
//! * Ray view: an orthographic camera looking along −ω that encloses the scene's bounding
//!   sphere, shifted by a random sub-texel offset. Ray-view depth grows along −ω, so a gather
//!   ray leaving x along +ω meets surfaces of decreasing depth.
//! * Depth peeling, back to front: layer 1 keeps the farthest fragment per texel (reversed
//!   depth test); layer k+1 the farthest strictly nearer than layer k. A counting pass first
//!   measures the depth complexity along ω, and exactly that many layers are peeled: its
//!   result is read back before the layers are encoded (one GPU→CPU synchronisation per
//!   direction).
//! * Projection: after each layer, every visible point x projects into the ray view like a
//!   shadow-map lookup. Where x's surface faces ω, the first layer (back to front) whose
//!   surface h lies in front of x — the plane of h's triangle crosses x's ray at t > ε — is the
//!   nearest hit along ω. Where it faces −ω, x gathers along −ω from the same view: it keeps
//!   the nearest layer behind it (per pixel: triangle and distance) until a layer lies in front
//!   of it, and one pass after the last layer makes its estimate. The plane test rejects x's
//!   own triangle and coplanar neighbours exactly, at any angle (no acne, no slope bias that
//!   would lose contact shadows).

use super::Gather;
use super::estimator::{
    GatherInputs, GatherSetup, GatherUniforms, RAY_VIEW_LOOKUP, estimate_group, estimate_resources, submit_and_renew,
};
use super::ray_view::{DEPTH_FORMAT, ray_view_module, ray_view_pipeline};
use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::profile::{Profiler, compute_pass, render_pass};
use crate::gpu::{Gpu, dispatch_pixels};
use crate::gpu_scene::GpuScene;

/// Ray-view texel: (triangle + 1, b1 bits, b2 bits, depth bits); 0 where empty.
const LAYER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Uint;

pub struct RasterGather {
    count_pipeline: wgpu::RenderPipeline,
    peel_pipeline: wgpu::RenderPipeline,
    project_pipeline: wgpu::ComputePipeline,
    resolve_pipeline: wgpu::ComputePipeline,
    layers: [wgpu::TextureView; 2],
    depth: wgpu::TextureView,
    counts: wgpu::Buffer,
    max_count: wgpu::Buffer,
    found: wgpu::Buffer,
    behind: wgpu::Buffer,
    count_group: wgpu::BindGroup,
    /// peel_groups[k]: reads layer texture 1−k (the previous layer).
    peel_groups: [wgpu::BindGroup; 2],
    /// project_groups[k]: reads layer texture k (the layer just peeled).
    project_groups: [wgpu::BindGroup; 2],
    profiler: Option<Profiler>,
}

/// The count's bind group 1: how many visible points each ray-view texel holds, and their
/// maximum (written by the fragments).
pub fn count_group() -> Group {
    let f = wgpu::ShaderStages::FRAGMENT;
    Group::new(
        "gather count",
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        &[
            Slot::uniform::<GatherUniforms>(0, "gather"),
            Slot::write::<u32>(1, "counts").only(f),
            Slot::write::<u32>(2, "max_count").only(f),
        ],
    )
}

/// A depth peel's bind group 1: the layer peeled before, read.
pub fn peel_group() -> Group {
    Group::new(
        "gather peel",
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        &[
            Slot::uniform::<GatherUniforms>(0, "gather"),
            Slot::uint_texture(1, "previous_layer").only(wgpu::ShaderStages::FRAGMENT),
        ],
    )
}

/// The projection's bind group 2: the G-buffer and a peeled layer read; which visible points
/// found their texel, the film, and the points behind written.
pub fn project_group() -> Group {
    estimate_group(
        "gather project",
        &[
            Slot::uint_texture(2, "layer"),
            Slot::write::<u32>(3, "found"),
            Slot::write::<[f32; 4]>(4, "film"),
            Slot::write::<[u32; 2]>(5, "behind"),
        ],
    )
}

impl RasterGather {
    /// The passes and ray-view textures for a `bundle`² ray view reading `uniforms`.
    pub fn new(gpu: &Gpu, setup: &GatherSetup, uniforms: &wgpu::Buffer, bundle: u32) -> Result<RasterGather> {
        let device = &gpu.device;
        crate::gpu::limits::check_bundle(&device.limits(), bundle)?;
        let (gbuffer, film) = (setup.gbuffer, setup.film);
        let texture = |label: &str, format: wgpu::TextureFormat, usage: wgpu::TextureUsages| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size: wgpu::Extent3d { width: bundle, height: bundle, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format,
                    usage,
                    view_formats: &[],
                })
                .create_view(&Default::default())
        };
        let layer_usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING;
        let layers = [
            texture("gather layer 0", LAYER_FORMAT, layer_usage),
            texture("gather layer 1", LAYER_FORMAT, layer_usage),
        ];
        let depth = texture("gather depth", DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
        let counts = gpu.zeroed_buffer(
            "gather depth complexity",
            bundle as u64 * bundle as u64 * 4,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let max_count = gpu.zeroed_buffer(
            "gather max depth complexity",
            4,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let pixels = film.width as u64 * film.height as u64;
        let found =
            gpu.zeroed_buffer("gather found", pixels * 4, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST);
        let behind =
            gpu.zeroed_buffer("gather behind", pixels * 8, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST);

        let (count_layout, count_group) = count_group().layout_and_bind(
            device,
            &[
                ("gather", uniforms.as_entire_binding()),
                ("counts", counts.as_entire_binding()),
                ("max_count", max_count.as_entire_binding()),
            ],
        );
        let (peel, project) = (peel_group(), project_group());
        let (peel_layout, project_layout) = (peel.layout(device), project.layout(device));
        let peel_group = |prev: &wgpu::TextureView| {
            let resources = [
                ("gather", uniforms.as_entire_binding()),
                ("previous_layer", wgpu::BindingResource::TextureView(prev)),
            ];
            peel.bind(device, &peel_layout, &resources)
        };
        let project_group = |layer: &wgpu::TextureView| {
            let own = [
                ("layer", wgpu::BindingResource::TextureView(layer)),
                ("found", found.as_entire_binding()),
                ("film", film.accumulation.as_entire_binding()),
                ("behind", behind.as_entire_binding()),
            ];
            project.bind(device, &project_layout, &[estimate_resources(uniforms, gbuffer).as_slice(), &own].concat())
        };
        let peel_groups = [peel_group(&layers[1]), peel_group(&layers[0])];
        let project_groups = [project_group(&layers[0]), project_group(&layers[1])];

        let module = ray_view_module(device);
        let scene_layout = &setup.scene.layout;
        let count_pipeline = ray_view_pipeline(
            device,
            "gather count",
            &module,
            &[scene_layout, &count_layout],
            "fs_count",
            (LAYER_FORMAT, wgpu::ColorWrites::empty()),
            false,
        );
        let peel_pipeline = ray_view_pipeline(
            device,
            "gather peel",
            &module,
            &[scene_layout, &peel_layout],
            "fs_peel",
            (LAYER_FORMAT, wgpu::ColorWrites::ALL),
            true,
        );
        let [project_pipeline, resolve_pipeline] = setup.estimate_pipelines(
            device,
            "gather project",
            &[RAY_VIEW_LOOKUP, include_str!("raster.wgsl")],
            &project_layout,
            ["main", "resolve_behind"],
        );
        Ok(RasterGather {
            count_pipeline,
            peel_pipeline,
            project_pipeline,
            resolve_pipeline,
            layers,
            depth,
            counts,
            max_count,
            found,
            behind,
            count_group,
            peel_groups,
            project_groups,
            profiler: gpu.profiler.clone(),
        })
    }

    /// Counts the depth complexity along the direction in the uniforms, submits `enc` and
    /// reads the count back, then encodes that many peeled layers with their projections into
    /// a new encoder, left in `enc`.
    fn encode_direction(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) -> Result<()> {
        self.encode_count(enc, inputs.scene);
        submit_and_renew(gpu, enc, "gather layers");
        let layers = self.read_layer_count(gpu)?;
        self.encode_layers(enc, inputs, layers);
        Ok(())
    }

    /// Encodes the depth-complexity count of the ray view; its result is read by
    /// [`RasterGather::read_layer_count`] after the encoder is submitted.
    fn encode_count(&self, enc: &mut wgpu::CommandEncoder, scene: &GpuScene) {
        enc.clear_buffer(&self.counts, 0, None);
        enc.clear_buffer(&self.max_count, 0, None);
        let ops = wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store };
        let mut pass = render_pass(enc, self.profiler.as_ref(), "gather count", (&self.layers[0], ops), None);
        pass.set_pipeline(&self.count_pipeline);
        pass.set_bind_group(0, &scene.bind_group, &[]);
        pass.set_bind_group(1, &self.count_group, &[]);
        pass.draw(0..3 * scene.triangle_count, 0..1);
    }

    /// The depth complexity along the current direction: the number of layers to peel.
    fn read_layer_count(&self, gpu: &Gpu) -> Result<u32> {
        let bytes = gpu.read_buffer(&self.max_count, 4)?;
        Ok(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]))
    }

    /// Peels `layers` layers back to front, projecting each onto the visible points, then
    /// resolves the points gathering along −ω from the nearest layer behind them.
    /// Reads: scene, frame, G-buffer, photon map. Adds to: the film's indirect component.
    fn encode_layers(&self, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs, layers: u32) {
        enc.clear_buffer(&self.found, 0, None);
        enc.clear_buffer(&self.behind, 0, None);
        // "Layer −1" (read by the first peel) is empty with depth bits above any depth.
        let beyond = f64::from(2.0f32.to_bits());
        {
            let clear = wgpu::LoadOp::Clear(wgpu::Color { r: 0.0, g: 0.0, b: 0.0, a: beyond });
            let ops = wgpu::Operations { load: clear, store: wgpu::StoreOp::Store };
            let _ = render_pass(enc, None, "gather layer init", (&self.layers[1], ops), None);
        }
        for k in 0..layers as usize {
            let cur = k % 2;
            {
                let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
                let ops = wgpu::Operations { load: clear, store: wgpu::StoreOp::Store };
                let (layer, depth) = (&self.layers[cur], Some(&self.depth));
                let mut pass = render_pass(enc, self.profiler.as_ref(), "gather peel", (layer, ops), depth);
                pass.set_pipeline(&self.peel_pipeline);
                pass.set_bind_group(0, &inputs.scene.bind_group, &[]);
                pass.set_bind_group(1, &self.peel_groups[cur], &[]);
                pass.draw(0..3 * inputs.scene.triangle_count, 0..1);
            }
            let mut pass = compute_pass(enc, self.profiler.as_ref(), "gather project");
            let groups = inputs.groups(&self.project_groups[cur]);
            dispatch_pixels(&mut pass, &self.project_pipeline, &groups, inputs.width, inputs.rows);
        }
        let mut pass = compute_pass(enc, self.profiler.as_ref(), "gather resolve behind");
        let groups = inputs.groups(&self.project_groups[0]);
        dispatch_pixels(&mut pass, &self.resolve_pipeline, &groups, inputs.width, inputs.rows);
    }
}

impl Gather for RasterGather {
    /// One ray view per direction: count, read back, peel and project layer by layer.
    fn encode(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) -> Result<()> {
        inputs.for_each_direction(gpu, enc, |enc, _| self.encode_direction(gpu, enc, inputs))
    }
}
