//! The lights of a scene as one discrete distribution by power: an emissive triangle (then a
//! point uniformly on it), a point or spot light, or a distant light (the sun). Entry weights
//! are Φ/π summed over R, G and B: A·ΣLe for a triangle (Φ = π·A·Le), 4·ΣI for a point light
//! (Φ = 4π·I), 2(1 − cos θ_o)·ΣI for a spot (its outer cone's solid angle times I, over π),
//! R²·ΣE for a distant light (Φ = E·πR² through a disc covering the scene's bounding sphere
//! of radius R), R²·Σ∫L dω for the environment (Φ = πR²·∫L dω: every direction's radiance
//! through its own disc). The same table drives the photon pass (emission), the direct pass and the
//! gather's exact hit light (light samples) and the path tracer.

use bytemuck::Zeroable;
use glam::Vec3;

use crate::gpu::structs::gpu_struct;
use crate::sampling::{cosine_hemisphere, orthonormal_basis, uniform_sphere, uniform_triangle};
use crate::scene::{Light, Scene, triangle_area, triangle_normal};

/// [`LightEntry::triangle`] bit of an entry that is a [`PunctualLight`] (the other bits: its
/// index in [`LightTable::punctual`]); [`PunctualLight::kind`] values.
pub use crate::gpu::consts::{
    AIM_FRACTION, ENVIRONMENT_LIGHT, LIGHT_DISTANT, LIGHT_POINT, LIGHT_SPOT, NEAR_FRACTION, NEAR_SCALE, PUNCTUAL_LIGHT,
};

gpu_struct! {
    /// One light of the distribution, as stored on the GPU (`LightEntry` in WGSL).
    #[derive(PartialEq)]
    pub struct LightEntry as "LightEntry" {
        /// Index of the triangle in the scene, or [`PUNCTUAL_LIGHT`] | index of the punctual light.
        pub triangle: u32,
        /// Cumulative probability up to and including this entry.
        pub cdf: f32,
        /// Probability of choosing this entry.
        pub pmf: f32,
        /// Area of the triangle (1 for a punctual light).
        pub area: f32,
    }
}

/// Whether a light table entry's `triangle` word names a punctual light (a point, spot or
/// distant light), not an emitter triangle or the environment.
pub fn is_punctual(triangle: u32) -> bool {
    triangle != ENVIRONMENT_LIGHT && triangle & PUNCTUAL_LIGHT != 0
}

gpu_struct! {
    /// A point, spot or distant light as stored on the GPU (`PunctualLight` in WGSL).
    #[derive(PartialEq)]
    pub struct PunctualLight as "PunctualLight" {
        /// Point and spot: where the light is.
        pub position: [f32; 3],
        /// [`LIGHT_POINT`], [`LIGHT_SPOT`] or [`LIGHT_DISTANT`].
        pub kind: u32,
        /// Spot: where it shines; distant: the way the light travels (unit).
        pub direction: [f32; 3],
        /// Spot: cos θ_o; distant: the cosine of its angular radius (1: one direction).
        pub cos_outer: f32,
        /// Intensity I (W/sr) or, distant, irradiance E (W/m²).
        pub intensity: [f32; 3],
        /// Spot: cos θ_i.
        pub cos_inner: f32,
        /// Distant: the centre of the scene's bounding sphere, which photons cross from a disc.
        pub disc_centre: [f32; 3],
        /// Distant: the photon disc's radius (the bounding sphere's, enlarged by 1 %).
        pub disc_radius: f32,
    }
}

impl PunctualLight {
    /// The GPU form of `light` for a scene whose bounding sphere is (centre, radius).
    pub fn new(light: &Light, centre: Vec3, radius: f32) -> PunctualLight {
        let disc = |p: PunctualLight| PunctualLight { disc_centre: centre.into(), disc_radius: 1.01 * radius, ..p };
        let zero = PunctualLight::zeroed();
        match *light {
            Light::Point { position, intensity } => PunctualLight {
                position: position.into(),
                kind: LIGHT_POINT,
                intensity: intensity.into(),
                cos_outer: -1.0,
                cos_inner: -1.0,
                ..zero
            },
            Light::Spot { position, direction, intensity, inner, outer } => PunctualLight {
                position: position.into(),
                kind: LIGHT_SPOT,
                direction: direction.normalize().into(),
                cos_outer: outer.cos(),
                intensity: intensity.into(),
                cos_inner: inner.cos(),
                ..zero
            },
            Light::Distant { direction, irradiance, angular_radius } => disc(PunctualLight {
                kind: LIGHT_DISTANT,
                direction: direction.normalize().into(),
                cos_outer: angular_radius.cos(),
                intensity: irradiance.into(),
                ..zero
            }),
        }
    }

    /// The spot's falloff s(cos θ) (glTF's: squared linear ramp between the cones, a step
    /// where they coincide; 1 for the others). Mirrors `spot_falloff` in WGSL.
    pub fn falloff(&self, cos_theta: f32) -> f32 {
        if self.kind != LIGHT_SPOT {
            return 1.0;
        }
        let width = self.cos_inner - self.cos_outer;
        if width <= 0.0 {
            return if cos_theta > self.cos_outer { 1.0 } else { 0.0 };
        }
        let t = ((cos_theta - self.cos_outer) / width).clamp(0.0, 1.0);
        t * t
    }

    /// Φ (RGB, W): 4π·I, I·∫s dω = 2π·I·((cos θ_i − cos θ_o)/3 + 1 − cos θ_i), E·πR².
    pub fn power(&self) -> Vec3 {
        let i = Vec3::from(self.intensity);
        match self.kind {
            LIGHT_POINT => 4.0 * std::f32::consts::PI * i,
            LIGHT_SPOT => {
                let ramp = (self.cos_inner - self.cos_outer) / 3.0 + (1.0 - self.cos_inner);
                2.0 * std::f32::consts::PI * ramp * i
            }
            _ => std::f32::consts::PI * self.disc_radius * self.disc_radius * i,
        }
    }

    /// Where photons start from, as a measure: the solid angle they leave into (4π for a
    /// point light, 2π(1 − cos θ_o) for a spot) or the disc's area πR² (distant).
    fn support(&self) -> f64 {
        match self.kind {
            LIGHT_POINT => 4.0 * std::f64::consts::PI,
            LIGHT_SPOT => 2.0 * std::f64::consts::PI * (1.0 - self.cos_outer as f64),
            _ => std::f64::consts::PI * (self.disc_radius as f64).powi(2),
        }
    }

    /// The entry weight (module docs): the support × the intensity summed over R, G, B, / π.
    fn weight(&self) -> f64 {
        let i = Vec3::from(self.intensity);
        self.support() * (i.x + i.y + i.z) as f64 / std::f64::consts::PI
    }
}

#[derive(Clone, Debug, Default)]
pub struct LightTable {
    pub entries: Vec<LightEntry>,
    /// The point, spot and distant lights that entries refer to.
    pub punctual: Vec<PunctualLight>,
    /// Total emitted power Φ (RGB), in watts of the scene's units.
    pub power: Vec3,
    /// Σ of the entries' weights (module docs): an emitter of radiance Le is picked with area
    /// density ΣLe / weight.
    pub weight: f64,
    /// The probability of picking the environment (0 without one).
    pub environment_pmf: f32,
    /// The photon disc of distant light and the environment: the bounding sphere's centre
    /// and its radius enlarged by 1 %.
    pub disc: (Vec3, f32),
}

impl LightTable {
    pub fn new(scene: &Scene) -> Self {
        let tris = scene.emissive_triangles();
        let bounds = scene.bounds();
        let (centre, radius) = (bounds.center(), 0.5 * bounds.extent().length());
        let punctual: Vec<PunctualLight> = scene.lights.iter().map(|l| PunctualLight::new(l, centre, radius)).collect();
        let mut weights: Vec<(u32, f64, f32)> = tris
            .iter()
            .map(|&i| {
                let le = scene.material_of(i as usize).emission;
                let area = triangle_area(&scene.triangles[i as usize]);
                (i, (area * (le.x + le.y + le.z)) as f64, area)
            })
            .collect();
        weights.extend(punctual.iter().enumerate().map(|(k, p)| (PUNCTUAL_LIGHT | k as u32, p.weight(), 1.0)));
        let disc = (centre, 1.01 * radius);
        let env_power =
            scene.environment.as_ref().map_or(Vec3::ZERO, |e| std::f32::consts::PI * disc.1 * disc.1 * e.integral);
        if let Some(env) = scene.environment.as_ref().filter(|e| !e.is_dark()) {
            let l = env.integral;
            weights.push((ENVIRONMENT_LIGHT, (disc.1 as f64).powi(2) * (l.x + l.y + l.z) as f64, 1.0));
        }
        weights.retain(|w| w.1 > 0.0);
        let total: f64 = weights.iter().map(|w| w.1).sum();
        let mut acc = 0.0f64;
        let mut entries: Vec<LightEntry> = weights
            .iter()
            .map(|&(triangle, w, area)| {
                acc += w;
                LightEntry { triangle, cdf: (acc / total) as f32, pmf: (w / total) as f32, area }
            })
            .collect();
        if let Some(last) = entries.last_mut() {
            last.cdf = 1.0;
        }
        let power = scene.emitted_power() + punctual.iter().map(PunctualLight::power).sum::<Vec3>() + env_power;
        let environment_pmf = entries.iter().find(|e| e.triangle == ENVIRONMENT_LIGHT).map_or(0.0, |e| e.pmf);
        Self { entries, punctual, power, weight: total, environment_pmf, disc }
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The punctual lights' entries, one run in the table (emitters, punctual lights, the
    /// environment): (first, count); (0, 0) without any.
    pub fn punctual_run(&self) -> (u32, u32) {
        let first = self.entries.iter().position(|e| is_punctual(e.triangle)).unwrap_or(0);
        let count = self.entries.iter().filter(|e| is_punctual(e.triangle)).count();
        (first as u32, count as u32)
    }

    /// The entry whose cdf interval holds u ∈ [0,1): the first with `u < cdf`.
    /// Mirrors `light_pick` in WGSL.
    pub fn pick(&self, u: f32) -> &LightEntry {
        &self.entries[self.pick_index(u)]
    }

    /// The index of the entry [`pick`](Self::pick) picks.
    pub fn pick_index(&self, u: f32) -> usize {
        self.entries.partition_point(|e| e.cdf <= u).min(self.entries.len() - 1)
    }

    /// The largest flux × N, over entries and channels, that a photon starts with
    /// ([`LightTable::emit_photon`]; a spot's falloff at most 1).
    pub fn max_photon_flux(&self, scene: &Scene, aimed: bool, guided: bool) -> f64 {
        // Aimed disc photons outside the aim and its surroundings carry 1/(1 − α − β) times
        // an unaimed one's flux; guided ones at most 1/(1 − g) times more
        // (crate::photons::guide).
        let aim_gain = if aimed { 1.0 / (1.0 - AIM_FRACTION as f64 - NEAR_FRACTION as f64) } else { 1.0 };
        let aim_gain = if guided { aim_gain / (1.0 - crate::photons::guide::GUIDED_FRACTION as f64) } else { aim_gain };
        (self.entries.iter())
            .map(|e| {
                let per_pmf = if e.triangle == ENVIRONMENT_LIGHT {
                    let env = scene.environment.as_ref().expect("an environment entry has a map");
                    std::f64::consts::PI * (self.disc.1 as f64).powi(2) * env.max_radiance_over_pdf() * aim_gain
                } else if e.triangle & PUNCTUAL_LIGHT == 0 {
                    let le = scene.material_of(e.triangle as usize).emission;
                    std::f64::consts::PI * le.max_element() as f64 * e.area as f64
                } else {
                    let p = &self.punctual[(e.triangle & !PUNCTUAL_LIGHT) as usize];
                    let gain = if p.kind == LIGHT_DISTANT { aim_gain } else { 1.0 };
                    Vec3::from(p.intensity).max_element() as f64 * p.support() * gain
                };
                per_pmf / e.pmf as f64
            })
            .fold(0.0, f64::max)
    }

    /// A photon leaving the lights, from uniforms (u0 … u4): (origin, direction, flux × N,
    /// the emitter triangle or `None`), `eps` the ray offset. Mirrors `emit_photon` in
    /// `gpu_scene.wgsl`: a triangle's point uniformly (u1, u2) and direction cos θ/π (u3, u4),
    /// flux π·Le·A/pmf; a point light's direction uniform on the sphere, 4π·I/pmf; a spot's
    /// uniform in its outer cone, I·s(cos θ)·2π(1 − cos θ_o)/pmf; a distant light's origin
    /// uniform on a disc of radius R across the bounding sphere (u1, u2) and direction uniform
    /// in its cone (u3, u4), E·πR²/pmf; the environment's direction from its distribution
    /// (u3, u4) and origin on the disc, L(ω)·πR²/(pdf(ω)·pmf); with `aim`, the sun's and the
    /// sky's origins aimed ([`disc_start`]: πR² becomes 1/p(x)). `emitted(triangle, b1, b2)`
    /// is the radiance a triangle emits at barycentrics (b1, b2)
    /// ([`crate::surface::PreparedScene::emitter_radiance`]).
    pub fn emit_photon(
        &self,
        scene: &Scene,
        emitted: impl Fn(usize, f32, f32) -> Vec3,
        u: [f32; 5],
        eps: f32,
        aim: Option<PhotonAim>,
    ) -> (Vec3, Vec3, Vec3, Option<u32>) {
        let s = self.emit_photon_guided(scene, emitted, u, eps, aim, None);
        (s.0, s.1, s.2, s.3)
    }

    /// [`emit_photon`](Self::emit_photon) with the sun's and the sky's starts guided by
    /// `guide`'s learned tables ([`crate::photons::guide`]), and the photon's counter bin
    /// ([`crate::photons::guide::NO_BIN`] for a light that is not guided). Mirrors
    /// `emit_photon` in `photons/emit.wgsl`.
    pub fn emit_photon_guided(
        &self,
        scene: &Scene,
        emitted: impl Fn(usize, f32, f32) -> Vec3,
        u: [f32; 5],
        eps: f32,
        aim: Option<PhotonAim>,
        guide: Option<&crate::photons::guide::GuideTable>,
    ) -> (Vec3, Vec3, Vec3, Option<u32>, u32) {
        use crate::photons::guide::{NO_BIN, env_direction_bin, guided_start};
        let index = self.pick_index(u[0]);
        let e = &self.entries[index];
        let guided = guide.and_then(|g| g.light(index as u32));
        if e.triangle == ENVIRONMENT_LIGHT {
            let env = scene.environment.as_ref().expect("an environment entry has a map");
            let (to_sky, pdf) = env.sample(u[3], u[4]);
            let d = env_direction_bin(to_sky);
            let cdf = guided.and_then(|g| g.cdf(d));
            let (origin, inv_p, position) = guided_start(-to_sky, self.disc, aim, cdf, (u[1], u[2]));
            let flux = env.eval(to_sky) * (inv_p / (pdf * e.pmf));
            return (origin, -to_sky, flux, None, guided.map_or(NO_BIN, |g| g.bin(d, position)));
        }
        if e.triangle & PUNCTUAL_LIGHT == 0 {
            let tri = &scene.triangles[e.triangle as usize];
            let n = triangle_normal(tri);
            let su = u[1].sqrt();
            let (b1, b2) = (u[2] * su, su * (1.0 - u[2]));
            let le = emitted(e.triangle as usize, b1, b2);
            let flux = le * (std::f32::consts::PI * e.area / e.pmf);
            let pos = uniform_triangle(tri, u[1], u[2]);
            return (pos + n * eps, cosine_hemisphere(n, u[3], u[4]), flux, Some(e.triangle), NO_BIN);
        }
        let p = &self.punctual[(e.triangle & !PUNCTUAL_LIGHT) as usize];
        let i = Vec3::from(p.intensity);
        let axis = Vec3::from(p.direction);
        match p.kind {
            LIGHT_POINT => {
                let flux = i * (4.0 * std::f32::consts::PI / e.pmf);
                (Vec3::from(p.position), uniform_sphere(u[3], u[4]), flux, None, NO_BIN)
            }
            LIGHT_SPOT => {
                let d = cone_direction(axis, p.cos_outer, u[3], u[4]);
                let solid = 2.0 * std::f32::consts::PI * (1.0 - p.cos_outer);
                let flux = i * (p.falloff(axis.dot(d)) * solid / e.pmf);
                (Vec3::from(p.position), d, flux, None, NO_BIN)
            }
            _ => {
                let cdf = guided.and_then(|g| g.cdf(0));
                let disc = (Vec3::from(p.disc_centre), p.disc_radius);
                let (origin, inv_p, position) = guided_start(axis, disc, aim, cdf, (u[1], u[2]));
                let flux = i * (inv_p / e.pmf);
                let bin = guided.map_or(NO_BIN, |g| g.bin(0, position));
                (origin, cone_direction(axis, p.cos_outer, u[3], u[4]), flux, None, bin)
            }
        }
    }
}

/// Where sun and sky photons are aimed: a sphere about the part of the scene the camera reads
/// (the photon region's bounding sphere), which a fraction [`AIM_FRACTION`] of them cross.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonAim {
    pub centre: Vec3,
    pub radius: f32,
}

/// The start of a photon crossing the sphere (`centre`, `radius`) along `axis`, from (u1, u2):
/// its origin on the disc of that radius perpendicular to `axis` before the sphere, and
/// 1/p(x), p the density per unit area of the disc's plane it was drawn with. Unaimed, x is
/// uniform on the disc: 1/p = πR². Aimed at a sphere (c_a, r_a), x is drawn from a mixture of
/// three uniform discs: with probability α = [`AIM_FRACTION`] the sphere's cross-section (radius
/// r_a about c_a's projection), with β = [`NEAR_FRACTION`] its surroundings (radius
/// s·r_a, s = [`NEAR_SCALE`], the same centre), else the whole disc (u1 picks, then is
/// rescaled):
///
/// ```text
/// p(x) = α·[x in aim]/(π r_a²) + β·[x in surroundings]/(π s² r_a²) + (1 − α − β)·[x in disc]/(π R²)
/// ```
///
/// the one-sample mixture's density, so Φ = E/p(x) (or L(ω)/(pdf(ω)·p(x))) keeps every photon
/// map unbiased while about α of the photons reach the region. The surroundings' share keeps
/// the photons that reach the region after a bounce nearby (the sunlit ground outside a window)
/// from carrying (R/r_a)² times an aimed one's flux: with two discs alone, the few such
/// photons from the 200 m ground of the sunroom carried 1600 times the flux of the room's own
/// and spotted a sky-lit render with fireflies in one pass of 2¹⁷ photons. The branch drawn
/// always counts its own term (rounding at a disc's rim never drops it). Mirrors `disc_start`
/// in `gpu_scene.wgsl`.
pub fn disc_start(axis: Vec3, centre: Vec3, radius: f32, aim: Option<PhotonAim>, u1: f32, u2: f32) -> (Vec3, f32) {
    use std::f32::consts::PI;
    let (t, b) = orthonormal_basis(axis);
    let phi = 2.0 * PI * u2;
    let dir = t * phi.cos() + b * phi.sin();
    let start = centre - axis * radius;
    let Some(a) = aim.filter(|a| a.radius > 0.0) else {
        return (start + dir * (radius * u1.sqrt()), PI * radius * radius);
    };
    let d = a.centre - centre;
    let towards = d - axis * d.dot(axis);
    let near = a.radius * NEAR_SCALE;
    let whole = 1.0 - AIM_FRACTION - NEAR_FRACTION;
    let branch = if u1 < AIM_FRACTION {
        0
    } else if u1 < AIM_FRACTION + NEAR_FRACTION {
        1
    } else {
        2
    };
    let offset = match branch {
        0 => towards + dir * (a.radius * (u1 / AIM_FRACTION).sqrt()),
        1 => towards + dir * (near * ((u1 - AIM_FRACTION) / NEAR_FRACTION).sqrt()),
        _ => dir * (radius * ((u1 - AIM_FRACTION - NEAR_FRACTION) / whole).sqrt()),
    };
    let from_aim = (offset - towards).length();
    let in_aim = branch == 0 || from_aim <= a.radius;
    let in_near = branch <= 1 || from_aim <= near;
    let in_whole = branch == 2 || offset.length() <= radius;
    let p = if in_aim { AIM_FRACTION / (PI * a.radius * a.radius) } else { 0.0 }
        + if in_near { NEAR_FRACTION / (PI * near * near) } else { 0.0 }
        + if in_whole { whole / (PI * radius * radius) } else { 0.0 };
    (start + offset, 1.0 / p)
}

/// The density per unit area of [`disc_start`]'s mixture at `offset` (a vector in the disc's
/// plane from its centre): the terms of the discs that hold it. Mirrors `disc_density` in
/// `photons/emit.wgsl`.
pub fn disc_density(axis: Vec3, centre: Vec3, radius: f32, aim: Option<PhotonAim>, offset: Vec3) -> f32 {
    use std::f32::consts::PI;
    let in_disc = offset.length() <= radius;
    let Some(a) = aim.filter(|a| a.radius > 0.0) else {
        return if in_disc { 1.0 / (PI * radius * radius) } else { 0.0 };
    };
    let d = a.centre - centre;
    let towards = d - axis * d.dot(axis);
    let near = a.radius * NEAR_SCALE;
    let whole = 1.0 - AIM_FRACTION - NEAR_FRACTION;
    let from_aim = (offset - towards).length();
    (if from_aim <= a.radius { AIM_FRACTION / (PI * a.radius * a.radius) } else { 0.0 })
        + if from_aim <= near { NEAR_FRACTION / (PI * near * near) } else { 0.0 }
        + if in_disc { whole / (PI * radius * radius) } else { 0.0 }
}

/// A direction uniform within the cone of half-angle cos⁻¹(cos_max) about `axis` (pdf
/// 1/(2π(1 − cos_max))); `axis` itself where cos_max = 1. Mirrors `cone_direction` in WGSL.
pub fn cone_direction(axis: Vec3, cos_max: f32, u1: f32, u2: f32) -> Vec3 {
    let cos_t = 1.0 - u1 * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = orthonormal_basis(axis);
    (t * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + axis * cos_t).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Material};

    #[test]
    fn picks_in_proportion_to_power() {
        let cam = Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        let mut s = Scene::new(cam);
        let a = s.add_material(Material { emission: Vec3::ONE, ..Material::diffuse("a", Vec3::ZERO) });
        let b = s.add_material(Material { emission: Vec3::splat(3.0), ..Material::diffuse("b", Vec3::ZERO) });
        s.add_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], a);
        s.add_triangle([Vec3::ZERO, Vec3::X, Vec3::Y], b);
        let t = LightTable::new(&s);
        assert!((t.entries[0].pmf - 0.25).abs() < 1e-6 && (t.entries[1].pmf - 0.75).abs() < 1e-6);
        assert_eq!(t.pick(0.0).triangle, 0);
        assert_eq!(t.pick(0.2499).triangle, 0);
        assert_eq!(t.pick(0.25).triangle, 1);
        assert_eq!(t.pick(0.9999).triangle, 1);
    }

    #[test]
    fn aimed_sun_photons_carry_the_same_flux_onto_every_patch_and_crowd_into_the_aim() {
        // A sun at 35° over a ground 200 m across; photons aimed at a sphere of radius 5 m
        // about (3, 1.5, 2). Through any patch of ground, inside the aim, near it or far, the
        // flux of N photons must be E·cos θ·A (the plane's irradiance times the patch's area)
        // within 4 standard errors of the photons' own spread, aimed or not; and most aimed
        // photons cross the aim's patch.
        let cam = Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        let mut s = Scene::new(cam);
        let m = s.add_material(Material::diffuse("ground", Vec3::splat(0.5)));
        s.add_quad(
            [
                Vec3::new(-100.0, 0.0, -100.0),
                Vec3::new(-100.0, 0.0, 100.0),
                Vec3::new(100.0, 0.0, 100.0),
                Vec3::new(100.0, 0.0, -100.0),
            ],
            m,
        );
        let el = 35f32.to_radians();
        let towards = Vec3::new(0.3 * el.cos(), el.sin(), -(1.0 - 0.09f32).sqrt() * el.cos()).normalize();
        s.lights.push(Light::Distant { direction: -towards, irradiance: Vec3::splat(3.0), angular_radius: 0.0 });
        let table = LightTable::new(&s);
        let aim = PhotonAim { centre: Vec3::new(3.0, 1.5, 2.0), radius: 5.0 };
        let n = 1 << 20;
        // Patches in the aim, in its surroundings (the disc 4 × as wide) and far from both.
        let patches =
            [(Vec3::new(3.0, 0.0, 2.0), 2.0), (Vec3::new(14.0, 0.0, 2.0), 2.0), (Vec3::new(-60.0, 0.0, 40.0), 10.0)];
        for (patch, half) in patches {
            let expected = 3.0 * towards.y as f64 * (2.0 * half as f64).powi(2);
            for aimed in [None, Some(aim)] {
                let mut rng = crate::sampling::Rng::new(17, 0, 0);
                let (mut s1, mut s2, mut hits) = (0.0f64, 0.0f64, 0u32);
                for _ in 0..n {
                    let u = [(); 5].map(|_| rng.next_f32());
                    let (o, d, flux, _) = table.emit_photon(&s, |_, _, _| Vec3::ZERO, u, 0.0, aimed);
                    let x = o + d * (-o.y / d.y);
                    if (x - patch).abs().max_element() < half {
                        let f = flux.x as f64 / n as f64;
                        s1 += f;
                        s2 += f * f;
                        hits += 1;
                    }
                }
                // The sum's standard error: √(n·Var(X)) for X = f/n·[the photon crosses].
                let se = (s2 - s1 * s1 / n as f64).max(0.0).sqrt();
                println!(
                    "patch {patch} aimed {}: {s1:.4} against {expected:.4} (se {se:.4}, {hits} photons)",
                    aimed.is_some()
                );
                assert!(
                    (s1 - expected).abs() < 4.0 * se,
                    "patch {patch}, aimed {}: {s1} vs {expected}",
                    aimed.is_some()
                );
            }
        }
        // The aim's own patch (a 4 m square inside it): about α·(4²/(π·5²))/cos… of the aimed
        // photons, against 16/(π·R²)/… of the unaimed: many times more.
        let count = |aimed| {
            let mut rng = crate::sampling::Rng::new(3, 0, 0);
            (0..1 << 16)
                .filter(|_| {
                    let u = [(); 5].map(|_| rng.next_f32());
                    let (o, d, _, _) = table.emit_photon(&s, |_, _, _| Vec3::ZERO, u, 0.0, aimed);
                    let x = o + d * (-o.y / d.y);
                    (x - Vec3::new(3.0, 0.0, 2.0)).abs().max_element() < 2.0
                })
                .count()
        };
        let (plain, aimed) = (count(None), count(Some(aim)));
        println!("photons on the aim's patch: {plain} unaimed, {aimed} aimed of 65536");
        assert!(aimed > 100 * plain.max(1), "{aimed} vs {plain}");
    }
}
