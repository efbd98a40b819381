//! The sensor: a perspective camera from its `to_world` and field of view, the film's size and
//! the sampler's sample count.

use glam::Vec3;

use super::xml::{Elem, Plugin};
use super::{Loader, Res, values};
use crate::scene::Camera;

impl<'a> Loader<'a> {
    /// A `perspective` (or `thinlens`) sensor: the camera, the film's size, the sample count.
    pub(super) fn sensor(&mut self, e: &'a Elem) -> Res<()> {
        let p = Plugin::new(e);
        match p.ty() {
            "perspective" => {}
            "thinlens" => {
                p.get("aperture_radius");
                p.get("focus_distance");
                self.warn("the thinlens sensor is rendered as a pinhole camera (no depth of field)".into());
            }
            other => {
                p.read_all();
                self.warn(format!("the sensor '{other}' is not supported; the scene is framed by a default camera"));
                return Ok(());
            }
        }
        let (mut width, mut height) = (768u32, 576u32);
        if let Some(film) = p.nested(&["film"]).first() {
            let f = Plugin::new(film);
            let size = |v: i64, what: &str| -> Res<u32> {
                u32::try_from(v).ok().filter(|&v| (1..=65536).contains(&v)).ok_or_else(|| {
                    self.err(film, format!("the film's {what} {v} is not a size in pixels (1 to 65536)"))
                })
            };
            width = size(self.integer(&f, "width", 768)?, "width")?;
            height = size(self.integer(&f, "height", 576)?, "height")?;
            for crop in ["crop_offset_x", "crop_offset_y", "crop_width", "crop_height"] {
                if f.get(crop).is_some() {
                    self.warn(format!("the film's {crop} is ignored: the whole image is rendered"));
                }
            }
            self.warn_unread(&f, &format!("film '{}'", f.ty()));
        }
        if let Some(sampler) = p.nested(&["sampler"]).first() {
            let s = Plugin::new(sampler);
            let count = self.integer(&s, "sample_count", 4)?;
            self.sample_count = Some(u32::try_from(count).unwrap_or(1).max(1));
            self.warn_unread(&s, &format!("sampler '{}'", s.ty()));
        }
        let aspect = width as f32 / height as f32;
        let (fov, axis) = if let Some(f) = p.get("fov") {
            let fov = self.v(values::float(f))?;
            let axis = self.string(&p, "fov_axis")?.unwrap_or("x");
            (fov, axis)
        } else if let Some(f) = p.get("focal_length") {
            let text = if f.tag == "string" { self.v(values::string(f))? } else { f.attr("value").unwrap_or("") };
            let mm = text.trim().trim_end_matches("mm").trim().parse::<f32>().ok().filter(|v| *v > 0.0);
            let mm = mm.ok_or_else(|| self.err(f, format!("focal_length \"{text}\" is not a length such as 50mm")))?;
            (2.0 * (36f32.hypot(24.0) / (2.0 * mm)).atan().to_degrees(), "diagonal")
        } else {
            (2.0 * (36f32.hypot(24.0) / 100.0).atan().to_degrees(), "diagonal")
        };
        let fov_y_deg = vertical_fov(fov, axis, aspect)
            .ok_or_else(|| self.err(e, format!("fov_axis '{axis}' is none of x, y, diagonal, smaller, larger")))?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(self.err(e, format!("the field of view {fov}° is not between 0 and 180")));
        }
        let m = self.transform(&p, "to_world")?;
        let eye = m.transform_point3(Vec3::ZERO);
        let forward = m.transform_vector3(Vec3::Z).normalize_or_zero();
        let up = m.transform_vector3(Vec3::Y).normalize_or_zero();
        let left = m.transform_vector3(Vec3::X);
        let camera = Camera { eye, target: eye + forward, up, fov_y_deg };
        camera.validate().map_err(|err| self.err(e, format!("the sensor's to_world gives no view: {err}")))?;
        if left.dot(forward.cross(up)) > 0.0 {
            self.warn(
                "the sensor's to_world is mirrored (its x axis points right, not left): Mitsuba renders this view mirrored left to right, rastergi does not"
                    .into(),
            );
        }
        self.camera = Some(camera);
        self.film = Some((width, height));
        self.warn_unread(&p, &format!("sensor '{}'", p.ty()));
        Ok(())
    }
}

/// The vertical field of view (degrees) for `fov` degrees along `axis` of an image of
/// `aspect` = width/height; `None` for an unknown axis.
fn vertical_fov(fov: f32, axis: &str, aspect: f32) -> Option<f32> {
    let t = (0.5 * fov.to_radians()).tan();
    let ty = match axis {
        "x" => t / aspect,
        "y" => t,
        "diagonal" => t / (1.0 + aspect * aspect).sqrt(),
        "smaller" if aspect >= 1.0 => t,
        "smaller" => t / aspect,
        "larger" if aspect >= 1.0 => t / aspect,
        "larger" => t,
        _ => return None,
    };
    Some(2.0 * ty.atan().to_degrees())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vertical_fov_of_each_axis() {
        // A 2:1 image with 90° across: tan(θ_y/2) = 1/2.
        let y = vertical_fov(90.0, "x", 2.0).unwrap();
        assert!((y - 2.0 * 0.5f32.atan().to_degrees()).abs() < 1e-4);
        assert_eq!(vertical_fov(40.0, "y", 2.0).unwrap(), 40.0);
        assert!((vertical_fov(40.0, "smaller", 2.0).unwrap() - 40.0).abs() < 1e-4);
        assert!((vertical_fov(40.0, "larger", 0.5).unwrap() - 40.0).abs() < 1e-4);
        assert!(vertical_fov(40.0, "z", 1.0).is_none());
    }
}
