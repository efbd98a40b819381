//! rastergi: global illumination on the GPU with photon maps and a rasterized final gather.
//!
//! The modules follow the data flow of a render:
//!
//! [`scene`] (loaders, materials, camera, lights, the sky) → [`bvh`] → [`surface`] (the prepared
//! scene the CPU twins query) → [`gpu_scene`] (its upload; [`rays::probe`] picks the ray path) →
//! [`photons`] (trace into the grid [`photons::map`]) → per iteration, the [`passes`]
//! ([`passes::frame`] → [`passes::gbuffer`] → [`passes::specular`] chains → [`passes::direct`] →
//! [`gather`] ([`gather::raster`], [`gather::lists`] or [`gather::trace`])) → [`passes::film`]
//! (accumulate, resolve) → [`passes::denoise`] → [`passes::display`] or [`image_io`].
//! [`path_tracer`] is the reference; both it and the [`renderer`] are [`progressive`] renderers.
//! Beneath them: [`bsdf`] (the scattering model by lobe, each beside its WGSL twin),
//! [`sampling`], [`lights`], [`environment`], [`textures`], and [`gpu`] (the device, shader
//! composition, the constants Rust and WGSL share, limits, pass timings in [`gpu::profile`]).
//! [`session`] turns a front end's options into a scene and a renderer, and runs it;
//! [`fuzzing`] drives the readers as their fuzz targets do.
//!
//! [`renderer::Renderer::iterate`] is the one place that shows the order of the passes.

pub mod bsdf;
pub mod bvh;
pub mod camera_control;
pub mod checkpoint;
pub mod environment;
pub mod error;
pub mod fit;
pub mod fuzzing;
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
pub mod settings;
pub mod surface;
pub mod textures;

pub use error::{Error, Result};
