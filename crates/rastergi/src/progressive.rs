//! The progressive-renderer interface shared by the photon-map renderer
//! ([`crate::renderer::Renderer`]) and the reference path tracer
//! ([`crate::path_tracer::PathTracer`]), each of which implements it beside itself: front ends (render, view, bench) drive either through
//! it. Each iteration adds one estimate per pixel to a [`Film`]; the image is the mean of the
//! estimates since the last restart (a camera move or [`Progressive::reset`]).

use crate::checkpoint::Progress;
use crate::error::Result;
use crate::gather::GatherMethod;
use crate::image_io::{DisplayImage, LinearImage};
use crate::passes::denoise::{DenoiseParams, GuideState};
use crate::passes::film::{Film, FilmState, Show};
use crate::scene::Camera;
use crate::settings::RenderSettings;

/// `Send`: a renderer may be built on one thread and used on another (the viewer's builds, the
/// Python package's renders with the interpreter's lock released). On wasm32, where wgpu's
/// WebGPU handles are not `Send` and there is one thread, no bound ([`wgpu::WasmNotSend`]).
pub trait Progressive: wgpu::WasmNotSend {
    /// What the renderer is, for tables and logs.
    fn name(&self) -> &'static str;
    fn settings(&self) -> &RenderSettings;
    /// Submits one iteration (it runs on the GPU asynchronously; see [`Progressive::wait`]).
    fn iterate(&mut self) -> Result<()>;
    /// Blocks until the submitted iterations have finished on the GPU.
    fn wait(&self) -> Result<()>;
    /// Submits the next `rows` rows of the image (at least one) of the iteration under way,
    /// beginning one where none is; true when that finished it. A renderer that cannot split
    /// an iteration runs a whole one (the default; the path tracer).
    fn iterate_rows(&mut self, _rows: u32) -> Result<bool> {
        self.iterate()?;
        Ok(true)
    }
    /// The rows the iteration under way has added to the film (0: none under way).
    fn rows_ahead(&self) -> u32 {
        0
    }
    /// [`iterate_rows`](Progressive::iterate_rows) for the preview at 1/`scale` of the
    /// image's size (a power of two from 2): an image of the same view, of its own iterations,
    /// that a viewer shows while the camera moves and blends in after it stops
    /// ([`encode_resolve_preview`](Progressive::encode_resolve_preview)); it never enters the
    /// film. `None` where the renderer draws no previews (the default; the path tracer).
    fn iterate_preview_rows(&mut self, _scale: u32, _rows: u32) -> Result<Option<bool>> {
        Ok(None)
    }
    /// The film of the preview at 1/`scale`, once one has been drawn (since the last restart
    /// it holds that view's iterations only).
    fn preview_film(&self, _scale: u32) -> Option<&Film> {
        None
    }
    /// Encodes the resolve of `show` blended with the preview at 1/`scale`, its mean weighted
    /// as `weight` of the film's iterations, and with what the view before the last camera
    /// move held, re-projected ([`Progressive::reproject`]; [`Film::encode_resolve_blend`]);
    /// the plain resolve where there is neither (the default).
    fn encode_resolve_blend(
        &mut self,
        enc: &mut wgpu::CommandEncoder,
        (show, exposure): (Show, f32),
        _preview: Option<(u32, f32)>,
    ) {
        self.encode_resolve(enc, show, exposure);
    }
    /// Where the film holds nothing of this view yet and nothing of the view before the move
    /// is blended in (a moving frame), encodes the preview's own resolve at its size, which
    /// the display then upscales ([`Film::show_upscaled`]), and returns true; else encodes
    /// nothing and returns false (the default).
    fn encode_resolve_upscaled(
        &mut self,
        _enc: &mut wgpu::CommandEncoder,
        _shown: (Show, f32),
        _preview: Option<(u32, f32)>,
    ) -> bool {
        false
    }
    /// Re-projects what the film held before the last camera move onto the current view, for
    /// the display ([`crate::passes::history`]); false where there is nothing to do (the
    /// default: the path tracer keeps nothing).
    fn reproject(&mut self) -> Result<bool> {
        Ok(false)
    }
    /// Traces each new photon pass in steps beside the current one
    /// ([`Progressive::photon_step`]) rather than at once (where the renderer has passes).
    fn set_photon_steps(&mut self, _on: bool) {}
    /// The next photon pass's photons traced and in all, while it is traced in steps.
    fn photons_pending(&self) -> Option<(u32, u32)> {
        None
    }
    /// Fits the photon region to the current view and begins a pass over it where it moved
    /// (passes in steps, the region following the camera); false where nothing began.
    fn refit_photon_region(&mut self) -> Result<bool> {
        Ok(false)
    }
    /// Traces up to `photons` more of the pass under way in steps; true once it is the map
    /// the iterations read.
    fn photon_step(&mut self, _photons: u32) -> Result<bool> {
        Ok(false)
    }
    /// The rays the renderer has traced since it was made (every pass: photons, the eye's
    /// chains, shadow rays, the gather's rays), where the device counts them
    /// ([`crate::gpu::GpuOptions::count_rays`]); `None` where it does not. Waits for the GPU.
    fn rays_traced(&self) -> Result<Option<crate::gpu_scene::RaysTraced>>;
    /// Iterations accumulated since the last restart.
    fn samples(&self) -> u32;
    fn camera(&self) -> Camera;
    /// Moves the camera; the image starts converging again.
    fn set_camera(&mut self, camera: Camera) -> Result<()>;
    /// Discards the accumulated iterations.
    fn reset(&mut self);
    /// The accumulated sums and the resolved images (for drawing them in a window).
    fn film(&self) -> &Film;
    /// Whether the renderer accumulates `show` separately (the path tracer has only
    /// [`Show::Full`] and shows it for every other view).
    fn has(&self, show: Show) -> bool;
    /// Encodes the resolve of `show` at `exposure` into the film's linear and display buffers.
    fn encode_resolve(&self, enc: &mut wgpu::CommandEncoder, show: Show, exposure: f32);
    /// The mean radiance of `show` so far, linear RGB.
    fn read_linear(&self, show: Show) -> Result<LinearImage>;
    /// The display encoding of `show`: 2^exposure · mean, clamped, sRGB, 8 bits.
    fn read_display(&self, show: Show, exposure: f32) -> Result<DisplayImage>;
    /// Where the render stands besides its film (for a checkpoint).
    fn progress(&self) -> Progress;
    /// The film's sums and their odd half, read back (checkpoints, the error estimate).
    fn film_state(&self) -> Result<FilmState>;
    /// Continues from a checkpoint's state: the next iteration is the one the checkpointed
    /// render would have run next.
    fn resume(&mut self, progress: &Progress, film: &FilmState) -> Result<()>;
    /// Changes the image size in place where the renderer can (the photon-map renderer keeps
    /// its scene and photon map, rebuilding only the passes of the image's size; the image
    /// restarts); `Ok(false)` where it must be built anew instead.
    fn resize(&mut self, _width: u32, _height: u32) -> Result<bool> {
        Ok(false)
    }
    /// The photon map's current pass and the final gather in use (the one `Auto` chose, once
    /// it has), where the renderer is the photon-map renderer.
    fn photon_pass_and_gather(&self) -> Option<(u32, GatherMethod)> {
        None
    }
    /// The renderer's denoiser, where it has one (the photon-map renderer; not the path
    /// tracer).
    fn denoising(&self) -> Option<&dyn Denoising> {
        None
    }
    fn denoising_mut(&mut self) -> Option<&mut dyn Denoising> {
        None
    }
}

/// A renderer's denoiser ([`crate::passes::denoise`]): its guides, accumulated from when it is
/// enabled, and the filtered image.
pub trait Denoising {
    /// Starts accumulating the guides (fails where their buffers exceed the device's limits);
    /// the iterations before have none, so an image with iterations should restart.
    fn enable_denoiser(&mut self) -> Result<()>;
    /// Whether the guides are accumulated.
    fn denoiser_enabled(&self) -> bool;
    /// The denoised full image, linear.
    fn read_denoised(&self, params: &DenoiseParams) -> Result<LinearImage>;
    /// The denoised full image, display-encoded at `exposure`.
    fn read_display_denoised(&self, params: &DenoiseParams, exposure: f32) -> Result<DisplayImage>;
    /// The guides: albedo, normal, distance per pixel.
    fn read_guides(&self) -> Result<GuideState>;
    /// Encodes the filter without reading it back (timing).
    fn encode_denoise(&self, enc: &mut wgpu::CommandEncoder, params: &DenoiseParams) -> Result<()>;
    /// The filter's dispatches ([`Denoising::encode_denoise_rows`]).
    fn denoise_stages(&self, params: &DenoiseParams) -> Result<usize>;
    /// Submits the rows `rows` of dispatch `stage` of the filter, alone: a filter run in steps,
    /// every row of a stage before the next, the image unchanged meanwhile
    /// ([`crate::passes::denoise::Denoiser::encode_rows`]).
    fn submit_denoise_rows(&self, params: &DenoiseParams, step: (usize, std::ops::Range<u32>)) -> Result<()>;
    /// Encodes the resolve of the denoiser's output image (as the last
    /// [`encode_denoise`](Denoising::encode_denoise) before it in submission order filtered it)
    /// at `exposure` into the film's linear and display buffers, with the display encoding of
    /// [`Progressive::encode_resolve`]: what a window draws is then the denoised full image.
    /// Changing the exposure needs no new filter.
    fn encode_resolve_denoised(&self, enc: &mut wgpu::CommandEncoder, exposure: f32) -> Result<()>;
}
