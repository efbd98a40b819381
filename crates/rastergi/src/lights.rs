//! The emitters of a scene as a discrete distribution: a triangle is chosen with probability
//! proportional to its emitted power π·A·(Le.r + Le.g + Le.b), then a point uniformly on it.
//! The same table drives the photon pass (emission) and the direct pass (light samples).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::scene::{Scene, triangle_area};

/// One emissive triangle, as stored on the GPU (`LightEntry` in `gpu_scene.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct LightEntry {
    /// Index of the triangle in the scene.
    pub triangle: u32,
    /// Cumulative probability up to and including this entry.
    pub cdf: f32,
    /// Probability of choosing this entry.
    pub pmf: f32,
    /// Area of the triangle.
    pub area: f32,
}

#[derive(Clone, Debug, Default)]
pub struct LightTable {
    pub entries: Vec<LightEntry>,
    /// Total emitted power Φ (RGB), in watts of the scene's units.
    pub power: Vec3,
}

impl LightTable {
    pub fn new(scene: &Scene) -> Self {
        let tris = scene.emissive_triangles();
        let weights: Vec<f64> = tris
            .iter()
            .map(|&i| {
                let le = scene.material_of(i as usize).emission;
                (triangle_area(&scene.triangles[i as usize]) * (le.x + le.y + le.z)) as f64
            })
            .collect();
        let total: f64 = weights.iter().sum();
        let mut acc = 0.0f64;
        let mut entries: Vec<LightEntry> = tris
            .iter()
            .zip(&weights)
            .map(|(&i, &w)| {
                acc += w;
                LightEntry {
                    triangle: i,
                    cdf: (acc / total) as f32,
                    pmf: (w / total) as f32,
                    area: triangle_area(&scene.triangles[i as usize]),
                }
            })
            .collect();
        if let Some(last) = entries.last_mut() {
            last.cdf = 1.0;
        }
        Self { entries, power: scene.emitted_power() }
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The entry whose cdf interval holds u ∈ [0,1): the first with `u < cdf`.
    /// Mirrors `light_pick` in `gpu_scene.wgsl`.
    pub fn pick(&self, u: f32) -> &LightEntry {
        let i = self.entries.partition_point(|e| e.cdf <= u);
        &self.entries[i.min(self.entries.len() - 1)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Material};

    #[test]
    fn picks_in_proportion_to_power() {
        let cam = Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        let mut s = Scene::new(cam);
        let a = s.add_material(Material { emission: Vec3::ONE, ..Material::diffuse("a", Vec3::ZERO) });
        let b = s.add_material(Material { emission: Vec3::splat(3.0), ..Material::diffuse("b", Vec3::ZERO) });
        s.add_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], a);
        s.add_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], b);
        let t = LightTable::new(&s);
        assert!((t.entries[0].pmf - 0.25).abs() < 1e-6 && (t.entries[1].pmf - 0.75).abs() < 1e-6);
        assert_eq!(t.pick(0.0).triangle, 0);
        assert_eq!(t.pick(0.2499).triangle, 0);
        assert_eq!(t.pick(0.25).triangle, 1);
        assert_eq!(t.pick(0.9999).triangle, 1);
    }
}
