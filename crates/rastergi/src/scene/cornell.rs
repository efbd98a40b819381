//! The built-in Cornell box: exactly Mitsuba 3's `mi.cornell_box()` geometry, materials and
//! camera (see `docs/cornell-box.md`), so renders compare pixel by pixel with Mitsuba.

use glam::{Mat3, Vec3};

use super::{Camera, Material, Scene};

const WHITE: Vec3 = Vec3::new(0.885809, 0.698859, 0.666422);
const RED: Vec3 = Vec3::new(0.570068, 0.0430135, 0.0443706);
const GREEN: Vec3 = Vec3::new(0.105421, 0.37798, 0.076425);
const LIGHT_RADIANCE: Vec3 = Vec3::new(18.387, 13.9873, 6.75357);

/// Small box: the cube [-1,1]³ mapped by the row-major 3×4 matrix [R|t].
const SMALL_BOX: [[f32; 4]; 3] =
    [[0.28689146, 0.0, -0.08771151, 0.335], [0.0, 0.3, 0.0, -0.7], [0.08771151, 0.0, 0.28689146, 0.38]];
/// Large box, likewise; its bottom is 1 cm under the floor.
const LARGE_BOX: [[f32; 4]; 3] =
    [[0.28490975, 0.0, 0.09394914, -0.33], [0.0, 0.61, 0.0, -0.4], [-0.09394914, 0.0, 0.28490975, -0.28]];

/// Corners of the parallelogram `c ± u ± v`, counter-clockwise about the normal `u × v`.
fn quad(c: Vec3, u: Vec3, v: Vec3) -> [Vec3; 4] {
    [c - u - v, c + u - v, c + u + v, c - u + v]
}

/// The six faces of the cube [-1,1]³ mapped by `m`, with outward normals.
fn add_box(scene: &mut Scene, m: [[f32; 4]; 3], material: u32) {
    let linear = Mat3::from_cols_array_2d(&[
        [m[0][0], m[1][0], m[2][0]],
        [m[0][1], m[1][1], m[2][1]],
        [m[0][2], m[1][2], m[2][2]],
    ]);
    let t = Vec3::new(m[0][3], m[1][3], m[2][3]);
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::AXES[axis] * sign;
            // u × v = n: u = the next axis, v = the one after, flipped for the negative side.
            let u = Vec3::AXES[(axis + 1) % 3];
            let v = Vec3::AXES[(axis + 2) % 3] * sign;
            let corners = quad(n, u, v).map(|p| linear * p + t);
            scene.add_quad(corners, material);
        }
    }
}

/// The Cornell box of `shared/cornell-box.md` (Mitsuba 3.9.1's `mi.cornell_box()`).
pub fn cornell_box() -> Scene {
    let camera = Camera { eye: Vec3::new(0.0, 0.0, 3.9), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 39.3077 };
    let mut s = Scene::new(camera);
    let white = s.add_material(Material::diffuse("white", WHITE));
    let red = s.add_material(Material::diffuse("red", RED));
    let green = s.add_material(Material::diffuse("green", GREEN));
    let light = s.add_material(Material { emission: LIGHT_RADIANCE, ..Material::diffuse("light", WHITE) });

    let (x, y, z) = (Vec3::X, Vec3::Y, Vec3::Z);
    s.add_quad(quad(-y, z, x), white); // floor, normal +y
    s.add_quad(quad(y, x, z), white); // ceiling, normal -y
    s.add_quad(quad(-z, x, y), white); // back wall, normal +z
    s.add_quad(quad(-x, y, z), red); // left wall, normal +x
    s.add_quad(quad(x, z, y), green); // right wall, normal -x
    // Light: x in [-0.23, 0.23], z in [-0.18, 0.20], y = 0.99, facing -y.
    s.add_quad(quad(Vec3::new(0.0, 0.99, 0.01), 0.23 * x, 0.19 * z), light);
    add_box(&mut s, SMALL_BOX, white);
    add_box(&mut s, LARGE_BOX, white);
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{triangle_area, triangle_normal};

    #[test]
    fn walls_face_into_the_box_and_boxes_face_out() {
        let s = cornell_box();
        assert_eq!(s.triangles.len(), 2 * (5 + 1 + 6 + 6));
        for (i, t) in s.triangles.iter().enumerate() {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            let n = triangle_normal(t);
            if i < 12 {
                // Walls and light: the normal points towards the box centre (the origin).
                assert!(n.dot(-c) > 0.0, "triangle {i} faces away from the inside");
            } else {
                // Box faces: the normal points away from that box's centre.
                let centre = if i < 24 { Vec3::new(0.335, -0.7, 0.38) } else { Vec3::new(-0.33, -0.4, -0.28) };
                assert!(n.dot(c - centre) > 0.0, "box triangle {i} faces inwards");
            }
        }
    }

    #[test]
    fn light_has_the_documented_rectangle_and_power() {
        let s = cornell_box();
        let lights = s.emissive_triangles();
        assert_eq!(lights.len(), 2);
        let area: f32 = lights.iter().map(|&i| triangle_area(&s.triangles[i as usize])).sum();
        assert!((area - 0.46 * 0.38).abs() < 1e-5);
        for &i in &lights {
            assert!((triangle_normal(&s.triangles[i as usize]) - Vec3::NEG_Y).length() < 1e-6);
        }
        let expected = std::f32::consts::PI * 0.46 * 0.38 * LIGHT_RADIANCE;
        assert!((s.emitted_power() - expected).length() < 1e-4 * expected.length());
    }
}
