//! MTL libraries: loading them (completing one-number colours tobj would refuse), texture
//! statements and their options, and the scattering model a material's statements make.

use super::*;

/// The MTL statements that name a texture rastergi reads.
pub(super) const TEXTURE_KEYS: [&str; 3] = ["map_Kd", "map_Ke", "map_d"];

/// The value of a tobj material's texture statement `key`.
pub(super) fn map_value<'a>(m: &'a tobj::Material, key: &str) -> Option<&'a String> {
    match key {
        "map_Kd" => m.diffuse_texture.as_ref(),
        "map_d" => m.dissolve_texture.as_ref(),
        _ => m.unknown_param.get(key),
    }
}

/// The file a texture statement names, once [`load_mtl`] resolved it.
pub(super) fn map_file<'a>(m: &'a tobj::Material, key: &str) -> Option<&'a String> {
    m.unknown_param.get(&format!("{key} file"))
}

/// Which OBJ `illum` models are glass (refraction on).
pub(super) const GLASS_ILLUM: [u8; 4] = [4, 6, 7, 9];

/// A material's scattering model from its MTL statements (the module's documentation).
pub(super) struct Scattering {
    pub(super) metallic: f32,
    pub(super) roughness: f32,
    pub(super) specular: f32,
    pub(super) ior: f32,
    pub(super) transmission: f32,
    /// The base colour where it is not `Kd` (glass: its tint `Tf`).
    pub(super) base: Option<Vec3>,
    /// The clear coat `Pc` and its roughness `Pcr` (default 0).
    pub(super) clearcoat: f32,
    pub(super) clearcoat_roughness: f32,
}

impl Scattering {
    pub(super) fn of(m: &tobj::Material, path: &Path) -> Scattering {
        let warn = |what: &str| log::warn!("{}: material '{}': {what}", path.display(), m.name);
        let unit = |key: &str| -> Option<f32> {
            let text = m.unknown_param.get(key)?;
            match text.split_whitespace().next().and_then(|w| w.parse::<f32>().ok()) {
                Some(v) if (0.0..=1.0).contains(&v) => Some(v),
                Some(v) if v.is_finite() => {
                    warn(&format!("{key} {v} is outside [0, 1]; clamped"));
                    Some(v.clamp(0.0, 1.0))
                }
                _ => {
                    warn(&format!("{key} '{text}' is not a number; ignored"));
                    None
                }
            }
        };
        let (pm, pr) = (unit("Pm"), unit("Pr"));
        let (clearcoat, clearcoat_roughness) = (unit("Pc").unwrap_or(0.0), unit("Pcr").unwrap_or(0.0));
        let illum = m.illumination_model;
        let ior = match m.optical_density {
            Some(n) if n.is_finite() && n > 0.0 => n,
            Some(n) => {
                warn(&format!("Ni {n} is not a positive index of refraction; 1.5 is used"));
                1.5
            }
            None => 1.5,
        };
        let lambertian = Scattering {
            metallic: 0.0,
            roughness: 1.0,
            specular: 0.0,
            ior,
            transmission: 0.0,
            base: None,
            clearcoat,
            clearcoat_roughness,
        };
        if illum.is_some_and(|i| GLASS_ILLUM.contains(&i)) {
            let tint = m.unknown_param.get("Tf").map(|t| {
                let v: Vec<f32> = t.split_whitespace().filter_map(|w| w.parse().ok()).collect();
                match v.as_slice() {
                    [g] => Vec3::splat(*g),
                    [r, g, b, ..] => Vec3::new(*r, *g, *b),
                    _ => Vec3::ONE,
                }
            });
            let tint = tint.unwrap_or(Vec3::ONE);
            if !(tint.is_finite() && tint.min_element() >= 0.0 && tint.max_element() <= 1.0) {
                warn("Tf is outside [0, 1]; clamped");
            }
            let tint = if tint.is_finite() { tint.clamp(Vec3::ZERO, Vec3::ONE) } else { Vec3::ONE };
            return Scattering {
                transmission: 1.0,
                roughness: pr.unwrap_or(0.0),
                specular: 1.0,
                base: Some(tint),
                ..lambertian
            };
        }
        if pm.is_none() && pr.is_none() && illum != Some(3) {
            return lambertian;
        }
        let (metallic, roughness) = if illum == Some(3) && pm.is_none() {
            (1.0, pr.unwrap_or(0.0))
        } else {
            (pm.unwrap_or(0.0), pr.unwrap_or(1.0))
        };
        let specular = if m.specular == Some([0.0; 3]) { 0.0 } else { 1.0 };
        Scattering { metallic, roughness, specular, ..lambertian }
    }
}

/// The texture transform of statement `key` as [`load_mtl`] recorded it.
pub(super) fn map_transform(m: &tobj::Material, key: &str) -> UvTransform {
    let values: Vec<f32> = m
        .unknown_param
        .get(&format!("{key} transform"))
        .map(|t| t.split_whitespace().filter_map(|w| w.parse().ok()).collect())
        .unwrap_or_default();
    match values.as_slice() {
        &[a, b, c, d, e, f] => UvTransform([[a, b, c], [d, e, f]]),
        _ => UvTransform::IDENTITY,
    }
}

/// A texture statement's value (`map_Kd`, `map_d`, `map_Ke`): its file name after the options,
/// and the placement its `-o` (offset) and `-s` (scale) options give: uv' = s·uv + o in OBJ's
/// texture coordinates (v up), written in the scene's (v down) as
/// (u, v) ↦ (s_u u + o_u, s_v v + 1 − s_v − o_v). The other options (`-clamp on`, `-bm`, and
/// those exporters invent) are skipped with their values and a warning.
pub(super) fn texture_statement(key: &str, value: &str) -> std::result::Result<(String, UvTransform), String> {
    let mut rest = value.trim();
    let (mut offset, mut scale) = ([0.0f32; 2], [1.0f32; 2]);
    while rest.starts_with('-') {
        let (option, after) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
        // Unknown options (exporters invent some) are skipped with the numbers after them.
        let (min, max) = match option {
            "-blendu" | "-blendv" | "-cc" | "-clamp" | "-texres" | "-bm" | "-boost" | "-imfchan" => (1, 1),
            "-type" | "-colorspace" => (1, 1),
            "-mm" => (2, 2),
            "-o" | "-s" | "-t" => (1, 3),
            _ => (0, usize::MAX),
        };
        rest = after.trim_start();
        // The required values are taken as they come, the optional ones only if numbers.
        let mut values = Vec::new();
        for k in 0..max {
            let (word, after) = rest.split_once(char::is_whitespace).unwrap_or((rest, ""));
            if word.is_empty() || (k >= min && word.parse::<f32>().is_err()) {
                if k < min {
                    return Err(format!("{key} option '{option}' lacks its value"));
                }
                break;
            }
            values.push(word);
            rest = after.trim_start();
        }
        if option == "-o" || option == "-s" {
            let numbers: Vec<f32> = values
                .iter()
                .map(|w| w.parse::<f32>())
                .collect::<std::result::Result<_, _>>()
                .ok()
                .filter(|v: &Vec<f32>| v.iter().all(|x| x.is_finite()))
                .ok_or_else(|| format!("{key} option '{option}' needs numbers, got '{}'", values.join(" ")))?;
            // -o u [v [w]], -s u [v [w]]: v defaults to 0 (offset) or 1 (scale); w is unused.
            let target = if option == "-o" { &mut offset } else { &mut scale };
            target[0] = numbers[0];
            if let Some(&v) = numbers.get(1) {
                target[1] = v;
            }
        } else {
            log::warn!("{key} option '{option}' is not supported and is ignored");
        }
    }
    if rest.is_empty() {
        return Err(format!("{key} names no file"));
    }
    let transform = UvTransform([[scale[0], 0.0, offset[0]], [0.0, scale[1], 1.0 - scale[1] - offset[1]]]);
    Ok((rest.to_owned(), transform))
}

/// Loads the MTL library `name`, found relative to the OBJ file `obj` as tobj does. MTL lets
/// a colour be one number (`Kd 0.5` means `Kd 0.5 0.5 0.5`) but tobj panics on fewer than
/// three: such lines are completed here first. The first failure is recorded in `error`.
pub(super) fn load_mtl(files: Files, obj: &Path, name: &Path, error: &RefCell<Option<String>>) -> tobj::MTLLoadResult {
    let mtl_path = obj.parent().unwrap_or(Path::new("")).join(name);
    let fail = |message: String, e: tobj::LoadError| {
        error.borrow_mut().get_or_insert(format!("{}: {message}", mtl_path.display()));
        Err(e)
    };
    if name.as_os_str().is_empty() {
        error.borrow_mut().get_or_insert("an mtllib line names no file".into());
        return Err(tobj::LoadError::OpenFileFailed);
    }
    // A device or a pipe (`mtllib /dev/zero`) would be read forever.
    if files.is_special(&mtl_path) {
        return fail("is not a regular file".into(), tobj::LoadError::OpenFileFailed);
    }
    let text = match files.read_to_string(&mtl_path) {
        Ok(text) => text,
        Err(e) => return fail(e.to_string(), tobj::LoadError::OpenFileFailed),
    };
    let mut completed = String::with_capacity(text.len());
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        if let Some(key @ ("Ka" | "Kd" | "Ks" | "Ke")) = words.next() {
            match words.collect::<Vec<_>>().as_slice() {
                [r] => {
                    completed.push_str(&format!("{key} {r} {r} {r}\n"));
                    continue;
                }
                [_, _, _, ..] => {}
                _ => {
                    let message = format!("line {}: '{key}' needs three numbers (r g b) or one", n + 1);
                    return fail(message, tobj::LoadError::MaterialParseError);
                }
            }
        }
        completed.push_str(line);
        completed.push('\n');
    }
    let (mut materials, names) =
        tobj::load_mtl_buf(&mut completed.as_bytes()).or_else(|e| fail(format!("not a valid MTL file ({e})"), e))?;
    // Texture files are named relative to the MTL file: each statement's resolved file and
    // placement are recorded beside it (map_file, map_transform).
    for m in &mut materials {
        for key in TEXTURE_KEYS {
            let Some(value) = map_value(m, key) else { continue };
            match texture_statement(key, value) {
                Ok((file, t)) => {
                    let resolved = mtl_path.parent().unwrap_or(Path::new("")).join(file);
                    m.unknown_param.insert(format!("{key} file"), resolved.to_string_lossy().into_owned());
                    let [r, s] = t.0;
                    let numbers = format!("{} {} {} {} {} {}", r[0], r[1], r[2], s[0], s[1], s[2]);
                    m.unknown_param.insert(format!("{key} transform"), numbers);
                }
                Err(message) => {
                    return fail(format!("material '{}': {message}", m.name), tobj::LoadError::MaterialParseError);
                }
            }
        }
    }
    Ok((materials, names))
}
