//! A physical sky: Mitsuba 3's `sunsky` in its RGB variant — the Hosek–Wilkie sky radiance
//! (Hosek & Wilkie 2012, "An Analytic Model for Full Spectral Sky-Dome Radiance", RGB
//! datasets through the `hw-skymodel` crate) and the Hosek–Wilkie sun as a disc (Hosek &
//! Wilkie 2013, "Adding a Solar-Radiance Function to the Hosek-Wilkie Skylight Model").
//! The sky becomes an [`Environment`] (so its sampling, MIS and photon emission are the
//! environment map's) and the sun a [`Light::Distant`] with its disc.
//!
//! # The sky
//! For a direction d at angle θ from the zenith and γ from the sun, with the sun at elevation
//! η, the radiance of channel c is
//!   L_c = k · R_c · (1 + A e^{B/(cos θ + 0.01)}) · (C + D e^{Eγ} + F cos²γ + G χ(H, γ) + I √cos θ),
//!   χ(H, γ) = (1 + cos²γ) / (1 + H² − 2H cos γ)^{3/2},
//! where R_c and A…I are the model's RGB datasets interpolated linearly in turbidity
//! (1 … 10) and ground albedo (0 … 1, per channel) and by a quintic Bézier curve in
//! (η/(π/2))^{1/3} (`hw_skymodel::rgb::SkyState`), and k = 1/106.856895 is Mitsuba's
//! `MI_CIE_Y_NORMALIZATION`, which its RGB `sunsky` multiplies the model by. Below the
//! horizon (cos θ < 0), and everywhere when the sun is below it, the sky is black, as in
//! Mitsuba 3. `sky_scale` multiplies it.
//!
//! # The sun
//! Mitsuba 3's RGB sun (not `complex_sun`) has uniform radiance over a disc of aperture
//! `sun_aperture` (default 0.5358°), scaled so that its irradiance does not depend on the
//! aperture: the irradiance on a surface facing it is E_c(T, η), the solar model's spectral
//! irradiance converted to linear sRGB, interpolated linearly in turbidity and in elevation
//! between the nodes 2°, 5°, …, 89° (clamped outside them). [`sun_irradiance_table`] holds those
//! nodes, read back from Mitsuba 3 by `scripts/sunsky_sun_table.py` (the solar model is not in
//! `hw-skymodel`). At the lowest elevations the blue channel is slightly negative there
//! (−0.0076 W/m² at T = 1, η = 2°; Mitsuba leaves it so); here it is clamped to 0.
//! `sun_scale` multiplies it.
//!
//! Units are Mitsuba 3's for `sunsky`: W m⁻² sr⁻¹ for the sky, W m⁻² for the sun, per unit of
//! its RGB (the sun at 35° elevation and turbidity 3 gives about 1.4 W/m² in red).

use glam::Vec3;

use crate::environment::{Environment, uv_to_direction};
use crate::error::{Error, Result};
use crate::scene::Light;
use crate::scene::sky_sun_table::sun_irradiance_table;

/// Mitsuba's `MI_CIE_Y_NORMALIZATION` (1 / ∫ ȳ(λ) dλ), by which its RGB `sunsky` scales the
/// Hosek–Wilkie RGB radiance.
pub const CIE_Y_NORMALIZATION: f32 = 1.0 / 106.856895;

/// Mitsuba 3's default sun aperture (full angle, degrees).
pub const SUN_APERTURE_DEG: f32 = 0.5358;

/// The sky's environment map size (equirectangular): 0.35° per pixel, fine enough for the
/// model's narrowest feature, the Mie peak about the sun (its width is about (1 − H) radians,
/// several degrees), and for the horizon's brightening.
pub const SKY_WIDTH: u32 = 1024;
pub const SKY_HEIGHT: u32 = 513;

/// The parameters of a sun and sky (Mitsuba 3's `sunsky`, module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunSky {
    /// Atmospheric turbidity, 1 … 10.
    pub turbidity: f32,
    /// Ground albedo per channel, 0 … 1.
    pub albedo: Vec3,
    /// Unit direction towards the sun (world).
    pub sun_direction: Vec3,
    /// Unit direction of the zenith (world): +Y for rastergi's scenes; Mitsuba's `sunsky` is
    /// Z-up in its own frame, so its `to_world` turns (0, 0, 1) to this.
    pub up: Vec3,
    pub sun_scale: f32,
    pub sky_scale: f32,
    /// The sun's full aperture in degrees (0, 90).
    pub sun_aperture_deg: f32,
}

impl SunSky {
    /// Mitsuba 3's defaults (turbidity 3, albedo 0.3, scales 1, aperture 0.5358°) with the sun
    /// towards `sun_direction` and the zenith along `up`.
    pub fn new(sun_direction: Vec3, up: Vec3) -> SunSky {
        SunSky {
            turbidity: 3.0,
            albedo: Vec3::splat(0.3),
            sun_direction,
            up,
            sun_scale: 1.0,
            sky_scale: 1.0,
            sun_aperture_deg: SUN_APERTURE_DEG,
        }
    }

    /// Checks the values against the model's ranges (Mitsuba 3's checks): one line saying
    /// which is wrong.
    pub fn validate(&self) -> std::result::Result<(), String> {
        if !(1.0..=10.0).contains(&self.turbidity) {
            return Err(format!("the sky's turbidity {} is not within the model's range 1..10", self.turbidity));
        }
        if !(self.albedo.is_finite() && self.albedo.min_element() >= 0.0 && self.albedo.max_element() <= 1.0) {
            return Err(format!("the sky's ground albedo {} is not within 0..1", self.albedo));
        }
        for (v, what) in [(self.sun_direction, "sun direction"), (self.up, "zenith")] {
            if !(v.is_finite() && v.length() > 0.0) {
                return Err(format!("the sky's {what} {v} is not a direction"));
            }
        }
        for (v, what) in [(self.sun_scale, "sun_scale"), (self.sky_scale, "sky_scale")] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("the sky's {what} {v} must be a finite number ≥ 0"));
            }
        }
        if !(self.sun_aperture_deg > 0.0 && self.sun_aperture_deg < 90.0) {
            return Err(format!("the sun's aperture {}° is not within (0, 90)", self.sun_aperture_deg));
        }
        Ok(())
    }

    /// The sun's elevation above the horizon, radians (negative below it).
    pub fn sun_elevation(&self) -> f32 {
        let c = self.sun_direction.normalize().dot(self.up.normalize()).clamp(-1.0, 1.0);
        std::f32::consts::FRAC_PI_2 - c.acos()
    }

    /// The model's state for this turbidity, albedo and sun elevation; `None` when the sun is
    /// below the horizon (the sky is black then) or the values are out of range.
    fn state(&self) -> Option<hw_skymodel::rgb::SkyState> {
        let eta = self.sun_elevation();
        if eta < 0.0 {
            return None;
        }
        hw_skymodel::rgb::SkyState::new(&hw_skymodel::rgb::SkyParams {
            elevation: eta.min(std::f32::consts::FRAC_PI_2),
            turbidity: self.turbidity,
            albedo: self.albedo.to_array(),
        })
        .ok()
    }

    /// The sky's radiance (RGB, without the sun) arriving from unit direction `d` (module
    /// docs).
    pub fn sky_radiance(&self, d: Vec3) -> Vec3 {
        self.state().map_or(Vec3::ZERO, |s| self.sky_radiance_with(&s, d))
    }

    fn sky_radiance_with(&self, s: &hw_skymodel::rgb::SkyState, d: Vec3) -> Vec3 {
        let (up, sun) = (self.up.normalize(), self.sun_direction.normalize());
        let cos_theta = d.dot(up);
        if cos_theta < 0.0 || self.sky_scale == 0.0 {
            return Vec3::ZERO;
        }
        let theta = cos_theta.min(1.0).acos();
        let gamma = d.dot(sun).clamp(-1.0, 1.0).acos();
        use hw_skymodel::rgb::Channel;
        let rgb = Vec3::new(
            s.radiance(theta, gamma, Channel::R),
            s.radiance(theta, gamma, Channel::G),
            s.radiance(theta, gamma, Channel::B),
        );
        rgb * (CIE_Y_NORMALIZATION * self.sky_scale)
    }

    /// The sun's irradiance (RGB, W/m²) on a surface facing it (module docs); zero when it is
    /// below the horizon.
    pub fn sun_irradiance(&self) -> Vec3 {
        let eta = self.sun_elevation();
        if eta < 0.0 {
            return Vec3::ZERO;
        }
        let t = (self.turbidity.clamp(1.0, 10.0) - 1.0).min(9.0);
        let e = ((eta.to_degrees() - 2.0) / 3.0).clamp(0.0, 29.0);
        let table = sun_irradiance_table();
        let node = |ti: usize, ei: usize| Vec3::from(table[ti][ei]);
        let (t0, e0) = ((t as usize).min(8), (e as usize).min(28));
        let (ft, fe) = (t - t0 as f32, e - e0 as f32);
        let lerp_e = |ti: usize| node(ti, e0) * (1.0 - fe) + node(ti, e0 + 1) * fe;
        let irradiance = lerp_e(t0) * (1.0 - ft) + lerp_e(t0 + 1) * ft;
        (irradiance * self.sun_scale).max(Vec3::ZERO)
    }

    /// The sky as an equirectangular environment of `width × height` pixels (radiance at
    /// each pixel's direction, `environment` module's mapping).
    pub fn environment(&self, width: u32, height: u32) -> Result<Environment> {
        self.validate().map_err(Error::InvalidScene)?;
        let state = self.state();
        Environment::from_fn(width, height, |i, j| {
            let uv = glam::Vec2::new((i as f32 + 0.5) / width as f32, j as f32 / (height - 1) as f32);
            state.as_ref().map_or(Vec3::ZERO, |s| self.sky_radiance_with(s, uv_to_direction(uv)))
        })
    }

    /// The sun as a distant light: its irradiance, its disc of the sun's aperture; `None`
    /// where it gives no light (below the horizon, `sun_scale` 0). The disc's radius is
    /// capped at the distant light's 0.5 rad.
    pub fn sun_light(&self) -> Option<Light> {
        let irradiance = self.sun_irradiance();
        if irradiance.max_element() <= 0.0 {
            return None;
        }
        Some(Light::Distant {
            direction: -self.sun_direction.normalize(),
            irradiance,
            angular_radius: (0.5 * self.sun_aperture_deg.to_radians()).min(0.5),
        })
    }
}

/// The direction towards the sun (Mitsuba 3's `sunsky` frame: Z up, X north) at a place and
/// time, by Blanco-Muriel et al., "Computing the Solar Vector" (Solar Energy 70(5), 2001), as
/// Mitsuba 3's `sun_coordinates` computes it (single precision there, double here).
/// `latitude`, `longitude` in degrees, `timezone` in hours east of UTC, `hour` local time.
#[allow(clippy::too_many_arguments)]
pub fn sun_direction_at(
    latitude: f64,
    longitude: f64,
    timezone: f64,
    year: i32,
    month: i32,
    day: i32,
    hour: f64,
    minute: f64,
    second: f64,
) -> Vec3 {
    let dec_hours = hour - timezone + (minute + second / 60.0) / 60.0;
    let aux1 = (month - 14) / 12;
    let aux2 = (1461 * (year + 4800 + aux1)) / 4 + (367 * (month - 2 - 12 * aux1)) / 12
        - (3 * ((year + 4900 + aux1) / 100)) / 4
        + day
        - 32075;
    let elapsed = aux2 as f64 - 0.5 + dec_hours / 24.0 - 2451545.0;
    let omega = 2.1429 - 0.0010394594 * elapsed;
    let mean_longitude = 4.8950630 + 0.017202791698 * elapsed;
    let anomaly = 6.2400600 + 0.0172019699 * elapsed;
    let ecliptic_longitude = mean_longitude + 0.03341607 * anomaly.sin() + 0.00034894 * (2.0 * anomaly).sin()
        - 0.0001134
        - 0.0000203 * omega.sin();
    let obliquity = 0.4090928 - 6.2140e-9 * elapsed + 0.0000396 * omega.cos();
    let sin_l = ecliptic_longitude.sin();
    let mut right_ascension = (obliquity.cos() * sin_l).atan2(ecliptic_longitude.cos());
    if right_ascension < 0.0 {
        right_ascension += std::f64::consts::TAU;
    }
    let declination = (obliquity.sin() * sin_l).asin();
    let gmst = 6.6974243242 + 0.0657098283 * elapsed + dec_hours;
    let lmst = (gmst * 15.0 + longitude).to_radians();
    let lat = latitude.to_radians();
    let hour_angle = lmst - right_ascension;
    let mut zenith = (lat.cos() * hour_angle.cos() * declination.cos() + declination.sin() * lat.sin()).acos();
    let mut azimuth = (-hour_angle.sin()).atan2(declination.tan() * lat.cos() - lat.sin() * hour_angle.cos());
    if azimuth < 0.0 {
        azimuth += std::f64::consts::TAU;
    }
    zenith += 6371.01 / 149597890.0 * zenith.sin();
    let phi = azimuth - std::f64::consts::PI;
    Vec3::new((zenith.sin() * phi.cos()) as f32, (zenith.sin() * phi.sin()) as f32, zenith.cos() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Radiance values printed by Mitsuba 3.9.1's `sunsky` (llvm_ad_rgb, `emitter.eval`) for
    /// sun_direction (cos 35°, 0, sin 35°) in its Z-up frame, turbidity 3, albedo 0.3,
    /// sun_scale 0 (the sky alone), and the sun alone at its centre (sky_scale 0).
    #[test]
    fn sky_and_sun_are_mitsubas() {
        let el = 35f32.to_radians();
        let s = SunSky::new(Vec3::new(el.cos(), 0.0, el.sin()), Vec3::Z);
        let cases = [
            (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.01878023, 0.03468121, 0.06990548)),
            (Vec3::new(1.0, 0.0, 0.01), Vec3::new(0.29884848, 0.3252583, 0.28963837)),
            (Vec3::new(0.0, 1.0, 0.2), Vec3::new(0.07339382, 0.11901174, 0.17946327)),
            (Vec3::new(el.cos() * 0.99, 0.1, el.sin()), Vec3::new(0.19399324, 0.21610506, 0.23567548)),
            (Vec3::new(0.3, -0.4, 0.5), Vec3::new(0.03938112, 0.06377406, 0.10904684)),
        ];
        for (d, want) in cases {
            let got = s.sky_radiance(d.normalize());
            assert!(((got - want) / want).abs().max_element() < 2e-3, "{d}: {got} vs Mitsuba {want}");
        }
        assert_eq!(s.sky_radiance(Vec3::new(0.3, 0.1, -0.2).normalize()), Vec3::ZERO);
        // The sun's radiance there, 20755.25, 16636.76, 11582.435, times its disc's solid angle.
        // (in double precision: 1 − cos of 0.27° loses half a per cent in single)
        let omega = (std::f64::consts::TAU * (1.0 - (0.5 * (SUN_APERTURE_DEG as f64).to_radians()).cos())) as f32;
        let want = Vec3::new(20755.25, 16636.76, 11582.435) * omega;
        let got = s.sun_irradiance();
        assert!(((got - want) / want).abs().max_element() < 2e-3, "sun {got} vs Mitsuba {want}");
        // Between the nodes (40°, turbidity 2.5), an azimuth off the X axis, a coloured albedo.
        let (el, az) = (40f32.to_radians(), 1.0f32);
        let sun = Vec3::new(el.cos() * az.cos(), el.cos() * az.sin(), el.sin());
        let s = SunSky { turbidity: 2.5, albedo: Vec3::new(0.1, 0.5, 0.9), ..SunSky::new(sun, Vec3::Z) };
        let want = Vec3::new(21356.215, 17380.262, 12481.997) * omega;
        let got = s.sun_irradiance();
        assert!(((got - want) / want).abs().max_element() < 2e-3, "sun {got} vs Mitsuba {want}");
        for (d, want) in [
            (Vec3::Z, Vec3::new(0.0174829, 0.040263, 0.099731)),
            (Vec3::new(0.5, 0.5, 0.3), Vec3::new(0.11797962, 0.18477024, 0.28372425)),
        ] {
            let got = s.sky_radiance(d.normalize());
            assert!(((got - want) / want).abs().max_element() < 2e-3, "{d}: {got} vs Mitsuba {want}");
        }
    }

    /// Mitsuba 3.9.1's `sun_direction` for its default place and time (Tokyo, 2010-07-10
    /// 15:00, UTC+9) and for Paris (48°, 2.3°, UTC+1) on 2020-03-21 at 9:30.
    #[test]
    fn sun_positions_are_mitsubas() {
        let tokyo = sun_direction_at(35.6894, 139.6917, 9.0, 2010, 7, 10, 15.0, 0.0, 0.0);
        assert!(tokyo.abs_diff_eq(Vec3::new(0.0513851, 0.691748, 0.720308), 2e-4), "{tokyo}");
        let paris = sun_direction_at(48.0, 2.3, 1.0, 2020, 3, 21, 9.5, 0.0, 0.0);
        // Mitsuba computes in single precision (the Julian date near 2.45e6 days): within 1e-3.
        assert!(paris.abs_diff_eq(Vec3::new(0.452752, -0.787719, 0.417748), 1e-3), "{paris}");
    }
}
