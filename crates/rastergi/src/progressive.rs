//! The progressive-renderer interface shared by the photon-map renderer ([`Renderer`]) and the
//! reference path tracer ([`PathTracer`]): front ends (render, view, bench) drive either through
//! it. Each iteration adds one estimate per pixel to a [`Film`]; the image is the mean of the
//! estimates since the last restart (a camera move or [`Progressive::reset`]).

use crate::checkpoint::Progress;
use crate::error::Result;
use crate::image_io::{DisplayImage, LinearImage};
use crate::passes::film::{Film, FilmState, Show};
use crate::path_tracer::PathTracer;
use crate::renderer::{RenderSettings, Renderer};
use crate::scene::Camera;

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
    /// The photon-map renderer behind this one (its denoiser, [`Renderer::enable_denoiser`]);
    /// `None` for the path tracer.
    fn as_renderer(&self) -> Option<&Renderer> {
        None
    }
    fn as_renderer_mut(&mut self) -> Option<&mut Renderer> {
        None
    }
}

impl Progressive for Renderer {
    fn name(&self) -> &'static str {
        "rastergi photon map + final gather"
    }
    fn settings(&self) -> &RenderSettings {
        Renderer::settings(self)
    }
    fn iterate(&mut self) -> Result<()> {
        Renderer::iterate(self)
    }
    fn wait(&self) -> Result<()> {
        Renderer::wait(self)
    }
    fn samples(&self) -> u32 {
        Renderer::samples(self)
    }
    fn camera(&self) -> Camera {
        Renderer::camera(self)
    }
    fn set_camera(&mut self, camera: Camera) -> Result<()> {
        Renderer::set_camera(self, camera)
    }
    fn reset(&mut self) {
        Renderer::reset(self)
    }
    fn film(&self) -> &Film {
        Renderer::film(self)
    }
    fn has(&self, show: Show) -> bool {
        show != Show::PhotonMap || self.settings().show_photon_map
    }
    fn encode_resolve(&self, enc: &mut wgpu::CommandEncoder, show: Show, exposure: f32) {
        Renderer::encode_resolve(self, enc, show, exposure)
    }
    fn read_linear(&self, show: Show) -> Result<LinearImage> {
        Renderer::read_linear(self, show)
    }
    fn read_display(&self, show: Show, exposure: f32) -> Result<DisplayImage> {
        Renderer::read_display(self, show, exposure)
    }
    fn progress(&self) -> Progress {
        Renderer::progress(self)
    }
    fn film_state(&self) -> Result<FilmState> {
        Renderer::film_state(self)
    }
    fn resume(&mut self, progress: &Progress, film: &FilmState) -> Result<()> {
        Renderer::resume(self, progress, film)
    }
    fn as_renderer(&self) -> Option<&Renderer> {
        Some(self)
    }
    fn as_renderer_mut(&mut self) -> Option<&mut Renderer> {
        Some(self)
    }
}

impl Progressive for PathTracer {
    fn name(&self) -> &'static str {
        "rastergi path tracer"
    }
    fn settings(&self) -> &RenderSettings {
        PathTracer::settings(self)
    }
    fn iterate(&mut self) -> Result<()> {
        PathTracer::iterate(self);
        Ok(())
    }
    fn wait(&self) -> Result<()> {
        PathTracer::wait(self)
    }
    fn samples(&self) -> u32 {
        PathTracer::samples(self)
    }
    fn camera(&self) -> Camera {
        PathTracer::camera(self)
    }
    fn set_camera(&mut self, camera: Camera) -> Result<()> {
        PathTracer::set_camera(self, camera)
    }
    fn reset(&mut self) {
        PathTracer::reset(self)
    }
    fn film(&self) -> &Film {
        PathTracer::film(self)
    }
    fn has(&self, show: Show) -> bool {
        show == Show::Full
    }
    fn encode_resolve(&self, enc: &mut wgpu::CommandEncoder, _show: Show, exposure: f32) {
        PathTracer::encode_resolve(self, enc, exposure)
    }
    fn read_linear(&self, _show: Show) -> Result<LinearImage> {
        PathTracer::read_linear(self)
    }
    fn read_display(&self, _show: Show, exposure: f32) -> Result<DisplayImage> {
        PathTracer::read_display(self, exposure)
    }
    fn progress(&self) -> Progress {
        Progress::default()
    }
    fn film_state(&self) -> Result<FilmState> {
        PathTracer::film_state(self)
    }
    fn resume(&mut self, _progress: &Progress, film: &FilmState) -> Result<()> {
        PathTracer::resume(self, film)
    }
}
