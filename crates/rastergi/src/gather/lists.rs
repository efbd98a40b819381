//! Final gather from per-texel fragment lists: the single-pass alternative to depth peeling.
//! The estimator is the one in [`super::estimator`].
//!
//! * One raster pass over the ray view ([`super::ray_view`], as in [`super::raster`]) with no depth test:
//!   every fragment prepends its triangle to its texel's linked list (an atomic exchange on
//!   the texel's head, a node from a pool taken by an atomic counter).
//! * One compute pass: every visible point x projects into the ray view like a shadow-map
//!   lookup and walks its texel's list; the hit is the fragment whose triangle's plane x's ray
//!   crosses first at t > ε (x's own triangle excluded) — the layer the peel would find, with
//!   the same texel approximation, without ordering the layers.
//! * No read-back: the pool is sized once to a bound on the fragments of any view. A triangle
//!   of area A and perimeter P covers at most A/s² + P/s + 1 texel centres of side s in any
//!   orthographic projection (projection shrinks both; a convex set holds at most A + P/2 + 1
//!   lattice points, Nosarzewska), so Σ(A/s² + P/s + 1) nodes always suffice.

use super::Gather;
use super::estimator::{
    GatherInputs, GatherSetup, GatherUniforms, RAY_VIEW_LOOKUP, estimate_group, estimate_resources,
};
use super::ray_view::{ray_view_module, ray_view_pipeline, texel_size};
use crate::error::{Error, Result};
use crate::gpu::binding::{Group, Slot};
use crate::gpu::profile::{Profiler, compute_pass, render_pass};
use crate::gpu::{Gpu, dispatch_pixels};
use crate::gpu_scene::GpuScene;

/// Render target of the list pass (nothing is written to it; a pass needs an attachment).
const TARGET_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R8Uint;

/// Nodes that hold every fragment of `scene` in any `bundle`² ray view over its bounding
/// sphere (see the module documentation).
pub fn node_capacity(scene: &GpuScene, bundle: u32) -> u64 {
    let s = texel_size(&scene.bounds, bundle);
    (scene.total_area / (s * s) + scene.total_perimeter / s + scene.triangle_count as f64).ceil() as u64
}

pub struct ListGather {
    fill_pipeline: wgpu::RenderPipeline,
    project_pipeline: wgpu::ComputePipeline,
    target: wgpu::TextureView,
    heads: wgpu::Buffer,
    node_count: wgpu::Buffer,
    fill_group: wgpu::BindGroup,
    project_group: wgpu::BindGroup,
    profiler: Option<Profiler>,
}

/// The fill's bind group 1: each fragment of the ray view pushes its visible point onto its
/// texel's list (heads, nodes and the node count written).
pub fn fill_group() -> Group {
    let f = wgpu::ShaderStages::FRAGMENT;
    Group::new(
        "gather list fill",
        wgpu::ShaderStages::VERTEX_FRAGMENT,
        &[
            Slot::uniform::<GatherUniforms>(0, "gather"),
            Slot::write::<u32>(1, "heads").only(f),
            Slot::write::<[u32; 2]>(2, "nodes").only(f),
            Slot::write::<u32>(3, "node_count").only(f),
        ],
    )
}

/// The projection's bind group 2: the G-buffer and the lists read, the film written.
pub fn project_group() -> Group {
    estimate_group(
        "gather list project",
        &[Slot::read::<u32>(2, "heads"), Slot::read::<[u32; 2]>(3, "nodes"), Slot::write::<[f32; 4]>(4, "film")],
    )
}

impl ListGather {
    /// The list buffers for a `bundle`² ray view. Fails where the node pool exceeds a
    /// binding.
    pub fn new(gpu: &Gpu, setup: &GatherSetup, uniforms: &wgpu::Buffer, bundle: u32) -> Result<ListGather> {
        let device = &gpu.device;
        crate::gpu::limits::check_bundle(&device.limits(), bundle)?;
        let capacity = node_capacity(setup.scene, bundle);
        let max = device.limits().max_storage_buffer_binding_size.min(device.limits().max_buffer_size);
        if capacity.saturating_mul(8) > max {
            return Err(Error::Limits(format!(
                "the gather's fragment lists for a {bundle}² ray view need {} MiB, more than the {} MiB this GPU binds; choose a smaller --bundle or --gather trace",
                (capacity * 8) >> 20,
                max >> 20
            )));
        }
        let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let heads = gpu.zeroed_buffer("gather list heads", bundle as u64 * bundle as u64 * 4, storage);
        let nodes = gpu.zeroed_buffer("gather list nodes", capacity * 8, storage);
        let node_count = gpu.zeroed_buffer("gather list node count", 4, storage);
        let target = device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some("gather list target"),
                size: wgpu::Extent3d { width: bundle, height: bundle, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: TARGET_FORMAT,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&Default::default());

        let (fill_layout, fill_group) = fill_group().layout_and_bind(
            device,
            &[
                ("gather", uniforms.as_entire_binding()),
                ("heads", heads.as_entire_binding()),
                ("nodes", nodes.as_entire_binding()),
                ("node_count", node_count.as_entire_binding()),
            ],
        );
        let (project_layout, project_group) = project_group().layout_and_bind(
            device,
            &[
                estimate_resources(uniforms, setup.gbuffer).as_slice(),
                &[
                    ("heads", heads.as_entire_binding()),
                    ("nodes", nodes.as_entire_binding()),
                    ("film", setup.film.accumulation.as_entire_binding()),
                ],
            ]
            .concat(),
        );

        let module = ray_view_module(device);
        let fill_pipeline = ray_view_pipeline(
            device,
            "gather list fill",
            &module,
            &[&setup.scene.layout, &fill_layout],
            "fs_list",
            (TARGET_FORMAT, wgpu::ColorWrites::empty()),
            false,
        );
        let project_pipeline = setup.estimate_pipeline(
            device,
            "gather list project",
            &[RAY_VIEW_LOOKUP, include_str!("lists.wgsl")],
            &project_layout,
        );
        Ok(ListGather {
            fill_pipeline,
            project_pipeline,
            target,
            heads,
            node_count,
            fill_group,
            project_group,
            profiler: gpu.profiler.clone(),
        })
    }

    /// Encodes the lists of the direction in the uniforms and their projection onto the
    /// visible points.
    fn encode_direction(&self, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) {
        enc.clear_buffer(&self.heads, 0, None);
        enc.clear_buffer(&self.node_count, 0, None);
        {
            let ops = wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Discard };
            let mut pass = render_pass(enc, self.profiler.as_ref(), "gather list fill", (&self.target, ops), None);
            pass.set_pipeline(&self.fill_pipeline);
            pass.set_bind_group(0, &inputs.scene.bind_group, &[]);
            pass.set_bind_group(1, &self.fill_group, &[]);
            pass.draw(0..3 * inputs.scene.triangle_count, 0..1);
        }
        let mut pass = compute_pass(enc, self.profiler.as_ref(), "gather list project");
        let groups = inputs.groups(&self.project_group);
        dispatch_pixels(&mut pass, &self.project_pipeline, &groups, inputs.width, inputs.rows);
    }
}

impl Gather for ListGather {
    /// One ray view per direction: its lists, then the walk of every visible point.
    fn encode(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, inputs: &GatherInputs) -> Result<()> {
        inputs.for_each_direction(gpu, enc, |enc, _| {
            self.encode_direction(enc, inputs);
            Ok(())
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::sampling::Rng;
    use glam::Vec2;

    /// Texel centres (i + ½, j + ½) inside or on the triangle: at least what a rasterizer's
    /// fill rule covers.
    fn covered(t: [Vec2; 3]) -> u64 {
        let lo = t[0].min(t[1]).min(t[2]).floor();
        let hi = t[0].max(t[1]).max(t[2]).ceil();
        let edge = |a: Vec2, b: Vec2, p: Vec2| (b - a).perp_dot(p - a);
        let area = edge(t[0], t[1], t[2]);
        let mut n = 0;
        for j in lo.y as i64..=hi.y as i64 {
            for i in lo.x as i64..=hi.x as i64 {
                let p = Vec2::new(i as f32 + 0.5, j as f32 + 0.5);
                let e = [edge(t[0], t[1], p), edge(t[1], t[2], p), edge(t[2], t[0], p)];
                if e.iter().all(|&e| e * area.signum() >= 0.0) {
                    n += 1;
                }
            }
        }
        n
    }

    #[test]
    fn texel_centres_covered_by_a_triangle_never_exceed_area_plus_perimeter_plus_one() {
        let mut rng = Rng::new(7, 0, 0);
        let mut tight = 0.0f64;
        for k in 0..4000 {
            // Sizes from a tenth of a texel to 60 texels, slivers included.
            let scale = 0.1 * 600f32.powf(rng.next_f32());
            let mut p = || Vec2::new(rng.next_f32(), rng.next_f32()) * scale + Vec2::splat(k as f32 * 0.37);
            let t = [p(), p(), p()];
            let area = 0.5 * (t[1] - t[0]).perp_dot(t[2] - t[0]).abs();
            let perimeter = t[0].distance(t[1]) + t[1].distance(t[2]) + t[2].distance(t[0]);
            let bound = (area + perimeter + 1.0) as f64;
            let n = covered(t) as f64;
            assert!(n <= bound, "{n} texels covered by {t:?}, bound {bound}");
            tight = tight.max(n / bound);
        }
        println!("largest coverage / bound: {tight:.3}");
    }
}
