//! History: what the film held before a camera move, re-projected onto the new view for the
//! display (`history.wgsl`), so that a moved camera sees the surfaces it saw before lit at
//! once.
//!
//! At the move, `snapshot` keeps per pixel the film's mean of the shown component and the
//! triangle the pixel sees and from which side (its G-buffer). At the new view, `reproject`
//! reads the window's G-buffer of the new camera (rasterized without jitter), takes each
//! pixel's point on its triangle (the sky: its direction) through the old view-projection to
//! the old pixel that saw it, and keeps that pixel's mean where it saw the same side of the
//! same triangle (the outside of a wall is not its lit inside). For a
//! Lambertian surface the radiance towards the eye does not depend on the view: the kept mean
//! is that of the same surface a fraction of a pixel away; for a glossy one it is the old
//! view's. The display weighs it as min(m, 16) iterations (m the old film's) fading as the new
//! view's n iterations grow ([`crate::passes::film::Film::encode_resolve_blend`]): the film
//! itself never holds it, so the image converges to exactly what it did.

use glam::Mat4;

use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu_scene::GpuScene;
use crate::passes::film::{Film, Show};
use crate::passes::frame::FrameBinding;
use crate::passes::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, GroupThree, PixelPass, PixelShader};
use crate::passes::{FrameContext, IterationPass};

gpu_struct! {
    /// The history passes' uniforms (`history.wgsl`).
    pub(crate) struct HistoryUniforms as "HistoryParams" {
        /// World → clip of the view before the move, without jitter.
        pub(crate) view_proj: [[f32; 4]; 4] as "mat4x4f",
        /// The component kept (as `ResolveUniforms::show`).
        pub(crate) show: u32,
        /// The old film's iterations, and the rows that held one more.
        pub(crate) samples: u32,
        pub(crate) rows_ahead: u32,
        pub(crate) _pad: u32,
    }
}

/// The history passes' bind group 3.
pub fn group() -> Group {
    Group::compute(
        "history",
        &[
            Slot::uniform::<HistoryUniforms>(0, "history_params"),
            Slot::write::<[f32; 4]>(1, "history"),
            Slot::write::<[f32; 4]>(2, "reprojected"),
        ],
    )
}

/// The passes' composed shader.
fn source() -> String {
    crate::passes::per_pixel(&[GBUFFER_FILM_WGSL, &HistoryUniforms::wgsl(), include_str!("history.wgsl")])
}

/// The kept view and its re-projection (buffers of the film's size).
pub struct History {
    uniforms: wgpu::Buffer,
    snapshot: PixelPass,
    reproject: PixelPass,
    /// Per pixel of the new view: the kept mean where valid (w = 1).
    pub reprojected: wgpu::Buffer,
    /// The old film's iterations (0: nothing kept) and the component kept.
    pub samples: u32,
    pub show: Show,
}

impl History {
    pub fn new(
        gpu: &Gpu,
        (scene, frame): (&GpuScene, &FrameBinding),
        (gbuffer, film): (&GBufferPass, &Film),
    ) -> History {
        let pixels = film.width as u64 * film.height as u64;
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let history = gpu.zeroed_buffer("history", pixels * 16, rw);
        let reprojected = gpu.zeroed_buffer("history re-projected", pixels * 16, rw);
        let uniforms = gpu.zeroed_buffer(
            "history uniforms",
            std::mem::size_of::<HistoryUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let layout = group().layout(&gpu.device);
        let bind = || {
            group().bind(
                &gpu.device,
                &layout,
                &[
                    ("history_params", uniforms.as_entire_binding()),
                    ("history", history.as_entire_binding()),
                    ("reprojected", reprojected.as_entire_binding()),
                ],
            )
        };
        let source = source();
        let pass = |label, entry| {
            let shader = PixelShader { label, source: &source, entry };
            PixelPass::new(gpu, (scene, frame), (gbuffer, film), shader, GroupThree::Own(&layout, bind()))
        };
        History {
            snapshot: pass("history snapshot", "snapshot"),
            reproject: pass("history reproject", "reproject"),
            uniforms,
            reprojected,
            samples: 0,
            show: Show::Full,
        }
    }

    /// Encodes the snapshot of `film` (its sums as they stand, `show`) and of the G-buffer,
    /// seen with `view_proj`; `ctx` is the old view's frame.
    pub fn encode_snapshot(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        ctx: &FrameContext,
        film: &Film,
        (show, view_proj): (Show, Mat4),
    ) -> Result<()> {
        let u = HistoryUniforms {
            view_proj: view_proj.to_cols_array_2d(),
            show: show.code(),
            samples: film.samples,
            rows_ahead: film.rows_ahead,
            _pad: 0,
        };
        ctx.gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        self.snapshot.encode(enc, ctx)?;
        (self.samples, self.show) = (film.samples, show);
        Ok(())
    }

    /// Encodes the re-projection onto the view of `ctx` (its G-buffer rasterized before).
    pub fn encode_reproject(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext) -> Result<()> {
        self.reproject.encode(enc, ctx)
    }
}
