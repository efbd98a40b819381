//! The glTF container: `.glb` chunks, buffers, URIs (base64 `data:` or files beside the
//! document), and the checks the `gltf` crate's validation takes for granted.

use super::*;

/// What the `gltf` crate's own validation and accessors take for granted (they panic on
/// files that break these rules): attributes naming existing accessors, images with exactly
/// one source (and a MIME type for a buffer view), cameras with the projection their type
/// names.
pub(super) fn check_before_validation(root: &::gltf::json::Root) -> Res<()> {
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

/// The first few of the validation errors the `gltf` crate reports, on one line.
pub(super) fn describe_gltf_error(e: ::gltf::Error) -> String {
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

pub(super) fn read_u32(bytes: &[u8], at: usize) -> u32 {
    u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
}

/// The JSON chunk and the optional BIN chunk of a `.glb` container, every length checked.
pub(super) fn split_glb(bytes: &[u8]) -> Res<(&[u8], Option<&[u8]>)> {
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
pub(super) fn percent_decode(uri: &str) -> String {
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
pub(super) fn read_uri(files: Files, dir: &Path, uri: &str) -> Res<Vec<u8>> {
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
    if files.is_special(&file) {
        return Err(format!("{} is not a regular file", file.display()));
    }
    files.read(&file).map_err(|e| format!("{} cannot be read ({e})", file.display()))
}

pub(super) fn load_buffer(files: Files, dir: &Path, buffer: &::gltf::Buffer, bin: Option<&[u8]>) -> Res<Vec<u8>> {
    let name = |b: &::gltf::Buffer| match b.name() {
        Some(n) => format!("buffer {} ('{n}')", b.index()),
        None => format!("buffer {}", b.index()),
    };
    let data = match buffer.source() {
        ::gltf::buffer::Source::Bin => match bin {
            Some(bin) if buffer.index() == 0 => bin.to_vec(),
            _ => return Err(format!("{} has no uri and there is no .glb binary chunk for it", name(buffer))),
        },
        ::gltf::buffer::Source::Uri(uri) => read_uri(files, dir, uri).map_err(|e| format!("{}: {e}", name(buffer)))?,
    };
    if (data.len() as u64) < buffer.length() as u64 {
        return Err(format!("{} holds {} bytes but its byteLength is {}", name(buffer), data.len(), buffer.length()));
    }
    Ok(data)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    pub(super) fn percent_escapes_are_decoded() {
        assert_eq!(percent_decode("my%20texture.png"), "my texture.png");
        assert_eq!(percent_decode("a%2"), "a%2");
        assert_eq!(percent_decode("100%"), "100%");
    }

    #[test]
    pub(super) fn glb_chunks_are_split_and_lengths_checked() {
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
