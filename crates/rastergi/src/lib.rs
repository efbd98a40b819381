//! rastergi: global illumination on the GPU with photon maps and a rasterized final gather.
//!
//! The modules follow the data flow of a render:
//!
//! scene → [`bvh`] → [`gpu_scene`] → [`photons`] (trace into the grid [`photons::map`]) → per
//! iteration ([`passes`]: [`passes::gbuffer`] → [`passes::specular`] chains → [`passes::direct`] →
//! [`gather`] ([`gather::raster`], [`gather::lists`] or [`gather::trace`])) → [`passes::film`]
//! (accumulate, resolve) → [`image_io`]. [`path_tracer`] is the reference; both it and the
//! [`renderer`] are [`progressive`] renderers. [`gpu`] holds the device, the shader composition
//! and the GPU's shared constants and limits; [`gpu::profile`] times the passes. [`session`] turns
//! a front end's options into a scene and a renderer, and runs it.
//!
//! [`renderer::Renderer::iterate`] is the one place that shows the order of the passes.

pub mod bsdf;
pub mod bvh;
pub mod camera_control;
pub mod checkpoint;
pub mod environment;
pub mod error;
pub mod fit;
pub mod gather;
pub mod gpu;
pub mod gpu_scene;
pub mod image_io;
pub mod lights;
pub mod metrics;
mod par;
pub mod passes;
pub mod path_tracer;
pub mod photons;
pub mod progressive;
pub mod rays;
pub mod renderer;
pub mod sampling;
pub mod scene;
pub mod session;
pub mod surface;
pub mod textures;

pub use error::{Error, Result};
