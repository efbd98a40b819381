//! The interactive loop that a window and a web page share: a progressive render being looked
//! at. A camera move restarts the image; the shown component, the exposure and the denoiser
//! are the viewer's choices; the denoised image is filtered again on a [`Schedule`] (more
//! iterations, or time) and resolved for display in between.

use crate::denoise::Schedule;
use crate::error::Result;
use crate::film::Show;
use crate::progressive::{Denoising, Progressive};
use crate::scene::Camera;

/// A progressive render as a viewer shows it.
pub struct Interactive {
    renderer: Box<dyn Progressive>,
    /// The component shown (the full image where the renderer lacks it).
    pub show: Show,
    /// Exposure in stops.
    pub exposure: f32,
    /// Whether the denoised full image is shown (where the renderer has a denoiser).
    denoise: bool,
    /// When the denoiser last ran for the display.
    denoised: Schedule,
}

impl Interactive {
    pub fn new(renderer: Box<dyn Progressive>, show: Show, exposure: f32) -> Interactive {
        Interactive { renderer, show, exposure, denoise: false, denoised: Schedule::default() }
    }

    pub fn renderer(&self) -> &dyn Progressive {
        self.renderer.as_ref()
    }

    /// The renderer, for iterating; a change to its image must be followed by
    /// [`Interactive::invalidate`].
    pub fn renderer_mut(&mut self) -> &mut dyn Progressive {
        self.renderer.as_mut()
    }

    /// A new renderer in place of the old (a setting changed): the camera goes with the view;
    /// where the denoiser is on, the new renderer's is enabled too.
    pub fn replace(&mut self, mut renderer: Box<dyn Progressive>, keep_camera: bool) -> Result<()> {
        if keep_camera {
            renderer.set_camera(self.renderer.camera())?;
        }
        if self.denoise {
            enable(renderer.as_mut())?;
        }
        self.renderer = renderer;
        self.denoised.clear();
        Ok(())
    }

    /// Moves the camera: the image restarts.
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        self.renderer.set_camera(camera)?;
        self.denoised.clear();
        Ok(())
    }

    /// Shows the denoised image or not. Turning it on enables the renderer's denoiser where it
    /// has one and none yet (fails where its buffers exceed the device's limits, leaving it
    /// off); its guides hold the iterations from then on, so an image that has iterations
    /// restarts.
    pub fn set_denoise(&mut self, on: bool) -> Result<()> {
        if on {
            enable(self.renderer.as_mut())?;
        }
        self.denoise = on;
        self.denoised.clear();
        Ok(())
    }

    pub fn denoise(&self) -> bool {
        self.denoise
    }

    /// The renderer's denoiser while the denoised full image is shown.
    pub fn denoising(&self) -> Option<&dyn Denoising> {
        let shown = self.denoise && self.show == Show::Full;
        self.renderer.denoising().filter(|r| shown && r.denoiser_enabled())
    }

    /// The shown image changed other than by iterations (a new renderer, a restart, a save
    /// that filters at once): the next denoised image is filtered at once.
    pub fn invalidate(&mut self) {
        self.denoised.clear();
    }

    /// Encodes the resolve of what is shown into the film's display buffer: the raw image of
    /// the shown component, or the denoised full image, filtered again first when the schedule
    /// says so at `now` (seconds from any fixed origin).
    pub fn encode_resolve(&mut self, enc: &mut wgpu::CommandEncoder, now: f64) -> Result<()> {
        let mut schedule = self.denoised;
        if let Some(r) = self.denoising() {
            r.encode_denoised_view(enc, &mut schedule, now, self.exposure)?;
            self.denoised = schedule;
        } else {
            let show = if self.renderer.has(self.show) { self.show } else { Show::Full };
            self.renderer.encode_resolve(enc, show, self.exposure);
            self.denoised.clear();
        }
        Ok(())
    }
}

/// Enables `renderer`'s denoiser where it has one and none yet, restarting an image that has
/// iterations (they have no guides).
fn enable(renderer: &mut dyn Progressive) -> Result<()> {
    let Some(d) = renderer.denoising_mut().filter(|d| !d.denoiser_enabled()) else { return Ok(()) };
    d.enable_denoiser()?;
    if renderer.samples() > 0 {
        renderer.reset();
    }
    Ok(())
}
