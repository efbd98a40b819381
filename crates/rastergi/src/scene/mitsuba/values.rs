//! Property values: numbers, booleans, points and vectors, colours and spectra, and
//! transforms, each read from its element with an error that points at it.
//!
//! Transforms compose in the order they are written: each operation applies after the ones
//! before it (M = Tₙ ⋯ T₂ T₁, Mitsuba's rule). `translate` (x, y, z or value), `scale` (x, y, z,
//! or value: one number for all axes or three), `rotate` (axis x, y, z or value, and `angle`
//! in degrees, counter-clockwise about the axis: the right-hand rule), `matrix` (16 numbers,
//! row by row, or 9 for the linear part) and `lookat` (origin, target, up: the columns of the
//! matrix are left = normalize(up × dir), up' = dir × left, dir = normalize(target − origin)
//! and the origin, so that the local +z looks at the target and +x points to the left, as in
//! Mitsuba).

use glam::{Mat3, Mat4, Vec3};

use super::spectra;
use super::xml::{Elem, Pos};

/// A value that cannot be read, and where.
#[derive(Debug)]
pub struct Bad(pub Pos, pub String);

pub type VRes<T> = Result<T, Bad>;

fn bad<T>(e: &Elem, message: impl Into<String>) -> VRes<T> {
    Err(Bad(e.pos, message.into()))
}

/// Numbers separated by commas and/or white space, each finite.
pub fn numbers(s: &str) -> Result<Vec<f32>, String> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|w| !w.is_empty())
        .map(|w| match w.parse::<f32>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => Err(format!("'{w}' is not a finite number")),
            Err(_) => Err(format!("'{w}' is not a number")),
        })
        .collect()
}

fn attr<'a>(e: &'a Elem, name: &str) -> VRes<&'a str> {
    e.attr(name).ok_or_else(|| Bad(e.pos, format!("<{}> needs a {name} attribute", e.tag)))
}

/// One number from attribute `name` of `e`.
pub fn number_attr(e: &Elem, name: &str) -> VRes<f32> {
    let v = attr(e, name)?;
    match numbers(v) {
        Ok(n) if n.len() == 1 => Ok(n[0]),
        Ok(_) => bad(e, format!("{name}=\"{v}\" is not one number")),
        Err(m) => bad(e, format!("{name}: {m}")),
    }
}

/// A `<float>` (or `<integer>`) property.
pub fn float(e: &Elem) -> VRes<f32> {
    match e.tag.as_str() {
        "float" | "integer" => number_attr(e, "value"),
        other => bad(e, format!("'{}' must be a <float>, not <{other}>", e.name())),
    }
}

/// An `<integer>` property.
pub fn integer(e: &Elem) -> VRes<i64> {
    let v = attr(e, "value")?;
    match (e.tag.as_str(), v.trim().parse::<i64>()) {
        ("integer", Ok(i)) => Ok(i),
        ("integer", Err(_)) => bad(e, format!("'{}' = \"{v}\" is not an integer", e.name())),
        (other, _) => bad(e, format!("'{}' must be an <integer>, not <{other}>", e.name())),
    }
}

/// A `<boolean>` property: true or false (any case), or 1 and 0.
pub fn boolean(e: &Elem) -> VRes<bool> {
    let v = attr(e, "value")?;
    if e.tag != "boolean" {
        return bad(e, format!("'{}' must be a <boolean>, not <{}>", e.name(), e.tag));
    }
    match v.trim().to_ascii_lowercase().as_str() {
        "true" | "1" => Ok(true),
        "false" | "0" => Ok(false),
        _ => bad(e, format!("'{}' = \"{v}\" is neither true nor false", e.name())),
    }
}

/// A `<string>` property.
pub fn string(e: &Elem) -> VRes<&str> {
    if e.tag != "string" {
        return bad(e, format!("'{}' must be a <string>, not <{}>", e.name(), e.tag));
    }
    attr(e, "value")
}

/// Three numbers: attributes x, y, z (each `missing` where absent) or `value` (three numbers,
/// or one for all three).
pub fn xyz(e: &Elem, missing: f32) -> VRes<Vec3> {
    if let Some(v) = e.attr("value") {
        return match numbers(v) {
            Ok(n) if n.len() == 3 => Ok(Vec3::new(n[0], n[1], n[2])),
            Ok(n) if n.len() == 1 => Ok(Vec3::splat(n[0])),
            Ok(_) => bad(e, format!("value=\"{v}\" is not three numbers")),
            Err(m) => bad(e, m),
        };
    }
    let mut out = [missing; 3];
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        if e.attr(name).is_some() {
            out[k] = number_attr(e, name)?;
        }
    }
    Ok(Vec3::from(out))
}

/// A `<point>` or `<vector>` property.
pub fn vec3(e: &Elem) -> VRes<Vec3> {
    match e.tag.as_str() {
        "point" | "vector" => xyz(e, 0.0),
        other => bad(e, format!("'{}' must be a <point> or <vector>, not <{other}>", e.name())),
    }
}

/// A point written as "x, y, z" in attribute `name` (lookat's origin, target and up).
fn point_attr(e: &Elem, name: &str) -> VRes<Vec3> {
    let v = attr(e, name)?;
    match numbers(v) {
        Ok(n) if n.len() == 3 => Ok(Vec3::new(n[0], n[1], n[2])),
        Ok(_) => bad(e, format!("{name}=\"{v}\" is not three numbers")),
        Err(m) => bad(e, format!("{name}: {m}")),
    }
}

/// What a colour property says: its linear RGB, and a warning where it was reduced from
/// something RGB cannot hold.
pub struct Colour {
    pub rgb: Vec3,
    pub note: Option<String>,
}

/// A colour or spectrum property as linear RGB: `<float>`, `<rgb>` (linear; three numbers,
/// one, or "#rrggbb" sRGB-encoded), `<srgb>` (sRGB-encoded, decoded), `<spectrum>` (one value;
/// "λ:v" pairs reduced by [`spectra::pairs_to_rgb`]) or `<blackbody>` (temperature, scale:
/// [`spectra::blackbody_rgb`], with a note).
pub fn colour(e: &Elem) -> VRes<Colour> {
    let plain = |rgb| Ok(Colour { rgb, note: None });
    match e.tag.as_str() {
        "float" | "integer" => plain(Vec3::splat(float(e)?)),
        "rgb" | "srgb" | "color" => {
            let v = attr(e, "value")?;
            let hex = v.trim().strip_prefix('#');
            let rgb = match hex {
                Some(h) => hex_colour(h).ok_or_else(|| Bad(e.pos, format!("\"{v}\" is not a colour #rrggbb")))?,
                None => match numbers(v) {
                    Ok(n) if n.len() == 3 => Vec3::new(n[0], n[1], n[2]),
                    Ok(n) if n.len() == 1 => Vec3::splat(n[0]),
                    Ok(_) => return bad(e, format!("'{}' = \"{v}\" is not three numbers (r, g, b)", e.name())),
                    Err(m) => return bad(e, m),
                },
            };
            let encoded = e.tag == "srgb" || hex.is_some();
            plain(if encoded { rgb.map(spectra::srgb_to_linear) } else { rgb })
        }
        "spectrum" => {
            if e.attr("filename").is_some() {
                return bad(
                    e,
                    "spectra from files (.spd) are not read; give the values inline (\"λ:v, …\") or as <rgb>",
                );
            }
            let v = attr(e, "value")?;
            if v.contains(':') {
                let mut pairs = Vec::new();
                for pair in v.split(',').map(str::trim).filter(|p| !p.is_empty()) {
                    let (l, x) = pair
                        .split_once(':')
                        .ok_or_else(|| Bad(e.pos, format!("\"{pair}\" is not a wavelength:value pair")))?;
                    let (Ok(l), Ok(x)) = (l.trim().parse::<f32>(), x.trim().parse::<f32>()) else {
                        return bad(e, format!("\"{pair}\" is not a wavelength:value pair of numbers"));
                    };
                    if !(l.is_finite() && x.is_finite()) {
                        return bad(e, format!("\"{pair}\" is not finite"));
                    }
                    pairs.push((l, x));
                }
                if pairs.windows(2).any(|w| w[1].0 <= w[0].0) || pairs.is_empty() {
                    return bad(e, "a spectrum's wavelengths must increase");
                }
                return plain(spectra::pairs_to_rgb(&pairs));
            }
            match numbers(v) {
                Ok(n) if n.len() == 1 => plain(Vec3::splat(n[0])),
                Ok(n) if n.len() == 3 => plain(Vec3::new(n[0], n[1], n[2])),
                Ok(_) => bad(e, format!("spectrum \"{v}\" is neither one value nor wavelength:value pairs")),
                Err(m) => bad(e, m),
            }
        }
        "blackbody" => {
            let t =
                number_attr(e, "temperature").or_else(|_| attr(e, "temperature").and_then(|t| parse_kelvin(e, t)))?;
            if t <= 0.0 {
                return bad(e, format!("a blackbody's temperature {t} K must be positive"));
            }
            let scale = if e.attr("scale").is_some() { number_attr(e, "scale")? } else { 1.0 };
            Ok(Colour {
                rgb: spectra::blackbody_rgb(t) * scale,
                note: Some(format!(
                    "a blackbody of {t} K is reduced to linear RGB through CIE 1931 (its mean spectral radiance per nm, W/(m²·sr·nm)); Mitsuba's RGB modes have no blackbody"
                )),
            })
        }
        other => bad(e, format!("'{}' must be a colour (<rgb>, <srgb>, <spectrum>, <float>), not <{other}>", e.name())),
    }
}

fn parse_kelvin(e: &Elem, t: &str) -> VRes<f32> {
    let t = t.trim().trim_end_matches(['k', 'K']).trim();
    t.parse::<f32>().map_err(|_| Bad(e.pos, format!("temperature \"{t}\" is not a number of kelvins")))
}

fn hex_colour(h: &str) -> Option<Vec3> {
    if h.len() != 6 || !h.is_ascii() {
        return None;
    }
    let c = |i: usize| u8::from_str_radix(&h[i..i + 2], 16).ok().map(|b| b as f32 / 255.0);
    Some(Vec3::new(c(0)?, c(2)?, c(4)?))
}

/// A `<transform>` property: its operations composed in order.
pub fn transform(e: &Elem) -> VRes<Mat4> {
    if e.tag != "transform" {
        return bad(e, format!("'{}' must be a <transform>, not <{}>", e.name(), e.tag));
    }
    let mut m = Mat4::IDENTITY;
    for op in &e.children {
        let t = match op.tag.as_str() {
            "translate" => Mat4::from_translation(xyz(op, 0.0)?),
            "scale" => Mat4::from_scale(xyz(op, 1.0)?),
            "rotate" => {
                let axis = xyz(op, 0.0)?;
                let angle = number_attr(op, "angle")?;
                if axis.length_squared() == 0.0 {
                    return bad(op, "a rotation needs a non-zero axis (x, y, z)");
                }
                Mat4::from_axis_angle(axis.normalize(), angle.to_radians())
            }
            "matrix" => {
                let v = attr(op, "value")?;
                match numbers(v) {
                    Ok(n) if n.len() == 16 => Mat4::from_cols_slice(&n).transpose(),
                    Ok(n) if n.len() == 9 => Mat4::from_mat3(Mat3::from_cols_slice(&n).transpose()),
                    Ok(n) => return bad(op, format!("a matrix has 16 (or 9) numbers, not {}", n.len())),
                    Err(m) => return bad(op, m),
                }
            }
            "lookat" => {
                let origin = point_attr(op, "origin")?;
                let target = point_attr(op, "target")?;
                let dir = (target - origin).normalize_or_zero();
                if dir == Vec3::ZERO {
                    return bad(op, "a lookat's origin and target are the same point");
                }
                let up = if op.attr("up").is_some() {
                    point_attr(op, "up")?
                } else if dir.cross(Vec3::Y).length_squared() > 1e-6 {
                    Vec3::Y
                } else {
                    Vec3::Z
                };
                let left = up.cross(dir).normalize_or_zero();
                if left == Vec3::ZERO {
                    return bad(op, "a lookat's up vector is parallel to its view direction");
                }
                let new_up = dir.cross(left);
                Mat4::from_cols(left.extend(0.0), new_up.extend(0.0), dir.extend(0.0), origin.extend(1.0))
            }
            other => {
                return bad(op, format!("<{other}> is not a transform (translate, rotate, scale, matrix, lookat)"));
            }
        };
        m = t * m;
    }
    if !m.is_finite() {
        return bad(e, "the transform is not finite");
    }
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_split_on_commas_and_spaces() {
        assert_eq!(numbers("1, 2 3,4").unwrap(), vec![1.0, 2.0, 3.0, 4.0]);
        assert!(numbers("1 nan").is_err());
        assert!(numbers("1 x").is_err());
    }

    #[test]
    fn hex_colours_decode() {
        assert_eq!(hex_colour("ff0080").unwrap(), Vec3::new(1.0, 0.0, 128.0 / 255.0));
        assert!(hex_colour("ff00").is_none());
    }
}
