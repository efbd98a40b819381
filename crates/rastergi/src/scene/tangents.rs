//! Tangents for normal maps where a model gives none: MikkTSpace (Mortensen's algorithm, the
//! one glTF names and Blender, Substance and most bakers use), through the `bevy_mikktspace`
//! crate (a safe Rust port of the reference C implementation, matching its results).
//!
//! The scene's texture coordinates have v down the image (glTF's convention); MikkTSpace is
//! fed (u, 1 − v), v up, so that its bitangent w · n × t points up the image: the +Y of a
//! tangent-space normal map in glTF's (OpenGL's) convention.

use glam::{Vec2, Vec3, Vec4};

/// A triangle soup as MikkTSpace reads it: three corners per face.
struct Soup<'a> {
    triangles: &'a [[Vec3; 3]],
    uvs: &'a [[Vec2; 3]],
    normals: Option<&'a [[Vec3; 3]]>,
    tangents: Vec<[Vec4; 3]>,
}

impl bevy_mikktspace::Geometry for Soup<'_> {
    fn num_faces(&self) -> usize {
        self.triangles.len()
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.triangles[face][vert].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        let n = self.normals.map(|n| n[face][vert]).filter(|n| n.length_squared() > 0.0);
        n.unwrap_or_else(|| super::triangle_normal(&self.triangles[face])).to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        let uv = self.uvs[face][vert];
        [uv.x, 1.0 - uv.y]
    }

    fn set_tangent(&mut self, tangent: Option<bevy_mikktspace::TangentSpace>, face: usize, vert: usize) {
        self.tangents[face][vert] = tangent.map_or(Vec4::ZERO, |t| Vec4::from_array(t.tangent_encoded()));
    }
}

/// MikkTSpace tangents at the corners of `triangles` (see the module documentation), from
/// their texture coordinates and normals (each face's own where `normals` is `None` or zero);
/// zero where it finds none (a degenerate mapping: the normal map is then not applied there).
pub fn mikktspace(triangles: &[[Vec3; 3]], uvs: &[[Vec2; 3]], normals: Option<&[[Vec3; 3]]>) -> Vec<[Vec4; 3]> {
    let mut soup = Soup { triangles, uvs, normals, tangents: vec![[Vec4::ZERO; 3]; triangles.len()] };
    if let Err(e) = bevy_mikktspace::generate_tangents(&mut soup) {
        log::warn!("MikkTSpace found no tangents ({e}); the normal map is not applied");
        return vec![[Vec4::ZERO; 3]; triangles.len()];
    }
    soup.tangents.into_iter().map(|t| t.map(|v| if v.is_finite() { v } else { Vec4::ZERO })).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quad_mapped_u_right_v_down_gets_tangent_along_u_and_bitangent_up_the_image() {
        // The quad z = 0 facing +z, u along +x, v (down the image) along −y.
        let p =
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let uv = |v: Vec3| Vec2::new(v.x, 1.0 - v.y);
        let triangles = [[p[0], p[1], p[2]], [p[0], p[2], p[3]]];
        let uvs = triangles.map(|t| t.map(uv));
        for t in mikktspace(&triangles, &uvs, None).iter().flatten() {
            assert!((t.truncate() - Vec3::X).length() < 1e-5, "{t}");
            // w · n × t = +y: up the image (v decreasing).
            assert_eq!(t.w, 1.0);
        }
        // Mirrored mapping (u along −x): the tangent turns, the handedness flips.
        let mirrored = triangles.map(|t| t.map(|v| Vec2::new(1.0 - v.x, 1.0 - v.y)));
        for t in mikktspace(&triangles, &mirrored, None).iter().flatten() {
            assert!((t.truncate() + Vec3::X).length() < 1e-5, "{t}");
            assert_eq!(t.w, -1.0);
        }
    }
}
