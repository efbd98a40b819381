//! Stanford PLY meshes (ASCII, binary little- and big-endian), as Mitsuba's `ply` shape reads
//! them: the `vertex` element's x, y, z, its normals nx, ny, nz and texture coordinates (u, v;
//! s, t; texture_u, texture_v or texture_s, texture_t; read as given, not flipped), and the
//! `face` element's `vertex_indices` (or `vertex_index`) lists, polygons split into fans.
//! Other elements and properties are read past. Counts are checked against the bytes left
//! and the vertex budget before anything is allocated from them; the triangles against their
//! budget as the faces are split ([`Budgets`]).

use glam::{Vec2, Vec3};

use super::shapes::Mesh;
use crate::scene::{Budget, Budgets};

#[derive(Clone, Copy, Debug, PartialEq)]
enum Kind {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Kind {
    fn of(name: &str) -> Option<Kind> {
        Some(match name {
            "char" | "int8" => Kind::I8,
            "uchar" | "uint8" => Kind::U8,
            "short" | "int16" => Kind::I16,
            "ushort" | "uint16" => Kind::U16,
            "int" | "int32" => Kind::I32,
            "uint" | "uint32" => Kind::U32,
            "float" | "float32" => Kind::F32,
            "double" | "float64" => Kind::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Kind::I8 | Kind::U8 => 1,
            Kind::I16 | Kind::U16 => 2,
            Kind::I32 | Kind::U32 | Kind::F32 => 4,
            Kind::F64 => 8,
        }
    }
}

struct Property {
    name: String,
    kind: Kind,
    /// The count's type, for a list.
    list: Option<Kind>,
}

struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

#[derive(Clone, Copy, PartialEq)]
enum Format {
    Ascii,
    Little,
    Big,
}

/// The data after the header: binary values or ASCII words.
struct Data<'a> {
    bytes: &'a [u8],
    at: usize,
    format: Format,
}

impl Data<'_> {
    fn value(&mut self, kind: Kind) -> Result<f64, String> {
        if self.format == Format::Ascii {
            let rest = &self.bytes[self.at..];
            let start = rest.iter().position(|b| !b.is_ascii_whitespace()).ok_or("ends early (truncated)")?;
            let len = rest[start..].iter().position(|b| b.is_ascii_whitespace()).unwrap_or(rest.len() - start);
            let word = std::str::from_utf8(&rest[start..start + len]).map_err(|_| "holds a value that is not text")?;
            self.at += start + len;
            return word.parse::<f64>().map_err(|_| format!("holds '{word}' where a number belongs"));
        }
        let n = kind.size();
        let b = self.bytes.get(self.at..self.at + n).ok_or("ends early (truncated)")?;
        self.at += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.format == Format::Big {
            a[..n].reverse();
        }
        Ok(match kind {
            Kind::I8 => a[0] as i8 as f64,
            Kind::U8 => a[0] as f64,
            Kind::I16 => i16::from_le_bytes([a[0], a[1]]) as f64,
            Kind::U16 => u16::from_le_bytes([a[0], a[1]]) as f64,
            Kind::I32 => i32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Kind::U32 => u32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Kind::F32 => f32::from_le_bytes([a[0], a[1], a[2], a[3]]) as f64,
            Kind::F64 => f64::from_le_bytes(a),
        })
    }

    fn left(&self) -> usize {
        self.bytes.len() - self.at
    }
}

/// Reads a PLY file's bytes within `budgets`, `used` triangles being the scene's already;
/// errors say what is wrong without naming the file.
pub fn read(bytes: &[u8], budgets: &Budgets, used: u64) -> Result<Mesh, String> {
    let end = bytes.windows(10).position(|w| w == b"end_header").ok_or("is not a PLY file (no 'end_header' line)")?;
    let header = std::str::from_utf8(&bytes[..end]).map_err(|_| "has a header that is not text")?;
    // The data starts after the end_header line's line break.
    let mut start = end + 10;
    while start < bytes.len() && bytes[start] != b'\n' {
        start += 1;
    }
    start = (start + 1).min(bytes.len());
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    for (n, line) in header.lines().enumerate() {
        let words: Vec<&str> = line.split_whitespace().collect();
        let bad = |what: &str| format!("header line {}: {what}", n + 1);
        match words.as_slice() {
            [] | ["comment", ..] | ["obj_info", ..] => {}
            ["ply"] if n == 0 => {}
            _ if n == 0 => return Err("is not a PLY file (it does not start with 'ply')".into()),
            ["format", f, _] => {
                format = Some(match *f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::Little,
                    "binary_big_endian" => Format::Big,
                    _ => return Err(bad(&format!("unknown format '{f}'"))),
                })
            }
            ["element", name, count] => {
                let count = count.parse().map_err(|_| bad(&format!("'{count}' is not an element count")))?;
                elements.push(Element { name: name.to_string(), count, properties: Vec::new() });
            }
            ["property", "list", c, k, name] => {
                let (Some(c), Some(k)) = (Kind::of(c), Kind::of(k)) else {
                    return Err(bad("unknown list types"));
                };
                let e = elements.last_mut().ok_or_else(|| bad("a property before any element"))?;
                e.properties.push(Property { name: name.to_string(), kind: k, list: Some(c) });
            }
            ["property", k, name] => {
                let k = Kind::of(k).ok_or_else(|| bad(&format!("unknown property type '{k}'")))?;
                let e = elements.last_mut().ok_or_else(|| bad("a property before any element"))?;
                e.properties.push(Property { name: name.to_string(), kind: k, list: None });
            }
            _ => return Err(bad(&format!("'{line}' is not a PLY header line"))),
        }
    }
    let format = format.ok_or("has no 'format' line")?;
    let mut data = Data { bytes, at: start, format };
    let mut mesh =
        Mesh { positions: Vec::new(), normals: Vec::new(), uvs: Vec::new(), faces: Vec::new(), face_normals: false };
    for e in &elements {
        // Every value takes at least one byte (ASCII: a digit), so a count beyond the bytes
        // left is a truncated or hostile file.
        if e.properties.is_empty() || e.count > data.left() / e.properties.len().max(1) {
            if e.count == 0 {
                continue;
            }
            if e.properties.is_empty() {
                return Err(format!("element '{}' has no properties", e.name));
            }
            return Err(format!(
                "element '{}' claims {} entries, more than the file holds (truncated?)",
                e.name, e.count
            ));
        }
        let index = |name: &str| e.properties.iter().position(|p| p.name == name && p.list.is_none());
        let is_vertex = e.name == "vertex";
        let is_face = e.name == "face";
        let xyz = [index("x"), index("y"), index("z")];
        let nxyz = [index("nx"), index("ny"), index("nz")];
        let uv = [["u", "v"], ["s", "t"], ["texture_u", "texture_v"], ["texture_s", "texture_t"]]
            .iter()
            .find_map(|[a, b]| Some([index(a)?, index(b)?]));
        let list = e
            .properties
            .iter()
            .position(|p| p.list.is_some() && (p.name == "vertex_indices" || p.name == "vertex_index"));
        if is_vertex {
            if xyz.iter().any(Option::is_none) {
                return Err("has vertices without x, y and z".into());
            }
            budgets.check(Budget::Vertices, e.count as u64, "its vertex element")?;
            mesh.positions.reserve(e.count);
        }
        if is_face && list.is_some() {
            // A face makes at least one triangle (a polygon of n corners, n − 2).
            budgets.check_more(Budget::Triangles, used, e.count as u64, &format!("its {} faces", e.count))?;
        }
        let mut values = vec![0.0f64; e.properties.len()];
        let mut polygon: Vec<u32> = Vec::new();
        for _ in 0..e.count {
            for (k, p) in e.properties.iter().enumerate() {
                match p.list {
                    None => values[k] = data.value(p.kind)?,
                    Some(c) => {
                        let n = data.value(c)?;
                        if !(0.0..=1e6).contains(&n) || n.fract() != 0.0 || n as usize > data.left() {
                            return Err(format!("a list of element '{}' has a bad length {n}", e.name));
                        }
                        polygon.clear();
                        for _ in 0..n as usize {
                            let i = data.value(p.kind)?;
                            if Some(k) == list {
                                if !(i >= 0.0 && i < u32::MAX as f64 && i.fract() == 0.0) {
                                    return Err(format!("a face names vertex {i}, which is not a vertex index"));
                                }
                                polygon.push(i as u32);
                            }
                        }
                    }
                }
            }
            let at = |o: Option<usize>| o.map_or(0.0, |k| values[k] as f32);
            if is_vertex {
                mesh.positions.push(Vec3::new(at(xyz[0]), at(xyz[1]), at(xyz[2])));
                if nxyz.iter().all(Option::is_some) {
                    mesh.normals.push(Vec3::new(at(nxyz[0]), at(nxyz[1]), at(nxyz[2])));
                }
                if let Some([u, v]) = uv {
                    mesh.uvs.push(Vec2::new(at(Some(u)), at(Some(v))));
                }
            } else if is_face && list.is_some() {
                let adding = (mesh.faces.len() + polygon.len().saturating_sub(2)) as u64;
                budgets.check_more(Budget::Triangles, used, adding, "its faces")?;
                for k in 2..polygon.len() {
                    mesh.faces.push([polygon[0], polygon[k - 1], polygon[k]]);
                }
            }
        }
    }
    let n = mesh.positions.len();
    if let Some(f) = mesh.faces.iter().position(|f| f.iter().any(|&i| i as usize >= n)) {
        return Err(format!("face {f} names a vertex beyond the {n} vertices"));
    }
    if !mesh.positions.iter().all(|p| p.is_finite()) {
        return Err("has a non-finite vertex position".into());
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_files_read_alike() {
        let ascii = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float u\nproperty float v\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n0 1 0 0 1\n4 0 1 2 3\n";
        let m = read(ascii, &Budgets::default(), 0).unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.faces, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.uvs[2], Vec2::new(1.0, 1.0));
        let mut binary = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar uint vertex_indices\nend_header\n".to_vec();
        for v in [0.0f32, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 2.0, 0.0] {
            binary.extend(v.to_be_bytes());
        }
        binary.push(3);
        for i in [0u32, 1, 2] {
            binary.extend(i.to_be_bytes());
        }
        let m = read(&binary, &Budgets::default(), 0).unwrap();
        assert_eq!(m.positions[1], Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(m.faces, vec![[0, 1, 2]]);
        assert!(read(&binary[..binary.len() - 2], &Budgets::default(), 0).unwrap_err().contains("truncated"));
        let tight = Budgets { triangles: 1, vertices: 3, ..Budgets::default() };
        assert!(read(&binary, &tight, 0).is_ok());
        let e = read(ascii, &tight, 0).unwrap_err();
        assert!(e.starts_with("needs 4 vertices (its vertex element)") && e.contains("--budget vertices=4"), "{e}");
        let e = read(ascii, &Budgets { triangles: 1, ..Budgets::default() }, 0).unwrap_err();
        assert!(e.contains("2 triangles") && e.contains("budget of 1"), "{e}");
        let e = read(&binary, &Budgets { triangles: 10, ..Budgets::default() }, 10).unwrap_err();
        assert!(e.starts_with("needs 11 triangles (its 1 faces and the 10 read before)"), "{e}");
    }
}
