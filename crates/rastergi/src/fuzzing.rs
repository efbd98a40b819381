//! The readers as the fuzz targets (`fuzz/`, `cargo fuzz`) and the regression corpus test
//! (`tests/fuzz_corpus.rs`) drive them: one input through the library's real load path to a
//! validated [`Scene`] or to its error, in memory, without a GPU. A reader is robust when
//! [`Target::read`] returns for every input, within the budgets, and every error is one line:
//! a panic, an abort, a hang or an allocation beyond the budgets is a bug ([`Target::read`]
//! panics itself where a checkpoint it reads is not written back as read).
//!
//! An input holds one file, or several (a scene and the files it names): the first file, then
//! for each further one a line `#file NAME` followed by its bytes ([`files_of`]).
//!
//! | target | the input | what reads it |
//! |---|---|---|
//! | `mitsuba_xml` | `scene.xml` and the files it names (includes, meshes, textures, envmaps) | [`load_mitsuba_in`] |
//! | `ply` | a PLY mesh, named by a Mitsuba `ply` shape | [`load_mitsuba_in`] |
//! | `serialized` | a byte (the `shape_index`), then a `.serialized` file named by a Mitsuba `serialized` shape | [`load_mitsuba_in`] |
//! | `obj_mtl` | `scene.obj` and its MTL libraries and textures | [`load_obj_with`] |
//! | `gltf` | `scene.gltf` (or `.glb`) and its buffers and images | [`load_gltf_in`] |
//! | `exr`, `hdr` | an environment map | [`Environment::decode`], then a scene lit by it |
//! | `checkpoint` | a checkpoint file, read as given and with its checksum made right (so that what follows the checksum is read too) | [`Checkpoint::from_bytes`] |

use std::path::Path;

use glam::Vec3;

use crate::checkpoint::Checkpoint;
use crate::environment::Environment;
use crate::scene::{
    Budgets, Camera, Files, GltfOptions, Material, MemoryFiles, MitsubaOptions, Scene, load_gltf_in, load_mitsuba_in,
    load_obj_with,
};

/// The readers fuzzed, one target each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    MitsubaXml,
    Ply,
    Serialized,
    ObjMtl,
    Gltf,
    Exr,
    Hdr,
    Checkpoint,
}

impl Target {
    pub const ALL: [Target; 8] = [
        Target::MitsubaXml,
        Target::Ply,
        Target::Serialized,
        Target::ObjMtl,
        Target::Gltf,
        Target::Exr,
        Target::Hdr,
        Target::Checkpoint,
    ];

    /// The name of its fuzz target and of its corpus folder.
    pub fn name(self) -> &'static str {
        match self {
            Target::MitsubaXml => "mitsuba_xml",
            Target::Ply => "ply",
            Target::Serialized => "serialized",
            Target::ObjMtl => "obj_mtl",
            Target::Gltf => "gltf",
            Target::Exr => "exr",
            Target::Hdr => "hdr",
            Target::Checkpoint => "checkpoint",
        }
    }

    /// Reads `data` as this target does (module docs) within [`budgets`]: the scene it loads
    /// (a checkpoint's target: none), or the error, one line.
    pub fn read(self, data: &[u8]) -> Result<Option<Scene>, String> {
        let budgets = budgets();
        let scene = |name: &str, files: &MemoryFiles| -> Result<Option<Scene>, String> {
            let options = MitsubaOptions { budgets, ..Default::default() };
            let m = load_mitsuba_in(Files::Memory(files), Path::new(name), &options).map_err(|e| e.to_string())?;
            Ok(Some(m.scene))
        };
        let shape = |ty: &str, extra: &str| {
            format!(
                "<scene version=\"3.0.0\"><shape type=\"{ty}\"><string name=\"filename\" value=\"mesh.{ty}\"/>{extra}</shape></scene>"
            )
        };
        match self {
            Target::MitsubaXml => scene("scene.xml", &files_of(data, "scene.xml")),
            Target::Ply => {
                let mut files = MemoryFiles::new();
                files.insert("mesh.ply", data.to_vec());
                files.insert("scene.xml", shape("ply", "").into_bytes());
                scene("scene.xml", &files)
            }
            Target::Serialized => {
                let Some((&index, file)) = data.split_first() else { return Err("an empty input".into()) };
                let mut files = MemoryFiles::new();
                files.insert("mesh.serialized", file.to_vec());
                let xml = shape("serialized", &format!("<integer name=\"shape_index\" value=\"{index}\"/>"));
                files.insert("scene.xml", xml.into_bytes());
                scene("scene.xml", &files)
            }
            Target::ObjMtl => {
                let files = files_of(data, "scene.obj");
                load_obj_with(Files::Memory(&files), Path::new("scene.obj"), &budgets)
                    .map(Some)
                    .map_err(|e| e.to_string())
            }
            Target::Gltf => {
                let name = if data.starts_with(b"glTF") { "scene.glb" } else { "scene.gltf" };
                let files = files_of(data, name);
                let options = GltfOptions { budgets, ..Default::default() };
                load_gltf_in(Files::Memory(&files), Path::new(name), &options).map(Some).map_err(|e| e.to_string())
            }
            Target::Exr | Target::Hdr => {
                let ext = if self == Target::Exr { "exr" } else { "hdr" };
                let env = Environment::decode(ext, data, 1.0, budgets.texels)?;
                lit_by(env).map(Some)
            }
            Target::Checkpoint => {
                let path = Path::new("fuzz.ckpt");
                let as_given = Checkpoint::from_bytes(path, data).map(|_| ()).map_err(|e| e.to_string());
                let Some(body) = data.len().checked_sub(8).map(|n| &data[..n]) else { return as_given.map(|()| None) };
                let mut fixed = body.to_vec();
                fixed.extend_from_slice(&xxhash_rust::xxh3::xxh3_64(body).to_le_bytes());
                // What is read is written back as it reads (a failure here is a bug: it panics).
                let written = Checkpoint::from_bytes(path, &fixed).map_err(|e| e.to_string())?.to_bytes();
                match Checkpoint::from_bytes(path, &written) {
                    Ok(again) => assert!(again.to_bytes() == written, "a checkpoint written back reads as another"),
                    Err(e) => panic!("a checkpoint written back is refused: {e}"),
                }
                as_given.map(|()| None)
            }
        }
    }
}

/// The budgets of a fuzzed load: the defaults scaled down so that whatever an input may make
/// a reader hold within them stays far below libFuzzer's 2 GiB (a fuzzer tries the budgets'
/// checks, not the machine's memory).
pub fn budgets() -> Budgets {
    Budgets {
        triangles: 1 << 20,
        vertices: 1 << 20,
        texels: 1 << 22,
        decompressed: 64 << 20,
        xml_bytes: 16 << 20,
        xml_depth: 256,
        expansion: 16 << 20,
        device_triangles: None,
    }
}

/// The files of an input (module docs): the first named `main`, each further one after a line
/// `#file NAME`.
pub fn files_of(data: &[u8], main: &str) -> MemoryFiles {
    const MARK: &[u8] = b"\n#file ";
    let mut files = MemoryFiles::new();
    let mut name = main.to_owned();
    let mut rest = data;
    loop {
        let at = rest.windows(MARK.len()).position(|w| w == MARK);
        let (file, next) = match at {
            Some(i) => (&rest[..i], Some(&rest[i + MARK.len()..])),
            None => (rest, None),
        };
        files.insert(&name, file.to_vec());
        let Some(next) = next else { return files };
        let end = next.iter().position(|&b| b == b'\n').unwrap_or(next.len());
        name = String::from_utf8_lossy(&next[..end]).trim().to_owned();
        rest = &next[(end + 1).min(next.len())..];
    }
}

/// A floor lit by `env` alone, validated: what a scene makes of an environment map.
fn lit_by(env: Environment) -> Result<Scene, String> {
    let mut scene =
        Scene::new(Camera { eye: Vec3::new(0.0, 1.0, 3.0), target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 });
    let m = scene.add_material(Material::diffuse("floor", Vec3::splat(0.5)));
    scene.add_quad([Vec3::new(-1., 0., 1.), Vec3::new(1., 0., 1.), Vec3::new(1., 0., -1.), Vec3::new(-1., 0., -1.)], m);
    scene.environment = Some(std::sync::Arc::new(env));
    scene.validate().map_err(|e| e.to_string())?;
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_splits_into_its_files() {
        let files = files_of(b"<scene/>\n#file a/b.ply\nply\n#file c.png\n\x89PNG", "scene.xml");
        let mut names: Vec<&str> = files.names().collect();
        names.sort();
        assert_eq!(names, ["a/b.ply", "c.png", "scene.xml"]);
        assert_eq!(files.get(Path::new("scene.xml")), Some(&b"<scene/>"[..]));
        assert_eq!(files.get(Path::new("a/b.ply")), Some(&b"ply"[..]));
        assert_eq!(files.get(Path::new("c.png")), Some(&b"\x89PNG"[..]));
    }
}
