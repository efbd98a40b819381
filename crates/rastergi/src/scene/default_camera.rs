//! The camera of a scene whose file gives none (issue 45: an interior framed from outside
//! showed its roof, a grey rectangle for Sponza).
//!
//! The framing camera ([`Scene::framing_camera`]: the whole bounds from +z) is kept where what it
//! sees says something: its view rays' hits are mostly front faces and no one plane
//! orientation fills the view. Otherwise — the outside of a building, a wall, a roof — the scene
//! is searched for a room to stand in: candidate eye points on a grid over the bounds (at a
//! third and a half of its height), each probed with [`PROBE_DIRECTIONS`] rays spread evenly over
//! the sphere. A candidate is inside a room when at least [`MIN_ENCLOSURE`] of them hit a surface
//! and at most [`MAX_BACK_FACES`] of those hit a back face (more: it stands inside a solid or
//! outside a shell of one-sided walls). Among those, the one with the longest mean free path
//! wins (the most open place), and it looks horizontally along the longest free sight line that
//! ends on a front face, with a 60° vertical field of view.

use glam::Vec3;

use super::{Aabb, Camera, Scene, triangle_normal};
use crate::bvh::Bvh;

/// Rays probing each candidate eye point.
pub const PROBE_DIRECTIONS: usize = 96;
/// The share of a candidate's probes that must hit a surface for it to be inside a room.
pub const MIN_ENCLOSURE: f32 = 0.75;
/// The largest share of a candidate's hits that may be back faces.
pub const MAX_BACK_FACES: f32 = 0.25;
/// The framing camera's view is uninformative where one plane orientation takes this share of
/// its hits or more.
const MAX_ONE_ORIENTATION: f32 = 0.7;
/// Or where fewer than this share of its hits are front faces.
const MIN_FRONT_FACES: f32 = 0.5;
/// The inside camera's vertical field of view, degrees.
const INSIDE_FOV_DEG: f32 = 60.0;

impl Scene {
    /// The camera for a scene whose file names none (see the module's notes): the framing
    /// camera where its view shows the scene, else a camera standing in the scene's most open
    /// room, looking along its longest sight line.
    pub fn default_camera(&self) -> Camera {
        let bounds = self.bounds();
        let outside = Scene::framing_camera(&bounds);
        if self.triangles.is_empty() {
            return outside;
        }
        let bvh = Bvh::build(&self.triangles);
        let triangles = bvh.permute(&self.triangles);
        let probe = Probe { bvh: &bvh, triangles: &triangles, bounds };
        if probe.view_is_informative(&outside) {
            return outside;
        }
        probe.inside_camera().unwrap_or(outside)
    }
}

struct Probe<'a> {
    bvh: &'a Bvh,
    triangles: &'a [[Vec3; 3]],
    bounds: Aabb,
}

/// What one ray found: the distance and whether the face it met faces the ray's origin.
struct Seen {
    t: f32,
    front: bool,
    normal: Vec3,
}

impl Probe<'_> {
    fn cast(&self, o: Vec3, d: Vec3) -> Option<Seen> {
        let h = self.bvh.intersect(self.triangles, o, d, 0.0, f32::INFINITY, u32::MAX, |_| true)?;
        let normal = triangle_normal(&self.triangles[h.triangle as usize]);
        Some(Seen { t: h.t, front: normal.dot(d) < 0.0, normal })
    }

    /// Whether the camera's view (a 24 × 24 grid of rays) shows mostly front faces of more than
    /// one orientation.
    fn view_is_informative(&self, camera: &Camera) -> bool {
        let (right, up, forward) = camera.frame();
        let tan = (0.5 * camera.fov_y_deg.to_radians()).tan();
        let n = 24;
        let mut normals: Vec<Vec3> = Vec::new();
        let mut front = 0usize;
        for j in 0..n {
            for i in 0..n {
                let x = (2.0 * (i as f32 + 0.5) / n as f32 - 1.0) * tan;
                let y = (1.0 - 2.0 * (j as f32 + 0.5) / n as f32) * tan;
                if let Some(s) = self.cast(camera.eye, (forward + right * x + up * y).normalize()) {
                    front += s.front as usize;
                    // The plane's orientation, either side.
                    normals.push(if s.normal.dot(forward) > 0.0 { -s.normal } else { s.normal });
                }
            }
        }
        if normals.is_empty() {
            return false;
        }
        let hits = normals.len() as f32;
        // The largest group of hits whose normals lie within about 10° of one another's.
        let largest = normals.iter().map(|a| normals.iter().filter(|b| a.dot(**b) > 0.985).count()).max().unwrap_or(0);
        (front as f32) >= MIN_FRONT_FACES * hits && (largest as f32) < MAX_ONE_ORIENTATION * hits
    }

    /// The most open candidate inside a room, looking along its longest sight line; `None`
    /// where no candidate is inside one.
    fn inside_camera(&self) -> Option<Camera> {
        let directions = fibonacci_sphere(PROBE_DIRECTIONS);
        let (min, extent) = (self.bounds.min, self.bounds.extent());
        let fractions = [0.1f32, 0.3, 0.5, 0.7, 0.9];
        let mut best: Option<(f32, Vec3)> = None;
        for &fy in &[1.0f32 / 3.0, 0.5] {
            for &fx in &fractions {
                for &fz in &fractions {
                    let eye = min + extent * Vec3::new(fx, fy, fz);
                    let (mut hits, mut back, mut path) = (0usize, 0usize, 0.0f32);
                    for &d in &directions {
                        if let Some(s) = self.cast(eye, d) {
                            hits += 1;
                            back += !s.front as usize;
                            path += s.t;
                        }
                    }
                    let enclosed = hits as f32 >= MIN_ENCLOSURE * directions.len() as f32;
                    if !enclosed || back as f32 > MAX_BACK_FACES * hits as f32 {
                        continue;
                    }
                    let open = path / hits as f32;
                    if best.is_none_or(|(b, _)| open > b) {
                        best = Some((open, eye));
                    }
                }
            }
        }
        let (_, eye) = best?;
        // The longest horizontal sight line that ends on a front face.
        let mut look: Option<(f32, Vec3)> = None;
        for k in 0..32 {
            let a = k as f32 / 32.0 * std::f32::consts::TAU;
            let d = Vec3::new(a.cos(), 0.0, a.sin());
            if let Some(s) = self.cast(eye, d)
                && s.front
                && look.is_none_or(|(t, _)| s.t > t)
            {
                look = Some((s.t, d));
            }
        }
        let (_, d) = look?;
        Some(Camera { eye, target: eye + d, up: Vec3::Y, fov_y_deg: INSIDE_FOV_DEG })
    }
}

/// `n` directions spread evenly over the unit sphere (a Fibonacci lattice).
fn fibonacci_sphere(n: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), z, r * phi.sin())
        })
        .collect()
}
