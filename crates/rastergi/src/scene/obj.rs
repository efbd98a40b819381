//! Wavefront OBJ + MTL loading through `tobj`: polygons are triangulated (fans), each
//! `usemtl` group takes its material's `Kd` as albedo and `Ke` as emitted radiance.
//!
//! OBJ has no notion of sidedness, so materials loaded from OBJ reflect on both faces; they
//! emit from the counter-clockwise front face only. Faces without a material get a grey
//! albedo of 0.5 (Mitsuba's default). OBJ carries no camera: the scene is framed from +z.

use std::path::Path;

use glam::Vec3;

use super::{Material, Scene};
use crate::error::{Error, Result};

const DEFAULT_ALBEDO: f32 = 0.5;

fn file_error(path: &Path, message: impl Into<String>) -> Error {
    Error::SceneFile { path: path.to_path_buf(), message: message.into() }
}

/// Loads an OBJ file (and the MTL libraries it names) as a scene.
pub fn load_obj(path: &Path) -> Result<Scene> {
    if !path.is_file() {
        let what = if path.exists() { "is not a file" } else { "no such file" };
        return Err(file_error(path, format!("{what}; give the path of a .obj file or the built-in scene name 'cornell'")));
    }
    let options = tobj::LoadOptions { triangulate: true, ignore_points: true, ignore_lines: true, ..Default::default() };
    let (models, materials) =
        tobj::load_obj(path, &options).map_err(|e| file_error(path, format!("not a valid OBJ file: {e}")))?;
    let materials = materials.map_err(|e| file_error(path, format!("its material library (mtllib) could not be loaded: {e}")))?;

    let mut scene = Scene::new(super::Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 });
    for m in &materials {
        let albedo = m.diffuse.map(Vec3::from).unwrap_or(Vec3::splat(DEFAULT_ALBEDO));
        let emission = m.emissive.map(Vec3::from).unwrap_or(Vec3::ZERO);
        scene.add_material(Material { name: m.name.clone(), albedo, emission, two_sided: true });
    }
    let mut default_material = None;
    for model in &models {
        let mesh = &model.mesh;
        let material = match mesh.material_id {
            Some(id) if id < materials.len() => id as u32,
            _ => *default_material.get_or_insert_with(|| {
                scene.add_material(Material {
                    two_sided: true,
                    ..Material::diffuse("default", Vec3::splat(DEFAULT_ALBEDO))
                })
            }),
        };
        let vertex_count = mesh.positions.len() / 3;
        for (f, face) in mesh.indices.chunks_exact(3).enumerate() {
            let mut tri = [Vec3::ZERO; 3];
            for (k, &i) in face.iter().enumerate() {
                let i = i as usize;
                if i >= vertex_count {
                    return Err(file_error(path, format!("face {f} of '{}' refers to a vertex that does not exist", model.name)));
                }
                tri[k] = Vec3::new(mesh.positions[3 * i], mesh.positions[3 * i + 1], mesh.positions[3 * i + 2]);
            }
            scene.add_triangle(tri, material);
        }
    }
    if scene.triangles.is_empty() {
        return Err(file_error(path, "contains no faces; an OBJ scene needs at least one triangle ('f' lines)"));
    }
    scene.camera = Scene::framing_camera(&scene.bounds());
    scene.validate().map_err(|e| file_error(path, e.to_string()))?;
    Ok(scene)
}
