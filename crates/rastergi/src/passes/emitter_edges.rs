//! Emitter edges: the emission the eye sees, supersampled where a pixel straddles the edge of
//! an emitter or of the sky (`seen_emission` in `visible_point.wgsl` states the estimator).
//!
//! A pixel's value is the box-filtered integral of the radiance over its area; an iteration
//! samples it at one jittered point. Where an emitter's edge crosses the pixel, that sample
//! is all or nothing: an error of the order of the emitter's radiance, which is tens of times
//! the image's mean. Those few pixels then hold most of an early image's squared error (the
//! Cornell box at 1280 × 720: 92–97 % of it in the 0.5 % of the pixels next to the light after
//! 1–9 iterations). Their emission, alone, is cheap to integrate better: only the first
//! surface along each sub-pixel ray matters, no light is reflected. So:
//!
//! 1. **Keys** (`keys`, once per view and image): the camera ray through each pixel's
//!    *centre*, not jittered, is traced; what it first meets as light — nothing, the
//!    environment, or an emitter's front face (by material) — is the pixel's key. The keys
//!    depend on the camera only, never on an iteration's random numbers.
//! 2. **Edges** (`flags`, with the keys): a pixel whose 3 × 3 neighbourhood holds different
//!    keys is flagged.
//! 3. **Estimate** (the direct pass every iteration, and the denoiser's guides with the same
//!    random numbers): at a flagged pixel the emission of its first surface is the mean over
//!    n × n stratified jittered sub-pixel rays (n = [`crate::settings::RenderSettings::emitter_edges`],
//!    [`DEFAULT_EMITTER_EDGES`]); elsewhere the jittered sample's, as before.
//!
//! Both estimators are unbiased for the same integral and the choice between them does not
//! depend on the samples it weighs, so the image converges to exactly what it did; only the
//! edge pixels' variance falls (stratified: faster than 1/n² for a straight edge; measured
//! on a turned square, the RMS error of an edge pixel after one iteration is 0.05 of the
//! emitter's radiance against 0.4 with one sample, `tests/direct_light.rs`). Cost: one ray a
//! pixel once per view, n² at each flagged pixel per iteration (the Cornell box at
//! 1280 × 720 on lavapipe: 35 ms once, then 4 ms of a 540 ms iteration).
//!
//! The keys and flags are kept in the w of each pixel's second eye-path slot (the specular
//! chains keep that w), so no pass binds another buffer (the web's limit of storage buffers
//! per stage). The window and the previews share the eye paths: [`EdgeKeys`] says whose keys
//! they hold, and an image whose keys another overwrote makes its own again. The banded
//! iterations make them band by band: the keys over the band's rows and the row below (which
//! the next band's flags read), the flags over the band's rows.

use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu_scene::GpuScene;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;
use crate::passes::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, GroupThree, PixelPass, PixelShader};
use crate::passes::{FrameContext, IterationPass};

/// Sub-pixel rays per axis at an emitter's edge by default (n² = 16 rays).
pub const DEFAULT_EMITTER_EDGES: u32 = 4;

/// The passes' composed shader.
pub fn source() -> String {
    crate::passes::per_pixel(&[GBUFFER_FILM_WGSL, include_str!("emitter_edges.wgsl")])
}

/// Whose keys the eye paths hold, by image size (the window's, a preview's): the passes run
/// until one image's keys are whole, then not again for it until the camera moves
/// (the renderer's reset takes them) or another image writes its own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct EdgeKeys {
    /// The image whose keys and flags are all there.
    valid: Option<(u32, u32)>,
    /// The image whose iteration under way has written them from its first band on.
    writing: Option<(u32, u32)>,
}

/// The keys and flags passes of one image. Reads: scene, frame. Writes: the eye paths' edge
/// slot (`emitter_edges.wgsl`).
pub struct EmitterEdges {
    keys: PixelPass,
    flags: PixelPass,
}

impl EmitterEdges {
    pub fn new(gpu: &Gpu, scene: &GpuScene, frame: &FrameBinding, gbuffer: &GBufferPass, film: &Film) -> EmitterEdges {
        let source = source();
        let pass = |entry, label| {
            let shader = PixelShader { label, source: &source, entry };
            PixelPass::new(gpu, (scene, frame), (gbuffer, film), shader, GroupThree::None)
        };
        EmitterEdges { keys: pass("keys", "emitter edges: keys"), flags: pass("flags", "emitter edges: flags") }
    }

    /// Encodes the band of `ctx` where the eye paths do not hold this image's keys yet
    /// (`keys`: the state, updated): the keys over its rows and the row below, then the flags
    /// over its rows.
    pub fn encode(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext, keys: &mut EdgeKeys) -> Result<()> {
        let image = (ctx.width, ctx.height);
        if keys.valid == Some(image) {
            return Ok(());
        }
        let below = FrameContext { rows: (ctx.rows + 1).min(ctx.height - ctx.y0), ..ctx.clone() };
        self.keys.encode(enc, &below)?;
        self.flags.encode(enc, ctx)?;
        keys.writing = (ctx.y0 == 0 || keys.writing == Some(image)).then_some(image);
        keys.valid = (ctx.y0 + ctx.rows >= ctx.height).then_some(image).filter(|_| keys.writing == Some(image));
        Ok(())
    }
}
