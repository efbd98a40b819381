//! The per-iteration passes over the image, in the order [`crate::renderer::Renderer::iterate`]
//! runs them: [`frame`] (the iteration's camera and uniforms) → [`gbuffer`] → [`specular`] chains
//! → [`direct`] → the final gather ([`crate::gather`]) and [`photon_view`] → [`film`]
//! (accumulate, resolve) → [`denoise`] → [`display`].

pub mod denoise;
pub mod direct;
pub mod display;
pub mod film;
pub mod frame;
pub mod gbuffer;
pub mod photon_view;
pub mod specular;
