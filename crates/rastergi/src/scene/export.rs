//! Writing a scene as Wavefront OBJ + MTL, so that generated scenes (`atrium`, `spheres:N`)
//! can be opened by other tools and loaded back with [`super::load_obj`].
//!
//! Vertices shared by triangles are written once; faces keep their corners' order (so their
//! front faces), grouped by `usemtl` runs; each material gets `Kd` (albedo) and `Ke`
//! (emission). Coordinates are written with the shortest decimal that reads back as the same
//! `f32`, so a loaded file has exactly the scene's triangles; shading normals are written as
//! `vn` (faces `f v//vn`, in objects of their own), so they load back bit for bit. OBJ has no sidedness and no
//! camera: materials load back two-sided, and the camera is written as a comment holding the
//! command-line options that restore it.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Write as _;
use std::path::Path;

use glam::Vec3;

use super::Scene;
use crate::error::{Error, Result};

fn file_error(path: &Path, message: impl Into<String>) -> Error {
    Error::SceneFile { path: path.to_path_buf(), message: message.into() }
}

/// The scene's materials' names made usable in OBJ/MTL: no whitespace, unique, not empty.
fn material_names(scene: &Scene) -> Vec<String> {
    let mut seen = std::collections::HashSet::new();
    scene
        .materials
        .iter()
        .enumerate()
        .map(|(i, m)| {
            let mut name: String = m.name.chars().map(|c| if c.is_whitespace() { '_' } else { c }).collect();
            if name.is_empty() || !seen.insert(name.clone()) {
                name = format!("{name}_{i}");
                seen.insert(name.clone());
            }
            name
        })
        .collect()
}

/// Writes `scene` to `obj` and its materials to the `.mtl` file beside it (same stem).
/// `comment` goes at the top of both. Each file is written to a temporary file first and
/// renamed, so a failure leaves no half-written file.
pub fn write_obj(scene: &Scene, obj: &Path, comment: &str) -> Result<()> {
    scene.validate()?;
    if let Some(m) = scene.materials.iter().find(|m| m.albedo_texture.is_some()) {
        return Err(file_error(
            obj,
            format!("material '{}' has an albedo texture; writing textures to OBJ is not supported", m.name),
        ));
    }
    let mtl = obj.with_extension("mtl");
    let mtl_name = mtl.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let names = material_names(scene);
    let header: String = comment.lines().map(|l| format!("# {l}\n")).collect();

    let mut m = header.clone();
    for (material, name) in scene.materials.iter().zip(&names) {
        let (a, e) = (material.albedo, material.emission);
        let _ = write!(m, "\nnewmtl {name}\nKd {} {} {}\n", a.x, a.y, a.z);
        if material.is_emitter() {
            let _ = writeln!(m, "Ke {} {} {}", e.x, e.y, e.z);
        }
    }

    let c = scene.camera;
    let mut o = header;
    let _ = writeln!(
        o,
        "# {} triangles, {} materials; camera: --eye {},{},{} --target {},{},{} --up {},{},{} --fov {}",
        scene.triangles.len(),
        scene.materials.len(),
        c.eye.x,
        c.eye.y,
        c.eye.z,
        c.target.x,
        c.target.y,
        c.target.z,
        c.up.x,
        c.up.y,
        c.up.z,
        c.fov_y_deg
    );
    let _ = writeln!(o, "mtllib {mtl_name}");
    // Vertices in order of first use, each once (by bit pattern: -0 and 0 stay distinct).
    let mut index: HashMap<[u32; 3], usize> = HashMap::new();
    let mut corners: Vec<[usize; 3]> = Vec::with_capacity(scene.triangles.len());
    for t in &scene.triangles {
        corners.push(t.map(|p| {
            let next = index.len() + 1;
            *index.entry(p.to_array().map(f32::to_bits)).or_insert_with(|| {
                let _ = writeln!(o, "v {} {} {}", p.x, p.y, p.z);
                next
            })
        }));
    }
    // Shading normals likewise, for the triangles that have them (`f v//vn`).
    let mut normal_index: HashMap<[u32; 3], usize> = HashMap::new();
    let normals: Vec<Option<[usize; 3]>> = (0..scene.triangles.len())
        .map(|i| {
            let n = scene.normals.get(i).filter(|n| n.iter().all(|v| *v != Vec3::ZERO))?;
            Some(n.map(|v| {
                let next = normal_index.len() + 1;
                *normal_index.entry(v.to_array().map(f32::to_bits)).or_insert_with(|| {
                    let _ = writeln!(o, "vn {} {} {}", v.x, v.y, v.z);
                    next
                })
            }))
        })
        .collect();
    // A new object wherever the material or smoothness changes: a reader takes an object's
    // normals only when all its faces have them.
    let mut current = None;
    for ((f, &material), n) in corners.iter().zip(&scene.material_ids).zip(&normals) {
        if current != Some((material, n.is_some())) {
            if !normal_index.is_empty() {
                let _ = writeln!(o, "o {}{}", names[material as usize], if n.is_some() { "_smooth" } else { "" });
            }
            let _ = writeln!(o, "usemtl {}", names[material as usize]);
            current = Some((material, n.is_some()));
        }
        match n {
            Some(n) => {
                let _ = writeln!(o, "f {}//{} {}//{} {}//{}", f[0], n[0], f[1], n[1], f[2], n[2]);
            }
            None => {
                let _ = writeln!(o, "f {} {} {}", f[0], f[1], f[2]);
            }
        }
    }
    write_atomically(&mtl, m.as_bytes())?;
    write_atomically(obj, o.as_bytes())
}

fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let fail = |e: std::io::Error| file_error(path, format!("cannot be written: {e}"));
    let mut builder = tempfile::Builder::new();
    builder.prefix(".rastergi-");
    // Temporary files are private by default; the scene should get the usual permissions.
    #[cfg(unix)]
    builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o644));
    let mut file = builder.tempfile_in(dir).map_err(fail)?;
    file.write_all(bytes).map_err(fail)?;
    file.persist(path).map_err(|e| fail(e.error))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{generate, load_obj};

    #[test]
    fn atrium_round_trips_through_obj_exactly() {
        let scene = generate::atrium();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("atrium.obj");
        write_obj(&scene, &path, "the atrium\nsecond line").unwrap();
        let back = load_obj(&path).unwrap();
        assert_eq!(back.triangles, scene.triangles, "same triangles, same corner order");
        for i in 0..scene.triangles.len() {
            let (a, b) = (scene.material_of(i), back.material_of(i));
            assert_eq!((a.albedo, a.emission, &a.name), (b.albedo, b.emission, &b.name), "triangle {i}");
            assert!(b.two_sided);
        }
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with("# the atrium\n# second line\n"));
        assert!(text.contains("--eye 0.5,1.7,2.85 --target -0.7,1.35,-6 --up 0,1,0 --fov 60"), "{}", &text[..300]);
    }

    #[test]
    fn names_are_made_unique_and_free_of_spaces() {
        let mut s = generate::spheres(100);
        s.materials[0].name = "two words".into();
        s.materials[1].name = "two_words".into();
        s.materials[2].name = String::new();
        let names = material_names(&s);
        assert_eq!(&names[..3], ["two_words", "two_words_1", "_2"]);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.obj");
        write_obj(&s, &path, "").unwrap();
        assert_eq!(load_obj(&path).unwrap().triangles, s.triangles);
    }
}
