//! The textured room of the glTF and texture tests, written by the tests themselves: a box
//! open at the front with a textured floor (a checker repeated three times), a textured back
//! wall (stripes repeated twice), red and green side walls, an emitter under the ceiling
//! (KHR_materials_emissive_strength), a textured cube placed by a two-level node hierarchy
//! (translation, then translation × rotation × scale), a textured panel placed twice, once
//! mirrored (scale −1 along x), and three cameras (two perspective, one orthographic).
//!
//! The same room is written as glTF with external files, as glTF with everything embedded in
//! base64 `data:` URIs, as a binary `.glb`, and as OBJ + MTL with `map_Kd` (world coordinates,
//! v flipped to OBJ's upward convention). The world placement of every node is stated here by
//! hand ([`CUBE`], [`PANEL`], [`MIRRORED_PANEL`], …) for the tests to check against.

use std::f32::consts::PI;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use glam::{Quat, Vec2, Vec3};
use serde_json::{Value, json};

/// Checker: 16×16 texels, checks of 4×4 texels in two colours (sRGB codes).
pub const CHECKER_SIZE: (u32, u32) = (16, 16);
pub const CHECKER_COLOURS: [[u8; 3]; 2] = [[230, 200, 60], [40, 90, 160]];
/// Stripes: 32×8 texels, vertical stripes 4 texels wide.
pub const STRIPES_SIZE: (u32, u32) = (32, 8);
pub const STRIPES_COLOURS: [[u8; 3]; 2] = [[220, 220, 220], [120, 30, 30]];

/// Light: emissiveFactor × emissive strength.
pub const EMISSIVE_FACTOR: [f32; 3] = [1.0, 0.9, 0.8];
pub const EMISSIVE_STRENGTH: f32 = 10.0;
/// yfov of the two perspective cameras, radians.
pub const YFOV: f32 = 0.7;

/// A node's placement: world = translation + rotation · (scale ⊙ local).
#[derive(Clone, Copy, Debug)]
pub struct Placement {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
}

impl Placement {
    pub const IDENTITY: Placement = Placement { translation: Vec3::ZERO, rotation: Quat::IDENTITY, scale: Vec3::ONE };

    pub fn apply(&self, p: Vec3) -> Vec3 {
        self.translation + self.rotation * (self.scale * p)
    }

    /// This placement after `parent`'s (parent ∘ self), for placements without shear.
    fn under(self, parent: Placement) -> Placement {
        Placement {
            translation: parent.apply(self.translation),
            rotation: parent.rotation * self.rotation,
            scale: parent.scale * self.scale,
        }
    }
}

fn rotation_y(deg: f32) -> Quat {
    Quat::from_rotation_y(deg.to_radians())
}

/// Node "furniture": lifts what it holds to the floor.
pub const FURNITURE: Placement = Placement { translation: Vec3::new(0.0, -0.7, 0.0), ..Placement::IDENTITY };
/// The cube's own node, under "furniture": 30° about y, scale 0.3.
pub fn cube_local() -> Placement {
    Placement { translation: Vec3::new(0.3, 0.0, 0.1), rotation: rotation_y(30.0), scale: Vec3::splat(0.3) }
}
/// Where the cube's corner (1, 1, 1) lands, written out by hand: (0.3, −0.7, 0.1) + R_y(30°)·(0.3, 0.3, 0.3),
/// R_y(θ)(x, y, z) = (x cos θ + z sin θ, y, −x sin θ + z cos θ).
pub fn cube_corner_world() -> Vec3 {
    let (s, c) = (30f32.to_radians().sin(), 30f32.to_radians().cos());
    Vec3::new(0.3 + 0.3 * (c + s), -0.7 + 0.3, 0.1 + 0.3 * (c - s))
}
pub const LAMP: Placement = Placement { translation: Vec3::new(0.0, -0.01, 0.0), ..Placement::IDENTITY };
pub const PANEL: Placement = Placement { translation: Vec3::new(0.2, -0.2, -0.98), ..Placement::IDENTITY };
pub const MIRRORED_PANEL: Placement =
    Placement { translation: Vec3::new(-0.2, -0.2, -0.98), rotation: Quat::IDENTITY, scale: Vec3::new(-1.0, 1.0, 1.0) };
/// The camera rig, holding both perspective cameras.
pub const RIG: Placement = Placement { translation: Vec3::new(0.0, 0.2, 0.0), ..Placement::IDENTITY };
pub fn main_camera_local() -> Placement {
    Placement {
        translation: Vec3::new(0.0, 0.0, 3.4),
        rotation: Quat::from_rotation_x((-3f32).to_radians()),
        scale: Vec3::ONE,
    }
}
pub fn side_camera_local() -> Placement {
    Placement { translation: Vec3::new(2.0, -0.2, 2.0), rotation: rotation_y(45.0), scale: Vec3::ONE }
}

/// One primitive: a triangle list with texture coordinates and a material (index below).
#[derive(Clone, Debug)]
pub struct Primitive {
    pub positions: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<u16>,
    pub material: usize,
}

/// A quad `a b c d`, counter-clockwise about its front face, with texture coordinates.
fn quad(corners: [Vec3; 4], uvs: [Vec2; 4], material: usize) -> Primitive {
    Primitive { positions: corners.to_vec(), uvs: uvs.to_vec(), indices: vec![0, 1, 2, 0, 2, 3], material }
}

fn v3(x: f32, y: f32, z: f32) -> Vec3 {
    Vec3::new(x, y, z)
}

/// Texture coordinates of a quad's corners from a function of position.
fn uv_of(corners: [Vec3; 4], f: impl Fn(Vec3) -> Vec2) -> [Vec2; 4] {
    corners.map(f)
}

// Materials, in file order.
pub const WHITE: usize = 0;
pub const RED: usize = 1;
pub const GREEN: usize = 2;
pub const FLOOR: usize = 3;
pub const BACK: usize = 4;
pub const CUBE: usize = 5;
pub const LIGHT: usize = 6;
pub const PANEL_MATERIAL: usize = 7;

/// A material of the room as the file states it.
#[derive(Clone, Copy, Debug)]
pub struct MaterialDef {
    pub name: &'static str,
    /// baseColorFactor (rgb; alpha 1).
    pub factor: [f32; 3],
    /// baseColorTexture: 0 checker, 1 stripes.
    pub texture: Option<usize>,
    pub double_sided: bool,
    /// Emits EMISSIVE_FACTOR × EMISSIVE_STRENGTH.
    pub emissive: bool,
}

const fn material(name: &'static str, factor: [f32; 3], texture: Option<usize>, double_sided: bool) -> MaterialDef {
    MaterialDef { name, factor, texture, double_sided, emissive: false }
}

pub const MATERIALS: [MaterialDef; 8] = [
    material("white", [0.8, 0.8, 0.8], None, true),
    material("red", [0.63, 0.065, 0.05], None, true),
    material("green", [0.14, 0.45, 0.09], None, true),
    material("floor", [0.9, 0.9, 0.9], Some(0), true),
    material("back", [1.0, 1.0, 1.0], Some(1), true),
    material("cube", [0.9, 0.8, 0.7], Some(1), false),
    MaterialDef { emissive: true, ..material("light", [0.5, 0.5, 0.5], None, true) },
    material("panel", [1.0, 1.0, 1.0], Some(0), true),
];

/// The meshes: 0 the room (five primitives), 1 the light, 2 the cube, 3 the panel.
pub fn meshes() -> Vec<(&'static str, Vec<Primitive>)> {
    let floor = [v3(-1., -1., 1.), v3(1., -1., 1.), v3(1., -1., -1.), v3(-1., -1., -1.)];
    let ceiling = [v3(-1., 1., -1.), v3(1., 1., -1.), v3(1., 1., 1.), v3(-1., 1., 1.)];
    let back = [v3(-1., -1., -1.), v3(1., -1., -1.), v3(1., 1., -1.), v3(-1., 1., -1.)];
    let left = [v3(-1., -1., 1.), v3(-1., -1., -1.), v3(-1., 1., -1.), v3(-1., 1., 1.)];
    let right = [v3(1., -1., -1.), v3(1., -1., 1.), v3(1., 1., 1.), v3(1., 1., -1.)];
    let none = |_: Vec3| Vec2::ZERO;
    let room = vec![
        quad(floor, uv_of(floor, |p| 1.5 * Vec2::new(p.x + 1.0, p.z + 1.0)), FLOOR),
        quad(ceiling, uv_of(ceiling, none), WHITE),
        quad(back, uv_of(back, |p| Vec2::new(p.x + 1.0, 0.5 * (1.0 - p.y))), BACK),
        quad(left, uv_of(left, none), RED),
        quad(right, uv_of(right, none), GREEN),
    ];
    let light_corners = [v3(-0.25, 0.98, -0.25), v3(0.25, 0.98, -0.25), v3(0.25, 0.98, 0.25), v3(-0.25, 0.98, 0.25)];
    let light = vec![quad(light_corners, uv_of(light_corners, none), LIGHT)];
    let mut cube = Primitive { positions: vec![], uvs: vec![], indices: vec![], material: CUBE };
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let n = Vec3::AXES[axis] * sign;
            let u = Vec3::AXES[(axis + 1) % 3];
            let v = Vec3::AXES[(axis + 2) % 3] * sign;
            let base = cube.positions.len() as u16;
            cube.positions.extend([n - u - v, n + u - v, n + u + v, n - u + v]);
            cube.uvs.extend([Vec2::new(0., 1.), Vec2::new(1., 1.), Vec2::new(1., 0.), Vec2::new(0., 0.)]);
            cube.indices.extend([0, 1, 2, 0, 2, 3].map(|i| base + i));
        }
    }
    let panel_corners = [v3(0., 0., 0.), v3(0.4, 0., 0.), v3(0.4, 0.4, 0.), v3(0., 0.4, 0.)];
    let panel =
        vec![quad(panel_corners, uv_of(panel_corners, |p| Vec2::new(p.x / 0.4, 1.0 - p.y / 0.4)), PANEL_MATERIAL)];
    vec![("room", room), ("lamp", light), ("cube", vec![cube]), ("panel", panel)]
}

/// Every mesh instance of the scene with its world placement.
pub fn instances() -> Vec<(usize, Placement)> {
    vec![(0, Placement::IDENTITY), (1, LAMP), (2, cube_local().under(FURNITURE)), (3, PANEL), (3, MIRRORED_PANEL)]
}

/// The cameras' world placements (main, side).
pub fn camera_placements() -> [Placement; 2] {
    [main_camera_local().under(RIG), side_camera_local().under(RIG)]
}

fn png(size: (u32, u32), texel: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
    let img = image::RgbaImage::from_fn(size.0, size.1, |x, y| {
        let [r, g, b] = texel(x, y);
        image::Rgba([r, g, b, 255])
    });
    let mut bytes = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut bytes), image::ImageFormat::Png).unwrap();
    bytes
}

pub fn checker_texel(x: u32, y: u32) -> [u8; 3] {
    CHECKER_COLOURS[((x / 4 + y / 4) % 2) as usize]
}

pub fn stripes_texel(x: u32, _y: u32) -> [u8; 3] {
    STRIPES_COLOURS[((x / 4) % 2) as usize]
}

pub fn checker_png() -> Vec<u8> {
    png(CHECKER_SIZE, checker_texel)
}

pub fn stripes_png() -> Vec<u8> {
    png(STRIPES_SIZE, stripes_texel)
}

/// How the glTF file holds its buffer and images.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Variant {
    /// scene.gltf + scene.bin + checker.png + stripes.png.
    External,
    /// One .gltf with base64 `data:` URIs.
    Embedded,
    /// One .glb: JSON chunk, BIN chunk with the geometry and both images.
    Binary,
}

/// A glTF document being written: its JSON and its binary buffer.
pub struct Gltf {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Gltf {
    /// Appends `bytes` (4-byte aligned) as a buffer view; returns its index.
    fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() });
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        self.bin.extend_from_slice(bytes);
        push(&mut self.json["bufferViews"], v)
    }

    fn accessor(
        &mut self,
        bytes: &[u8],
        component: u32,
        kind: &str,
        count: usize,
        target: u32,
        minmax: Option<(Vec<f32>, Vec<f32>)>,
    ) -> usize {
        let view = self.view(bytes, Some(target));
        let mut a = json!({ "bufferView": view, "componentType": component, "count": count, "type": kind });
        if let Some((min, max)) = minmax {
            a["min"] = json!(min);
            a["max"] = json!(max);
        }
        push(&mut self.json["accessors"], a)
    }

    /// The .glb container of this document.
    pub fn glb(&self) -> Vec<u8> {
        glb_bytes(&serde_json::to_vec(&self.json).unwrap(), Some(&self.bin))
    }

    /// Writes the document as `name` (.gltf or .glb) in `dir`, with the external files the
    /// variant needs, and returns the path of the main file.
    pub fn write(&self, dir: &Path, name: &str) -> PathBuf {
        let path = dir.join(name);
        if name.ends_with(".glb") {
            std::fs::write(&path, self.glb()).unwrap();
        } else {
            std::fs::write(&path, serde_json::to_string_pretty(&self.json).unwrap()).unwrap();
            if let Some(uri) = self.json["buffers"][0]["uri"].as_str()
                && !uri.starts_with("data:")
                && Path::new(uri).is_relative()
            {
                std::fs::write(dir.join(uri), &self.bin).unwrap();
            }
            for image in self.json["images"].as_array().into_iter().flatten() {
                if let Some(uri) = image["uri"].as_str() {
                    match uri {
                        "checker.png" => std::fs::write(dir.join(uri), checker_png()).unwrap(),
                        "stripes.png" => std::fs::write(dir.join(uri), stripes_png()).unwrap(),
                        _ => {}
                    }
                }
            }
        }
        path
    }
}

fn push(array: &mut Value, v: Value) -> usize {
    if !array.is_array() {
        *array = json!([]);
    }
    let a = array.as_array_mut().unwrap();
    a.push(v);
    a.len() - 1
}

/// A .glb container: a JSON chunk and, when given, a BIN chunk (each padded to 4 bytes).
pub fn glb_bytes(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(0u32.to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(&bin);
    }
    let len = out.len() as u32;
    out[8..12].copy_from_slice(&len.to_le_bytes());
    out
}

fn base64(bytes: &[u8]) -> String {
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

fn bytes_f32(values: impl IntoIterator<Item = f32>) -> Vec<u8> {
    values.into_iter().flat_map(f32::to_le_bytes).collect()
}

fn node(name: &str, p: Placement) -> Value {
    let mut n = json!({ "name": name });
    if p.translation != Vec3::ZERO {
        n["translation"] = json!(p.translation.to_array());
    }
    if p.rotation != Quat::IDENTITY {
        n["rotation"] = json!(p.rotation.to_array());
    }
    if p.scale != Vec3::ONE {
        n["scale"] = json!(p.scale.to_array());
    }
    n
}

/// The room as a glTF document of the given variant.
pub fn room_gltf(variant: Variant) -> Gltf {
    let mut g = Gltf {
        json: json!({
            "asset": { "version": "2.0", "generator": "rastergi tests" },
            "extensionsUsed": ["KHR_materials_emissive_strength", "KHR_materials_specular"],
            "scene": 0,
        }),
        bin: Vec::new(),
    };
    for (name, primitives) in meshes() {
        let mut prims = Vec::new();
        for p in primitives {
            let (min, max) =
                p.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(a, b), &q| (a.min(q), b.max(q)));
            let pos = g.accessor(
                &bytes_f32(p.positions.iter().flat_map(|v| v.to_array())),
                5126,
                "VEC3",
                p.positions.len(),
                34962,
                Some((min.to_array().to_vec(), max.to_array().to_vec())),
            );
            let uv =
                g.accessor(&bytes_f32(p.uvs.iter().flat_map(|v| v.to_array())), 5126, "VEC2", p.uvs.len(), 34962, None);
            let idx: Vec<u8> = p.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
            let indices = g.accessor(&idx, 5123, "SCALAR", p.indices.len(), 34963, None);
            prims.push(json!({
                "attributes": { "POSITION": pos, "TEXCOORD_0": uv },
                "indices": indices,
                "material": p.material,
            }));
        }
        push(&mut g.json["meshes"], json!({ "name": name, "primitives": prims }));
    }
    for MaterialDef { name, factor, texture, double_sided, emissive } in MATERIALS {
        let mut pbr = json!({ "baseColorFactor": [factor[0], factor[1], factor[2], 1.0], "metallicFactor": 0.0 });
        if let Some(t) = texture {
            pbr["baseColorTexture"] = json!({ "index": t });
        }
        // Without glTF's specular layer (specularFactor 0): Lambertian, like the OBJ room.
        let mut m = json!({
            "name": name,
            "pbrMetallicRoughness": pbr,
            "doubleSided": double_sided,
            "extensions": { "KHR_materials_specular": { "specularFactor": 0.0 } },
        });
        if emissive {
            m["emissiveFactor"] = json!(EMISSIVE_FACTOR);
            m["extensions"]["KHR_materials_emissive_strength"] = json!({ "emissiveStrength": EMISSIVE_STRENGTH });
        }
        push(&mut g.json["materials"], m);
    }
    g.json["samplers"] = json!([{ "wrapS": 10497, "wrapT": 10497, "magFilter": 9729, "minFilter": 9987 }]);
    g.json["textures"] = json!([{ "source": 0, "sampler": 0 }, { "source": 1, "sampler": 0 }]);
    let images = [("checker", checker_png()), ("stripes", stripes_png())];
    g.json["images"] = match variant {
        Variant::External => json!([{ "uri": "checker.png" }, { "uri": "stripes.png" }]),
        Variant::Embedded => Value::Array(
            images.iter().map(|(_, png)| json!({ "uri": format!("data:image/png;base64,{}", base64(png)) })).collect(),
        ),
        Variant::Binary => Value::Array(
            images
                .iter()
                .map(|(name, png)| json!({ "name": name, "bufferView": g.view(png, None), "mimeType": "image/png" }))
                .collect(),
        ),
    };
    if variant != Variant::Binary {
        // Image names for the other variants too, so that all three load to equal scenes.
        for (k, (name, _)) in images.iter().enumerate() {
            g.json["images"][k]["name"] = json!(name);
        }
    }
    g.json["cameras"] = json!([
        { "name": "main", "type": "perspective", "perspective": { "yfov": YFOV, "znear": 0.01 } },
        { "name": "side", "type": "perspective", "perspective": { "yfov": YFOV, "znear": 0.01, "aspectRatio": 1.5 } },
        { "name": "plan", "type": "orthographic", "orthographic": { "xmag": 1.0, "ymag": 1.0, "znear": 0.01, "zfar": 10.0 } },
    ]);
    let with = |mut n: Value, key: &str, v: Value| {
        n[key] = v;
        n
    };
    g.json["nodes"] = json!([
        json!({ "name": "room", "mesh": 0, "children": [1] }),
        with(node("lamp", LAMP), "mesh", json!(1)),
        with(node("furniture", FURNITURE), "children", json!([3])),
        with(node("cube", cube_local()), "mesh", json!(2)),
        with(node("panel", PANEL), "mesh", json!(3)),
        with(node("panel mirrored", MIRRORED_PANEL), "mesh", json!(3)),
        with(node("rig", RIG), "children", json!([7, 8])),
        with(node("main camera", main_camera_local()), "camera", json!(0)),
        with(node("side camera", side_camera_local()), "camera", json!(1)),
        json!({ "name": "plan camera", "camera": 2, "translation": [0.0, 5.0, 0.0], "rotation": Quat::from_rotation_x(-PI / 2.0).to_array() }),
    ]);
    g.json["scenes"] = json!([{ "name": "room", "nodes": [0, 2, 4, 5, 6, 9] }]);
    g.json["buffers"] = match variant {
        Variant::External => json!([{ "uri": "scene.bin", "byteLength": g.bin.len() }]),
        Variant::Embedded => {
            json!([{ "uri": format!("data:application/octet-stream;base64,{}", base64(&g.bin)), "byteLength": g.bin.len() }])
        }
        Variant::Binary => json!([{ "byteLength": g.bin.len() }]),
    };
    g
}

/// Writes the room as OBJ + MTL (world coordinates, `map_Kd`) with its PNGs into `dir`.
pub fn write_room_obj(dir: &Path) -> PathBuf {
    std::fs::write(dir.join("checker.png"), checker_png()).unwrap();
    std::fs::write(dir.join("stripes.png"), stripes_png()).unwrap();
    let mut mtl = String::new();
    for MaterialDef { name, factor, texture, emissive, .. } in MATERIALS {
        writeln!(mtl, "newmtl {name}\nKd {} {} {}", factor[0], factor[1], factor[2]).unwrap();
        if let Some(t) = texture {
            writeln!(mtl, "map_Kd {}", ["checker.png", "stripes.png"][t]).unwrap();
        }
        if emissive {
            let e = Vec3::from(EMISSIVE_FACTOR) * EMISSIVE_STRENGTH;
            writeln!(mtl, "Ke {} {} {}", e.x, e.y, e.z).unwrap();
        }
    }
    std::fs::write(dir.join("room.mtl"), mtl).unwrap();
    let meshes = meshes();
    let mut obj = String::from("mtllib room.mtl\n");
    let (mut v, mut vt) = (0usize, 0usize);
    for (k, (mesh, placement)) in instances().into_iter().enumerate() {
        let mirrored = placement.scale.x * placement.scale.y * placement.scale.z < 0.0;
        for p in &meshes[mesh].1 {
            writeln!(obj, "o {}_{k}\nusemtl {}", meshes[mesh].0, MATERIALS[p.material].name).unwrap();
            for &q in &p.positions {
                let w = placement.apply(q);
                writeln!(obj, "v {} {} {}", w.x, w.y, w.z).unwrap();
            }
            for uv in &p.uvs {
                writeln!(obj, "vt {} {}", uv.x, 1.0 - uv.y).unwrap();
            }
            for t in p.indices.chunks_exact(3) {
                let mut t = [t[0], t[1], t[2]];
                if mirrored {
                    t.swap(1, 2);
                }
                let c = t.map(|i| format!("{}/{}", v + i as usize + 1, vt + i as usize + 1));
                writeln!(obj, "f {} {} {}", c[0], c[1], c[2]).unwrap();
            }
            v += p.positions.len();
            vt += p.uvs.len();
        }
    }
    let path = dir.join("room.obj");
    std::fs::write(&path, obj).unwrap();
    path
}
