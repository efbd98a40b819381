//! Closed forms: the Fresnel terms, Snell's law and the η² scaling of radiance, the Lambertian
//! model and part, the tinted layer and the clear coat at normal incidence.

use glam::Vec3;

use super::*;

#[test]
fn fresnel_terms_match_their_closed_forms() {
    // Normal incidence: ((η − 1)/(η + 1))² = 0.04 for η = 1.5, from either side.
    assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
    assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
    // Brewster's angle tan θ_B = η: the parallel part vanishes, F = r_⊥²/2 with
    // r_⊥ = (cos θ_i − η cos θ_t)/(cos θ_i + η cos θ_t) and θ_t = 90° − θ_B.
    let tb = 1.5f64.atan();
    let (ci, ct) = (tb.cos(), tb.sin());
    let r_perp = (ci - 1.5 * ct) / (ci + 1.5 * ct);
    assert!((fresnel_dielectric(ci as f32, 1.5) as f64 - r_perp * r_perp / 2.0).abs() < 1e-6);
    // Total internal reflection past the critical angle asin(1/η) from inside.
    let critical = (1.0f32 / 1.5).asin();
    assert_eq!(fresnel_dielectric(-(critical + 0.01).cos(), 1.5), 1.0);
    assert!(fresnel_dielectric(-(critical - 0.01).cos(), 1.5) < 1.0);
    // Schlick: f₀ at normal incidence, 1 at grazing.
    let c = Vec3::new(0.9, 0.6, 0.3);
    assert_eq!(schlick(c, 1.0), c);
    assert!((schlick(c, 0.0) - Vec3::ONE).abs().max_element() < 1e-6);
    // A smooth white glass's reflected share at normal incidence is 4 %: of 10⁵ samples,
    // 4000 ± 62 reflect.
    let g = glass(0.0, false);
    let mut rng = Rng::new(1, 2, 3);
    let reflected = (0..100_000)
        .filter(|_| {
            g.sample(Vec3::Z, [rng.next_f32(), rng.next_f32(), rng.next_f32()], Transport::Radiance).unwrap().wi.z > 0.0
        })
        .count();
    assert!((reflected as f64 - 4000.0).abs() < 5.0 * 62.0, "{reflected}");
}

#[test]
fn glass_refracts_by_snells_law_and_scales_radiance_by_eta_squared() {
    let g = glass(0.0, false);
    let wo = dir(40.0, 0.0);
    // Take the transmitted branch: u0 past F.
    let s = g.sample(wo, [0.99, 0.5, 0.5], Transport::Radiance).unwrap();
    assert!(s.delta && s.wi.z < 0.0);
    let sin_t = (1.0 - s.wi.z * s.wi.z).sqrt();
    assert!((40f32.to_radians().sin() - 1.5 * sin_t).abs() < 1e-5, "Snell: {}", sin_t);
    // Seen from outside, light refracted out of glass: radiance × (1 − F)/η².
    let f = fresnel_dielectric(wo.z, 1.5);
    assert!((s.weight.x * (1.0 - f) - (1.0 - f) / 2.25).abs() < 1e-5, "{}", s.weight.x);
    let i = g.sample(wo, [0.99, 0.5, 0.5], Transport::Importance).unwrap();
    assert!((i.weight.x - 1.0).abs() < 1e-6);
}

#[test]
fn a_lambertian_model_evaluates_to_albedo_over_pi() {
    let c = Vec3::new(0.8, 0.5, 0.2);
    let b = Bsdf::diffuse(c);
    assert!(b.is_lambertian());
    let f = b.eval(dir(30.0, 10.0), dir(70.0, 250.0), Transport::Radiance);
    assert!((f - c / std::f32::consts::PI).abs().max_element() < 1e-7);
    // Both on the back side: a two-sided surface reflects alike; opposite sides: nothing.
    assert_eq!(b.eval(-dir(30.0, 10.0), -dir(70.0, 250.0), Transport::Radiance), f);
    assert_eq!(b.eval(dir(30.0, 10.0), -dir(70.0, 250.0), Transport::Radiance), Vec3::ZERO);
}

/// The Lambertian part's albedo a(μ_o) (what the photon map answers for at the gather's hits)
/// against a quadrature of the cosine lobes it stands for — the base under the layer and the
/// metal's multiple scattering, c(1 − m)(1 − t)·share/π + m·M_ms — at every roughness and
/// angle: a(μ_o) = ∫(those lobes)·cos θ_i dω_i, so the rest f − a/π reflects the model's
/// glossy lobes' albedo. A Lambertian model is all Lambertian part.
#[test]
fn the_lambertian_part_reflects_what_the_cosine_lobes_do() {
    let c = Vec3::new(0.9, 0.6, 0.3);
    for roughness in [0.0, 0.1, 0.3, 0.6, 1.0] {
        let a2 = roughness * roughness;
        for b in [
            plastic(c, roughness),
            metal(c, roughness),
            Bsdf { metallic: 0.4, specular: 0.7, ..plastic(c, roughness) },
            Bsdf { transmission: 0.5, ..plastic(c, roughness) },
            Bsdf { alpha: a2, ..Bsdf::diffuse(c) },
            tinted_plastic(c, roughness),
            coated(plastic(c, roughness), 0.7, 0.5),
            coated(metal(c, roughness), 1.0, roughness),
        ] {
            for theta in [0.0f32, 30.0, 60.0, 80.0, 88.0] {
                let wo = dir(theta, 10.0);
                let n = 1024;
                let mut sum = Vec3::ZERO.as_dvec3();
                for i in 0..n {
                    let mu = (i as f32 + 0.5) / n as f32;
                    let opaque = (1.0 - b.metallic) * (1.0 - b.transmission);
                    let lobes = (opaque * b.base * b.diffuse_share(wo.z, mu) / std::f32::consts::PI
                        + b.metallic * b.ms_eval(wo.z, mu))
                        * (1.0 - b.coat_albedo(wo.z));
                    // ∫ over φ gives 2π; dω = dμ dφ.
                    sum += (lobes * mu * 2.0 * std::f32::consts::PI / n as f32).as_dvec3();
                }
                let a = b.lambertian_albedo(wo.z);
                assert!(
                    (a.as_dvec3() - sum).abs().max_element() < 1e-4,
                    "{b:?} at {theta}°: a {a} vs quadrature {sum}"
                );
            }
        }
    }
    let d = Bsdf::diffuse(c);
    assert_eq!(d.lambertian_albedo(0.3), c);
}

/// A smooth tinted layer over black reflects what glTF's specular extension says at normal
/// incidence and in the mean: its delta lobe carries s·F₀ with F₀ = min(f₀(η)·colour, 1) per
/// channel at cos θ = 1 (Schlick), and the F₉₀ = s at grazing angles whatever the colour.
#[test]
fn a_tinted_layer_reflects_its_colour_at_normal_incidence() {
    let b = tinted_plastic(Vec3::ZERO, 0.0);
    let f0 = ((1.5f32 - 1.0) / 2.5).powi(2);
    for (cos, want) in [(1.0f32, 0.8 * (Vec3::new(3.0, 1.0, 0.25) * f0).min(Vec3::ONE)), (0.0, Vec3::splat(0.8))] {
        let wo = Vec3::new((1.0 - cos * cos).max(0.0).sqrt(), 0.0, cos.max(1e-6));
        // Every sample of the black-based layer is its delta lobe.
        let s = b.sample(wo, [0.5, 0.5, 0.5], Transport::Radiance).expect("a sample");
        assert!(s.delta);
        assert!((s.weight - want).abs().max_element() < 1e-4, "cos {cos}: {} vs {want}", s.weight);
    }
}

/// A clear coat over black reflects what `KHR_materials_clearcoat` says: smooth, its delta
/// lobe carries k·F_k(μ) with Schlick's F_k of f₀ 0.04 (k·0.04 at normal incidence, → k at
/// grazing); rough, its albedo by a quadrature of `eval` is k times the GGX lobe's with that
/// Fresnel term, f₀E₁ + (1 − f₀)E₅ — computed here from a black metal (E₅) and a white one
/// (E₁) of the coat's roughness, independently of the coat's code.
#[test]
fn a_clear_coat_over_black_reflects_its_fresnel_term() {
    let black = Bsdf::diffuse(Vec3::ZERO);
    for cos in [1.0f32, 0.5, 1e-4] {
        let want = 0.6 * (0.04 + 0.96 * (1.0 - cos).powi(5));
        let wo = Vec3::new((1.0 - cos * cos).sqrt(), 0.0, cos);
        let s = coated(black, 0.6, 0.0).sample(wo, [0.3, 0.5, 0.5], Transport::Radiance).expect("a sample");
        assert!(s.delta && (s.wi - Vec3::new(-wo.x, -wo.y, wo.z)).length() < 1e-6);
        assert!((s.weight - Vec3::splat(want)).abs().max_element() < 1e-4, "cos {cos}: {} vs {want}", s.weight);
    }
    for r in [0.4f32, 0.7, 1.0] {
        for theta in [0.0f32, 50.0, 75.0] {
            let wo = dir(theta, 40.0);
            let single = |c: Vec3| Bsdf { multiple_scattering: false, ..metal(c, r) };
            let e1 = albedo_by_quadrature(&single(Vec3::ONE), wo, Transport::Radiance).x;
            let e5 = albedo_by_quadrature(&single(Vec3::ZERO), wo, Transport::Radiance).x;
            let want = 0.6 * (0.04 * e1 + 0.96 * e5);
            let got = albedo_by_quadrature(&coated(black, 0.6, r), wo, Transport::Radiance);
            assert!((got - Vec3::splat(want)).abs().max_element() < 1e-4, "r {r}, θ {theta}°: {got} vs {want}");
        }
    }
}
