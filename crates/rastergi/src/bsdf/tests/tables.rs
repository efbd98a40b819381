//! The albedo tables and the energy they restore: the committed GGX and glass tables against
//! quadratures of their lobes, and the compensated metal's white furnace.

use glam::Vec3;

use super::*;

/// Kulla & Conty's compensation: a white metal reflects all the light at every roughness and
/// angle, by the quadrature of `eval` (independent of sampling and of the lobe's own
/// normalisation, whose Ē is the table's); single scattering loses what E₁ says; a coloured
/// metal gains less than the white one's loss, and stays below 1.
#[test]
fn compensated_white_metal_reflects_everything_at_every_roughness() {
    let mut worst = 0.0f32;
    for r in [0.05f32, 0.1, 0.2, 0.3, 0.45, 0.6, 0.8, 1.0] {
        for theta in [0.0f32, 30.0, 60.0, 75.0, 85.0] {
            let wo = dir(theta, 30.0);
            // By sampling at every roughness; the quadrature (¼° steps) resolves the lobe from
            // roughness 0.3 on (at 0.2 it finds 0.97 of the lobe's own E₁ at normal incidence).
            let (s, se) = albedo_by_sampling(&metal(Vec3::ONE, r), wo, 100_000, Transport::Radiance);
            worst = worst.max((s.x - 1.0).abs());
            assert!((s.x - 1.0).abs() < 0.01 + 5.0 * se, "roughness {r}, θ {theta}°: white metal reflects {s} ± {se}");
            if r < 0.3 {
                continue;
            }
            let a = albedo_by_quadrature(&metal(Vec3::ONE, r), wo, Transport::Radiance).x;
            worst = worst.max((a - 1.0).abs());
            assert!((a - 1.0).abs() < 0.01, "roughness {r}, θ {theta}°: white metal reflects {a}");
            let single = Bsdf { multiple_scattering: false, ..metal(Vec3::ONE, r) };
            let a1 = albedo_by_quadrature(&single, wo, Transport::Radiance).x;
            let e1 = ggx_albedo().at(wo.z, r * r)[0];
            assert!((a1 - e1).abs() < 5e-3, "roughness {r}, θ {theta}°: single scattering {a1}, E₁ {e1}");
            let gold = Vec3::new(1.0, 0.78, 0.34);
            let c = albedo_by_quadrature(&metal(gold, r), wo, Transport::Radiance);
            let c1 =
                albedo_by_quadrature(&Bsdf { multiple_scattering: false, ..metal(gold, r) }, wo, Transport::Radiance);
            let gain = c - c1;
            assert!(gain.min_element() >= -1e-4 && (gain - Vec3::splat(1.0 - a1)).max_element() <= 5e-3, "{gain}");
            assert!(c.max_element() < 1.01, "gold reflects {c}");
        }
    }
    println!("white metal with compensation: albedo within {worst:.2e} of 1 at every roughness and angle");
}

#[test]
fn ggx_albedo_table_matches_a_quadrature_of_the_lobe() {
    // E₁ is the albedo of a white metal (Schlick's F = 1) and E₅ that of a black one (F =
    // (1 − ω_o·h)⁵): both computed here by the 1024² quadrature of `eval`, independently of
    // the table's VNDF integration, at angles and roughnesses between the table's cells.
    let mut worst = 0.0f32;
    for r in [0.35f32, 0.62, 0.87, 1.0] {
        for theta in [0.0f32, 37.0, 66.0, 83.0] {
            let wo = dir(theta, 10.0);
            let [e1, e5] = ggx_albedo().at(wo.z, r * r);
            let single = |c: Vec3| Bsdf { multiple_scattering: false, ..metal(c, r) };
            let q1 = albedo_by_quadrature(&single(Vec3::ONE), wo, Transport::Radiance).x;
            let q5 = albedo_by_quadrature(&single(Vec3::ZERO), wo, Transport::Radiance).x;
            worst = worst.max((e1 - q1).abs()).max((e5 - q5).abs());
            assert!(
                (e1 - q1).abs() < 4e-3 && (e5 - q5).abs() < 4e-3,
                "r {r}, θ {theta}°: ({e1}, {e5}) vs ({q1}, {q5})"
            );
        }
    }
    println!("GGX albedo table against the quadrature: largest difference {worst:.2e}");
    // The mean is the cosine-weighted mean of the interpolated table: 2∫E(μ)μ dμ.
    for alpha in [0.1f32, 0.5, 1.0] {
        let n = 20_000;
        let (mut m1, mut m5) = (0.0f64, 0.0f64);
        for k in 0..n {
            let mu = (k as f32 + 0.5) / n as f32;
            let [a, b] = ggx_albedo().at(mu, alpha);
            m1 += 2.0 * (a * mu) as f64 / n as f64;
            m5 += 2.0 * (b * mu) as f64 / n as f64;
        }
        let [t1, t5] = ggx_albedo().mean_at(alpha);
        assert!(
            (t1 as f64 - m1).abs() < 1e-4 && (t5 as f64 - m5).abs() < 1e-4,
            "α {alpha}: ({t1}, {t5}) vs ({m1}, {m5})"
        );
    }
}

/// ∫ f(ω_o, ω) |cos θ| dω by a midpoint rule in (θ, φ) with weight sin θ, 2048 × 512 cells:
/// uniform in θ, so a refracted lobe peaking at a pole is resolved (a rule in cos θ spaces its
/// points 3.6° apart there).
fn albedo_by_theta_quadrature(b: &Bsdf, wo: Vec3, transport: Transport) -> f64 {
    let (nt, np) = (2048, 512);
    let (dt, dp) = (PI / nt as f64, 2.0 * PI / np as f64);
    let rows: Vec<f64> = (0..nt)
        .into_par_iter()
        .map(|i| {
            let theta = (i as f64 + 0.5) * dt;
            let (st, ct) = theta.sin_cos();
            let mut sum = 0.0f64;
            for j in 0..np {
                let phi = (j as f64 + 0.5) * dp;
                let w = Vec3::new((st * phi.cos()) as f32, (st * phi.sin()) as f32, ct as f32);
                sum += b.eval(wo, w, transport).x as f64 * ct.abs() * st * dt * dp;
            }
            sum
        })
        .collect();
    rows.iter().sum()
}

/// The rough glass's single-scattering albedo table (VNDF integration) against the quadrature
/// of the single-scattering model's `eval` under importance transport, from outside and from
/// inside, at roughnesses, angles and indices between the table's cells.
#[test]
fn glass_albedo_table_matches_a_quadrature_of_the_lobe() {
    let mut worst = 0.0f32;
    for r in [0.45f32, 0.73, 1.0] {
        for eta in [1.33f32, 1.5, 2.4] {
            for theta in [0.0f32, 41.0, 72.0] {
                let single = Bsdf { multiple_scattering: false, ior: eta, ..glass(r, false) };
                for inside in [false, true] {
                    let wo = dir(theta, 15.0) * if inside { -1.0 } else { 1.0 };
                    let q = albedo_by_theta_quadrature(&single, wo, Transport::Importance) as f32;
                    let t = albedo::glass_albedo().at(wo.z.abs(), r * r, eta, inside);
                    worst = worst.max((q - t).abs());
                    assert!(
                        (q - t).abs() < 5e-3,
                        "r {r}, η {eta}, θ {theta}°, inside {inside}: table {t}, quadrature {q}"
                    );
                }
            }
        }
    }
    println!("glass albedo table against the quadrature: largest difference {worst:.2e}");
}

/// The committed glass table holds what its integral gives: 64 cells spread over the table
/// (both sides, every η row), integrated again.
#[test]
fn the_committed_glass_table_is_what_the_integral_gives() {
    let table = albedo::glass_albedo();
    let mut rng = Rng::new(5, 6, 7);
    for _ in 0..64 {
        let k = (rng.next_f32() * albedo::GLASS_CELLS as f32) as usize % albedo::GLASS_CELLS;
        let e = albedo::glass_cell(k);
        assert!((table.e[k] - e).abs() <= 1e-6, "cell {k}: committed {}, integrated {e}", table.e[k]);
    }
}

#[test]
fn the_committed_ggx_table_is_what_the_integral_gives() {
    let table = albedo::ggx_albedo();
    let integrated = albedo::GgxAlbedo::compute();
    for (k, (c, e)) in table.e.iter().zip(&integrated.e).enumerate() {
        for i in 0..2 {
            assert!((c[i] - e[i]).abs() <= 1e-6, "cell {k}: committed {c:?}, integrated {e:?}");
        }
    }
    for (j, (c, e)) in table.mean.iter().zip(&integrated.mean).enumerate() {
        assert_eq!(c, e, "the cosine-weighted mean at √α cell {j}");
    }
}
