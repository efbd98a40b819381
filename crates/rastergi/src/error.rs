//! The library's error type. Every message is one line that says what is wrong and, where
//! it helps, what to do about it.

use std::path::PathBuf;

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Another crate's error message on one line (`image`'s, `exr`'s, `flate2`'s may hold line
/// breaks, which would make an error of several lines): line breaks and other control
/// characters become spaces, runs of white space one.
pub fn one_line(message: impl std::fmt::Display) -> String {
    let text = message.to_string();
    text.split(|c: char| c.is_whitespace() || c.is_control()).filter(|w| !w.is_empty()).collect::<Vec<_>>().join(" ")
}

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error(
        "no GPU adapter found{0}; install a Vulkan driver (on Debian without a GPU: `apt-get install mesa-vulkan-drivers libvulkan1` for the lavapipe CPU rasterizer) or choose another backend with --backend / WGPU_BACKEND"
    )]
    NoAdapter(String),
    #[error("could not open the GPU device: {0}")]
    Device(String),
    #[error("{0}")]
    Limits(String),
    #[error("{}: {message}", path.display())]
    SceneFile { path: PathBuf, message: String },
    #[error("invalid scene: {0}")]
    InvalidScene(String),
    #[error("invalid camera: {0}")]
    InvalidCamera(String),
    #[error("{}: {message}", path.display())]
    ImageFile { path: PathBuf, message: String },
    #[error("GPU error: {0}")]
    Gpu(String),
    #[error("{0}")]
    Checkpoint(String),
    #[error("checkpoint {}: {message}", path.display())]
    CheckpointFile { path: PathBuf, message: String },
    /// Options, or inputs, that do not fit together (a front end's flags named in the message:
    /// `--sky` without a sun, two images of different sizes to compare).
    #[error("{0}")]
    Invalid(String),
}
