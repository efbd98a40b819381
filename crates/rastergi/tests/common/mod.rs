//! Shared test harness: the GPU (lavapipe on CI), renders and references.
#![allow(dead_code)]

pub mod textured_room;

use std::path::PathBuf;

use rastergi::film::Show;
use rastergi::gpu::{Gpu, GpuOptions};
use rastergi::image_io::{LinearImage, read_exr};
use rastergi::renderer::{RenderSettings, Renderer};
use rastergi::scene::Scene;

pub fn gpu() -> Gpu {
    Gpu::new(&GpuOptions::default()).unwrap_or_else(|e| panic!("tests need a GPU adapter (lavapipe on CI): {e}"))
}

/// Renders `iterations` iterations and returns the mean image of `show`.
pub fn render(gpu: &Gpu, scene: &Scene, settings: RenderSettings, iterations: u32, show: Show) -> LinearImage {
    let mut r = Renderer::new(gpu, scene, settings).expect("renderer");
    for i in 0..iterations {
        r.iterate().expect("iteration");
        if i % 16 == 15 {
            r.wait().unwrap();
        }
    }
    r.read_linear(show).expect("readback")
}

pub fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

/// A committed reference pair (two independent renders): their mean, and the RMS noise of
/// that mean estimated from their difference, rmse(a, b)/2.
pub fn reference_pair(stem: &str, mask: Option<&[bool]>) -> (LinearImage, f64) {
    let a = read_exr(&data(&format!("{stem}_a.exr"))).expect("reference a");
    let b = read_exr(&data(&format!("{stem}_b.exr"))).expect("reference b");
    let noise = rastergi::metrics::rmse(&a, &b, mask) / 2.0;
    (average(&a, &b), noise)
}

pub fn average(a: &LinearImage, b: &LinearImage) -> LinearImage {
    LinearImage {
        width: a.width,
        height: a.height,
        pixels: a.pixels.iter().zip(&b.pixels).map(|(p, q)| [0, 1, 2].map(|c| 0.5 * (p[c] + q[c]))).collect(),
    }
}

/// A visible point decoded from a G-buffer texel (`Renderer::read_gbuffer`).
pub struct VisiblePoint {
    /// Triangle index in BVH order (`PreparedScene::scene`).
    pub tri: usize,
    pub b1: f32,
    pub b2: f32,
    /// Texture level of detail.
    pub lod: f32,
    pub pos: glam::Vec3,
    /// The triangle's geometric normal (counter-clockwise front).
    pub normal: glam::Vec3,
}

impl VisiblePoint {
    /// The point of G-buffer texel `g` of `scene` (prepared: triangles in BVH order), or
    /// `None` where the texel saw nothing.
    pub fn decode(scene: &Scene, g: [u32; 4]) -> Option<VisiblePoint> {
        let tri = (g[0] as usize).checked_sub(1)?;
        let (b1, b2, lod) = (f32::from_bits(g[1]), f32::from_bits(g[2]), f32::from_bits(g[3]));
        let t = scene.triangles[tri];
        let pos = t[0] * (1.0 - b1 - b2) + t[1] * b1 + t[2] * b2;
        Some(VisiblePoint { tri, b1, b2, lod, pos, normal: rastergi::scene::triangle_normal(&t) })
    }
}
