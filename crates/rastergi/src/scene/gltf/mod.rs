//! glTF 2.0 loading: `.gltf` (JSON with external or base64-embedded buffers and images) and
//! `.glb` (binary container), parsed and validated by the `gltf` crate.
//!
//! What a scene takes from the file:
//! - **Geometry**: every mesh of the displayed scene (the default scene, else the first, else
//!   every root node) placed by its node's world transform (parent × local, matrix or TRS).
//!   Triangle lists, strips and fans; points and lines have no area and are skipped with a
//!   warning. glTF's front faces are counter-clockwise like ours; a transform with a negative
//!   determinant mirrors the mesh, so its triangles' corners are swapped to keep the front.
//!   `NORMAL` gives the shading normals (through the inverse transpose of the transform);
//!   primitives without it, or with one that cannot be read (quantized, non-finite), shade
//!   flat (the latter with a warning). `TANGENT` where a normal map needs it. Other attributes
//!   (COLOR_0, JOINTS, WEIGHTS, more UV sets) are not read.
//! - **Materials** (glTF's metallic-roughness model, [`crate::bsdf`]): base colour =
//!   baseColorFactor.rgb × baseColorTexture (sRGB); metallicFactor and roughnessFactor ×
//!   metallicRoughnessTexture's B and G (linear); `KHR_materials_specular`'s specularFactor
//!   × specularTexture's A and specularColorFactor × specularColorTexture (sRGB) (the layer's
//!   F₀ = min(f₀(η)·colour, 1)), `KHR_materials_ior`,
//!   `KHR_materials_transmission`'s factor × transmissionTexture's R (linear) and
//!   `KHR_materials_volume` (a thickness > 0 makes the glass a refracting solid; without a
//!   volume it is thin-walled, as the extension says; its attenuationColor and
//!   attenuationDistance give the solid's Beer–Lambert attenuation σ = −ln(c)/d,
//!   [`super::Material::attenuation`]);
//!   emitted radiance = emissiveFactor × KHR_materials_emissive_strength × emissiveTexture
//!   (sRGB, per texel); `doubleSided` → two-sided reflection (glTF's default is one-sided).
//!   `alphaMode` MASK (a cut-out at `alphaCutoff`, default 0.5) and BLEND (stochastic
//!   opacity, [`super::AlphaMode::Blend`]) with α = baseColorFactor.a × the base texture's
//!   alpha; OPAQUE ignores α. `normalTexture` (linear, with its `scale`) in the frame of the
//!   primitive's `TANGENT`s, or of MikkTSpace tangents (the `mikktspace` crate, fed v flipped
//!   to v up so that the bitangent points up the image, glTF's +Y) where it has none.
//!   `KHR_texture_transform` on every texture (offset, rotation, scale; uv' = T·R·S·uv with
//!   R = [[cos r, sin r], [−sin r, cos r]], as the extension's worked example needs). One
//!   TEXCOORD set per primitive: the base colour texture's (else the emissive's, else the
//!   normal map's); textures naming another set read it with a warning. Primitives without a
//!   material get a grey Lambertian albedo of 0.5 like OBJ faces without one.
//! - **Lights** (`KHR_lights_punctual`): point, spot and directional lights placed by their
//!   node (position: the node's origin; direction: its local −Z), `color` × `intensity` read
//!   1:1 as radiometric — W/sr for point and spot lights, W/m² on a surface facing a
//!   directional light (Mitsuba's `point`, `spot` and `directional` take the same values).
//!   Spot cones from the extension's inner and outer angles with its smooth falloff
//!   ([`super::Light::Spot`]). `range` is a hint and ignored with a warning (1/d² at every
//!   distance). Invalid values (negative intensity, outer cone below the inner) are refused; equal cones are a hard edge.
//! - **Camera**: a perspective camera placed by the first node of the scene that uses it,
//!   looking down its −z with +y up (yfov is the vertical field of view; the aspect ratio is the
//!   image's). [`GltfOptions::camera`] picks one by its index in the file's `cameras`; by
//!   default the first perspective camera the scene uses. Without one, the scene's default
//!   camera ([`Scene::default_camera`]: framed from outside, or inside its most open room).
//!
//! Robustness: every size and index is checked before it is used and before anything is
//! allocated from it (accessor ranges against their buffer views and the bytes actually
//! present, the triangle total against the triangle budget ([`GltfOptions::budgets`]), each
//! mesh's vertices against the vertex budget, each image's declared size against the texel
//! budget before it is decoded, the node hierarchy against cycles); an image file named by
//! several images (or spellings of its path) is decoded once;
//! a file that breaks a rule gives a one-line error naming it and the offending element.
//!
//! The loader is one module per concern: [`file`] (the container, buffers and URIs, checks the
//! `gltf` crate takes for granted), this module (the document: the node tree, instances and the
//! camera), [`meshes`] (accessors, primitives and their attributes), [`materials`] (materials,
//! their extensions and textures) and [`lights`] (`KHR_lights_punctual`).

mod file;
mod lights;
mod materials;
mod meshes;

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::path::{Path, PathBuf};

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use ::gltf::{Document, Semantic};
use base64::Engine as _;
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

use super::{AlphaMode, Budget, Budgets, Camera, Files, Light, Material, Scene, Texture, TextureRef, UvTransform};
use crate::error::{Error, Result};

use file::{check_before_validation, describe_gltf_error, load_buffer, percent_decode, read_uri, split_glb};
use lights::punctual_light;
use materials::texture_sets;
use meshes::Primitive;

/// glTF extensions that a file may require.
const SUPPORTED_REQUIRED: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_volume",
    "KHR_materials_specular",
    "KHR_materials_clearcoat",
];
const DEFAULT_ALBEDO: f32 = 0.5;

/// Choices made when loading a glTF file.
#[derive(Clone, Debug, Default)]
pub struct GltfOptions {
    /// Index into the file's `cameras` of the camera to use; `None`: the first perspective
    /// camera that a node of the scene uses.
    pub camera: Option<usize>,
    /// What the file may make the loader read and hold.
    pub budgets: Budgets,
}

fn file_error(path: &Path, message: impl Into<String>) -> Error {
    Error::SceneFile { path: path.to_path_buf(), message: message.into() }
}

/// Loads a `.gltf` or `.glb` file with the default options.
pub fn load_gltf(path: &Path) -> Result<Scene> {
    load_gltf_with(path, &GltfOptions::default())
}

/// Loads a `.gltf` or `.glb` file.
pub fn load_gltf_with(path: &Path, options: &GltfOptions) -> Result<Scene> {
    load_gltf_in(Files::Disk, path, options)
}

/// Loads the `.gltf` or `.glb` file at `path` of `files` (its buffers and images too).
pub fn load_gltf_in(files: Files, path: &Path, options: &GltfOptions) -> Result<Scene> {
    if let Some(what) = files.missing(path) {
        return Err(file_error(path, format!("{what}; give the path of a .gltf or .glb file")));
    }
    let bytes = files.read(path).map_err(|e| file_error(path, format!("cannot be read: {e}")))?;
    load(files, path, &bytes, options).map_err(|message| file_error(path, message))
}

/// Everything wrong with a file is a message; `load_gltf_with` prefixes the file's name.
type Res<T> = std::result::Result<T, String>;

fn load(files: Files, path: &Path, bytes: &[u8], options: &GltfOptions) -> Res<Scene> {
    let (json, bin) = if bytes.starts_with(b"glTF") { split_glb(bytes)? } else { (bytes, None) };
    let root = ::gltf::json::Root::from_slice(json).map_err(|e| format!("not valid glTF JSON ({e})"))?;
    check_before_validation(&root)?;
    let document = Document::from_json(root).map_err(describe_gltf_error)?;
    for ext in document.extensions_required() {
        if !SUPPORTED_REQUIRED.contains(&ext) {
            return Err(format!("requires the glTF extension {ext}, which rastergi does not support"));
        }
    }
    for ext in document.extensions_used().filter(|e| !SUPPORTED_REQUIRED.contains(e)) {
        log::warn!("{}: uses the glTF extension {ext}, which rastergi ignores", path.display());
    }
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    let buffers = document.buffers().map(|b| load_buffer(files, &dir, &b, bin)).collect::<Res<Vec<Vec<u8>>>>()?;
    let mut loader = Loader {
        files,
        dir,
        document: &document,
        buffers,
        scene: Scene::new(placeholder_camera()),
        materials: HashMap::new(),
        textures: HashMap::new(),
        image_files: HashMap::new(),
        budgets: options.budgets,
        texels: 0,
        warned_sets: false,
        warned_coat_normal: false,
        camera: None,
        warned_sampler: false,
    };
    loader.build(options)?;
    let mut scene = loader.scene;
    if scene.triangles.is_empty() {
        return Err("contains no triangles in the displayed scene".into());
    }
    if loader.camera.is_none() {
        scene.camera = scene.default_camera();
    }
    scene.validate().map_err(|e| e.to_string())?;
    Ok(scene)
}

fn placeholder_camera() -> Camera {
    Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 }
}

struct Loader<'a> {
    files: Files<'a>,
    dir: PathBuf,
    document: &'a Document,
    buffers: Vec<Vec<u8>>,
    scene: Scene,
    /// glTF material index (None: the default material) → scene material.
    materials: HashMap<Option<usize>, u32>,
    /// Scene textures by (image, read as linear data).
    textures: HashMap<(usize, bool), usize>,
    /// Scene textures by (canonical image file, read as linear data): images that name one
    /// file are one texture.
    image_files: HashMap<(PathBuf, bool), usize>,
    budgets: Budgets,
    /// Texels of the images decoded so far.
    texels: u64,
    /// The camera chosen, once found.
    camera: Option<Camera>,
    warned_sampler: bool,
    warned_sets: bool,
    /// Whether a clearcoatNormalTexture has been warned about.
    warned_coat_normal: bool,
}

/// A name for an element in messages: `mesh 3 ('Chair')`.
fn named(kind: &str, index: usize, name: Option<&str>) -> String {
    match name {
        Some(n) => format!("{kind} {index} ('{n}')"),
        None => format!("{kind} {index}"),
    }
}

impl<'a> Loader<'a> {
    fn doc(&self) -> &'a Document {
        self.document
    }

    /// Walks the displayed scene's node tree, then adds its meshes and picks its camera.
    fn build(&mut self, options: &GltfOptions) -> Res<()> {
        let doc = self.doc();
        let roots: Vec<::gltf::Node> = match doc.default_scene().or_else(|| doc.scenes().next()) {
            Some(s) => s.nodes().collect(),
            None => {
                let mut child = vec![false; doc.nodes().len()];
                doc.nodes().flat_map(|n| n.children()).for_each(|c| child[c.index()] = true);
                doc.nodes().filter(|n| !child[n.index()]).collect()
            }
        };
        // Depth first, each node once: a node reached twice (a cycle, or a node with two
        // parents) breaks glTF's tree rule and could multiply the scene without bound.
        let mut visited = vec![false; doc.nodes().len()];
        let mut stack: Vec<(::gltf::Node, Mat4)> = roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY)).collect();
        let mut instances: Vec<(::gltf::Mesh, Mat4)> = Vec::new();
        let mut cameras: Vec<(usize, Mat4)> = Vec::new();
        let mut warned_range = false;
        while let Some((node, parent)) = stack.pop() {
            let what = || named("node", node.index(), node.name());
            if std::mem::replace(&mut visited[node.index()], true) {
                return Err(format!("{} appears twice in the node hierarchy (a cycle or two parents)", what()));
            }
            let world = parent * local_transform(&node).map_err(|e| format!("{}: {e}", what()))?;
            if !world.is_finite() {
                return Err(format!("{}: its world transform is not finite", what()));
            }
            if let Some(mesh) = node.mesh() {
                instances.push((mesh, world));
            }
            if let Some(camera) = node.camera() {
                cameras.push((camera.index(), world));
            }
            if let Some(light) = node.light() {
                let what = || format!("{}'s light {}", what(), named("light", light.index(), light.name()));
                if light.range().is_some() && !std::mem::replace(&mut warned_range, true) {
                    log::warn!(
                        "{}: light ranges are ignored (a glTF hint): lights fall off as 1/d² at every distance",
                        what()
                    );
                }
                let l = punctual_light(&light, world).map_err(|e| format!("{}: {e}", what()))?;
                l.validate().map_err(|e| format!("{}: {e}", what()))?;
                self.scene.lights.push(l);
            }
            let children: Vec<::gltf::Node> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
        }

        // Count before allocating: accessor ranges are checked here, so the counts are real.
        let mut total = 0u64;
        for (mesh, _) in &instances {
            for p in mesh.primitives() {
                total += self.triangle_count(mesh, &p)?;
            }
        }
        self.budgets.check(Budget::Triangles, total, "its meshes, instances included")?;
        self.scene.triangles.reserve(total as usize);
        self.scene.material_ids.reserve(total as usize);
        let mut meshes: HashMap<usize, Vec<Primitive>> = HashMap::new();
        for (mesh, world) in &instances {
            if let Entry::Vacant(entry) = meshes.entry(mesh.index()) {
                let primitives = mesh.primitives().map(|p| self.primitive(mesh, &p)).collect::<Res<Vec<_>>>()?;
                entry.insert(primitives.into_iter().flatten().collect());
            }
            self.add_instance(&meshes[&mesh.index()], *world);
        }
        self.camera = self.pick_camera(&cameras, options)?;
        if let Some(camera) = self.camera {
            self.scene.camera = camera;
        }
        Ok(())
    }

    /// Adds a mesh's primitives transformed by `world`.
    /// Normals go through the inverse transpose of `world` (mirrored instances too: the
    /// winding is swapped to keep the front face, the normals keep pointing where they did).
    fn add_instance(&mut self, primitives: &[Primitive], world: Mat4) {
        let mirrored = world.determinant() < 0.0;
        let normal_matrix = glam::Mat3::from_mat4(world).inverse().transpose();
        for p in primitives {
            for (k, t) in p.triangles.iter().enumerate() {
                let mut tri = t.map(|v| world.transform_point3(v));
                let mut uv = p.uvs.as_ref().map(|uvs| uvs[k]);
                let mut normals = p.normals.as_ref().map(|n| n[k].map(|v| normal_matrix * v));
                // Tangents follow the surface (the transform itself); a mirror flips the
                // handedness: (M n) × (M t) = det M · M(n × t) for orthogonal M.
                let handedness = if mirrored { -1.0 } else { 1.0 };
                let mut tangents = p
                    .tangents
                    .as_ref()
                    .map(|t| t[k].map(|v| (glam::Mat3::from_mat4(world) * v.truncate()).extend(v.w * handedness)));
                if mirrored {
                    tri.swap(1, 2);
                    if let Some(t) = &mut tangents {
                        t.swap(1, 2);
                    }
                    if let Some(uv) = &mut uv {
                        uv.swap(1, 2);
                    }
                    if let Some(n) = &mut normals {
                        n.swap(1, 2);
                    }
                }
                match uv {
                    Some(uv) => self.scene.add_textured_triangle(tri, uv, p.material),
                    None => self.scene.add_triangle(tri, p.material),
                }
                if let Some(n) = normals {
                    self.scene.set_last_normals(n);
                }
                if let Some(t) = tangents {
                    self.scene.set_last_tangents(t);
                }
            }
        }
    }

    fn pick_camera(&self, cameras: &[(usize, Mat4)], options: &GltfOptions) -> Res<Option<Camera>> {
        let doc = self.doc();
        let count = doc.cameras().len();
        let placed = |index: usize| cameras.iter().find(|c| c.0 == index).map(|c| c.1);
        let Some(index) = options.camera else {
            // The first perspective camera (in the file's order) that the scene uses.
            for camera in doc.cameras() {
                if let (::gltf::camera::Projection::Perspective(p), Some(world)) =
                    (camera.projection(), placed(camera.index()))
                {
                    let what = named("camera", camera.index(), camera.name());
                    return camera_from(world, p.yfov()).map(Some).map_err(|e| format!("{what}: {e}"));
                }
            }
            if count > 0 {
                log::warn!("no perspective camera of the file is used by the scene; framing the scene instead");
            }
            return Ok(None);
        };
        let Some(camera) = doc.cameras().nth(index) else {
            return Err(format!("has {count} cameras; camera {index} does not exist (cameras count from 0)"));
        };
        let what = named("camera", index, camera.name());
        let ::gltf::camera::Projection::Perspective(p) = camera.projection() else {
            return Err(format!("{what} is orthographic; only perspective cameras are supported"));
        };
        let world = placed(index).ok_or_else(|| format!("{what} is not used by any node of the displayed scene"))?;
        camera_from(world, p.yfov()).map(Some).map_err(|e| format!("{what}: {e}"))
    }
}

/// A node's local transform: its matrix, or translation × rotation × scale.
fn local_transform(node: &::gltf::Node) -> Res<Mat4> {
    match node.transform() {
        ::gltf::scene::Transform::Matrix { matrix } => Ok(Mat4::from_cols_array_2d(&matrix)),
        ::gltf::scene::Transform::Decomposed { translation, rotation, scale } => {
            let q = Quat::from_array(rotation);
            if !q.is_finite() || q.length_squared() < 1e-12 {
                return Err(format!("its rotation {rotation:?} is not a unit quaternion"));
            }
            Ok(Mat4::from_scale_rotation_translation(Vec3::from(scale), q.normalize(), Vec3::from(translation)))
        }
    }
}

/// The camera a node's world transform places: at its origin, looking down its −z, +y up.
fn camera_from(world: Mat4, yfov: f32) -> Res<Camera> {
    let eye = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(-Vec3::Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
    let camera = Camera { eye, target: eye + forward, up, fov_y_deg: yfov.to_degrees() };
    camera.validate().map_err(|e| e.to_string())?;
    Ok(camera)
}
