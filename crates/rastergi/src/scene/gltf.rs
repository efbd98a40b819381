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
//!   (its colour and textures are not read, with a warning), `KHR_materials_ior`,
//!   `KHR_materials_transmission`'s factor (its texture is not read, with a warning) and
//!   `KHR_materials_volume` (a thickness > 0 makes the glass a refracting solid; without a
//!   volume it is thin-walled, as the extension says; attenuation is not read);
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
//!   default the first perspective camera the scene uses. Without one, the scene is framed
//!   ([`Scene::framing_camera`]).
//!
//! Robustness: every size and index is checked before it is used and before anything is
//! allocated from it (accessor ranges against their buffer views and the bytes actually
//! present, the triangle total against [`MAX_TRIANGLES`], the node hierarchy against cycles);
//! a file that breaks a rule gives a one-line error naming it and the offending element.

use std::collections::HashMap;
use std::collections::hash_map::Entry;
use std::path::{Path, PathBuf};

use ::gltf::accessor::{DataType, Dimensions};
use ::gltf::mesh::Mode;
use ::gltf::{Document, Semantic};
use base64::Engine as _;
use glam::{Mat4, Quat, Vec2, Vec3, Vec4};

use super::{AlphaMode, Camera, Light, Material, Scene, Texture, TextureRef, UvTransform};
use crate::error::{Error, Result};

/// Most triangles a glTF scene may expand to (instances included).
pub const MAX_TRIANGLES: u64 = 1 << 25;
/// glTF extensions that a file may require.
const SUPPORTED_REQUIRED: &[&str] = &[
    "KHR_materials_emissive_strength",
    "KHR_lights_punctual",
    "KHR_texture_transform",
    "KHR_materials_transmission",
    "KHR_materials_ior",
    "KHR_materials_volume",
    "KHR_materials_specular",
];
const DEFAULT_ALBEDO: f32 = 0.5;

/// Choices made when loading a glTF file.
#[derive(Clone, Debug, Default)]
pub struct GltfOptions {
    /// Index into the file's `cameras` of the camera to use; `None`: the first perspective
    /// camera that a node of the scene uses.
    pub camera: Option<usize>,
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
    if !path.is_file() {
        let what = if path.exists() { "is not a file" } else { "no such file" };
        return Err(file_error(path, format!("{what}; give the path of a .gltf or .glb file")));
    }
    let bytes = std::fs::read(path).map_err(|e| file_error(path, format!("cannot be read: {e}")))?;
    load(path, &bytes, options).map_err(|message| file_error(path, message))
}

/// Everything wrong with a file is a message; `load_gltf_with` prefixes the file's name.
type Res<T> = std::result::Result<T, String>;

fn load(path: &Path, bytes: &[u8], options: &GltfOptions) -> Res<Scene> {
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
    let buffers = document.buffers().map(|b| load_buffer(&dir, &b, bin)).collect::<Res<Vec<Vec<u8>>>>()?;
    let mut loader = Loader {
        dir,
        document: &document,
        buffers,
        scene: Scene::new(placeholder_camera()),
        materials: HashMap::new(),
        textures: HashMap::new(),
        warned_sets: false,
        camera: None,
        warned_sampler: false,
    };
    loader.build(options)?;
    let mut scene = loader.scene;
    if scene.triangles.is_empty() {
        return Err("contains no triangles in the displayed scene".into());
    }
    if loader.camera.is_none() {
        scene.camera = Scene::framing_camera(&scene.bounds());
    }
    scene.validate().map_err(|e| e.to_string())?;
    Ok(scene)
}

/// What the `gltf` crate's own validation and accessors take for granted (they panic on
/// files that break these rules): attributes naming existing accessors, images with exactly
/// one source (and a MIME type for a buffer view), cameras with the projection their type
/// names.
fn check_before_validation(root: &::gltf::json::Root) -> Res<()> {
    use ::gltf::json::validation::Checked;
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, accessor) in &primitive.attributes {
                if accessor.value() >= root.accessors.len() {
                    let name = match semantic {
                        Checked::Valid(s) => s.to_string(),
                        Checked::Invalid => "an attribute".into(),
                    };
                    return Err(format!(
                        "invalid glTF: meshes[{m}].primitives[{p}]: {name} names accessor {}, but there are {}",
                        accessor.value(),
                        root.accessors.len()
                    ));
                }
            }
        }
    }
    for (i, image) in root.images.iter().enumerate() {
        match (&image.uri, &image.buffer_view, &image.mime_type) {
            (Some(_), None, _) | (None, Some(_), Some(_)) => {}
            (None, Some(_), None) => return Err(format!("invalid glTF: images[{i}] has a bufferView but no mimeType")),
            _ => return Err(format!("invalid glTF: images[{i}] needs either a uri or a bufferView")),
        }
    }
    for (i, camera) in root.cameras.iter().enumerate() {
        use ::gltf::json::camera::Type;
        let ok = match camera.type_ {
            Checked::Valid(Type::Perspective) => camera.perspective.is_some(),
            Checked::Valid(Type::Orthographic) => camera.orthographic.is_some(),
            Checked::Invalid => true,
        };
        if !ok {
            return Err(format!("invalid glTF: cameras[{i}] lacks the projection its type names"));
        }
    }
    Ok(())
}

fn placeholder_camera() -> Camera {
    Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 }
}

/// The first few of the validation errors the `gltf` crate reports, on one line.
fn describe_gltf_error(e: ::gltf::Error) -> String {
    match e {
        ::gltf::Error::Validation(errors) => {
            let shown: Vec<String> = errors.iter().take(3).map(|(path, error)| format!("{path}: {error}")).collect();
            let more = errors.len().saturating_sub(3);
            let more = if more > 0 { format!(" (and {more} more)") } else { String::new() };
            format!("invalid glTF: {}{more}", shown.join("; "))
        }
        e => format!("invalid glTF: {}", e.to_string().replace('\n', " ")),
    }
}

fn read_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// The JSON chunk and the optional BIN chunk of a `.glb` container, every length checked.
fn split_glb(bytes: &[u8]) -> Res<(&[u8], Option<&[u8]>)> {
    if bytes.len() < 20 {
        return Err(format!("truncated .glb: {} bytes, fewer than a header and a chunk header", bytes.len()));
    }
    let version = read_u32(bytes, 4);
    if version != 2 {
        return Err(format!("a .glb of version {version}; only glTF 2.0 is supported"));
    }
    let length = read_u32(bytes, 8) as usize;
    if length > bytes.len() {
        return Err(format!("truncated .glb: its header announces {length} bytes but the file has {}", bytes.len()));
    }
    let mut rest = &bytes[12..length.max(12)];
    let mut chunk = |what: &str| -> Res<Option<(u32, &[u8])>> {
        if rest.is_empty() {
            return Ok(None);
        }
        if rest.len() < 8 {
            return Err(format!("truncated .glb: the {what} chunk's header is cut off"));
        }
        let (len, kind) = (read_u32(rest, 0) as usize, read_u32(rest, 4));
        if len > rest.len() - 8 {
            return Err(format!(
                "truncated .glb: the {what} chunk announces {len} bytes but {} remain",
                rest.len() - 8
            ));
        }
        let data = &rest[8..8 + len];
        rest = &rest[(8 + len.next_multiple_of(4)).min(rest.len())..];
        Ok(Some((kind, data)))
    };
    const JSON: u32 = u32::from_le_bytes(*b"JSON");
    const BIN: u32 = u32::from_le_bytes(*b"BIN\0");
    let json = match chunk("first")? {
        Some((JSON, data)) => data,
        _ => return Err("not a valid .glb: its first chunk is not JSON".into()),
    };
    // Chunks of unknown types are skipped, as the specification requires.
    let mut bin = None;
    while let Some((kind, data)) = chunk("next")? {
        if kind == BIN && bin.is_none() {
            bin = Some(data);
        }
    }
    Ok((json, bin))
}

/// Decodes `%XX` escapes of a URI reference.
fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        let hex = |b: u8| (b as char).to_digit(16);
        if bytes[i] == b'%'
            && i + 2 < bytes.len()
            && let (Some(h), Some(l)) = (hex(bytes[i + 1]), hex(bytes[i + 2]))
        {
            out.push((h * 16 + l) as u8);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// The bytes a URI names: a base64 `data:` URI, or a file relative to the glTF file.
fn read_uri(dir: &Path, uri: &str) -> Res<Vec<u8>> {
    if let Some(data) = uri.strip_prefix("data:") {
        let (header, payload) = data.split_once(',').ok_or("a data: URI without ','")?;
        if !header.ends_with(";base64") {
            return Err("a data: URI that is not base64-encoded".into());
        }
        let engine = base64::engine::general_purpose::GeneralPurpose::new(
            &base64::alphabet::STANDARD,
            base64::engine::GeneralPurposeConfig::new()
                .with_decode_padding_mode(base64::engine::DecodePaddingMode::Indifferent),
        );
        return engine.decode(payload).map_err(|e| format!("a data: URI with invalid base64 ({e})"));
    }
    if uri.contains("://") {
        return Err(format!("the URI {uri} is not a file; only relative file names and data: URIs are supported"));
    }
    let file: PathBuf = dir.join(percent_decode(uri));
    // A device or a pipe (`/dev/zero`) would be read forever.
    if file.exists() && !file.is_file() {
        return Err(format!("{} is not a regular file", file.display()));
    }
    std::fs::read(&file).map_err(|e| format!("{} cannot be read ({e})", file.display()))
}

fn load_buffer(dir: &Path, buffer: &::gltf::Buffer, bin: Option<&[u8]>) -> Res<Vec<u8>> {
    let name = |b: &::gltf::Buffer| match b.name() {
        Some(n) => format!("buffer {} ('{n}')", b.index()),
        None => format!("buffer {}", b.index()),
    };
    let data = match buffer.source() {
        ::gltf::buffer::Source::Bin => match bin {
            Some(bin) if buffer.index() == 0 => bin.to_vec(),
            _ => return Err(format!("{} has no uri and there is no .glb binary chunk for it", name(buffer))),
        },
        ::gltf::buffer::Source::Uri(uri) => read_uri(dir, uri).map_err(|e| format!("{}: {e}", name(buffer)))?,
    };
    if (data.len() as u64) < buffer.length() as u64 {
        return Err(format!("{} holds {} bytes but its byteLength is {}", name(buffer), data.len(), buffer.length()));
    }
    Ok(data)
}

/// An accessor's elements, located and range-checked in its buffer.
struct Elements<'a> {
    data: &'a [u8],
    stride: usize,
    size: usize,
    count: usize,
    data_type: DataType,
    normalized: bool,
}

impl Elements<'_> {
    fn element(&self, i: usize) -> &[u8] {
        &self.data[i * self.stride..i * self.stride + self.size]
    }

    /// Component `c` of element `i` as a float (normalised integers mapped to [0, 1]).
    fn float(&self, i: usize, c: usize) -> f32 {
        let e = self.element(i);
        match self.data_type {
            DataType::F32 => f32::from_le_bytes([e[4 * c], e[4 * c + 1], e[4 * c + 2], e[4 * c + 3]]),
            DataType::U8 => e[c] as f32 / if self.normalized { 255.0 } else { 1.0 },
            DataType::U16 => {
                u16::from_le_bytes([e[2 * c], e[2 * c + 1]]) as f32 / if self.normalized { 65535.0 } else { 1.0 }
            }
            _ => f32::NAN,
        }
    }

    /// Element `i` of a scalar unsigned-integer accessor.
    fn index(&self, i: usize) -> u32 {
        let e = self.element(i);
        match self.data_type {
            DataType::U8 => e[0] as u32,
            DataType::U16 => u16::from_le_bytes([e[0], e[1]]) as u32,
            _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
        }
    }
}

/// The triangles of one primitive in the mesh's own space.
struct Primitive {
    triangles: Vec<[Vec3; 3]>,
    uvs: Option<Vec<[Vec2; 3]>>,
    /// The corners' NORMALs in the mesh's space, where the primitive has them.
    normals: Option<Vec<[Vec3; 3]>>,
    /// The corners' tangents in the mesh's space, where its material has a normal map.
    tangents: Option<Vec<[Vec4; 3]>>,
    material: u32,
}

struct Loader<'a> {
    dir: PathBuf,
    document: &'a Document,
    buffers: Vec<Vec<u8>>,
    scene: Scene,
    /// glTF material index (None: the default material) → scene material.
    materials: HashMap<Option<usize>, u32>,
    /// glTF image index → scene texture.
    /// Scene textures by (image, read as linear data).
    textures: HashMap<(usize, bool), usize>,
    /// The camera chosen, once found.
    camera: Option<Camera>,
    warned_sampler: bool,
    warned_sets: bool,
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
        if total > MAX_TRIANGLES {
            return Err(format!("expands to {total} triangles, more than the {MAX_TRIANGLES} rastergi loads"));
        }
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

    /// An accessor's elements after checking its type and its byte range.
    fn elements(
        &self,
        accessor: &::gltf::Accessor,
        what: &str,
        types: &[DataType],
        dims: Dimensions,
    ) -> Res<Elements<'_>> {
        let name = format!("{what} (accessor {})", accessor.index());
        if accessor.sparse().is_some() {
            return Err(format!("{name} is sparse, which is not supported"));
        }
        if accessor.dimensions() != dims || !types.contains(&accessor.data_type()) {
            return Err(format!(
                "{name} holds {:?} of {:?}, expected {dims:?} of {}",
                accessor.dimensions(),
                accessor.data_type(),
                types.iter().map(|t| format!("{t:?}")).collect::<Vec<_>>().join(" or ")
            ));
        }
        let view = accessor.view().ok_or_else(|| format!("{name} has no bufferView"))?;
        let buffer = &self.buffers[view.buffer().index()];
        let size = accessor.size();
        let stride = view.stride().unwrap_or(size);
        if stride < size {
            return Err(format!(
                "{name}: its bufferView's byteStride {stride} is smaller than an element ({size} bytes)"
            ));
        }
        let count = accessor.count();
        let (view_start, view_len) = (view.offset() as u64, view.length() as u64);
        if view_start.checked_add(view_len).is_none_or(|end| end > buffer.len() as u64) {
            return Err(format!(
                "{name}: bufferView {} (bytes {view_start}..+{view_len}) runs past the end of its buffer ({} bytes)",
                view.index(),
                buffer.len()
            ));
        }
        let needed = if count == 0 {
            Some(0)
        } else {
            (count as u64 - 1)
                .checked_mul(stride as u64)
                .and_then(|n| n.checked_add(size as u64))
                .and_then(|n| n.checked_add(accessor.offset() as u64))
        };
        if needed.is_none_or(|n| n > view_len) {
            return Err(format!(
                "{name}: {count} elements from byte {} do not fit its bufferView of {view_len} bytes",
                accessor.offset()
            ));
        }
        let start = (view_start + accessor.offset() as u64) as usize;
        let end = (view_start + view_len) as usize;
        Ok(Elements {
            data: &buffer[start..end],
            stride,
            size,
            count,
            data_type: accessor.data_type(),
            normalized: accessor.normalized(),
        })
    }

    fn positions(&self, p: &::gltf::Primitive, what: &str) -> Res<Elements<'_>> {
        let accessor = p.get(&Semantic::Positions).ok_or_else(|| format!("{what} has no POSITION attribute"))?;
        self.elements(&accessor, &format!("{what} POSITION"), &[DataType::F32], Dimensions::Vec3)
    }

    fn indices(&self, p: &::gltf::Primitive, what: &str) -> Res<Option<Elements<'_>>> {
        let Some(accessor) = p.indices() else { return Ok(None) };
        let types = [DataType::U8, DataType::U16, DataType::U32];
        self.elements(&accessor, &format!("{what} indices"), &types, Dimensions::Scalar).map(Some)
    }

    /// The number of triangles a primitive makes, its accessors checked.
    fn triangle_count(&self, mesh: &::gltf::Mesh, p: &::gltf::Primitive) -> Res<u64> {
        let what = format!("{} primitive {}", named("mesh", mesh.index(), mesh.name()), p.index());
        let positions = self.positions(p, &what)?;
        let n = match self.indices(p, &what)? {
            Some(indices) => indices.count,
            None => positions.count,
        } as u64;
        Ok(match p.mode() {
            Mode::Triangles => n / 3,
            Mode::TriangleStrip | Mode::TriangleFan => n.saturating_sub(2),
            _ => 0,
        })
    }

    /// Reads a primitive's triangles (None for points and lines).
    fn primitive(&mut self, mesh: &::gltf::Mesh, p: &::gltf::Primitive) -> Res<Option<Primitive>> {
        let what = format!("{} primitive {}", named("mesh", mesh.index(), mesh.name()), p.index());
        if !matches!(p.mode(), Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            log::warn!("{what}: {:?} have no area and are skipped", p.mode());
            return Ok(None);
        }
        let material = self.material(&p.material())?;
        let sets = texture_sets(&p.material());
        let tex_coord_set = sets.first().copied();
        if sets.iter().any(|&s| Some(s) != tex_coord_set) && !std::mem::replace(&mut self.warned_sets, true) {
            log::warn!("{what}: its material's textures name different TEXCOORD sets; all read TEXCOORD_{}", sets[0]);
        }
        let positions = self.positions(p, &what)?;
        let vertices: Vec<Vec3> = (0..positions.count)
            .map(|i| Vec3::new(positions.float(i, 0), positions.float(i, 1), positions.float(i, 2)))
            .collect();
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(format!("{what}: vertex {i} has a non-finite POSITION"));
        }
        let indices: Vec<u32> = match self.indices(p, &what)? {
            Some(e) => (0..e.count).map(|i| e.index(i)).collect(),
            None => (0..vertices.len() as u32).collect(),
        };
        if let Some(&i) = indices.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(format!("{what}: index {i} is out of range ({} vertices)", vertices.len()));
        }
        let corners: Vec<[u32; 3]> = match p.mode() {
            Mode::Triangles => indices.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
            // Strip triangle i: (i, i+1, i+2) for even i, (i+1, i, i+2) for odd i, so all keep
            // the first triangle's orientation.
            Mode::TriangleStrip => (0..indices.len().saturating_sub(2))
                .map(|i| if i % 2 == 0 { [i, i + 1, i + 2] } else { [i + 1, i, i + 2] }.map(|k| indices[k]))
                .collect(),
            _ => (1..indices.len().saturating_sub(1)).map(|i| [indices[i], indices[i + 1], indices[0]]).collect(),
        };
        let triangles: Vec<[Vec3; 3]> = corners.iter().map(|c| c.map(|i| vertices[i as usize])).collect();
        let uvs: Option<Vec<[Vec2; 3]>> = match tex_coord_set {
            Some(set) => {
                let accessor = p
                    .get(&Semantic::TexCoords(set))
                    .ok_or_else(|| format!("{what} has a texture but no TEXCOORD_{set} attribute"))?;
                let types = [DataType::F32, DataType::U8, DataType::U16];
                let e = self.elements(&accessor, &format!("{what} TEXCOORD_{set}"), &types, Dimensions::Vec2)?;
                if e.data_type != DataType::F32 && !e.normalized {
                    return Err(format!("{what} TEXCOORD_{set}: integer texture coordinates must be normalized"));
                }
                if e.count != vertices.len() {
                    return Err(format!(
                        "{what} TEXCOORD_{set} has {} elements for {} vertices",
                        e.count,
                        vertices.len()
                    ));
                }
                let uv: Vec<Vec2> = (0..e.count).map(|i| Vec2::new(e.float(i, 0), e.float(i, 1))).collect();
                if let Some(i) = uv.iter().position(|v| !v.is_finite()) {
                    return Err(format!("{what}: vertex {i} has a non-finite TEXCOORD_{set}"));
                }
                Some(corners.iter().map(|c| c.map(|i| uv[i as usize])).collect())
            }
            None => None,
        };
        // Normals rastergi cannot read (quantized, sparse, the wrong count, non-finite) make
        // the primitive shade flat, with a warning: the geometry is still right.
        let normals: Option<Vec<[Vec3; 3]>> = p.get(&Semantic::Normals).and_then(|accessor| {
            let read = || -> Res<Vec<Vec3>> {
                let e = self.elements(&accessor, &format!("{what} NORMAL"), &[DataType::F32], Dimensions::Vec3)?;
                if e.count != vertices.len() {
                    return Err(format!("{what} NORMAL has {} elements for {} vertices", e.count, vertices.len()));
                }
                let n: Vec<Vec3> =
                    (0..e.count).map(|i| Vec3::new(e.float(i, 0), e.float(i, 1), e.float(i, 2))).collect();
                match n.iter().position(|v| !v.is_finite()) {
                    Some(i) => Err(format!("{what}: vertex {i} has a non-finite NORMAL")),
                    None => Ok(n),
                }
            };
            match read() {
                Ok(n) => Some(corners.iter().map(|c| c.map(|i| n[i as usize])).collect()),
                Err(e) => {
                    log::warn!("{e}; it shades flat");
                    None
                }
            }
        });
        let tangents = match (p.material().normal_texture(), &uvs) {
            (Some(_), Some(uvs)) => Some(self.tangents(p, &what, &corners, &triangles, uvs, normals.as_deref())),
            _ => None,
        };
        Ok(Some(Primitive { triangles, uvs, normals, tangents, material }))
    }

    /// The corners' tangents of a primitive with a normal map: its TANGENT attribute, or
    /// MikkTSpace's from its positions, normals (the faces' where it has none) and texture
    /// coordinates when it has none or one that cannot be read (with a warning).
    fn tangents(
        &self,
        p: &::gltf::Primitive,
        what: &str,
        corners: &[[u32; 3]],
        triangles: &[[Vec3; 3]],
        uvs: &[[Vec2; 3]],
        normals: Option<&[[Vec3; 3]]>,
    ) -> Vec<[Vec4; 3]> {
        if let Some(accessor) = p.get(&Semantic::Tangents) {
            let read = || -> Res<Vec<[Vec4; 3]>> {
                let e = self.elements(&accessor, &format!("{what} TANGENT"), &[DataType::F32], Dimensions::Vec4)?;
                let count = corners.iter().flatten().max().map_or(0, |&i| i as usize + 1);
                if e.count < count {
                    return Err(format!("{what} TANGENT has {} elements for {count} vertices", e.count));
                }
                let t: Vec<Vec4> = (0..e.count)
                    .map(|i| Vec4::new(e.float(i, 0), e.float(i, 1), e.float(i, 2), e.float(i, 3)))
                    .collect();
                match t.iter().position(|v| !v.is_finite()) {
                    Some(i) => Err(format!("{what}: vertex {i} has a non-finite TANGENT")),
                    None => Ok(corners.iter().map(|c| c.map(|i| t[i as usize])).collect()),
                }
            };
            match read() {
                Ok(t) => return t,
                Err(e) => log::warn!("{e}; MikkTSpace tangents are used instead"),
            }
        }
        super::tangents::mikktspace(triangles, uvs, normals)
    }

    /// The scene material of a glTF material, created on first use.
    fn material(&mut self, m: &::gltf::Material) -> Res<u32> {
        if let Some(&id) = self.materials.get(&m.index()) {
            return Ok(id);
        }
        let material = match m.index() {
            None => Material::diffuse("default", Vec3::splat(DEFAULT_ALBEDO)),
            Some(index) => {
                let what = named("material", index, m.name());
                let pbr = m.pbr_metallic_roughness();
                let mut texture = |info: Option<(::gltf::Texture, UvTransform)>, linear: bool| match info {
                    Some((t, transform)) => self
                        .texture(&t, linear)
                        .map(|texture| Some(TextureRef { texture, transform }))
                        .map_err(|e| format!("{what}: {e}")),
                    None => Ok(None),
                };
                let base = texture(pbr.base_color_texture().map(|i| (i.texture(), info_transform(&i))), false)?;
                let emission = Vec3::from(m.emissive_factor()) * m.emissive_strength().unwrap_or(1.0);
                let emissive = m.emissive_texture().filter(|_| emission.max_element() > 0.0);
                let emission_texture = texture(emissive.map(|i| (i.texture(), info_transform(&i))), false)?;
                let normal = m.normal_texture();
                let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
                let normal_texture = texture(normal.map(|n| (n.texture(), normal_transform(&n))), true)?;
                let alpha_mode = match m.alpha_mode() {
                    ::gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
                    ::gltf::material::AlphaMode::Mask => AlphaMode::Mask { cutoff: m.alpha_cutoff().unwrap_or(0.5) },
                    ::gltf::material::AlphaMode::Blend => AlphaMode::Blend,
                };
                if let AlphaMode::Mask { cutoff } = alpha_mode
                    && !(cutoff.is_finite() && cutoff >= 0.0)
                {
                    return Err(format!("{what}: alphaCutoff {cutoff} is not a non-negative number"));
                }
                let opacity = pbr.base_color_factor()[3];
                if !(0.0..=1.0).contains(&opacity) {
                    return Err(format!("{what}: baseColorFactor's alpha {opacity} is outside [0, 1]"));
                }
                let metal_rough = pbr.metallic_roughness_texture().map(|i| (i.texture(), info_transform(&i)));
                let metal_rough_texture = texture(metal_rough, true)?;
                let unit = |name: &str, v: f32| -> Res<f32> {
                    if (0.0..=1.0).contains(&v) { Ok(v) } else { Err(format!("{what}: {name} {v} is outside [0, 1]")) }
                };
                let metallic = unit("metallicFactor", pbr.metallic_factor())?;
                let roughness = unit("roughnessFactor", pbr.roughness_factor())?;
                let transmission = m.transmission();
                if transmission.as_ref().is_some_and(|t| t.transmission_texture().is_some()) {
                    log::warn!("{what}: transmissionTexture is not read; its transmissionFactor applies everywhere");
                }
                let transmission = unit("transmissionFactor", transmission.map_or(0.0, |t| t.transmission_factor()))?;
                let ior = m.ior().unwrap_or(1.5);
                if !(ior.is_finite() && (ior == 0.0 || ior >= 1.0)) {
                    return Err(format!("{what}: ior {ior} is not 0 or at least 1"));
                }
                // ior 0 is the extension's "infinite": a perfect reflector; clamped to 10⁴.
                let ior = if ior == 0.0 { 1e4 } else { ior };
                let specular = m.specular();
                if specular.as_ref().is_some_and(|s| {
                    s.specular_color_factor() != [1.0; 3]
                        || s.specular_texture().is_some()
                        || s.specular_color_texture().is_some()
                }) {
                    log::warn!(
                        "{what}: KHR_materials_specular's colour and textures are not read; its specularFactor is"
                    );
                }
                let specular = unit("specularFactor", specular.map_or(1.0, |s| s.specular_factor()))?;
                // A volume makes the glass a refracting solid; thickness 0 (its default) or no
                // volume: thin-walled, as the extension says.
                let thin = m.volume().is_none_or(|v| v.thickness_factor() <= 0.0);
                Material {
                    albedo_texture: base.map(|t| t.texture),
                    albedo_transform: base.map_or(UvTransform::IDENTITY, |t| t.transform),
                    emission,
                    emission_texture,
                    opacity,
                    opacity_texture: base.filter(|_| alpha_mode != AlphaMode::Opaque),
                    alpha_mode,
                    normal_texture,
                    normal_scale,
                    metallic,
                    roughness,
                    metal_rough_texture,
                    specular,
                    ior,
                    transmission,
                    thin,
                    two_sided: m.double_sided(),
                    ..Material::diffuse(
                        &m.name().map_or_else(|| format!("material {index}"), str::to_owned),
                        Vec3::from_slice(&pbr.base_color_factor()[..3]),
                    )
                }
            }
        };
        let id = self.scene.add_material(material);
        self.materials.insert(m.index(), id);
        Ok(id)
    }

    /// The scene texture of a glTF texture's image (sRGB colour, or `linear` data), decoded on
    /// first use.
    fn texture(&mut self, texture: &::gltf::Texture, linear: bool) -> Res<usize> {
        let sampler = texture.sampler();
        use ::gltf::texture::WrappingMode::Repeat;
        if (sampler.wrap_s() != Repeat || sampler.wrap_t() != Repeat)
            && !std::mem::replace(&mut self.warned_sampler, true)
        {
            log::warn!("textures are always sampled with repeat addressing; clamped and mirrored samplers are ignored");
        }
        let image = texture.source();
        if let Some(&t) = self.textures.get(&(image.index(), linear)) {
            return Ok(t);
        }
        let what = named("image", image.index(), image.name());
        let bytes: Vec<u8> = match image.source() {
            ::gltf::image::Source::View { view, .. } => {
                let buffer = &self.buffers[view.buffer().index()];
                let range = view.offset().checked_add(view.length()).filter(|&end| end <= buffer.len());
                let end = range.ok_or_else(|| format!("{what}: its bufferView runs past the end of its buffer"))?;
                buffer[view.offset()..end].to_vec()
            }
            ::gltf::image::Source::Uri { uri, .. } => read_uri(&self.dir, uri).map_err(|e| format!("{what}: {e}"))?,
        };
        let name = image.name().map_or_else(|| format!("image {}", image.index()), str::to_owned);
        let decoded = Texture::decode(&name, &bytes).map_err(|e| format!("{what} {e}"))?;
        let t = self.scene.add_texture(if linear { decoded.into_linear() } else { decoded });
        self.textures.insert((image.index(), linear), t);
        Ok(t)
    }
}

/// A node's local transform: its matrix, or translation × rotation × scale.
/// A `KHR_lights_punctual` light placed by its node's world transform: at the node's origin,
/// shining along its local −Z; `color` × `intensity` read 1:1 as W/sr (point, spot) or W/m²
/// (directional).
fn punctual_light(light: &::gltf::khr_lights_punctual::Light, world: Mat4) -> Res<Light> {
    use ::gltf::khr_lights_punctual::Kind;
    let value = Vec3::from(light.color()) * light.intensity();
    let position = world.transform_point3(Vec3::ZERO);
    let axis = world.transform_vector3(-Vec3::Z);
    if axis.is_nan() || axis.length() <= 1e-12 {
        return Err("its node's transform collapses the light's direction".into());
    }
    let direction = axis.normalize();
    Ok(match light.kind() {
        Kind::Point => Light::Point { position, intensity: value },
        Kind::Spot { inner_cone_angle, outer_cone_angle } => {
            Light::Spot { position, direction, intensity: value, inner: inner_cone_angle, outer: outer_cone_angle }
        }
        Kind::Directional => Light::Distant { direction, irradiance: value, angular_radius: 0.0 },
    })
}

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

/// The mean linear colour of a texture.
/// KHR_texture_transform's affine map, T(offset) · R(rotation) · S(scale): (u, v) ↦
/// (c·sx·u + s·sy·v + ox, −s·sx·u + c·sy·v + oy) with c, s the rotation's cosine and sine.
pub fn texture_transform(offset: [f32; 2], rotation: f32, scale: [f32; 2]) -> UvTransform {
    let (s, c) = rotation.sin_cos();
    UvTransform([[c * scale[0], s * scale[1], offset[0]], [-s * scale[0], c * scale[1], offset[1]]])
}

fn info_transform(info: &::gltf::texture::Info) -> UvTransform {
    info.texture_transform().map_or(UvTransform::IDENTITY, |t| texture_transform(t.offset(), t.rotation(), t.scale()))
}

/// The normal texture's KHR_texture_transform (the `gltf` crate leaves it unparsed there).
fn normal_transform(n: &::gltf::material::NormalTexture) -> UvTransform {
    parsed_normal_transform(n).map_or(UvTransform::IDENTITY, |t| texture_transform(t.offset.0, t.rotation.0, t.scale.0))
}

fn parsed_normal_transform(
    n: &::gltf::material::NormalTexture,
) -> Option<::gltf::json::extensions::texture::TextureTransform> {
    let value = n.extension_value("KHR_texture_transform")?;
    ::gltf::json::deserialize::from_value(value.clone())
        .map_err(|e| log::warn!("a normal texture's KHR_texture_transform is not valid ({e}); it is ignored"))
        .ok()
}

/// The TEXCOORD sets a material's textures read (base colour, emissive, normal map,
/// metallic-roughness), each
/// overridden by its KHR_texture_transform's texCoord.
fn texture_sets(m: &::gltf::Material) -> Vec<u32> {
    let info = |i: ::gltf::texture::Info| i.texture_transform().and_then(|t| t.tex_coord()).unwrap_or(i.tex_coord());
    let base = m.pbr_metallic_roughness().base_color_texture().map(info);
    let emissive = m.emissive_texture().map(info);
    let normal =
        m.normal_texture().map(|n| parsed_normal_transform(&n).and_then(|t| t.tex_coord).unwrap_or(n.tex_coord()));
    let metal_rough = m.pbr_metallic_roughness().metallic_roughness_texture().map(info);
    base.into_iter().chain(emissive).chain(normal).chain(metal_rough).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percent_escapes_are_decoded() {
        assert_eq!(percent_decode("my%20texture.png"), "my texture.png");
        assert_eq!(percent_decode("a%2"), "a%2");
        assert_eq!(percent_decode("100%"), "100%");
    }

    #[test]
    fn glb_chunks_are_split_and_lengths_checked() {
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(36u32.to_le_bytes());
        glb.extend(4u32.to_le_bytes());
        glb.extend(b"JSON{}  ");
        glb.extend(4u32.to_le_bytes());
        glb.extend(b"BIN\0abcd");
        let (json, bin) = split_glb(&glb).unwrap();
        assert_eq!(json, b"{}  ");
        assert_eq!(bin, Some(&b"abcd"[..]));
        for cut in 0..glb.len() {
            assert!(split_glb(&glb[..cut]).is_err(), "a .glb cut at {cut} bytes was accepted");
        }
        let mut short_header = glb.clone();
        short_header[8..12].copy_from_slice(&4u32.to_le_bytes());
        assert!(split_glb(&short_header).is_err(), "a header length shorter than the header was accepted");
    }
}
