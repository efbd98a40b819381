//! Direct pass: emitted radiance of the visible point plus direct light from the area
//! lights, with soft shadows from shadow rays traced against the BVH.
//!
//! For a visible point x with normal n and albedo ρ, each of the K light samples picks an
//! emitter point y with density p(y) = pmf(triangle)/area(triangle) and adds
//!
//! ```text
//!   (1/K) · (ρ/π) · Le(y) · V(x,y) · max(0, n·ω) · max(0, n_y·(−ω)) / |y − x|² / p(y)
//! ```
//!
//! (ω = (y − x)/|y − x|), an unbiased estimate of ∫ (ρ/π) Le cos θ_x cos θ_y / r² V dA.
//!
//! The light samples are quasi-random ([`light_sample_uniforms`]): pixel (x, y) has its own
//! Owen-scrambled Sobol' sequence (Burley 2020, [`sobol_owen_2d`]) with scramble seed
//! [`pixel_seed`]`(`[`light_sample_key`]`(seed), x, y)`, and sample k of iteration i is its
//! point of index b_i + k, b_i the light samples of the iterations before (i·L for L light samples
//! per iteration; [`crate::passes::light_budget`] chooses L as the render goes on). Every aligned block of 2^m
//! consecutive indices — the first 2^m samples of a pixel, in particular — is a (0, m, 2)-net,
//! so the pixel's samples stay stratified over the emitters as the image converges, instead of
//! clumping like independent ones. The seed does not depend on the restart: the light samples
//! of an image repeat after [`crate::renderer::Renderer::reset`]. Each pixel's own scramble
//! makes neighbouring pixels' errors independent (noise, not structured artefacts).
//!
//! Three numbers choose a light sample and a 2D point gives two; the point on the emitters
//! is what matters, so both coordinates go to it and the choice of the triangle reuses the
//! first one (sample reuse): x picks the triangle by its cdf interval [c₋, c₊) and
//! (x − c₋)/(c₊ − c₋), uniform in [0, 1) again, is the point's first coordinate on it. For a
//! light of triangles of equal power — the Cornell box's quad, two triangles — each triangle
//! then receives exactly its share of every aligned block of 2^m samples, which themselves
//! form a (0, m − 1, 2)-net on it. A second, independently scrambled point for the choice
//! would split the block between the triangles at random, losing the net on each.

use crate::gpu::Gpu;
use crate::gpu_scene::GpuScene;
use crate::lights::LightTable;
use crate::passes::film::Film;
use crate::passes::frame::FrameBinding;
use crate::passes::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, GroupThree, PixelPass, PixelShader};
use crate::sampling::{pcg_hash, pixel_seed, sobol_owen_2d, stream, unit_f32};

/// The key of the light samples' per-pixel scramble seeds for `seed` (no restart: a reset
/// replays them). `pcg_hash(frame.seed ^ STREAM_DIRECT)` in `direct.wgsl`.
pub fn light_sample_key(seed: u32) -> u32 {
    pcg_hash(seed ^ stream::DIRECT)
}

/// The position of the 32-bit fraction `a` (a / 2³²) inside the cdf interval [c₋, c₊) of
/// light entry `e` of `lights`, rescaled to [0, 1): `(a − c₋)/(c₊ − c₋)` computed on the
/// 32-bit offset, so it keeps 24 significant bits however small the interval. Mirrors
/// `remap_in_entry` in `gpu_scene.wgsl` (the same operations; the GPU's division may round
/// differently in the last bit).
pub fn remap_in_entry(a: u32, lights: &LightTable, e: usize) -> f32 {
    let lo = if e > 0 { lights.entries[e - 1].cdf } else { 0.0 };
    let offset = a.wrapping_sub((lo * 4_294_967_296.0) as u32);
    (offset as f32 / ((lights.entries[e].cdf - lo) * 4_294_967_296.0)).min(1.0 - f32::EPSILON / 2.0)
}

/// The light sample (u0, u1, u2) — u0 picks the light, (u1, u2) the point or direction on
/// it — of index j = i·L + k (iteration i, sample k) of pixel
/// (x, y) for `seed`: the Owen-scrambled Sobol' point (a, b) = [`sobol_owen_2d`]`(j, s)`
/// with s = [`pixel_seed`]`(`[`light_sample_key`]`(seed), x, y)`; u0 = a, u1 = a's position
/// in the picked entry's cdf interval ([`remap_in_entry`]), u2 = b. Mirrors
/// `light_sample_uniforms` in `gpu_scene.wgsl`, which returns the picked entry in place of u0
/// (its `LightChoice`, the argument of `sample_light_at`).
pub fn light_sample_uniforms(seed: u32, x: u32, y: u32, j: u32, lights: &LightTable) -> [f32; 3] {
    let [a, b] = sobol_owen_2d(j, pixel_seed(light_sample_key(seed), x, y));
    let u0 = unit_f32(a);
    let e = lights.entries.partition_point(|l| l.cdf <= u0).min(lights.entries.len() - 1);
    [u0, remap_in_entry(a, lights, e), unit_f32(b)]
}

/// The pass's composed shader.
pub fn source() -> String {
    crate::passes::per_pixel(&[
        GBUFFER_FILM_WGSL,
        DENSITY_UNGUIDED,
        crate::passes::sky_guide::UNGUIDED_WGSL,
        include_str!("direct.wgsl"),
    ])
}

/// The direct pass's shader where the photon map's guide buffer holds guides' tables: with
/// the map's group (3), so its environment samples are drawn from the guided sky
/// ([`crate::passes::sky_guide`]) and weighed against the guided gather's density
/// ([`crate::gather::guide`]).
pub fn source_with_map() -> String {
    crate::passes::per_pixel(&[
        GBUFFER_FILM_WGSL,
        &crate::photons::gpu::lookup_wgsl(),
        crate::gather::guide::WGSL,
        crate::gather::guide::DENSITY_WGSL,
        crate::passes::sky_guide::WGSL,
        DENSITY_GUIDED,
        include_str!("direct.wgsl"),
    ])
}

/// The gather's density of direction w at p that the environment's samples are weighed
/// against, without a guide.
const DENSITY_UNGUIDED: &str = "
fn direct_gather_density(p: VisiblePoint, w: vec3f) -> f32 {
    return gather_density(p, w);
}
";

/// The same with the gather guide: the density the guided gather drew its directions with at
/// p's cell, as its tables stood this iteration (the gather's own weighs its escapes with).
const DENSITY_GUIDED: &str = "
fn direct_gather_density(p: VisiblePoint, w: vec3f) -> f32 {
    if frame.gather_guided == 0u {
        return gather_density(p, w);
    }
    let e = gather_guide_entry(gather_guide_key(p.x.pos, p.ns), false);
    return guided_gather_density(p, e, gather_guide_total(e), w);
}
";

/// The direct pass. Reads: scene, frame, G-buffer. Adds to: the film's direct component.
pub fn pass(
    gpu: &Gpu,
    scene: &GpuScene,
    frame: &FrameBinding,
    (gbuffer, film): (&GBufferPass, &Film),
    map: Option<&crate::photons::gpu::GpuPhotonMap>,
) -> PixelPass {
    match map {
        Some(map) => {
            let shader = PixelShader { label: "direct", source: &source_with_map(), entry: "main" };
            PixelPass::new(gpu, (scene, frame), (gbuffer, film), shader, GroupThree::PhotonMap(map))
        }
        None => {
            let shader = PixelShader { label: "direct", source: &source(), entry: "main" };
            PixelPass::new(gpu, (scene, frame), (gbuffer, film), shader, GroupThree::None)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::tests::is_net;
    use crate::scene::cornell_box;

    /// A fraction in [0, 1) as a 32-bit fraction (exact for multiples of 2^−32).
    fn fraction(u: f32) -> u32 {
        (u as f64 * 4_294_967_296.0) as u32
    }

    #[test]
    fn a_pixels_light_samples_are_stratified_on_each_light_triangle() {
        // The Cornell box's light: one quad, two triangles of equal power.
        let lights = LightTable::new(&cornell_box());
        assert_eq!(lights.entries.len(), 2);
        for (seed, x, y) in [(0u32, 0u32, 0u32), (1, 64, 17), (0xdead_beef, 127, 127)] {
            for m in 1..=10u32 {
                // The first 2^m samples of the pixel, and a later aligned block (iterations
                // 3·2^m.. with L = 1, or any L dividing 2^m).
                for first in [0u32, 3 << m] {
                    let samples: Vec<[f32; 3]> =
                        (first..first + (1 << m)).map(|j| light_sample_uniforms(seed, x, y, j, &lights)).collect();
                    assert!(samples.iter().flatten().all(|u| (0.0..1.0).contains(u)));
                    for e in 0..2 {
                        let on_e: Vec<[u32; 2]> = samples
                            .iter()
                            .filter(|u| lights.entries.partition_point(|l| l.cdf <= u[0]) == e)
                            .map(|u| [fraction(u[1]), fraction(u[2])])
                            .collect();
                        // Exactly half the block on each triangle, as a (0, m − 1, 2)-net in
                        // the (u1, u2) that place the point on it.
                        assert_eq!(on_e.len(), 1 << (m - 1), "seed {seed} pixel ({x},{y}) block {first}: triangle {e}");
                        assert!(
                            is_net(&on_e, m - 1),
                            "seed {seed} pixel ({x},{y}) samples {first}.. (2^{m}): not a (0,{},2)-net on triangle {e}",
                            m - 1
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn light_samples_differ_between_pixels_and_seeds_but_not_restarts() {
        let lights = LightTable::new(&cornell_box());
        let u = |seed, x, y, j| light_sample_uniforms(seed, x, y, j, &lights);
        assert_ne!(u(0, 0, 0, 0), u(0, 1, 0, 0));
        assert_ne!(u(0, 0, 0, 0), u(0, 0, 1, 0));
        assert_ne!(u(0, 0, 0, 0), u(1, 0, 0, 0));
        // Nothing but (seed, pixel, index) enters: the same call gives the same sample.
        assert_eq!(u(5, 3, 4, 9), u(5, 3, 4, 9));
    }

    #[test]
    fn remapping_into_an_entry_is_uniform_and_keeps_small_intervals_precise() {
        // Entries of pmf ¼, ½, ¼: a in the second quarter maps linearly onto [0, 1).
        let mut lights = LightTable::default();
        for (cdf, pmf) in [(0.25f32, 0.25f32), (0.75, 0.5), (1.0, 0.25)] {
            lights.entries.push(crate::lights::LightEntry { triangle: 0, cdf, pmf, area: 1.0 });
        }
        assert_eq!(remap_in_entry(0, &lights, 0), 0.0);
        assert_eq!(remap_in_entry(1 << 30, &lights, 1), 0.0);
        assert_eq!(remap_in_entry(3 << 29, &lights, 1), 0.25);
        assert_eq!(remap_in_entry(u32::MAX, &lights, 2), 1.0 - f32::EPSILON / 2.0);
        // An interval of width 2^−20 holds 2^12 32-bit fractions, each a value of its own (a
        // 24-bit a would give them all 0).
        lights.entries = vec![
            crate::lights::LightEntry { triangle: 0, cdf: 0.5, pmf: 0.5, area: 1.0 },
            crate::lights::LightEntry { triangle: 1, cdf: 0.5 + 1.0 / 1_048_576.0, pmf: 1.0 / 1_048_576.0, area: 1.0 },
        ];
        let v: Vec<f32> = (0..1u32 << 12).map(|i| remap_in_entry((1 << 31) + i, &lights, 1)).collect();
        assert!(v.windows(2).all(|w| w[0] < w[1]) && v[0] == 0.0 && *v.last().unwrap() < 1.0);
    }
}
