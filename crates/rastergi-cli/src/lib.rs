//! The subcommands of the `rastergi` program, as a library: the binary (`main.rs`) parses the
//! command line into them. Their scene, renderer and GPU options ([`args::SceneArgs`]), the
//! scene loading, the building of the renderer and the render loop are the `rastergi`
//! library's (`rastergi::session`), which the Python package uses too, so both take the same
//! options, give the same images and say the same things about bad input.

pub mod args;
pub mod bench;
pub mod compare;
pub mod export;
pub mod merge;
pub mod noise;
pub mod render;
pub mod serve;
pub mod view;
