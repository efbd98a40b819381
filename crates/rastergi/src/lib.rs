//! rastergi: global illumination on the GPU with photon maps and a rasterized final gather.
//!
//! The modules follow the data flow of a render:
//!
//! scene → [`bvh`] → [`gpu_scene`] → [`photons`] (trace into the grid [`photons::map`]) → per
//! iteration ([`gbuffer`] → [`specular`] chains → [`direct`] → [`gather`] ([`gather::raster`], [`gather::lists`] or
//! [`gather::trace`])) → [`film`] (accumulate, resolve) → [`image_io`]. [`path_tracer`] is the
//! reference; both it and the [`renderer`] are [`progressive`] renderers. [`profile`] times the
//! passes. [`session`] turns a front end's options into a scene and a renderer, and runs it.
//!
//! [`renderer::Renderer::iterate`] is the one place that shows the order of the passes.

pub mod accel;
pub mod binding;
pub mod bsdf;
pub mod bvh;
pub mod camera_control;
pub mod checkpoint;
pub mod compiled;
pub mod consts;
pub mod denoise;
pub mod direct;
pub mod display;
pub mod environment;
pub mod error;
pub mod film;
pub mod fit;
pub mod frame;
pub mod gather;
pub mod gbuffer;
pub mod gpu;
pub mod gpu_scene;
pub mod image_io;
#[cfg(test)]
mod layout_test;
pub mod lights;
pub mod limits;
pub mod metrics;
mod par;
pub mod pass;
pub mod path_tracer;
pub mod photon_view;
pub mod photons;
pub mod profile;
pub mod progressive;
pub mod rays;
pub mod renderer;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod settings;
mod shader;
pub mod sky;
mod sky_sun_table;
pub mod specular;
pub mod textures;

pub use error::{Error, Result};
