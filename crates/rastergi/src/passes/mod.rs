//! The per-iteration passes over the image, in the order [`crate::renderer::Renderer::iterate`]
//! runs them: [`frame`] (the iteration's camera and uniforms) → [`gbuffer`] → [`specular`] chains
//! → [`emitter_edges`] (keys) → [`direct`] → the final gather ([`crate::gather`]) and [`photon_view`] → [`film`]
//! (accumulate, resolve) → [`denoise`] → [`display`].
//!
//! What the passes of an iteration share: one [`FrameContext`] that each reads, and one
//! [`IterationPass::encode`] signature. A pass's own resources (its bind groups,
//! [`crate::gpu::binding`]) are bound to the G-buffer and film it was made with; what changes from
//! iteration to iteration — the frame's uniforms, the photon map of the current photon pass,
//! the gather's directions — comes through the context. [`crate::renderer::Renderer::iterate`]
//! runs them in the order of the data flow.

pub mod denoise;
pub mod direct;
pub mod display;
pub mod emitter_edges;
pub mod film;
pub mod frame;
pub mod gbuffer;
pub mod history;
pub mod light_budget;
pub mod photon_view;
pub mod sky_guide;
pub mod specular;

use glam::{Vec2, Vec3};

use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu::shader::{self, BVH, SAMPLING};
use crate::gpu_scene::GpuScene;
use crate::passes::frame::FrameBinding;
use crate::photons::gpu::GpuPhotonMap;

/// The G-buffer texel → visible point decode (`visible_point`), for per-pixel passes.
pub const VISIBLE_POINT: &str = include_str!("visible_point.wgsl");
/// Film writes by component (`film_add`), for passes that bind `film`.
pub const FILM: &str = include_str!("film.wgsl");
/// The camera ray's texture footprint (ray differentials) where the visible point is traced.
pub const EYE_RAY: &str = include_str!("eye_ray.wgsl");

/// The common prelude of every pass that reads the scene (its bind group 0) and the frame
/// (bind group 1, [`frame::wgsl`]), then `pass`.
pub fn with_scene(pass: &str) -> String {
    shader::compose(&[SAMPLING, &crate::gpu_scene::wgsl(), BVH, &frame::wgsl(), pass])
}

/// The prelude of a per-pixel pass over the G-buffer that adds to the film, then `pieces`.
pub fn per_pixel(pieces: &[&str]) -> String {
    let (scene, frame) = (crate::gpu_scene::wgsl(), frame::wgsl());
    let mut all = vec![SAMPLING, scene.as_str(), BVH, frame.as_str(), VISIBLE_POINT, FILM];
    all.extend_from_slice(pieces);
    shader::compose(&all)
}

/// What every pass of one iteration reads besides its own resources.
#[derive(Clone)]
pub struct FrameContext<'a> {
    pub gpu: &'a Gpu,
    /// Bind group 0 of every pass.
    pub scene: &'a GpuScene,
    /// Bind group 1: this iteration's uniforms (camera jitter, seed, gather strategy).
    pub frame: &'a FrameBinding,
    /// The current photon pass's map; `None` where the render has none (direct light only).
    pub map: Option<&'a GpuPhotonMap>,
    pub width: u32,
    pub height: u32,
    /// The rows of this dispatch, from row `y0` on (the frame's `band_y0`): `height` from 0
    /// for a whole iteration, fewer for one of its row bands
    /// ([`crate::renderer::Renderer::iterate_rows`]).
    pub y0: u32,
    pub rows: u32,
    /// The iteration's index since the film was last cleared.
    pub iteration: u32,
    /// The gather's directions per pixel and iteration (1 to [`crate::gpu::consts::MAX_DIRECTIONS`]).
    pub directions: u32,
    /// Random choices fixed for a test ([`crate::renderer::Overrides`]).
    pub fixed: FixedSample,
}

/// Values that replace the sampler's for one iteration (tests compare the gather with other
/// estimators for the same samples).
#[derive(Clone, Copy, Debug, Default)]
pub struct FixedSample {
    /// One direction ω instead of the iteration's.
    pub direction: Option<Vec3>,
    /// The ray view's sub-texel offset instead of a random one.
    pub texel_jitter: Option<Vec2>,
}

/// One pass of an iteration: it adds its commands to `enc` (an implementation that must read
/// a result back may submit `enc` and leave a new encoder in it).
pub trait IterationPass {
    fn encode(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext) -> Result<()>;
}
