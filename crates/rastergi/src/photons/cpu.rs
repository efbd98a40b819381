//! The CPU twin of the photon tracer: the same photons, the same map, in f64 with rayon.
//! Reference in tests, baseline in `rastergi bench photons`.

use super::{MAX_BOUNCES, PhotonSettings, STREAM_PHOTON};
use crate::bsdf::{Frame, Transport};
use crate::par::prelude::*;
use crate::photons::map::{GridSpec, MapLayout, PhotonMap};
use crate::sampling::{Rng, bend_towards, pcg_hash};
use crate::scene::triangle_normal;
use crate::surface::{PreparedScene, alpha_uniform};

/// Flux deposited per slot, with the squares and counts used for noise estimates.
pub struct Tally {
    pub flux: Vec<[f64; 3]>,
    pub flux_sq: Vec<f64>,
    pub deposits: Vec<u32>,
    /// Deposits that found no slot ([`MapLayout::deposit_slot`]).
    pub dropped: u64,
}

impl Tally {
    fn new(n: usize) -> Self {
        Self { flux: vec![[0.0; 3]; n], flux_sq: vec![0.0; n], deposits: vec![0; n], dropped: 0 }
    }

    fn merge(mut self, o: Tally) -> Tally {
        for i in 0..self.flux.len() {
            for c in 0..3 {
                self.flux[i][c] += o.flux[i][c];
            }
            self.flux_sq[i] += o.flux_sq[i];
            self.deposits[i] += o.deposits[i];
        }
        self.dropped += o.dropped;
        self
    }
}

/// Traces `settings.count` photons (pass 0) on all CPU cores into a photon map over `grid`.
pub fn trace(prepared: &PreparedScene, grid: &GridSpec, settings: &PhotonSettings) -> PhotonMap {
    trace_pass(prepared, grid, settings, 0)
}

/// [`trace`] with the photons of `pass` (the stream (seed ⊕ photon stream, index, pass)).
pub fn trace_pass(prepared: &PreparedScene, grid: &GridSpec, settings: &PhotonSettings, pass: u32) -> PhotonMap {
    let layout = MapLayout::new(&prepared.scene, grid);
    let tally = trace_flux(prepared, &layout, settings, pass);
    PhotonMap { layout, flux: tally.flux, flux_sq: tally.flux_sq, deposits: tally.deposits, dropped: tally.dropped }
}

/// The photon tracing alone into the slots of `layout` (what `rastergi bench photons` times).
pub fn trace_flux(prepared: &PreparedScene, layout: &MapLayout, settings: &PhotonSettings, pass: u32) -> Tally {
    trace_flux_guided(prepared, layout, settings, pass, None)
}

/// [`trace_flux`] with the sun's and the sky's photons started as `guide`'s tables say
/// ([`crate::photons::guide`]), as the GPU tracer starts them with the same tables.
pub fn trace_flux_guided(
    prepared: &PreparedScene,
    layout: &MapLayout,
    settings: &PhotonSettings,
    pass: u32,
    guide: Option<&crate::photons::guide::GuideTable>,
) -> Tally {
    let slots = layout.table.capacity();
    if prepared.lights.is_empty() || settings.count == 0 {
        return Tally::new(slots);
    }
    const CHUNK: u32 = 4096;
    let chunks = settings.count.div_ceil(CHUNK);
    (0..chunks)
        .into_par_iter()
        .with_min_len(16)
        .fold(
            || Tally::new(slots),
            |mut t, chunk| {
                for i in chunk * CHUNK..((chunk + 1) * CHUNK).min(settings.count) {
                    trace_photon(prepared, layout, settings, guide, (i, pass), &mut t);
                }
                t
            },
        )
        .reduce(|| Tally::new(slots), Tally::merge)
}

/// One photon's path (`trace_photon` in `trace.wgsl`, draw for draw).
fn trace_photon(
    prepared: &PreparedScene,
    layout: &MapLayout,
    settings: &PhotonSettings,
    guide: Option<&crate::photons::guide::GuideTable>,
    (index, pass): (u32, u32),
    t: &mut Tally,
) {
    let scene = &prepared.scene;
    let eps = prepared.ray_epsilon();
    let alpha_seed = pcg_hash(settings.seed ^ STREAM_PHOTON ^ pcg_hash(pass));
    let mut rng = Rng::new(settings.seed ^ STREAM_PHOTON, index, pass);
    let u = [(); 5].map(|_| rng.next_f32());
    let emitted = |t, b1, b2| prepared.emitter_radiance(t, b1, b2);
    let (mut origin, mut dir, flux, emitter, _) =
        prepared.lights.emit_photon_guided(scene, emitted, u, eps, settings.aim(), guide);
    let mut flux = flux / settings.count as f32;
    let mut skip = emitter.unwrap_or(u32::MAX);
    let first_deposit = settings.sampled_direct.skips_first(prepared.lights.pick(u[0]).triangle) as u32;
    // Every scattering so far was a specular (delta) one, and there was one.
    let mut caustic = false;
    // Whether the photon's one aimed bounce (super::lambertian_bounce) is still to come.
    let mut aim_bounce = true;
    let aim = settings.aim();
    for bounce in 0..MAX_BOUNCES {
        let solid = |h: &crate::bvh::Hit| {
            let u = alpha_uniform(h.triangle, h.b1, h.b2, alpha_seed);
            !prepared.passes_through(h.triangle as usize, h.b1, h.b2, u)
        };
        let Some(hit) = prepared.bvh.intersect(&scene.triangles, origin, dir, eps, f32::INFINITY, skip, solid) else {
            break;
        };
        let tri = &scene.triangles[hit.triangle as usize];
        let material = scene.material_of(hit.triangle as usize);
        let n = triangle_normal(tri);
        flux *= material.segment_transmittance(dir, n, hit.t);
        let front = n.dot(dir) < 0.0;
        // Glass is entered and left by either face (the transmission at the point: its
        // factor × transmissionTexture, as surface_at reads it).
        if !front
            && !material.two_sided
            && (material.transmission <= 0.0
                || material.transmission_texture.is_some()
                    && prepared.bsdf_at(hit.triangle as usize, hit.b1, hit.b2, 0.0).transmission <= 0.0)
        {
            break;
        }
        let n = if front { n } else { -n };
        let p = tri[0] * (1.0 - hit.b1 - hit.b2) + tri[1] * hit.b1 + tri[2] * hit.b2;
        let shading = prepared.shading_normal_at(hit.triangle as usize, hit.b1, hit.b2);
        let ns = bend_towards(if front { shading } else { -shading }, -dir);
        let arrive = (-dir).dot(ns) / (-dir).dot(n);
        if bounce >= first_deposit {
            let deposit = flux * arrive;
            match layout.deposit_slot(hit.triangle as usize, !front, p) {
                Some(slot) => {
                    for c in 0..3 {
                        t.flux[slot][c] += deposit[c] as f64;
                    }
                    t.flux_sq[slot] += (deposit.y as f64).powi(2);
                    t.deposits[slot] += 1;
                }
                None => t.dropped += 1,
            }
        }
        // A photon that came through specular surfaces alone adds to the caustic map too.
        if caustic
            && let Some(slot) =
                layout.deposit_slot(hit.triangle as usize, !front, p).and_then(|s| layout.caustic_twin(s))
        {
            let deposit = flux * arrive;
            for c in 0..3 {
                t.flux[slot][c] += deposit[c] as f64;
            }
            t.flux_sq[slot] += (deposit.y as f64).powi(2);
            t.deposits[slot] += 1;
        }
        let mut below = false;
        if material.is_lambertian() {
            let albedo = prepared.albedo_at(hit.triangle as usize, hit.b1, hit.b2, 0.0);
            let survive = albedo.max_element();
            if rng.next_f32() >= survive {
                break;
            }
            flux *= albedo / survive;
            let (u1, u2) = (rng.next_f32(), rng.next_f32());
            let outside =
                aim.as_ref().is_some_and(|a| a.radius > 0.0 && (a.centre - p).length_squared() > a.radius * a.radius);
            let (d, factor) = super::lambertian_bounce(p, ns, aim.as_ref().filter(|_| aim_bounce && outside), u1, u2);
            aim_bounce &= !outside;
            dir = d;
            let (cos_s, cos_g) = (dir.dot(ns), dir.dot(n));
            if cos_g <= 0.0 || cos_s <= 0.0 || factor <= 0.0 {
                break;
            }
            flux *= arrive * (cos_g / cos_s) * factor;
            caustic = false;
        } else {
            // trace.wgsl: a direction from the BSDF, then roulette by its weight.
            let frame = Frame::new(ns);
            let mut b = prepared.bsdf_at(hit.triangle as usize, hit.b1, hit.b2, 0.0);
            if !front && !b.thin {
                b.ior = 1.0 / b.ior;
            }
            let v = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
            let sample = b.sample(frame.to_local(-dir), v, Transport::Importance);
            let u_rr = rng.next_f32();
            let Some(bs) = sample else { break };
            let wi = frame.to_world(bs.wi).normalize();
            let cos_g = wi.dot(n);
            below = cos_g < 0.0;
            if (bs.wi.z < 0.0) != below || cos_g == 0.0 || bs.wi.z == 0.0 {
                break;
            }
            let w = bs.weight * (arrive * (cos_g / bs.wi.z).abs());
            let survive = w.max_element().min(1.0);
            if u_rr >= survive {
                break;
            }
            flux *= w / survive;
            dir = wi;
            // trace.wgsl: caustic light only through surfaces the gather's rays pass.
            caustic = bs.delta && b.passes_rays() && (caustic || bounce == 0);
        }
        origin = p + if below { -n } else { n } * eps;
        skip = hit.triangle;
    }
}
