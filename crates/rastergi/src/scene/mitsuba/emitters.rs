//! Emitters outside shapes: point, spot and directional lights, the environment (`envmap`,
//! `constant`), and the physical sky (`sunsky`; Mitsuba 0.5/0.6's `sun` and `sky` too).

use std::sync::Arc;

use glam::{Mat4, Vec2, Vec3};

use super::materials::Value;
use super::xml::{self, Elem, Plugin};
use super::{Loader, Res, values};
use crate::scene::Light;

impl<'a> Loader<'a> {
    /// A top-level emitter: a light or the environment.
    pub(super) fn emitter(&mut self, e: &'a Elem) -> Res<()> {
        let p = Plugin::new(e);
        let ty = p.ty();
        let light = match ty {
            "point" => {
                let m = self.transform(&p, "to_world")?;
                let position = self.point(&p, "position")?.unwrap_or_else(|| m.transform_point3(Vec3::ZERO));
                Some(Light::Point { position, intensity: self.colour(&p, "intensity")? })
            }
            "spot" => {
                let m = self.transform(&p, "to_world")?;
                let cutoff = self.float(&p, "cutoff_angle", 20.0)?;
                let beam = self.float(&p, "beam_width", cutoff * 0.75)?;
                let outer = cutoff.to_radians().clamp(1e-4, std::f32::consts::FRAC_PI_2);
                self.warn(
                    "spot lights fall off smoothly between beam_width and cutoff_angle (glTF's curve); Mitsuba's falloff is linear in angle"
                        .into(),
                );
                Some(Light::Spot {
                    position: m.transform_point3(Vec3::ZERO),
                    direction: m.transform_vector3(Vec3::Z).normalize_or_zero(),
                    intensity: self.colour(&p, "intensity")?,
                    inner: beam.to_radians().clamp(0.0, outer),
                    outer,
                })
            }
            "directional" => {
                let m = self.transform(&p, "to_world")?;
                let direction = match p.get("direction") {
                    Some(d) => self.v(values::vec3(d))?,
                    None => m.transform_vector3(Vec3::Z),
                };
                let irradiance = self.colour(&p, "irradiance")?;
                Some(Light::Distant { direction: direction.normalize_or_zero(), irradiance, angular_radius: 0.0 })
            }
            "envmap" | "constant" => {
                let env = if ty == "constant" {
                    crate::environment::Environment::checked_constant(self.colour(&p, "radiance")?)
                        .map_err(|err| self.err(e, err))?
                } else {
                    let filename =
                        self.string(&p, "filename")?.ok_or_else(|| self.err(e, "an envmap needs a filename"))?;
                    let path = xml::resolve(self.dir_of(e), filename);
                    let scale = self.float(&p, "scale", 1.0)?;
                    let env =
                        crate::environment::Environment::load_in(self.files, &path, scale.max(0.0), &self.budgets)
                            .map_err(|err| self.err(e, format!("the envmap: {err}")))?;
                    let m = self.transform(&p, "to_world")?;
                    rotated(&env, m).unwrap_or_else(|| (*env).clone())
                };
                if self.scene.environment.is_some() {
                    self.warn(format!("only the first environment is used; the {ty} at line {} is not", e.pos.line));
                } else {
                    self.scene.environment = Some(Arc::new(env));
                }
                None
            }
            "sun" | "sky" | "sunsky" => {
                let sky = self.sunsky(e, &p)?;
                let env = sky
                    .environment(crate::scene::sky::SKY_WIDTH, crate::scene::sky::SKY_HEIGHT)
                    .map_err(|m| self.err(e, m))?;
                if sky.sun_elevation() < 0.0 {
                    self.warn(format!("the {ty} emitter's sun is below the horizon: it and its sky are black"));
                }
                if self.scene.environment.is_some() {
                    self.warn(format!("only the first environment is used; the {ty} at line {} is not", e.pos.line));
                } else if !env.is_dark() {
                    self.scene.environment = Some(Arc::new(env));
                }
                sky.sun_light()
            }
            "area" => {
                p.read_all();
                self.warn(format!("an area emitter at line {} is not inside a shape; it is skipped", e.pos.line));
                None
            }
            other => {
                p.read_all();
                self.warn(format!("the emitter '{other}' is not supported; it is skipped"));
                None
            }
        };
        if let Some(light) = light {
            light.validate().map_err(|m| self.err(e, m))?;
            self.scene.lights.push(light);
        }
        self.warn_unread(&p, &format!("emitter '{ty}'"));
        Ok(())
    }

    /// A `sunsky` (Mitsuba 3 and 0.6), or 0.6's `sun` (the sun alone) or `sky` (the sky alone),
    /// as a [`SunSky`](crate::scene::sky::SunSky). Mitsuba 3's frame is Z up, 0.6's Y up, each turned
    /// by the emitter's `to_world`; `sun_direction` is in world space in both. Without it, the sun stands where
    /// the place and time put it (Mitsuba 3's defaults: Tokyo, 2010-07-10 15:00). 0.6's
    /// differences: its albedo defaults to 0.15 (3: 0.3); `scale` sets both `sun_scale` and
    /// `sky_scale`; `sun_radius_scale` × 0.5358° is the aperture (0: a delta direction); its
    /// sun followed Preetham's model and its sky was tabulated at `resolution`, neither
    /// reproduced here (`stretch`, `resolution`, `extend` are not used: a warning names them).
    fn sunsky(&mut self, e: &'a Elem, p: &Plugin<'a>) -> Res<crate::scene::sky::SunSky> {
        let ty = p.ty();
        let legacy = self.doc.legacy() || ty != "sunsky";
        let m = self.transform(p, "to_world")?;
        let up = m.transform_vector3(if legacy { Vec3::Y } else { Vec3::Z }).normalize_or_zero();
        let time_keys = ["latitude", "longitude", "timezone", "year", "month", "day", "hour", "minute", "second"];
        let sun = match p.get("sun_direction") {
            Some(d) => {
                if !legacy && time_keys.iter().any(|k| p.has(k)) {
                    return Err(self.err(e, "a sunsky takes sun_direction or a place and time, not both"));
                }
                self.v(values::vec3(d))?.normalize_or_zero()
            }
            None => {
                let f = |s: &Self, k: &str, d: f32| s.float(p, k, d).map(f64::from);
                let local = crate::scene::sky::sun_direction_at(
                    f(self, "latitude", 35.6894)?,
                    f(self, "longitude", 139.6917)?,
                    f(self, "timezone", 9.0)?,
                    self.integer(p, "year", 2010)? as i32,
                    self.integer(p, "month", 7)? as i32,
                    self.integer(p, "day", 10)? as i32,
                    f(self, "hour", 15.0)?,
                    f(self, "minute", 0.0)?,
                    f(self, "second", 0.0)?,
                );
                // 0.6's spherical coordinates put the zenith on +Y: (x, z, y) of 3's.
                let local = if legacy { Vec3::new(local.x, local.z, local.y) } else { local };
                m.transform_vector3(local).normalize_or_zero()
            }
        };
        let scale = if legacy { self.float(p, "scale", 1.0)? } else { 1.0 };
        let mut sky = crate::scene::sky::SunSky::new(sun, up);
        sky.turbidity = self.float(p, "turbidity", 3.0)?;
        if ty != "sun" {
            sky.albedo = match self.value(p, "albedo", Vec3::splat(if legacy { 0.15 } else { 0.3 }))? {
                Value::Constant(c) => c,
                Value::Texture { factor, .. } => {
                    self.warn(format!("emitter '{ty}': a texture as albedo is not supported; its factor is used"));
                    factor
                }
            };
        }
        sky.sun_scale = if ty == "sky" { 0.0 } else { self.float(p, "sun_scale", scale)? };
        sky.sky_scale = if ty == "sun" { 0.0 } else { self.float(p, "sky_scale", scale)? };
        if legacy {
            let r = self.float(p, "sun_radius_scale", 1.0)?;
            if !(r.is_finite() && r >= 0.0) {
                return Err(self.err(e, format!("sun_radius_scale {r} must be a finite number ≥ 0")));
            }
            sky.sun_aperture_deg = (crate::scene::sky::SUN_APERTURE_DEG * r).max(f32::MIN_POSITIVE);
        } else {
            sky.sun_aperture_deg = self.float(p, "sun_aperture", crate::scene::sky::SUN_APERTURE_DEG)?;
            if self.boolean(p, "complex_sun", false)? {
                self.warn(format!(
                    "emitter '{ty}': complex_sun (limb darkening) is not reproduced; the sun's disc is uniform"
                ));
            }
        }
        sky.validate().map_err(|m| self.err(e, m))?;
        Ok(sky)
    }

    /// A constant colour property of an emitter (default 1). Given as a `<spectrum>` it is an
    /// emission spectrum, which Mitsuba 3's RGB mode projects to sRGB: a flat one (one value,
    /// or flat wavelength:value pairs) is equal-energy light, [`EQUAL_ENERGY_SRGB`] times the
    /// value, not grey (`<rgb>` and `<float>` stay as given, as there). Measured on Sponza
    /// (its light is `<spectrum value="16000"/>`): read as grey, the image's channel means were
    /// 0.83, 1.05, 1.10 of Mitsuba 3's on the same file.
    ///
    /// The value must be finite, ≥ 0 and at most [`MAX_LIGHT`](crate::scene::MAX_LIGHT).
    fn colour(&mut self, p: &Plugin<'a>, key: &str) -> Res<Vec3> {
        let given = p.get(key);
        let spectrum = given.is_some_and(|e| e.tag == "spectrum");
        let c = match self.value(p, key, Vec3::ONE)? {
            Value::Constant(c) if spectrum => c * EQUAL_ENERGY_SRGB,
            Value::Constant(c) => c,
            Value::Texture { factor, .. } => {
                self.warn(format!("emitter '{}': a texture as {key} is not supported; its factor is used", p.ty()));
                factor
            }
        };
        crate::scene::check_light(c, key)
            .map_err(|m| self.err(given.unwrap_or(p.elem), format!("emitter '{}': {m}", p.ty())))?;
        Ok(c)
    }
}

/// The environment turned by `m` (an envmap's to_world): the radiance arriving from world
/// direction d is the image's at M⁻¹d, resampled bilinearly at every pixel's direction.
/// `None` where `m` leaves directions unchanged.
fn rotated(env: &crate::environment::Environment, m: Mat4) -> Option<crate::environment::Environment> {
    let linear = glam::Mat3::from_mat4(m);
    if (linear - glam::Mat3::IDENTITY).abs_diff_eq(glam::Mat3::ZERO, 1e-6) || linear.determinant() == 0.0 {
        return None;
    }
    let inverse = linear.inverse();
    let (w, h) = (env.width, env.height);
    crate::environment::Environment::from_fn(w, h, |i, j| {
        let uv = Vec2::new((i as f32 + 0.5) / w as f32, j as f32 / (h - 1).max(1) as f32);
        let d = crate::environment::uv_to_direction(uv);
        env.eval((inverse * d).normalize_or_zero())
    })
    .ok()
}

/// Linear sRGB of an equal-energy emission spectrum of value 1, as Mitsuba 3's RGB variants
/// compute it (`<spectrum name="radiance" value="1"/>` on an area emitter prints
/// `SRGBReflectanceSpectrum[value = [1.20479, 0.948291, 0.908916]]`, mitsuba 3.9.1).
pub const EQUAL_ENERGY_SRGB: Vec3 = Vec3::new(1.20479, 0.948291, 0.908916);
