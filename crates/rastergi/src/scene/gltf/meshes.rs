//! Meshes: accessors located and range-checked in their buffers, primitives' triangles,
//! texture coordinates, normals and tangents (MikkTSpace where a normal map needs them).

use super::*;

/// An accessor's elements, located and range-checked in its buffer.
pub(super) struct Elements<'a> {
    data: &'a [u8],
    stride: usize,
    size: usize,
    count: usize,
    data_type: DataType,
    normalized: bool,
}

impl Elements<'_> {
    pub(super) fn element(&self, i: usize) -> &[u8] {
        &self.data[i * self.stride..i * self.stride + self.size]
    }

    /// Component `c` of element `i` as a float (normalised integers mapped to [0, 1]).
    pub(super) fn float(&self, i: usize, c: usize) -> f32 {
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
    pub(super) fn index(&self, i: usize) -> u32 {
        let e = self.element(i);
        match self.data_type {
            DataType::U8 => e[0] as u32,
            DataType::U16 => u16::from_le_bytes([e[0], e[1]]) as u32,
            _ => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
        }
    }
}

/// The triangles of one primitive in the mesh's own space.
pub(super) struct Primitive {
    pub(super) triangles: Vec<[Vec3; 3]>,
    pub(super) uvs: Option<Vec<[Vec2; 3]>>,
    /// The corners' NORMALs in the mesh's space, where the primitive has them.
    pub(super) normals: Option<Vec<[Vec3; 3]>>,
    /// The corners' tangents in the mesh's space, where its material has a normal map.
    pub(super) tangents: Option<Vec<[Vec4; 3]>>,
    pub(super) material: u32,
}

impl Loader<'_> {
    /// An accessor's elements after checking its type and its byte range.
    pub(super) fn elements(
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

    pub(super) fn positions(&self, p: &::gltf::Primitive, what: &str) -> Res<Elements<'_>> {
        let accessor = p.get(&Semantic::Positions).ok_or_else(|| format!("{what} has no POSITION attribute"))?;
        self.elements(&accessor, &format!("{what} POSITION"), &[DataType::F32], Dimensions::Vec3)
    }

    pub(super) fn indices(&self, p: &::gltf::Primitive, what: &str) -> Res<Option<Elements<'_>>> {
        let Some(accessor) = p.indices() else { return Ok(None) };
        let types = [DataType::U8, DataType::U16, DataType::U32];
        self.elements(&accessor, &format!("{what} indices"), &types, Dimensions::Scalar).map(Some)
    }

    /// The number of triangles a primitive makes, its accessors checked.
    pub(super) fn triangle_count(&self, mesh: &::gltf::Mesh, p: &::gltf::Primitive) -> Res<u64> {
        let what = format!("{} primitive {}", named("mesh", mesh.index(), mesh.name()), p.index());
        let positions = self.positions(p, &what)?;
        self.budgets.check(Budget::Vertices, positions.count as u64, "").map_err(|m| format!("{what} {m}"))?;
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
    pub(super) fn primitive(&mut self, mesh: &::gltf::Mesh, p: &::gltf::Primitive) -> Res<Option<Primitive>> {
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
    pub(super) fn tangents(
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
        crate::scene::tangents::mikktspace(triangles, uvs, normals)
    }
}
