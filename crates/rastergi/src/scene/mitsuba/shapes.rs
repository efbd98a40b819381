//! Shape geometry: meshes (indexed, from `.serialized` and PLY files; triangle soups from the
//! OBJ loader) and Mitsuba's analytic shapes tessellated, in the shape's local space, then
//! placed by its `to_world` transform.
//!
//! - **Normals**: a mesh's own vertex normals where it has them; where it has none, vertex
//!   normals as Mitsuba computes them (each vertex the mean of the normals of the triangles
//!   around it weighted by their angles there, Thürmer and Wüthrich 1998), per vertex index —
//!   for OBJ triangles, per distinct (position, texture coordinate) pair, as Mitsuba's OBJ
//!   reader splits vertices. `face_normals` (or the `.serialized` flag) drops them: flat
//!   shading. Positions go through M, normals through (M⁻¹)ᵀ.
//! - **flip_normals** turns the front face around: the corners' order is reversed (our front
//!   face is the counter-clockwise one) and the shading normals negated.
//! - **Analytic shapes** (Mitsuba's local definitions): `rectangle` [−1, 1]² at z = 0 facing +z
//!   (uv = ((x + 1)/2, (y + 1)/2)); `cube` [−1, 1]³ facing out; `disk` the unit disk at z = 0
//!   facing +z ([`SEGMENTS`] sectors); `cylinder` the open tube of `radius` from `p0` to `p1`
//!   facing out; `sphere` of `radius` about `center` facing out ([`SEGMENTS`] × [`SEGMENTS`]/2
//!   latitude–longitude quads, uv = (φ/2π, θ/π), shading normals radial). A polygon inscribed in
//!   a circle has less area than the circle, so the tessellated disk, cylinder and sphere are
//!   scaled about their centre until their area is the exact one (an emitter keeps its power:
//!   Φ = π·L·A). A transform with a negative determinant mirrors an analytic shape; its corners
//!   are swapped so that it still faces the way Mitsuba's normal (M⁻¹)ᵀ n does. A mesh under
//!   such a transform faces the mirrored way, as in Mitsuba (its face normal is the cross
//!   product of its transformed edges).

use std::collections::HashMap;
use std::f32::consts::PI;

use glam::{Mat3, Mat4, Vec2, Vec3};

/// Sectors around a tessellated disk, cylinder or sphere (and half as many rings on a sphere).
pub const SEGMENTS: usize = 64;

/// An indexed triangle mesh as a file holds it.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// Empty, or one per vertex.
    pub normals: Vec<Vec3>,
    /// Empty, or one per vertex (Mitsuba's convention: v down the image, as the scene's).
    pub uvs: Vec<Vec2>,
    pub faces: Vec<[u32; 3]>,
    /// The file asks for flat shading.
    pub face_normals: bool,
}

/// A shape's triangles with their corners' texture coordinates and shading normals.
#[derive(Clone, Debug, Default)]
pub struct Soup {
    pub triangles: Vec<[Vec3; 3]>,
    pub uvs: Option<Vec<[Vec2; 3]>>,
    pub normals: Option<Vec<[Vec3; 3]>>,
}

/// The angle of triangle `t` at corner `k`.
fn corner_angle(t: &[Vec3; 3], k: usize) -> f32 {
    let (a, b) = ((t[(k + 1) % 3] - t[k]).normalize_or_zero(), (t[(k + 2) % 3] - t[k]).normalize_or_zero());
    a.dot(b).clamp(-1.0, 1.0).acos()
}

/// Angle-weighted vertex normals of the triangles, the corners grouped by `key`.
fn smooth_normals<K: std::hash::Hash + Eq>(triangles: &[[Vec3; 3]], key: impl Fn(usize, usize) -> K) -> Vec<[Vec3; 3]> {
    let mut sums: HashMap<K, Vec3> = HashMap::new();
    for (f, t) in triangles.iter().enumerate() {
        let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
        for k in 0..3 {
            *sums.entry(key(f, k)).or_insert(Vec3::ZERO) += n * corner_angle(t, k);
        }
    }
    (0..triangles.len()).map(|f| std::array::from_fn(|k| sums[&key(f, k)].normalize_or_zero())).collect()
}

impl Mesh {
    /// The mesh's triangles; shading normals its own or computed, none where `flat`.
    pub fn into_soup(self, flat: bool) -> Soup {
        let flat = flat || self.face_normals;
        let corners = |f: &[u32; 3]| f.map(|i| i as usize);
        let triangles: Vec<[Vec3; 3]> = self.faces.iter().map(|f| corners(f).map(|i| self.positions[i])).collect();
        let uvs = (self.uvs.len() == self.positions.len() && !self.uvs.is_empty())
            .then(|| self.faces.iter().map(|f| corners(f).map(|i| self.uvs[i])).collect());
        let normals = if flat {
            None
        } else if self.normals.len() == self.positions.len() && !self.normals.is_empty() {
            Some(self.faces.iter().map(|f| corners(f).map(|i| self.normals[i])).collect())
        } else {
            Some(smooth_normals(&triangles, |f, k| self.faces[f][k]))
        };
        Soup { triangles, uvs, normals }
    }
}

impl Soup {
    /// Shading normals for a soup without them: per distinct (position, uv) corner.
    pub fn with_smooth_normals(mut self) -> Soup {
        if self.normals.is_none() {
            let bits = |v: Vec3| v.to_array().map(f32::to_bits);
            let uv = |f: usize, k: usize| self.uvs.as_ref().map_or([0; 2], |u| u[f][k].to_array().map(f32::to_bits));
            self.normals = Some(smooth_normals(&self.triangles, |f, k| (bits(self.triangles[f][k]), uv(f, k))));
        }
        self
    }

    /// Places the soup by `m`; `flip` reverses its front face.
    pub fn transformed(mut self, m: Mat4, flip: bool) -> Soup {
        let normal_matrix = Mat3::from_mat4(m).inverse().transpose();
        for t in &mut self.triangles {
            *t = t.map(|p| m.transform_point3(p));
        }
        if let Some(normals) = &mut self.normals {
            for n in normals.iter_mut() {
                *n = n.map(|v| (normal_matrix * v).normalize_or_zero() * if flip { -1.0 } else { 1.0 });
            }
        }
        if flip {
            self.triangles.iter_mut().for_each(|t| t.swap(1, 2));
            self.uvs.iter_mut().flatten().for_each(|t| t.swap(1, 2));
            self.normals.iter_mut().flatten().for_each(|t| t.swap(1, 2));
        }
        self
    }

    fn push(&mut self, t: [Vec3; 3], uv: [Vec2; 3], n: Option<[Vec3; 3]>) {
        self.triangles.push(t);
        self.uvs.get_or_insert_with(Vec::new).push(uv);
        if let Some(n) = n {
            self.normals.get_or_insert_with(Vec::new).push(n);
        }
    }
}

/// Mitsuba's `rectangle`: [−1, 1]² at z = 0, facing +z.
pub fn rectangle() -> Soup {
    let p = |x: f32, y: f32| Vec3::new(x, y, 0.0);
    let uv = |x: f32, y: f32| Vec2::new(0.5 * x + 0.5, 0.5 * y + 0.5);
    let mut s = Soup::default();
    s.push([p(-1., -1.), p(1., -1.), p(1., 1.)], [uv(-1., -1.), uv(1., -1.), uv(1., 1.)], None);
    s.push([p(-1., -1.), p(1., 1.), p(-1., 1.)], [uv(-1., -1.), uv(1., 1.), uv(-1., 1.)], None);
    s
}

/// Mitsuba's `cube`: [−1, 1]³, each face facing out, uv over each face.
pub fn cube() -> Soup {
    let mut s = Soup::default();
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            // A frame (u, v, n) with u × v = n pointing out.
            let n = Vec3::from(std::array::from_fn::<f32, 3, _>(|k| if k == axis { sign } else { 0.0 }));
            let u = Vec3::from(std::array::from_fn::<f32, 3, _>(|k| if k == (axis + 1) % 3 { 1.0 } else { 0.0 }));
            let v = n.cross(u);
            let p = |a: f32, b: f32| n + a * u + b * v;
            let uv = |a: f32, b: f32| Vec2::new(0.5 * a + 0.5, 0.5 * b + 0.5);
            s.push([p(-1., -1.), p(1., -1.), p(1., 1.)], [uv(-1., -1.), uv(1., -1.), uv(1., 1.)], None);
            s.push([p(-1., -1.), p(1., 1.), p(-1., 1.)], [uv(-1., -1.), uv(1., 1.), uv(-1., 1.)], None);
        }
    }
    s
}

/// The factor that gives a regular n-gon inscribed in the unit circle the circle's area.
fn polygon_area_scale(n: usize) -> f32 {
    let area = 0.5 * n as f32 * (2.0 * PI / n as f32).sin();
    (PI / area).sqrt()
}

/// Mitsuba's `disk`: the unit disk at z = 0 facing +z, uv = (r, φ/2π).
pub fn disk() -> Soup {
    let r = polygon_area_scale(SEGMENTS);
    let mut s = Soup::default();
    for i in 0..SEGMENTS {
        let (a, b) = (i as f32 / SEGMENTS as f32, (i + 1) as f32 / SEGMENTS as f32);
        let p = |t: f32| Vec3::new(r * (2.0 * PI * t).cos(), r * (2.0 * PI * t).sin(), 0.0);
        s.push([Vec3::ZERO, p(a), p(b)], [Vec2::new(0.0, a), Vec2::new(1.0, a), Vec2::new(1.0, b)], None);
    }
    s
}

/// Mitsuba's `cylinder`: the open tube of `radius` from `p0` to `p1`, facing out, uv = (φ/2π,
/// t along the axis), radial shading normals.
pub fn cylinder(p0: Vec3, p1: Vec3, radius: f32) -> Option<Soup> {
    let axis = p1 - p0;
    let length = axis.length();
    if !(length > 0.0 && radius > 0.0) {
        return None;
    }
    let w = axis / length;
    let u = w.any_orthonormal_vector();
    let v = w.cross(u);
    // The perimeter of the inscribed polygon made the circle's: the lateral area is exact.
    let r = radius * PI / (SEGMENTS as f32 * (PI / SEGMENTS as f32).sin());
    let mut s = Soup::default();
    for i in 0..SEGMENTS {
        let (a, b) = (i as f32 / SEGMENTS as f32, (i + 1) as f32 / SEGMENTS as f32);
        let radial = |t: f32| (2.0 * PI * t).cos() * u + (2.0 * PI * t).sin() * v;
        let (na, nb) = (radial(a), radial(b));
        let (q0, q1, q2, q3) = (p0 + r * na, p0 + r * nb, p1 + r * nb, p1 + r * na);
        s.push([q0, q1, q2], [Vec2::new(a, 0.0), Vec2::new(b, 0.0), Vec2::new(b, 1.0)], Some([na, nb, nb]));
        s.push([q0, q2, q3], [Vec2::new(a, 0.0), Vec2::new(b, 1.0), Vec2::new(a, 1.0)], Some([na, nb, na]));
    }
    Some(s)
}

/// A unit sphere about the origin (scaled to the exact area), facing out.
pub fn sphere() -> Soup {
    let (n_phi, n_theta) = (SEGMENTS, SEGMENTS / 2);
    let dir = |i: usize, j: usize| {
        let (phi, theta) = (2.0 * PI * i as f32 / n_phi as f32, PI * j as f32 / n_theta as f32);
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    };
    let uv = |i: usize, j: usize| Vec2::new(i as f32 / n_phi as f32, j as f32 / n_theta as f32);
    let mut s = Soup::default();
    for j in 0..n_theta {
        for i in 0..n_phi {
            let (a, b, c, d) = (dir(i, j), dir(i + 1, j), dir(i + 1, j + 1), dir(i, j + 1));
            let (ua, ub, uc, ud) = (uv(i, j), uv(i + 1, j), uv(i + 1, j + 1), uv(i, j + 1));
            // Counter-clockwise seen from outside: θ grows downwards from +z, φ to the left.
            if j + 1 < n_theta {
                s.push([a, d, c], [ua, ud, uc], Some([a, d, c]));
            }
            if j > 0 {
                s.push([a, c, b], [ua, uc, ub], Some([a, c, b]));
            }
        }
    }
    let area: f32 = s.triangles.iter().map(crate::scene::triangle_area).sum();
    let scale = (4.0 * PI / area).sqrt();
    s.triangles.iter_mut().for_each(|t| *t = t.map(|p| p * scale));
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{triangle_area, triangle_normal};

    fn area(s: &Soup) -> f32 {
        s.triangles.iter().map(triangle_area).sum()
    }

    #[test]
    fn tessellated_shapes_have_the_exact_area_and_face_out() {
        assert!((area(&sphere()) - 4.0 * PI).abs() < 1e-3);
        assert!((area(&disk()) - PI).abs() < 1e-4);
        let c = cylinder(Vec3::ZERO, Vec3::Z * 2.0, 0.5).unwrap();
        assert!((area(&c) - 2.0 * PI * 0.5 * 2.0).abs() < 1e-3);
        assert!((area(&cube()) - 24.0).abs() < 1e-5);
        for t in &sphere().triangles {
            let centre = (t[0] + t[1] + t[2]) / 3.0;
            assert!(triangle_normal(t).dot(centre) > 0.0);
        }
        for t in &cube().triangles {
            assert!(triangle_normal(t).dot((t[0] + t[1] + t[2]) / 3.0) > 0.0);
        }
        for t in &c.triangles {
            let centre = (t[0] + t[1] + t[2]) / 3.0;
            assert!(triangle_normal(t).dot(centre - Vec3::new(0.0, 0.0, centre.z)) > 0.0);
        }
        assert!(disk().triangles.iter().chain(&rectangle().triangles).all(|t| triangle_normal(t).z > 0.999));
    }

    #[test]
    fn a_flat_fan_gets_the_plane_normal_and_flipping_turns_the_front() {
        let mesh = Mesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::X],
            faces: vec![[0, 1, 2], [0, 2, 3]],
            ..Default::default()
        };
        let soup = mesh.into_soup(false);
        assert!(soup.normals.as_ref().unwrap().iter().flatten().all(|n| (*n - Vec3::Z).length() < 1e-6));
        let flipped = soup.transformed(Mat4::IDENTITY, true);
        assert!(flipped.triangles.iter().all(|t| triangle_normal(t).z < -0.999));
        assert!(flipped.normals.unwrap().iter().flatten().all(|n| (*n + Vec3::Z).length() < 1e-6));
    }
}
