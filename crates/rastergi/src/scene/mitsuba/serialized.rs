//! Mitsuba's `.serialized` meshes (the format of Mitsuba 0.4 to 3; read from its description in
//! Mitsuba's `serialized` shape): meshes one after another, each a little-endian header —
//! u16 0x041C, u16 version (3 or 4) — followed by a zlib stream holding
//!
//! ```text
//! u32 flags       0x0001 vertex normals, 0x0002 texture coordinates, 0x0008 vertex colours,
//!                 0x0010 face normals, 0x1000 single precision, 0x2000 double precision
//! name            version 4 only: UTF-8, null-terminated
//! u64 vertices, u64 triangles
//! positions       3 floats (f32, or f64 with 0x2000) per vertex
//! normals         3 per vertex, if flagged
//! uvs             2 per vertex, if flagged
//! colours         3 per vertex, if flagged (skipped)
//! indices         3 per triangle: u32, or u64 where the vertex count exceeds 2³² − 1
//! ```
//!
//! and the file ends with a dictionary: the byte offset of each mesh (u64 in version 4, u32 in
//! version 3) and the u32 count of meshes; `shape_index` picks a mesh through it. Every count
//! is checked before anything is allocated from it: against what the compressed stream can
//! hold (zlib shrinks by 1032:1 at most) and against the budgets (the triangles, the vertices
//! and the bytes to decompress, [`Budgets`]).

use std::io::Read;

use glam::{Vec2, Vec3};

use super::shapes::Mesh;
use crate::scene::{Budget, Budgets};

const HEADER: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_UVS: u32 = 0x0002;
const HAS_COLOURS: u32 = 0x0008;
const FACE_NORMALS: u32 = 0x0010;
const DOUBLE: u32 = 0x2000;

fn u16_at(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(b.get(at..at + 2)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

/// The byte offset of mesh `index`: 0 for the first, the others' from the dictionary at the
/// file's end.
fn mesh_offset(bytes: &[u8], version: u16, index: u32) -> Result<usize, String> {
    if index == 0 {
        return Ok(0);
    }
    let n = bytes.len();
    let count = n.checked_sub(4).and_then(|at| u32_at(bytes, at)).ok_or("is too short for its dictionary")?;
    // Where the dictionary entry of mesh `index` starts, counted back from the end (u64 arithmetic:
    // no overflow on 32-bit targets).
    let back =
        |entry: u64, extra: u64| (n as u64).checked_sub(entry * (count - index) as u64 + extra).map(|a| a as usize);
    if index >= count {
        return Err(format!("holds {count} meshes; shape_index {index} is out of range (0 to {})", count.max(1) - 1));
    }
    let offset = if version >= 4 {
        let at = back(8, 4).ok_or("has a dictionary longer than the file")?;
        u64_at(bytes, at).ok_or("has a truncated dictionary")?
    } else {
        let at = back(4, 4).ok_or("has a dictionary longer than the file")?;
        u32_at(bytes, at).ok_or("has a truncated dictionary")? as u64
    };
    if offset >= n as u64 {
        return Err(format!("mesh {index}'s offset {offset} lies beyond the file's end ({n} bytes)"));
    }
    Ok(offset as usize)
}

/// A little-endian reader over the decompressed stream.
struct Stream<R: Read> {
    r: R,
}

impl<R: Read> Stream<R> {
    fn bytes(&mut self, n: usize, what: &str) -> Result<Vec<u8>, String> {
        let mut out = Vec::new();
        (&mut self.r)
            .take(n as u64)
            .read_to_end(&mut out)
            .map_err(|e| format!("its {what} cannot be decompressed ({})", crate::error::one_line(e)))?;
        if out.len() < n {
            return Err(format!("ends inside its {what} (truncated)"));
        }
        Ok(out)
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        Ok(u32::from_le_bytes(self.bytes(4, what)?.try_into().expect("4 bytes")))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        Ok(u64::from_le_bytes(self.bytes(8, what)?.try_into().expect("8 bytes")))
    }

    /// `count` floats (f32, or f64 read as f32).
    fn floats(&mut self, count: usize, double: bool, what: &str) -> Result<Vec<f32>, String> {
        let size = if double { 8 } else { 4 };
        let b = self.bytes(count * size, what)?;
        Ok(if double {
            b.chunks_exact(8).map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")) as f32).collect()
        } else {
            b.chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().expect("4 bytes"))).collect()
        })
    }
}

/// Reads mesh `index` of a `.serialized` file's bytes within `budgets`, `used` being the
/// triangles and the bytes decompressed by the scene's meshes read before; returns the mesh
/// and the bytes decompressed. Errors say what is wrong without naming the file.
pub fn read(bytes: &[u8], index: u32, budgets: &Budgets, used: (u64, u64)) -> Result<(Mesh, u64), String> {
    let header = u16_at(bytes, 0).ok_or("is too short to be a .serialized mesh")?;
    if header != HEADER {
        return Err(format!("is not a Mitsuba .serialized mesh (it starts with 0x{header:04X}, not 0x041C)"));
    }
    let version = u16_at(bytes, 2).ok_or("is too short to be a .serialized mesh")?;
    if version != 3 && version != 4 {
        return Err(format!("has format version {version}; versions 3 and 4 are read"));
    }
    let offset = mesh_offset(bytes, version, index)?;
    match (u16_at(bytes, offset), u16_at(bytes, offset + 2)) {
        (Some(HEADER), Some(v)) if v == version => {}
        _ => return Err(format!("mesh {index} (at byte {offset}) does not start with the mesh header 0x041C")),
    }
    let compressed = &bytes[offset + 4..];
    let mut s =
        Stream { r: flate2::read::ZlibDecoder::new(compressed).take(budgets.decompressed.saturating_sub(used.1)) };
    let flags = s.u32("flags")?;
    if version >= 4 {
        // The name: bytes up to a zero.
        let mut name_len = 0usize;
        loop {
            if s.bytes(1, "name")?[0] == 0 {
                break;
            }
            name_len += 1;
            if name_len > 1 << 16 {
                return Err("has a mesh name longer than 64 KiB (not a valid file)".into());
            }
        }
    }
    let vertices = s.u64("vertex count")?;
    let triangles = s.u64("triangle count")?;
    let double = flags & DOUBLE != 0;
    let size = if double { 8u64 } else { 4 };
    let wide = vertices > u32::MAX as u64;
    let per_vertex = 3
        + if flags & HAS_NORMALS != 0 { 3 } else { 0 }
        + if flags & HAS_UVS != 0 { 2 } else { 0 }
        + if flags & HAS_COLOURS != 0 { 3 } else { 0 };
    let need = vertices
        .checked_mul(per_vertex * size)
        .and_then(|v| triangles.checked_mul(3 * if wide { 8 } else { 4 }).and_then(|t| v.checked_add(t)));
    // Compressed data shrinks by at most zlib's limit of about 1032:1.
    let need = match need {
        Some(n) if n / 1032 <= compressed.len() as u64 + 64 => n,
        _ => {
            return Err(format!(
                "mesh {index} claims {vertices} vertices and {triangles} triangles, more than the file can hold (truncated or not a valid file)"
            ));
        }
    };
    budgets.check_more(Budget::Triangles, used.0, triangles, &format!("mesh {index}"))?;
    budgets.check(Budget::Vertices, vertices, &format!("mesh {index}"))?;
    budgets.check_more(Budget::Decompressed, used.1, need, &format!("mesh {index}"))?;
    let (nv, nt) = (vertices as usize, triangles as usize);
    let p = s.floats(3 * nv, double, "positions")?;
    let positions: Vec<Vec3> = p.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
    let normals: Vec<Vec3> = if flags & HAS_NORMALS != 0 {
        s.floats(3 * nv, double, "normals")?.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
    } else {
        Vec::new()
    };
    let uvs: Vec<Vec2> = if flags & HAS_UVS != 0 {
        s.floats(2 * nv, double, "texture coordinates")?.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect()
    } else {
        Vec::new()
    };
    if flags & HAS_COLOURS != 0 {
        s.floats(3 * nv, double, "vertex colours")?;
    }
    let width = if wide { 8 } else { 4 };
    let index_bytes = s.bytes(3 * nt * width, "triangles")?;
    let corner = |c: &[u8]| match *c {
        [a, b, c, d] => u32::from_le_bytes([a, b, c, d]) as u64,
        _ => u64::from_le_bytes(c.try_into().unwrap_or([0xff; 8])),
    };
    let mut faces = Vec::with_capacity(nt);
    for (t, c) in index_bytes.chunks_exact(3 * width).enumerate() {
        let face = [corner(&c[..width]), corner(&c[width..2 * width]), corner(&c[2 * width..])];
        if let Some(&bad) = face.iter().find(|&&i| i >= vertices) {
            return Err(format!("triangle {t} of mesh {index} names vertex {bad}, but the mesh has {vertices}"));
        }
        faces.push(face.map(|i| i as u32));
    }
    if !positions.iter().all(|p| p.is_finite()) {
        return Err(format!("mesh {index} has a non-finite vertex position"));
    }
    let mesh = Mesh { positions, normals, uvs, faces, face_normals: flags & FACE_NORMALS != 0 };
    Ok((mesh, need))
}
