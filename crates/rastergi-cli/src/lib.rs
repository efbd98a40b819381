//! The subcommands of the `rastergi` program, as a library: the binary (`main.rs`) parses the
//! command line into them, and the Python package (`python/`) builds its renders from the same
//! options ([`args::SceneArgs`]), so both take the same options, give the same images and say
//! the same things about bad input.

pub mod args;
pub mod bench;
pub mod compare;
pub mod export;
pub mod merge;
pub mod render;
pub mod serve;
pub mod view;
