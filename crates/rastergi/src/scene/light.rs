//! Lights that are not surfaces: punctual lights and the sun.

use glam::Vec3;

/// A sun's direction as `--sun`, the viewer and the web page turn it: degrees from +Z towards
/// +X about +Y (azimuth), and degrees above the XZ plane (elevation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunAngles {
    pub azimuth: f32,
    pub elevation: f32,
}

impl SunAngles {
    /// The angles of a distant light travelling along `direction`.
    pub fn of_direction(direction: Vec3) -> SunAngles {
        let towards = -direction.normalize();
        SunAngles {
            azimuth: towards.x.atan2(towards.z).to_degrees().rem_euclid(360.0),
            elevation: towards.y.clamp(-1.0, 1.0).asin().to_degrees(),
        }
    }

    /// The direction a sun at these angles shines along (as `--sun`).
    pub fn direction(self) -> Vec3 {
        let (a, e) = (self.azimuth.to_radians(), self.elevation.to_radians());
        -Vec3::new(a.sin() * e.cos(), e.sin(), a.cos() * e.cos())
    }
}

/// A light that is not a surface: glTF `KHR_lights_punctual` lights (values read 1:1 as
/// radiometric, as Mitsuba's `point`, `spot` and `directional` take them) and the sun.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// Radiant intensity I (W/sr, RGB) from `position` into every direction: E = I cos θ / d².
    Point { position: Vec3, intensity: Vec3 },
    /// A point light within a cone about `direction` (unit, where it shines): intensity
    /// I · s(cos θ), s = clamp((cos θ − cos θ_o)/(cos θ_i − cos θ_o), 0, 1)² (glTF's smooth
    /// falloff between the inner and outer cone half-angles, radians, 0 ≤ θ_i ≤ θ_o ≤ π/2, θ_o > 0;
    /// equal angles are a hard-edged cone, as Blender exports a spot without blend).
    Spot { position: Vec3, direction: Vec3, intensity: Vec3, inner: f32, outer: f32 },
    /// Light from far away along `direction` (unit, the way it travels): irradiance E (W/m²,
    /// RGB) on a surface facing it, E cos θ on others, from a disc of `angular_radius` radians
    /// of uniform radiance (0: one direction; the sun's is 0.27°).
    Distant { direction: Vec3, irradiance: Vec3, angular_radius: f32 },
}

impl Light {
    /// Checks the values: finite, non-negative, unit directions, cone angles in order.
    pub fn validate(&self) -> std::result::Result<(), String> {
        let colour = |v: Vec3, what: &str| super::check_light(v, &format!("a light's {what}"));
        let unit = |d: Vec3| {
            if d.is_finite() && (d.length() - 1.0).abs() < 1e-3 {
                Ok(())
            } else {
                Err(format!("a light's direction {d} is not a unit vector"))
            }
        };
        let finite =
            |p: Vec3| if p.is_finite() { Ok(()) } else { Err(format!("a light's position {p} is not finite")) };
        match *self {
            Light::Point { position, intensity } => finite(position).and(colour(intensity, "intensity")),
            Light::Spot { position, direction, intensity, inner, outer } => {
                finite(position)?;
                unit(direction)?;
                colour(intensity, "intensity")?;
                if !(inner >= 0.0 && inner <= outer && outer > 0.0 && outer <= std::f32::consts::FRAC_PI_2 + 1e-6) {
                    return Err(format!(
                        "a spot light's cone angles (inner {inner}, outer {outer} radians) must satisfy 0 ≤ inner ≤ outer ≤ π/2 and outer > 0"
                    ));
                }
                Ok(())
            }
            Light::Distant { direction, irradiance, angular_radius } => {
                unit(direction)?;
                colour(irradiance, "irradiance")?;
                if !(0.0..=0.5).contains(&angular_radius) {
                    return Err(format!("a distant light's angular radius {angular_radius} rad is not in [0, 0.5]"));
                }
                Ok(())
            }
        }
    }
}
