//! Wavefront OBJ + MTL loading through `tobj`: polygons are triangulated (fans), each
//! `usemtl` group takes its material's `Kd` as albedo and `Ke` as emitted radiance.
//!
//! OBJ has no notion of sidedness, so materials loaded from OBJ reflect on both faces; they
//! emit from the counter-clockwise front face only. Faces without a material get a grey
//! albedo of 0.5 (Mitsuba's default). OBJ carries no camera: the scene is framed from +z.
//!
//! A material's `map_Kd` image (PNG or JPEG, found relative to its .mtl file) multiplies its
//! `Kd` (1 when `Kd` is absent), read at the faces' `vt` coordinates; OBJ's v points up the
//! image, so v is flipped into the scene's convention (v down). `map_Ke` likewise multiplies
//! `Ke` (1 when absent), per texel. Opacity: `d` (or 1 − `Tr`) times `map_d`'s alpha channel
//! (its first channel when the image has no transparent texel: a grey mask), as stochastic
//! opacity ([`super::AlphaMode::Blend`], Mitsuba's `mask`). The texture options `-o u v` and
//! `-s u v` place the image (uv' = s·uv + o in OBJ's coordinates); the others (`-bm`,
//! `-blendu`, `-clamp`, `-colorspace`, `-type` …) are skipped with a warning.
//!
//! Scattering (`crate::bsdf`; the Mitsuba reference script maps these the same way):
//! - no `Pm`, `Pr` nor a glass `illum`: Lambertian `Kd` (`Ks`, `Ns` and the Phong models of
//!   `illum` 2 are not read);
//! - `Pm m` and/or `Pr r` (the PBR extension of MTL that Blender and others write): glTF's
//!   metallic-roughness with base colour `Kd`, metallic m (default 0), roughness r (default
//!   1), and its dielectric specular layer (f₀ from `Ni`, default 1.5: 0.04) unless `Ks 0 0 0`;
//! - `illum 3` (reflection, ray traced) without `Pm`: a metal, roughness `Pr` (default 0);
//! - `illum` 4, 6, 7 or 9 (refraction): glass, a refracting solid of index `Ni` (default 1.5)
//!   tinted by `Tf` (default white), roughness `Pr` (default 0); `Kd` and `Pm` are not used;
//! - `Pc k` and `Pcr r` (the same extension's clear coat): a clear coat of weight k and
//!   roughness r (default 0) over any of the above.
//!
//! Values outside their range are clamped with a warning.
//!
//! Faces whose corners name `vn` normals (`f v//vn`, `f v/vt/vn`) shade with them, interpolated
//! (normalised as read); a model whose faces do not all have them shades flat. Faces without
//! `vn` in a smoothing group (`s 1`, `s 2` …; not `s off` or `s 0`) get vertex normals: at each
//! vertex the area-weighted mean of the normals of the group's faces around it (faces of
//! other groups and flat faces keep their own), as Blender and 3ds Max read them.

use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};

use super::{Budget, Budgets, Files, Material, Scene, Texture, TextureRef, UvTransform};
use crate::error::{Error, Result};

mod mtl;
use mtl::*;

const DEFAULT_ALBEDO: f32 = 0.5;

fn file_error(path: &Path, message: impl Into<String>) -> Error {
    Error::SceneFile { path: path.to_path_buf(), message: message.into() }
}

/// Loads an OBJ file (and the MTL libraries it names) as a scene.
pub fn load_obj(path: &Path) -> Result<Scene> {
    load_obj_in(Files::Disk, path)
}

/// Loads the OBJ file at `path` of `files` (its MTL libraries and textures too).
pub fn load_obj_in(files: Files, path: &Path) -> Result<Scene> {
    load_obj_with(files, path, &Budgets::default())
}

/// [`load_obj_in`] within `budgets`: the faces' triangles and the vertices are counted in the
/// text before it is parsed, each texture's size is read before it is decoded.
pub fn load_obj_with(files: Files, path: &Path, budgets: &Budgets) -> Result<Scene> {
    load(files, path, false, budgets, 0)
}

/// The OBJ file's geometry alone, for scene formats that name OBJ meshes (Mitsuba's `obj`
/// shape): its triangles with their texture coordinates (v flipped as above) and normals
/// (`vn`, or its smoothing groups'), its MTL libraries not read (every face gets the grey
/// default material), no camera chosen and the scene not validated; `used`: the triangles of
/// the scene's shapes read before, which count against the same budget.
pub(crate) fn load_obj_geometry(files: Files, path: &Path, budgets: &Budgets, used: u64) -> Result<Scene> {
    load(files, path, true, budgets, used)
}

fn load(files: Files, path: &Path, geometry_only: bool, budgets: &Budgets, used: u64) -> Result<Scene> {
    if let Some(what) = files.missing(path) {
        return Err(file_error(
            path,
            format!("{what}; give the path of a .obj file or the built-in scene name 'cornell'"),
        ));
    }
    if files.is_special(path) {
        return Err(file_error(path, "is not a regular file"));
    }
    let mut text = text_of(files, path)?;
    check_counts(&text, budgets, used).map_err(|m| file_error(path, m))?;
    if geometry_only {
        comment_out(&mut text, b"mtllib");
    }
    comment_out_texcoords_and_normals(&mut text);
    let options =
        tobj::LoadOptions { triangulate: true, ignore_points: true, ignore_lines: true, ..Default::default() };
    let (mut models, materials) = load_obj_text(files, path, &text, &options)?;
    if models.iter().any(|m| m.mesh.positions.iter().any(|c| !c.is_finite())) {
        let (line, word) = first_non_finite_vertex(&text).unwrap_or((0, "?".into()));
        return Err(file_error(
            path,
            format!(
                "line {line}: a vertex has a non-finite coordinate ('{word}' is NaN or beyond ±3.4e38); fix the vertex"
            ),
        ));
    }
    let mut text = text_of(files, path)?;
    if geometry_only {
        comment_out(&mut text, b"mtllib");
    }
    let textured = if geometry_only {
        has_keyword(&text, b"vt")
    } else {
        materials.iter().any(|m| TEXTURE_KEYS.iter().any(|&key| map_file(m, key).is_some()))
    };
    // Normals that faces refer to out of range are not used (the faces shade flat), nor are
    // smoothing groups then: their normals go before the file's, so a reference out of range
    // backwards would reach before the first (tobj's index wraps round and overflows).
    let normals_in_range = check_references(&text, "vn", 2, "normal")
        .map_err(|message| log::warn!("{}: {message}; its faces shade flat", path.display()))
        .is_ok();
    let mut smooth = has_keyword(&text, b"vn") && normals_in_range;
    // Smoothing groups become vertex normals (written into the text tobj reads).
    if normals_in_range
        && (smooth || !has_keyword(&text, b"vn"))
        && let Some(with_normals) = apply_smoothing_groups(&text)
    {
        text = with_normals;
        smooth = true;
    }
    if textured || smooth {
        // Textures need the texture coordinates and smooth shading the normals: load again
        // with them, once every face's references are known to be in range (tobj overflows
        // on some that are not).
        if !textured {
            comment_out(&mut text, b"vt");
        }
        if !smooth {
            comment_out(&mut text, b"vn");
        }
        if textured {
            check_references(&text, "vt", 1, "texture coordinate").map_err(|message| file_error(path, message))?;
        }
        models = load_obj_text(files, path, &text, &tobj::LoadOptions { single_index: true, ..options })?.0;
    }

    let mut scene = Scene::new(super::Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 });
    // Each image once as colour and once as an opacity mask, however many materials use it
    // and however its path is spelled.
    let mut texture_of_file: HashMap<(PathBuf, bool), usize> = HashMap::new();
    let mut texels = 0u64;
    for m in &materials {
        let mut texture = |key: &str, opacity: bool| -> Result<Option<TextureRef>> {
            let Some(file) = map_file(m, key) else { return Ok(None) };
            let transform = map_transform(m, key);
            let named = PathBuf::from(file);
            let file = files.canonical(&named);
            if let Some(&t) = texture_of_file.get(&(file.clone(), opacity)) {
                return Ok(Some(TextureRef { texture: t, transform }));
            }
            // An image with an alpha channel serves as colour and opacity from one texture.
            if let Some(&t) = texture_of_file.get(&(file.clone(), false))
                && opacity
                && scene.textures[t].has_alpha()
            {
                return Ok(Some(TextureRef { texture: t, transform }));
            }
            let mut texture = read_texture(files, &named, budgets, &mut texels).map_err(|e| {
                file_error(path, format!("the texture {} ({key} of material '{}') {e}", named.display(), m.name))
            })?;
            if opacity && !texture.has_alpha() {
                // A grey mask: its first channel is the opacity.
                texture.texels.iter_mut().for_each(|t| t[3] = t[0]);
                texture.name += " (opacity)";
            }
            let has_alpha = texture.has_alpha();
            let t = scene.add_texture(texture);
            if opacity && has_alpha {
                texture_of_file.insert((file.clone(), false), t);
            }
            texture_of_file.insert((file, opacity), t);
            Ok(Some(TextureRef { texture: t, transform }))
        };
        let albedo_map = texture("map_Kd", false)?;
        let emission_texture = texture("map_Ke", false)?;
        let opacity_texture = texture("map_d", true)?;
        let default_albedo = if albedo_map.is_some() { 1.0 } else { DEFAULT_ALBEDO };
        let albedo = m.diffuse.map(Vec3::from).unwrap_or(Vec3::splat(default_albedo));
        let default_emission = if emission_texture.is_some() { 1.0 } else { 0.0 };
        let emission = m.emissive.map(Vec3::from).unwrap_or(Vec3::splat(default_emission));
        let transparency = m.unknown_param.get("Tr").and_then(|t| t.trim().parse::<f32>().ok());
        let mut opacity = m.dissolve.or(transparency.map(|t| 1.0 - t)).unwrap_or(1.0);
        if !(0.0..=1.0).contains(&opacity) {
            log::warn!(
                "{}: material '{}' has an opacity d = {opacity} outside [0, 1]; clamped",
                path.display(),
                m.name
            );
            opacity = if opacity.is_nan() { 1.0 } else { opacity.clamp(0.0, 1.0) };
        }
        let alpha_mode =
            if opacity < 1.0 || opacity_texture.is_some() { super::AlphaMode::Blend } else { super::AlphaMode::Opaque };
        let scattering = Scattering::of(m, path);
        let albedo = scattering.base.unwrap_or(albedo);
        scene.add_material(Material {
            metallic: scattering.metallic,
            roughness: scattering.roughness,
            specular: scattering.specular,
            ior: scattering.ior,
            transmission: scattering.transmission,
            clearcoat: scattering.clearcoat,
            clearcoat_roughness: scattering.clearcoat_roughness,
            albedo_texture: albedo_map.map(|t| t.texture),
            albedo_transform: albedo_map.map_or(UvTransform::IDENTITY, |t| t.transform),
            emission,
            emission_texture,
            opacity,
            opacity_texture,
            alpha_mode,
            two_sided: true,
            ..Material::diffuse(&m.name, albedo)
        });
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
        // tobj gives texture coordinates per vertex only when every vertex of the model has one.
        let has_uvs = !mesh.texcoords.is_empty() && mesh.texcoords.len() / 2 == vertex_count;
        let needs_uvs = scene.materials[material as usize].texture_refs().next().is_some();
        if needs_uvs && !has_uvs {
            return Err(file_error(
                path,
                format!(
                    "faces of '{}' use the textured material '{}' but lack texture coordinates (f v/vt)",
                    model.name, scene.materials[material as usize].name
                ),
            ));
        }
        // Likewise normals: a model whose faces do not all have them shades flat.
        let has_normals = !mesh.normals.is_empty() && mesh.normals.len() / 3 == vertex_count;
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
            if has_uvs {
                let uv: [Vec2; 3] = std::array::from_fn(|k| {
                    let i = face[k] as usize;
                    Vec2::new(mesh.texcoords[2 * i], 1.0 - mesh.texcoords[2 * i + 1])
                });
                scene.add_textured_triangle(tri, uv, material);
            } else {
                scene.add_triangle(tri, material);
            }
            if has_normals {
                scene.set_last_normals(std::array::from_fn(|k| {
                    let i = face[k] as usize;
                    Vec3::new(mesh.normals[3 * i], mesh.normals[3 * i + 1], mesh.normals[3 * i + 2])
                }));
            }
        }
    }
    if scene.triangles.is_empty() {
        return Err(file_error(path, "contains no faces; an OBJ scene needs at least one triangle ('f' lines)"));
    }
    if geometry_only {
        return Ok(scene);
    }
    scene.camera = scene.default_camera();
    scene.validate().map_err(|e| file_error(path, e.to_string()))?;
    Ok(scene)
}

/// Reads a `map_Kd` image; a device or a pipe (`map_Kd /dev/zero`) would be read forever.
/// Its texels and the `texels` of those read before are checked against their budget before
/// it is decoded.
fn read_texture(
    files: Files,
    file: &Path,
    budgets: &Budgets,
    texels: &mut u64,
) -> std::result::Result<Texture, String> {
    if files.is_special(file) {
        return Err("is not a regular file".into());
    }
    let bytes = files.read(file).map_err(|e| format!("cannot be read ({e})"))?;
    let name = file.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let (w, h) = Texture::dimensions(&bytes)?;
    let n = w as u64 * h as u64;
    budgets.check_more(Budget::Texels, *texels, n, &format!("{w}x{h}"))?;
    *texels += n;
    Texture::decode(&name, &bytes)
}

/// Checks the vertices (`v` lines) and the triangles the faces (`f` lines, a polygon of n
/// corners making n − 2) will make against the budgets, before the text is parsed; `used`:
/// the triangles read before.
fn check_counts(text: &[u8], budgets: &Budgets, used: u64) -> std::result::Result<(), String> {
    let (mut vertices, mut triangles) = (0u64, 0u64);
    for line in text.split(|&b| b == b'\n') {
        match keyword_of(line) {
            b"v" => vertices += 1,
            b"f" => {
                // The keyword and the corners.
                let words = match std::str::from_utf8(line) {
                    Ok(text) => text.split_whitespace().count(),
                    Err(_) => line.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty()).count(),
                } as u64;
                triangles += words.saturating_sub(3);
            }
            _ => {}
        }
    }
    budgets.check(Budget::Vertices, vertices, "its v lines")?;
    budgets.check_more(Budget::Triangles, used, triangles, "its f lines")
}

/// Parses OBJ text with tobj, loading its MTL libraries relative to `path`.
fn load_obj_text(
    files: Files,
    path: &Path,
    text: &[u8],
    options: &tobj::LoadOptions,
) -> Result<(Vec<tobj::Model>, Vec<tobj::Material>)> {
    // tobj keeps only the last MTL error, and none at all once one library loaded; the first
    // failure, with the library's path, is kept here.
    let mtl_error = RefCell::new(None);
    let (models, materials) = tobj::load_obj_buf(&mut &text[..], options, |mtl| load_mtl(files, path, mtl, &mtl_error))
        .map_err(|e| file_error(path, obj_error_message(e, text)))?;
    let mtl_failure = mtl_error.into_inner().or_else(|| materials.as_ref().err().map(|e| e.to_string()));
    if let Some(message) = mtl_failure {
        let hint = "fix the .mtl file, put it beside the .obj or remove the mtllib line";
        return Err(file_error(path, format!("its material library (mtllib) could not be loaded: {message}; {hint}")));
    }
    Ok((models, materials.unwrap_or_default()))
}

/// The file's bytes.
fn text_of(files: Files, path: &Path) -> Result<Vec<u8>> {
    files.read(path).map_err(|e| file_error(path, format!("cannot be read: {e}")))
}

/// The first word of a line, split at whitespace as tobj splits it (Unicode's: a line that
/// a no-break space indents is a `vn` line for tobj too). A line that is not UTF-8 is split at
/// ASCII whitespace (tobj refuses the file at it).
fn keyword_of(line: &[u8]) -> &[u8] {
    let indent = indent_of(line);
    let line = &line[indent..];
    let end = match std::str::from_utf8(line) {
        Ok(text) => text.find(char::is_whitespace).unwrap_or(text.len()),
        Err(_) => line.iter().position(u8::is_ascii_whitespace).unwrap_or(line.len()),
    };
    &line[..end]
}

/// The bytes of whitespace before a line's first word (Unicode's, as [`keyword_of`]).
fn indent_of(line: &[u8]) -> usize {
    match std::str::from_utf8(line) {
        Ok(text) => text.len() - text.trim_start().len(),
        Err(_) => line.iter().take_while(|b| b.is_ascii_whitespace()).count(),
    }
}

/// Whether any line starts with `keyword`.
fn has_keyword(text: &[u8], keyword: &[u8]) -> bool {
    text.split(|&b| b == b'\n').any(|l| keyword_of(l) == keyword)
}

/// Turns the lines starting with `keyword` into comments in place (see
/// [`comment_out_texcoords_and_normals`]).
fn comment_out(text: &mut [u8], keyword: &[u8]) {
    for line in text.split_mut(|&b| b == b'\n') {
        if keyword_of(line) == keyword {
            let indent = indent_of(line);
            line[indent] = b'#';
        }
    }
}

/// Checks that every reference of an `f` line in slot `slot` (1: texture coordinate, 2:
/// normal) names a `keyword` line of the file: 1 to the number of such lines, or −1 back to
/// the first one before it.
fn check_references(text: &[u8], keyword: &str, slot: usize, what: &str) -> Result<(), String> {
    let is_keyword = |line: &[u8]| keyword_of(line) == keyword.as_bytes();
    let total = text.split(|&b| b == b'\n').filter(|&l| is_keyword(l)).count() as i64;
    let mut seen = 0i64;
    for (n, line) in text.split(|&b| b == b'\n').enumerate() {
        if is_keyword(line) {
            seen += 1;
            continue;
        }
        let line = String::from_utf8_lossy(line);
        let mut words = line.split_whitespace();
        if words.next() != Some("f") {
            continue;
        }
        for vertex in words {
            let Some(Ok(i)) = vertex.split('/').nth(slot).filter(|s| !s.is_empty()).map(str::parse::<i64>) else {
                continue;
            };
            if (i > 0 && i > total) || (i < 0 && seen + i < 0) {
                return Err(format!(
                    "line {}: a face refers to {what} {i}, but there are {} ({keyword} lines); fix the face or export the file again",
                    n + 1,
                    if i > 0 { total } else { seen }
                ));
            }
        }
    }
    Ok(())
}

/// The OBJ text with smoothing groups turned into vertex normals, or `None` where no face
/// without `vn` is in a smoothing group (or a line cannot be read: tobj then says why). Every
/// face without `vn` gets normals: its group's vertex normals (the area-weighted mean of the
/// group's face normals at each vertex position), or its own face normal at every corner if
/// it is flat (`s off`). The new `vn` lines go first, so tobj knows them wherever it looks
/// them up; the file's own positive `vn` references shift past them.
fn apply_smoothing_groups(text: &[u8]) -> Option<Vec<u8>> {
    let text = std::str::from_utf8(text).ok()?;
    let mut positions: Vec<glam::DVec3> = Vec::new();
    let mut group = 0u32;
    // Faces without normals: (line, absolute 1-based position indices, group).
    let mut faces: Vec<(usize, Vec<usize>, u32)> = Vec::new();
    let mut any_group = false;
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words.take(3).map(|w| w.parse().unwrap_or(0.0)).collect();
                positions.push(glam::DVec3::new(
                    c.first().copied().unwrap_or(0.0),
                    c.get(1).copied().unwrap_or(0.0),
                    c.get(2).copied().unwrap_or(0.0),
                ));
            }
            Some("s") => {
                group = match words.next() {
                    Some("off") | None => 0,
                    Some(w) => w.parse().ok()?,
                };
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.iter().any(|c| c.split('/').nth(2).is_some_and(|v| !v.is_empty())) {
                    continue;
                }
                let mut indices = Vec::with_capacity(corners.len());
                for c in &corners {
                    let i: i64 = c.split('/').next()?.parse().ok()?;
                    let i = if i < 0 { positions.len() as i64 + 1 + i } else { i };
                    if i < 1 || i as usize > positions.len() {
                        return None;
                    }
                    indices.push(i as usize);
                }
                any_group |= group != 0;
                faces.push((n, indices, group));
            }
            _ => {}
        }
    }
    if !any_group {
        return None;
    }
    // Newell's normal: twice the area times the unit normal of a planar polygon.
    let newell = |ix: &[usize]| {
        (0..ix.len()).fold(glam::DVec3::ZERO, |acc, k| {
            let (a, b) = (positions[ix[k] - 1], positions[ix[(k + 1) % ix.len()] - 1]);
            acc + glam::DVec3::new((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x), (a.x - b.x) * (a.y + b.y))
        })
    };
    let mut sums: HashMap<(u32, usize), glam::DVec3> = HashMap::new();
    for (_, ix, g) in faces.iter().filter(|f| f.2 != 0) {
        let n = newell(ix);
        for &i in ix {
            *sums.entry((*g, i)).or_default() += n;
        }
    }
    // One new vn per (group, vertex) and per flat face; corners map to them.
    let mut normals: Vec<glam::DVec3> = Vec::new();
    let mut index_of: HashMap<(u32, usize), usize> = HashMap::new();
    let mut rewritten: HashMap<usize, Vec<usize>> = HashMap::new();
    for (line, ix, g) in &faces {
        let refs = if *g == 0 {
            normals.push(newell(ix));
            vec![normals.len(); ix.len()]
        } else {
            ix.iter()
                .map(|&i| {
                    *index_of.entry((*g, i)).or_insert_with(|| {
                        normals.push(sums[&(*g, i)]);
                        normals.len()
                    })
                })
                .collect()
        };
        rewritten.insert(*line, refs);
    }
    let shift = normals.len() as i64;
    let mut out = String::with_capacity(text.len() + 40 * normals.len());
    for n in &normals {
        let n = n.normalize_or_zero();
        out += &format!("vn {} {} {}\n", n.x, n.y, n.z);
    }
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match (words.next(), rewritten.get(&k)) {
            (Some("f"), Some(refs)) => {
                out += "f";
                for (c, r) in words.zip(refs) {
                    let mut parts = c.split('/');
                    let v = parts.next().unwrap_or("");
                    let vt = parts.next().unwrap_or("");
                    out += &format!(" {v}/{vt}/{r}");
                }
            }
            (Some("f"), None) => {
                // A face with its own normals: positive vn indices move past the new ones.
                out += "f";
                for c in words {
                    let parts: Vec<&str> = c.split('/').collect();
                    match parts.as_slice() {
                        [v, vt, vn] => match vn.parse::<i64>() {
                            Ok(i) if i > 0 => out += &format!(" {v}/{vt}/{}", i + shift),
                            _ => out += &format!(" {c}"),
                        },
                        _ => out += &format!(" {c}"),
                    }
                }
            }
            _ => out += line,
        }
        out.push('\n');
    }
    Some(out.into_bytes())
}

/// What is wrong with an OBJ file tobj refused, where, and what to do about it.
fn obj_error_message(e: tobj::LoadError, text: &[u8]) -> String {
    use tobj::LoadError as E;
    let located = match e {
        E::PositionParseError | E::ScalingByZeroError | E::ColorParseError => first_bad_vertex(text),
        E::FaceParseError | E::InvalidPolygon | E::FaceVertexOutOfBounds => first_bad_face(text),
        _ => None,
    };
    if let Some((line, what)) = located {
        return format!(
            "not a valid OBJ file: line {line}: {what}; fix that line or export the file again as Wavefront OBJ"
        );
    }
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

/// The OBJ's lines (numbered from 1) split into words, as tobj reads them.
fn numbered_lines(text: &[u8]) -> impl Iterator<Item = (usize, Vec<&str>)> {
    text.split(|&b| b == b'\n')
        .enumerate()
        .map(|(n, line)| (n + 1, std::str::from_utf8(line).unwrap_or("").split_whitespace().collect()))
}

/// The first `v` line tobj refuses, and why: three coordinates, then nothing, a weight w ≠ 0
/// or a colour (r g b).
fn first_bad_vertex(text: &[u8]) -> Option<(usize, String)> {
    let number = |w: &str| w.parse::<f32>().is_ok();
    numbered_lines(text).find_map(|(n, words)| {
        let values = match words.split_first() {
            Some((&"v", values)) => values,
            _ => return None,
        };
        let what = match values {
            [x, y, z, rest @ ..] if number(x) && number(y) && number(z) => match rest {
                [] => return None,
                [w] if w.parse::<f32>().is_ok_and(|w| w != 0.0) => return None,
                [w] if number(w) => "a vertex has a weight w of 0".to_owned(),
                [r, g, b] if number(r) && number(g) && number(b) => return None,
                _ => format!(
                    "a vertex has {} values after its coordinates; expected none, a weight or a colour (r g b)",
                    rest.len()
                ),
            },
            _ => format!("'{}' does not start with three numbers (x y z)", words.join(" ")),
        };
        Some((n, what))
    })
}

/// The first `v` line with a coordinate that is not a finite `f32` (tobj reads `nan`, `inf`
/// and `1e39` as such), and that word.
fn first_non_finite_vertex(text: &[u8]) -> Option<(usize, String)> {
    numbered_lines(text).find_map(|(n, words)| match words.split_first() {
        Some((&"v", values)) => {
            let bad = values.iter().take(3).find(|w| w.parse::<f32>().is_ok_and(|x| !x.is_finite()))?;
            Some((n, bad.to_string()))
        }
        _ => None,
    })
}

/// The first `f` (or `l`) line tobj refuses, and why: a face needs three or more corners
/// whose vertex indices count from 1 (or back from −1) within the vertices of the file.
fn first_bad_face(text: &[u8]) -> Option<(usize, String)> {
    let total = numbered_lines(text).filter(|(_, w)| w.first() == Some(&"v")).count() as i64;
    let mut seen = 0i64;
    numbered_lines(text).find_map(|(n, words)| {
        let (keyword, corners) = words.split_first()?;
        match *keyword {
            "v" => seen += 1,
            "f" | "l" => {
                if *keyword == "f" && corners.len() < 3 {
                    return Some((n, format!("a face has {} corners; it needs three or more", corners.len())));
                }
                for corner in corners {
                    let index = corner.split('/').next().unwrap_or("");
                    let what = match index.parse::<i64>() {
                        Err(_) => format!("'{corner}' is not a vertex index"),
                        Ok(0) => "vertex index 0 does not exist (OBJ counts vertices from 1)".to_owned(),
                        Ok(i) if i > total => format!("vertex {i} does not exist: the file has {total} vertices"),
                        Ok(i) if i < 0 && seen + i < 0 => {
                            format!("vertex {i} does not exist: {seen} vertices come before this line")
                        }
                        Ok(_) => continue,
                    };
                    return Some((n, what));
                }
            }
            _ => {}
        }
        None
    })
}

/// Turns `vt` and `vn` lines into comments in place: a scene needs positions only, and tobj
/// rejects (in debug builds: panics on) texture and normal indices out of range.
fn comment_out_texcoords_and_normals(text: &mut [u8]) {
    comment_out(text, b"vt");
    comment_out(text, b"vn");
}

#[cfg(test)]
mod tests {
    use super::UvTransform;
    use glam::Vec2;

    fn texture_file_name(value: &str) -> Result<String, String> {
        super::texture_statement("map_Kd", value).map(|(file, _)| file)
    }

    #[test]
    fn texture_options_are_skipped_and_unknown_ones_do_not_refuse_the_file() {
        assert_eq!(texture_file_name("tex.png"), Ok("tex.png".into()));
        assert_eq!(texture_file_name("-o 0.5 0.5 -s 2 2 1 -bm 0.3 tex.png"), Ok("tex.png".into()));
        // Options exporters write that MTL does not define: skipped with their values.
        assert_eq!(texture_file_name("-colorspace sRGB -type sphere tex.png"), Ok("tex.png".into()));
        assert_eq!(texture_file_name("-invented 1 2 3 tex.png"), Ok("tex.png".into()));
        assert!(texture_file_name("-bm").unwrap_err().contains("lacks its value"));
        assert!(texture_file_name("-s 1 1").unwrap_err().contains("names no file"));
        assert_eq!(super::texture_statement("map_Kd", "tex.png").unwrap().1, UvTransform::IDENTITY);
    }

    #[test]
    fn offset_and_scale_place_the_texture_in_obj_coordinates() {
        // -s 2 4 -o 0.25 0.5: OBJ (u, v) ↦ (2u + 0.25, 4v + 0.5); the scene's v is 1 − OBJ's
        // on both sides of the map.
        let (_, t) = super::texture_statement("map_Kd", "-s 2 4 1 -o 0.25 0.5 0 tex.png").unwrap();
        for (u, v) in [(0.0, 0.0), (0.3, 0.7), (1.0, 0.2)] {
            let obj = Vec2::new(2.0 * u + 0.25, 4.0 * v + 0.5);
            let expected = Vec2::new(obj.x, 1.0 - obj.y);
            assert!((t.apply(Vec2::new(u, 1.0 - v)) - expected).length() < 1e-6, "{u} {v}");
        }
        // One value: the u scale alone (v keeps 1), the u offset alone (v keeps 0).
        let (_, t) = super::texture_statement("map_Kd", "-s 3 -o 0.5 tex.png").unwrap();
        assert_eq!(t, UvTransform([[3.0, 0.0, 0.5], [0.0, 1.0, 0.0]]));
        assert!(super::texture_statement("map_Kd", "-s 1 nan tex.png").is_err());
    }
}
