//! The BSDF against independent computations: sampled directions against the density by a
//! chi-square test (as pbrt and Mitsuba test theirs), the mean sample weight against a
//! quadrature of f·|cos θ| (sampling agrees with evaluation), reciprocity, the white furnace
//! and the closed forms of the Fresnel terms.

use std::f64::consts::PI;

use glam::Vec3;
use rayon::prelude::*;

use super::*;
use crate::sampling::Rng;

mod closed_forms;
mod tables;

fn dir(theta_deg: f32, phi_deg: f32) -> Vec3 {
    let (t, p) = (theta_deg.to_radians(), phi_deg.to_radians());
    Vec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
}

fn metal(base: Vec3, roughness: f32) -> Bsdf {
    Bsdf { metallic: 1.0, alpha: roughness * roughness, specular: 1.0, ..Bsdf::diffuse(base) }
}

fn plastic(base: Vec3, roughness: f32) -> Bsdf {
    Bsdf { alpha: roughness * roughness, specular: 1.0, ..Bsdf::diffuse(base) }
}

/// A layer tinted by `KHR_materials_specular`'s colour (3, 1, 0.25) at weight 0.8, η 1.5:
/// F₀ = min(0.04·colour, 1) = (0.12, 0.04, 0.01).
fn tinted_plastic(base: Vec3, roughness: f32) -> Bsdf {
    Bsdf { specular: 0.8, specular_color: Vec3::new(3.0, 1.0, 0.25), ..plastic(base, roughness) }
}

/// `b` under a clear coat of weight k and roughness r (α = r²).
fn coated(b: Bsdf, k: f32, roughness: f32) -> Bsdf {
    Bsdf { clearcoat: k, clearcoat_alpha: roughness * roughness, ..b }
}

fn glass(roughness: f32, thin: bool) -> Bsdf {
    Bsdf { transmission: 1.0, alpha: roughness * roughness, specular: 1.0, thin, ..Bsdf::diffuse(Vec3::ONE) }
}

/// Bins of the sphere: cos θ uniform in [−1, 1] (equal solid angles) × φ.
const COS_BINS: usize = 24;
const PHI_BINS: usize = 48;
const SUB: usize = 16;

fn bin_of(w: Vec3) -> usize {
    let c = ((w.z.clamp(-1.0, 1.0) + 1.0) * 0.5 * COS_BINS as f32).min(COS_BINS as f32 - 1.0) as usize;
    let phi = (w.y as f64).atan2(w.x as f64).rem_euclid(2.0 * PI);
    let p = ((phi / (2.0 * PI) * PHI_BINS as f64) as usize).min(PHI_BINS - 1);
    c * PHI_BINS + p
}

/// ∫ over each bin of the density, by a midpoint rule in (θ, φ) with weight sin θ, steps of
/// at most ¼° in θ and SUB per bin in φ (a rule in cos θ puts too few points near the poles,
/// where a refracted lobe, a third as wide as its microfacets' spread, peaks).
fn expected_fractions(b: &Bsdf, wo: Vec3) -> Vec<f64> {
    let dp = 2.0 * PI / (PHI_BINS * SUB) as f64;
    let mut e = vec![0.0f64; COS_BINS * PHI_BINS];
    for c in 0..COS_BINS {
        let cos_lo = -1.0 + 2.0 * c as f64 / COS_BINS as f64;
        let cos_hi = -1.0 + 2.0 * (c + 1) as f64 / COS_BINS as f64;
        let (t0, t1) = (cos_hi.clamp(-1.0, 1.0).acos(), cos_lo.clamp(-1.0, 1.0).acos());
        let steps = (((t1 - t0) / 0.25f64.to_radians()).ceil() as usize).max(SUB);
        let dt = (t1 - t0) / steps as f64;
        for i in 0..steps {
            let theta = t0 + (i as f64 + 0.5) * dt;
            let (st, ct) = theta.sin_cos();
            for j in 0..PHI_BINS * SUB {
                let phi = (j as f64 + 0.5) * dp;
                let w = Vec3::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, ct as f32);
                e[c * PHI_BINS + j / SUB] += b.pdf(wo, w) as f64 * st * dt * dp;
            }
        }
    }
    e
}

/// 1 − the chi-square distribution's cdf at x for k degrees of freedom (Wilson–Hilferty's
/// normal approximation, good to 10⁻³ in p for k ≥ 30).
fn chi2_p_value(x: f64, k: usize) -> f64 {
    let k = k as f64;
    let z = ((x / k).powf(1.0 / 3.0) - (1.0 - 2.0 / (9.0 * k))) / (2.0 / (9.0 * k)).sqrt();
    0.5 * erfc(z / std::f64::consts::SQRT_2)
}

/// The complementary error function (Numerical Recipes' erfcc, relative error < 1.2·10⁻⁷).
fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 { r } else { 2.0 - r }
}

/// Pearson's test of N sampled directions (non-specular samples; specular ones and failures
/// pooled into one more cell, whose expectation is 1 − ∫pdf) against the density; bins
/// expecting fewer than 5 samples are pooled too. Returns the p-value.
fn chi_square(b: &Bsdf, wo: Vec3, n: usize, seed: u32) -> f64 {
    let expected: Vec<f64> = expected_fractions(b, wo).iter().map(|f| f * n as f64).collect();
    // CHUNKS independent streams on the cores, counted in a fixed order.
    let counts: Vec<(Vec<f64>, f64)> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let mut observed = vec![0.0f64; expected.len()];
            let mut rng = Rng::new(seed, 7, 11 + c as u32);
            let mut outside = 0.0;
            for _ in 0..chunk_len(n, c) {
                let u = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
                match b.sample(wo, u, Transport::Radiance) {
                    Some(s) if !s.delta => observed[bin_of(s.wi)] += 1.0,
                    _ => outside += 1.0,
                }
            }
            (observed, outside)
        })
        .collect();
    let mut observed = vec![0.0f64; expected.len()];
    let mut outside = 0.0;
    for (o, out) in counts {
        observed.iter_mut().zip(o).for_each(|(a, b)| *a += b);
        outside += out;
    }
    let mut cells = vec![(n as f64 - expected.iter().sum::<f64>(), outside)];
    let (mut pooled_e, mut pooled_o) = (0.0, 0.0);
    for (e, o) in expected.iter().zip(&observed) {
        if *e < 5.0 {
            pooled_e += e;
            pooled_o += o;
        } else {
            cells.push((*e, *o));
        }
    }
    cells.push((pooled_e, pooled_o));
    let cells: Vec<(f64, f64)> = cells.into_iter().filter(|&(e, o)| e >= 5.0 || o > 0.0).collect();
    let chi2: f64 = cells.iter().map(|&(e, o)| (o - e) * (o - e) / e.max(1e-9)).sum();
    chi2_p_value(chi2, cells.len() - 1)
}

/// The materials and outgoing directions every statistical test runs on.
fn cases() -> Vec<(&'static str, Bsdf, Vec3)> {
    let c = Vec3::new(0.9, 0.6, 0.3);
    let mut v = vec![];
    for (name, b) in [
        ("diffuse", Bsdf::diffuse(c)),
        ("metal 0.5", metal(c, 0.5)),
        ("metal 0.8", metal(c, 0.8)),
        ("plastic 0.6", plastic(c, 0.6)),
        ("mix", Bsdf { metallic: 0.5, ..plastic(c, 0.7) }),
        ("glass 0.6", glass(0.6, false)),
        ("glass 0.8", glass(0.8, false)),
        ("thin glass 0.6", glass(0.6, true)),
        ("half glass", Bsdf { transmission: 0.5, ..plastic(c, 0.7) }),
        ("smooth plastic", plastic(c, 0.0)),
        ("tinted plastic", tinted_plastic(c, 0.5)),
        ("coated plastic", coated(plastic(c, 0.6), 0.8, 0.3)),
        ("coated metal", coated(metal(c, 0.5), 1.0, 0.2)),
        ("coated glass", coated(glass(0.6, false), 0.5, 0.4)),
        ("smooth coat over diffuse", coated(Bsdf::diffuse(c), 1.0, 0.0)),
    ] {
        for wo in [dir(10.0, 30.0), dir(60.0, 200.0), dir(150.0, 80.0)] {
            v.push((name, b, wo));
        }
    }
    v
}

#[test]
fn sampled_directions_follow_the_density() {
    // 18 + 12 cases at a 10⁻⁴ threshold: a false alarm with probability 0.3 %.
    for (k, (name, b, wo)) in cases().into_iter().enumerate() {
        let p = chi_square(&b, wo, 400_000, k as u32);
        assert!(p > 1e-4, "{name}, ω_o = {wo}: chi-square p-value {p:.2e}");
    }
}

/// The statistical tests' samples are drawn in this many independent streams, on every core.
const CHUNKS: usize = 16;

/// Samples in chunk `c` of `n` split into [`CHUNKS`].
fn chunk_len(n: usize, c: usize) -> usize {
    n / CHUNKS + usize::from(c < n % CHUNKS)
}

/// ∫ f(ω_o, ω) |cos θ| dω by a midpoint rule over (cos θ, φ), 1024 × 1024 cells, plus the
/// specular lobes' reflectance given separately (Dirac deltas have no density to integrate).
/// Rows of cos θ on the cores, summed in order.
fn albedo_by_quadrature(b: &Bsdf, wo: Vec3, transport: Transport) -> Vec3 {
    let n = 1024;
    let (dc, dp) = (2.0 / n as f64, 2.0 * PI / n as f64);
    let rows: Vec<[f64; 3]> = (0..n)
        .into_par_iter()
        .map(|i| {
            let c = -1.0 + (i as f64 + 0.5) * dc;
            let s = (1.0 - c * c).sqrt();
            let mut sum = [0.0f64; 3];
            for j in 0..n {
                let phi = (j as f64 + 0.5) * dp;
                let w = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, c as f32);
                let f = b.eval(wo, w, transport) * c.abs() as f32;
                for k in 0..3 {
                    sum[k] += f[k] as f64 * dc * dp;
                }
            }
            sum
        })
        .collect();
    let sum = rows.iter().fold([0.0f64; 3], |a, r| [a[0] + r[0], a[1] + r[1], a[2] + r[2]]);
    Vec3::new(sum[0] as f32, sum[1] as f32, sum[2] as f32)
}

/// What a surface sends towards ω_o (radiance transport) where the light is in equilibrium,
/// relative to that equilibrium: uniform radiance L·η² on each side of a solid glass (1 above,
/// η below), so each sample's weight × (η(ω_i)/η(ω_o))². 1 for a lossless model; the mean over
/// `n` samples and its standard error (largest channel).
fn equilibrium_albedo(b: &Bsdf, wo: Vec3, n: usize) -> (Vec3, f32) {
    let eta = |w: Vec3| if b.transmission > 0.0 && !b.thin && w.z < 0.0 { b.ior } else { 1.0 };
    let mut rng = Rng::new(3, 5, 7);
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        let u = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
        if let Some(s) = b.sample(wo, u, Transport::Radiance) {
            let w = (s.weight.x * (eta(s.wi) / eta(wo)).powi(2)) as f64;
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    let se = ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt();
    (Vec3::splat(mean as f32), se as f32)
}

/// E[weight] over `n` samples and its standard error (per channel, the largest).
fn albedo_by_sampling(b: &Bsdf, wo: Vec3, n: usize, transport: Transport) -> (Vec3, f32) {
    let chunks: Vec<([f64; 3], [f64; 3])> = (0..CHUNKS)
        .into_par_iter()
        .map(|c| {
            let mut rng = Rng::new(3, 5, 7 + c as u32);
            let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
            for _ in 0..chunk_len(n, c) {
                let u = [rng.next_f32(), rng.next_f32(), rng.next_f32()];
                if let Some(s) = b.sample(wo, u, transport) {
                    for k in 0..3 {
                        sum[k] += s.weight[k] as f64;
                        sum2[k] += (s.weight[k] as f64).powi(2);
                    }
                }
            }
            (sum, sum2)
        })
        .collect();
    let (mut sum, mut sum2) = ([0.0f64; 3], [0.0f64; 3]);
    for (s, s2) in chunks {
        for k in 0..3 {
            sum[k] += s[k];
            sum2[k] += s2[k];
        }
    }
    let mean = sum.map(|s| s / n as f64);
    let se = (0..3).map(|k| ((sum2[k] / n as f64 - mean[k] * mean[k]).max(0.0) / n as f64).sqrt()).fold(0.0, f64::max);
    (Vec3::new(mean[0] as f32, mean[1] as f32, mean[2] as f32), se as f32)
}

#[test]
fn sampling_agrees_with_evaluation() {
    // The rough cases (no specular lobe): the mean sample weight estimates ∫ f |cos| dω,
    // which the quadrature of `eval` computes independently of `sample` and `pdf`.
    for (name, b, wo) in cases().into_iter().filter(|(n, ..)| !n.starts_with("smooth")) {
        for transport in [Transport::Radiance, Transport::Importance] {
            let q = albedo_by_quadrature(&b, wo, transport);
            let (s, se) = albedo_by_sampling(&b, wo, 400_000, transport);
            let tol = 5.0 * se + 2e-3 * q.max_element();
            assert!(
                (q - s).abs().max_element() < tol,
                "{name}, ω_o = {wo}, {transport:?}: quadrature {q}, sampling {s} ± {se}"
            );
        }
    }
}

#[test]
fn reflection_is_reciprocal_and_refraction_obeys_the_eta_squared_rule() {
    let mut rng = Rng::new(9, 9, 9);
    for (name, b, _) in cases() {
        for _ in 0..2000 {
            let a = crate::sampling::uniform_sphere(rng.next_f32(), rng.next_f32());
            let c = crate::sampling::uniform_sphere(rng.next_f32(), rng.next_f32());
            // Within 2° of the critical angle on the microfacet, the Fresnel term's slope is
            // unbounded and f32 cannot resolve it: skip those pairs of a solid.
            if b.transmission > 0.0 && !b.thin && a.z * c.z < 0.0 {
                let h = (if a.z > 0.0 { c * b.ior + a } else { a * b.ior + c }).normalize();
                if h.dot(a).abs().min(h.dot(c).abs()) < 2f32.to_radians().sin() {
                    continue;
                }
            }
            // f(a → c) η(c)² = f(c → a) η(a)², η(w) the index on w's side: 1 above, η below for
            // a solid (reflection and thin slabs: both 1).
            let eta = |w: Vec3| if b.transmission > 0.0 && !b.thin && w.z < 0.0 { b.ior } else { 1.0 };
            // A coat scales the model under it by its albedo towards the viewer alone, and rough
            // glass's compensation by the incident direction's albedo (module docs): not
            // reciprocal, only the adjoint below holds; their single-scattering models are.
            let r = if b.clearcoat == 0.0 && !b.glass_compensates() {
                b
            } else {
                Bsdf { clearcoat: 0.0, multiple_scattering: false, ..b }
            };
            let lhs = r.eval(a, c, Transport::Radiance) * eta(c).powi(2);
            let rhs = r.eval(c, a, Transport::Radiance) * eta(a).powi(2);
            let scale = lhs.max_element().max(rhs.max_element()).max(1e-3);
            assert!((lhs - rhs).abs().max_element() < 2e-3 * scale, "{name}: f({a} → {c}) = {lhs}, reversed {rhs}");
            let lhs = b.eval(a, c, Transport::Radiance);
            let scale = lhs.max_element().max(b.eval(c, a, Transport::Radiance).max_element()).max(1e-3);
            // Importance transport's BTDF is the adjoint: f*(a → c) = f(c → a).
            let adj = b.eval(a, c, Transport::Importance);
            let rev = b.eval(c, a, Transport::Radiance);
            assert!(
                (adj - rev).abs().max_element() < 2e-3 * scale.max(rev.max_element()),
                "{name}: adjoint {adj} vs {rev}"
            );
        }
    }
}

#[test]
fn white_furnace() {
    let white = Vec3::ONE;
    let mut rows = vec![];
    for theta in [0.0f32, 45.0, 80.0] {
        let wo = dir(theta, 20.0);
        let albedo = |b: Bsdf| albedo_by_sampling(&b, wo, 200_000, Transport::Importance);
        // Lossless lobes: a white diffuse surface, a white mirror, smooth glass (R + T from
        // either side) and a thin slab reflect or pass all the energy.
        for (name, b) in [
            ("diffuse", Bsdf::diffuse(white)),
            ("mirror", metal(white, 0.0)),
            ("smooth specular layer over diffuse", plastic(white, 0.0)),
            ("glass", glass(0.0, false)),
            ("thin glass", glass(0.0, true)),
            // Half glass, half a smooth layer over white: each half lossless, weighted by its
            // share (the glass's delta lobes carry (1 − m)·t of the energy, not 1 − m).
            ("half smooth glass", Bsdf { transmission: 0.5, ..plastic(white, 0.0) }),
            ("half smooth thin glass", Bsdf { transmission: 0.5, thin: true, ..plastic(white, 0.0) }),
        ] {
            for w in [wo, -wo] {
                let (a, se) = albedo_by_sampling(&b, w, 200_000, Transport::Importance);
                assert!((a - Vec3::ONE).abs().max_element() < 5.0 * se + 1e-4, "{name} at {theta}°: albedo {a} ± {se}");
            }
        }
        // Single scattering loses energy to the bounces between microfacets and gains none;
        // the metal's and the glass's compensations give it back
        // (compensated_white_metal_reflects_everything): glass of either index, from outside
        // and from inside (total internal reflection included), solid and thin, sends the
        // equilibrium radiance of uniform light.
        for r in [0.3f32, 0.6, 1.0] {
            let (m, se) = albedo(metal(white, r));
            let (single, se_1) = albedo(Bsdf { multiple_scattering: false, ..metal(white, r) });
            let mut glass_row = String::new();
            for (label, b) in
                [("", glass(r, false)), (" η 1.33", Bsdf { ior: 1.33, ..glass(r, false) }), (" thin", glass(r, true))]
            {
                for (side, w) in [("out", wo), ("in", -wo)] {
                    let (g, se_g) = equilibrium_albedo(&b, w, 200_000);
                    let (g1, se_g1) = equilibrium_albedo(&Bsdf { multiple_scattering: false, ..b }, w, 200_000);
                    glass_row += &format!(", glass{label} {side} {:.4} ({:.4})", g.x, g1.x);
                    assert!(
                        (g - Vec3::ONE).abs().max_element() < 0.01 + 5.0 * se_g,
                        "glass{label} r {r} at {theta}° {side}: {g} ± {se_g}"
                    );
                    assert!(g1.max_element() < 1.0 + 5.0 * se_g1, "single-scattering glass{label}: {g1}");
                }
            }
            rows.push(format!(
                "θ {theta:>2}°, roughness {r}: metal {:.4} (single scattering {:.4}){glass_row}",
                m.x, single.x
            ));
            assert!((m - Vec3::ONE).abs().max_element() < 0.01 + 5.0 * se, "metal r {r} at {theta}°: {m} ± {se}");
            assert!(single.max_element() < 1.0 + 5.0 * se_1);
            // A mix is the mix of its lobes' albedos (each lobe weighted as the model says).
            let (mix, se_mix) = albedo(Bsdf { metallic: 0.3, ..metal(white, r) });
            let (d, _) = albedo(Bsdf::diffuse(white));
            let (layer, _) = albedo(plastic(white, r));
            let want = 0.3 * m + 0.7 * layer;
            assert!((mix - want).abs().max_element() < 5.0 * (se_mix + se) + 2e-3, "mix {mix} vs {want}");
            // A rough specular layer over a white diffuse base conserves energy: the base takes
            // what the layer does not reflect (diffuse_share), at every roughness.
            rows.push(format!("θ {theta:>2}°, roughness {r}: specular layer over white diffuse {:.4}", layer.x));
            assert!((layer - d).abs().max_element() < 0.01, "layer {layer} vs diffuse {d}");
        }
        // A clear coat over white models reflects k·E_k(μ_o) towards the viewer and leaves
        // them the rest: under uniform light (radiance transport: the coat scales by the
        // viewer's direction, module docs) 1 in all, at every roughness of the coat and of the
        // model under it; smooth (k·F_k by its delta lobe), exactly.
        let radiance = |b: Bsdf| albedo_by_sampling(&b, wo, 200_000, Transport::Radiance);
        for (name, b) in [("diffuse", Bsdf::diffuse(white)), ("mirror", metal(white, 0.0))] {
            let (a, se) = radiance(coated(b, 0.7, 0.0));
            assert!(
                (a - Vec3::ONE).abs().max_element() < 5.0 * se + 1e-4,
                "smooth coat over {name} at {theta}°: {a} ± {se}"
            );
        }
        for r in [0.05f32, 0.1, 0.2, 0.45, 0.8] {
            for (name, b) in [
                ("diffuse", Bsdf::diffuse(white)),
                ("metal 0.5", metal(white, 0.5)),
                ("plastic 0.3", plastic(white, 0.3)),
                ("mirror", metal(white, 0.0)),
            ] {
                let (a, se) = radiance(coated(b, 1.0, r));
                rows.push(format!("θ {theta:>2}°, coat roughness {r}: over white {name} {:.4}", a.x));
                assert!(
                    (a - Vec3::ONE).abs().max_element() < 0.01 + 3.0 * se,
                    "coat r {r} over {name} at {theta}°: {a} ± {se}"
                );
            }
            let (layer, se) = albedo(plastic(white, r));
            assert!(
                (layer - Vec3::ONE).abs().max_element() < 0.01 + 3.0 * se,
                "layer r {r} at {theta}°: {layer} ± {se}"
            );
            // A tinted layer (KHR_materials_specular's colour; F₀ of one channel clamped at 1)
            // over white conserves energy channel by channel too.
            let (tinted, se) = albedo(tinted_plastic(white, r));
            assert!(
                (tinted - Vec3::ONE).abs().max_element() < 0.01 + 3.0 * se,
                "tinted layer r {r} at {theta}°: {tinted} ± {se}"
            );
        }
    }
    println!(
        "white furnace (GGX metal compensated, glass single scattering; the layer energy-conserving):\n{}",
        rows.join("\n")
    );
}
