//! Wavefront OBJ + MTL loading through `tobj`: polygons are triangulated (fans), each
//! `usemtl` group takes its material's `Kd` as albedo and `Ke` as emitted radiance.
//!
//! OBJ has no notion of sidedness, so materials loaded from OBJ reflect on both faces; they
//! emit from the counter-clockwise front face only. Faces without a material get a grey
//! albedo of 0.5 (Mitsuba's default). OBJ carries no camera: the scene is framed from +z.

use std::cell::RefCell;
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
        return Err(file_error(
            path,
            format!("{what}; give the path of a .obj file or the built-in scene name 'cornell'"),
        ));
    }
    let mut text = std::fs::read(path).map_err(|e| file_error(path, format!("cannot be read: {e}")))?;
    comment_out_texcoords_and_normals(&mut text);
    let options =
        tobj::LoadOptions { triangulate: true, ignore_points: true, ignore_lines: true, ..Default::default() };
    // tobj keeps only the last MTL error, and none at all once one library loaded; the first
    // failure, with the library's path, is kept here.
    let mtl_error = RefCell::new(None);
    let (models, materials) = tobj::load_obj_buf(&mut text.as_slice(), &options, |mtl| load_mtl(path, mtl, &mtl_error))
        .map_err(|e| file_error(path, obj_error_message(e)))?;
    let mtl_failure = mtl_error.into_inner().or_else(|| materials.as_ref().err().map(|e| e.to_string()));
    if let Some(message) = mtl_failure {
        let hint = "fix the .mtl file, put it beside the .obj or remove the mtllib line";
        return Err(file_error(path, format!("its material library (mtllib) could not be loaded: {message}; {hint}")));
    }
    let materials = materials.unwrap_or_default();

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
                    return Err(file_error(
                        path,
                        format!("face {f} of '{}' refers to a vertex that does not exist", model.name),
                    ));
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

/// What is wrong with an OBJ file tobj refused, and what to do about it.
fn obj_error_message(e: tobj::LoadError) -> String {
    use tobj::LoadError as E;
    let what = match e {
        E::ReadError => return "not a valid OBJ file: it is not UTF-8 text; export it again as Wavefront OBJ".into(),
        E::PositionParseError => "a 'v' line does not hold three numbers",
        E::ScalingByZeroError => "a 'v' line has a weight w of 0",
        E::ColorParseError => "a 'v' line has a vertex colour with too many or too few numbers",
        E::FaceParseError => "an 'f' line holds something other than vertex indices",
        E::InvalidPolygon => "an 'f' line has fewer than three vertices",
        E::FaceVertexOutOfBounds => "a face ('f' line) refers to a vertex that does not exist",
        E::FaceColorOutOfBounds => "some vertices have colours and others do not",
        E::MaterialParseError => "a 'usemtl' line names no material",
        _ => return format!("not a valid OBJ file ({e}); check it or export it again as Wavefront OBJ"),
    };
    format!("not a valid OBJ file: {what}; fix that line or export the file again as Wavefront OBJ")
}

/// Turns `vt` and `vn` lines into comments in place: a scene needs positions only, and tobj
/// rejects (in debug builds: panics on) texture and normal indices out of range.
fn comment_out_texcoords_and_normals(text: &mut [u8]) {
    for line in text.split_mut(|&b| b == b'\n') {
        let indent = line.iter().take_while(|b| b.is_ascii_whitespace()).count();
        let line = &mut line[indent..];
        let keyword = line.iter().position(u8::is_ascii_whitespace).unwrap_or(line.len());
        if matches!(&line[..keyword], b"vt" | b"vn") {
            line[0] = b'#';
        }
    }
}

/// Loads the MTL library `name`, found relative to the OBJ file `obj` as tobj does. MTL lets
/// a colour be one number (`Kd 0.5` means `Kd 0.5 0.5 0.5`) but tobj panics on fewer than
/// three: such lines are completed here first. The first failure is recorded in `error`.
fn load_mtl(obj: &Path, name: &Path, error: &RefCell<Option<String>>) -> tobj::MTLLoadResult {
    let mtl_path = obj.parent().unwrap_or(Path::new("")).join(name);
    let fail = |message: String, e: tobj::LoadError| {
        error.borrow_mut().get_or_insert(format!("{}: {message}", mtl_path.display()));
        Err(e)
    };
    if name.as_os_str().is_empty() {
        error.borrow_mut().get_or_insert("an mtllib line names no file".into());
        return Err(tobj::LoadError::OpenFileFailed);
    }
    let text = match std::fs::read_to_string(&mtl_path) {
        Ok(text) => text,
        Err(e) => return fail(e.to_string(), tobj::LoadError::OpenFileFailed),
    };
    let mut completed = String::with_capacity(text.len());
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() {
            match words.collect::<Vec<_>>().as_slice() {
                [r] => {
                    completed.push_str(&format!("{key} {r} {r} {r}\n"));
                    continue;
                }
                [_, _, _, ..] => {}
                _ => {
                    let message = format!("line {}: '{key}' needs three numbers (r g b) or one", n + 1);
                    return fail(message, tobj::LoadError::MaterialParseError);
                }
            }
        }
        completed.push_str(line);
        completed.push('\n');
    }
    tobj::load_mtl_buf(&mut completed.as_bytes()).or_else(|e| fail(format!("not a valid MTL file ({e})"), e))
}
