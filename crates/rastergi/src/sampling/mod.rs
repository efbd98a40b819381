//! Random numbers and sampling routines, bit-for-bit twins of `sampling.wgsl`.
//!
//! The generator is PCG-RXS-M-XS on 32 bits (O'Neill 2014). Streams are keyed by a hash of
//! (seed, a, b) — e.g. (seed, pixel, iteration) or (seed, photon, batch) — so every sample
//! is reproducible from `--seed` and independent of scheduling.

pub mod gpu_check;

use glam::Vec3;

pub use crate::gpu::consts::stream;

/// One round of the PCG permutation, also used as an integer hash.
#[inline]
pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// A PCG stream.
#[derive(Clone, Copy, Debug)]
pub struct Rng {
    pub state: u32,
}

impl Rng {
    /// The stream for key (seed, a, b); mirrors `rng_new` in WGSL.
    pub fn new(seed: u32, a: u32, b: u32) -> Self {
        Self { state: pcg_hash(a ^ pcg_hash(b ^ pcg_hash(seed))) }
    }

    pub fn next_u32(&mut self) -> u32 {
        let s = self.state;
        self.state = s.wrapping_mul(747796405).wrapping_add(2891336453);
        let word = ((s >> ((s >> 28) + 4)) ^ s).wrapping_mul(277803737);
        (word >> 22) ^ word
    }

    /// Uniform in [0, 1) with 24 bits of precision.
    pub fn next_f32(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }
}

/// An orthonormal basis (t, b) completing the unit normal n (Duff et al. 2017).
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = if n.z >= 0.0 { 1.0f32 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// A shading normal `ns` seen from unit direction `v` (towards the viewer): unchanged where it
/// faces v, else bent in the plane of ns and v until it is just past perpendicular to v.
/// Mirrors `bend_towards` in `gpu_scene.wgsl`.
pub fn bend_towards(ns: Vec3, v: Vec3) -> Vec3 {
    let c = ns.dot(v);
    if c >= 0.0 { ns } else { (ns + (1e-3 - c) * v).normalize() }
}

/// A direction about the unit normal n with pdf cos θ / π (Malley's method).
pub fn cosine_hemisphere(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = orthonormal_basis(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
}

/// A direction uniform in the cone about the unit `axis` whose half-angle θ_max has
/// 1 − cos θ_max = `one_minus_cos` (pdf 1/(2π·one_minus_cos); passed so, it stays exact for
/// narrow cones). Mirrors `uniform_cone` in `sampling.wgsl`.
pub fn uniform_cone(axis: Vec3, one_minus_cos: f32, u1: f32, u2: f32) -> Vec3 {
    let a = u1 * one_minus_cos;
    let sin_t = (a * (2.0 - a)).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = orthonormal_basis(axis);
    (t * (sin_t * phi.cos()) + b * (sin_t * phi.sin()) + axis * (1.0 - a)).normalize()
}

/// A point uniformly distributed on the triangle (pdf 1/area).
pub fn uniform_triangle(t: &[Vec3; 3], u1: f32, u2: f32) -> Vec3 {
    let su = u1.sqrt();
    let (b0, b1) = (1.0 - su, u2 * su);
    t[0] * b0 + t[1] * b1 + t[2] * (1.0 - b0 - b1)
}

/// A direction uniformly distributed over the unit sphere (pdf 1/4π).
pub fn uniform_sphere(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The radical inverse of `i` in `base` (van der Corput), for Halton sequences.
pub fn radical_inverse(mut i: u32, base: u32) -> f32 {
    let inv = 1.0 / base as f64;
    let (mut f, mut r) = (inv, 0.0f64);
    while i > 0 {
        r += f * (i % base) as f64;
        i /= base;
        f *= inv;
    }
    r as f32
}

/// The 2D Sobol' sequence (its dimensions 0 and 1) at index `i`, as 32-bit binary fractions
/// (x / 2³²). Dimension 0 is the van der Corput sequence (the bits of i reversed); dimension 1
/// has the primitive polynomial x + 1, whose direction numbers are v₀ = ½, v_k = v_{k−1} ⊕
/// v_{k−1}/2 (Pascal's triangle mod 2). Together a (0, 2)-sequence in base 2: every aligned
/// block of 2^m points is a (0, m, 2)-net. Mirrors `sobol_2d` in WGSL.
pub fn sobol_2d(i: u32) -> [u32; 2] {
    let (mut y, mut v, mut j) = (0u32, 1u32 << 31, i);
    while j != 0 {
        if j & 1 != 0 {
            y ^= v;
        }
        j >>= 1;
        v ^= v >> 1;
    }
    [i.reverse_bits(), y]
}

/// A hash-based nested scramble of the bits of `x` from the least significant up (Laine and
/// Karras 2011, with the mixing Burley 2020 reports from Vegdahl): each step is a bijection
/// in which bit k of the result is bit k of its input XOR a function of the bits below k
/// (adding, multiplying by an odd number, XOR with a multiple by an even number), so every
/// bit is flipped or not depending on the seed and the lower bits only.
fn lk_permutation(mut x: u32, seed: u32) -> u32 {
    x ^= x.wrapping_mul(0x3d20_adea);
    x = x.wrapping_add(seed);
    x = x.wrapping_mul((seed >> 16) | 1);
    x ^= x.wrapping_mul(0x0552_6c56);
    x ^= x.wrapping_mul(0x53a2_2864);
    x
}

/// An Owen scramble of the binary fraction x / 2³² keyed by `seed`: [`lk_permutation`] on the
/// reversed bits, so each digit (most significant first) is flipped depending on the digits
/// before it. It maps every elementary interval [j/2^k, (j+1)/2^k) onto one of the same size,
/// so a scrambled (0, m, 2)-net is one too. Mirrors `owen_scramble` in WGSL.
pub fn owen_scramble(x: u32, seed: u32) -> u32 {
    lk_permutation(x.reverse_bits(), seed).reverse_bits()
}

/// The Owen-scrambled 2D Sobol' point of `index` for `seed` (Burley 2020): the index is
/// shuffled first by the same scramble (applied to its bits as a fraction, so the first 2^m
/// indices map onto one aligned block of 2^m Sobol' indices, itself a (0, m, 2)-net), then each
/// coordinate is scrambled with its own seed. Points as 32-bit fractions; mirrors
/// `sobol_owen_2d` in WGSL.
pub fn sobol_owen_2d(index: u32, seed: u32) -> [u32; 2] {
    let shuffled = owen_scramble(index, pcg_hash(seed ^ 0x0b2f_5a31));
    let [x, y] = sobol_2d(shuffled);
    [owen_scramble(x, pcg_hash(seed ^ 0x68e3_1da4)), owen_scramble(y, pcg_hash(seed ^ 0xb5c1_8b27))]
}

/// A 32-bit fraction as an f32 in [0, 1) (its top 24 bits: exact), as `rng_f32` rounds.
pub fn unit_f32(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// Standard normal deviates from `seed` (splitmix64 uniforms, the Box–Muller transform): noise
/// of a known level for the tests of error metrics.
pub fn gaussian_deviates(seed: u64) -> impl FnMut() -> f64 {
    let mut state = seed;
    let mut uniform = move || {
        state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    };
    move || {
        let (u1, u2) = (1.0 - uniform(), uniform());
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

/// The scramble seed of pixel (x, y) for a frame's `key`; mirrors `pixel_seed` in WGSL.
pub fn pixel_seed(key: u32, x: u32, y: u32) -> u32 {
    pcg_hash(x ^ pcg_hash(y ^ key))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn rng_is_uniform_in_mean_and_variance() {
        let mut rng = Rng::new(7, 1, 2);
        let n = 200_000;
        let xs: Vec<f32> = (0..n).map(|_| rng.next_f32()).collect();
        let mean = xs.iter().map(|&x| x as f64).sum::<f64>() / n as f64;
        let var = xs.iter().map(|&x| (x as f64 - mean).powi(2)).sum::<f64>() / n as f64;
        // Standard error of the mean of U(0,1): sqrt(1/12/n) ≈ 6.5e-4.
        assert!((mean - 0.5).abs() < 5.0 * (1.0f64 / 12.0 / n as f64).sqrt());
        assert!((var - 1.0 / 12.0).abs() < 1e-3);
        assert!(xs.iter().all(|&x| (0.0..1.0).contains(&x)));
    }

    #[test]
    fn cosine_hemisphere_has_mean_cosine_two_thirds() {
        // E[cos θ] under pdf cos θ/π is ∫cos² θ/π dω = 2/3.
        let n = Vec3::new(0.3, -0.5, 0.81).normalize();
        let mut rng = Rng::new(1, 2, 3);
        let m = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..m {
            let d = cosine_hemisphere(n, rng.next_f32(), rng.next_f32());
            assert!((d.length() - 1.0).abs() < 1e-4 && d.dot(n) >= -1e-6);
            sum += d.dot(n) as f64;
        }
        let mean = sum / m as f64;
        // Var[cos θ] = E[cos³θ·…] = 1/2 - 4/9 = 1/18.
        assert!((mean - 2.0 / 3.0).abs() < 5.0 * (1.0f64 / 18.0 / m as f64).sqrt());
    }

    #[test]
    fn orthonormal_basis_is_orthonormal_for_all_signs() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(1.0, 2.0, -3.0).normalize()] {
            let (t, b) = orthonormal_basis(n);
            for (x, y) in [(t, b), (t, n), (b, n)] {
                assert!(x.dot(y).abs() < 1e-5);
            }
            assert!((t.length() - 1.0).abs() < 1e-5 && (b.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn radical_inverse_matches_hand_values() {
        assert_eq!(radical_inverse(1, 2), 0.5);
        assert_eq!(radical_inverse(3, 2), 0.75);
        assert!((radical_inverse(5, 3) - (2.0 / 3.0 + 1.0 / 9.0)).abs() < 1e-6);
    }

    #[test]
    fn sobol_2d_first_points_match_hand_values() {
        // Dimension 0: 0, ½, ¼, ¾, ⅛, ⅝, ⅜, ⅞ (van der Corput). Dimension 1 by hand from
        // v₀ = 0.1₂, v₁ = 0.11₂, v₂ = 0.101₂: i = 2 → v₁ = ¾, i = 3 → v₀ ⊕ v₁ = 0.01₂ = ¼,
        // i = 5 → v₀ ⊕ v₂ = 0.001₂ = ⅛, i = 6 → v₁ ⊕ v₂ = 0.011₂ = ⅜, i = 7 → 0.111₂ = ⅞.
        let expected = [
            (0.0, 0.0),
            (0.5, 0.5),
            (0.25, 0.75),
            (0.75, 0.25),
            (0.125, 0.625),
            (0.625, 0.125),
            (0.375, 0.375),
            (0.875, 0.875),
        ];
        for (i, &(x, y)) in expected.iter().enumerate() {
            let [sx, sy] = sobol_2d(i as u32);
            assert_eq!((sx as f64 / 4_294_967_296.0, sy as f64 / 4_294_967_296.0), (x, y), "point {i}");
        }
        // v₃ = v₂ ⊕ v₂/2 = 0.1111₂: point 8 is (1/16, 15/16).
        assert_eq!(sobol_2d(8), [1 << 28, 0xf000_0000]);
    }

    /// Whether `points` (2^m of them, 32-bit fractions) put exactly one point in every
    /// elementary interval [a/2^j, (a+1)/2^j) × [b/2^(m−j), (b+1)/2^(m−j)), for all j.
    pub(crate) fn is_net(points: &[[u32; 2]], m: u32) -> bool {
        (0..=m).all(|j| {
            let mut seen = vec![false; 1 << m];
            points.iter().all(|&[x, y]| {
                let cell = |v: u32, bits: u32| if bits == 0 { 0 } else { (v >> (32 - bits)) as usize };
                let k = (cell(x, j) << (m - j)) | cell(y, m - j);
                !std::mem::replace(&mut seen[k], true)
            })
        })
    }

    #[test]
    fn scrambled_sobol_prefixes_are_02_nets_for_every_seed() {
        for seed in [0u32, 1, 7, 0xdead_beef, pixel_seed(3, 10, 20)] {
            for m in [1u32, 2, 4, 6, 8, 10] {
                let points: Vec<[u32; 2]> = (0..1u32 << m).map(|i| sobol_owen_2d(i, seed)).collect();
                assert!(is_net(&points, m), "seed {seed:#x}: the first 2^{m} points are not a (0,{m},2)-net");
                // An iteration of K = 4 directions takes an aligned block: a (0,2,2)-net.
                let block: Vec<[u32; 2]> = (40..44).map(|i| sobol_owen_2d(i, seed)).collect();
                assert!(is_net(&block, 2), "seed {seed:#x}: points 40..44 are not a (0,2,2)-net");
            }
        }
        // The check itself rejects a non-net: four points on the diagonal's first half.
        assert!(!is_net(&[[0, 0], [1 << 29, 1 << 29], [2 << 29, 2 << 29], [3 << 29, 3 << 29]], 2));
        // And the scramble does change the points.
        assert_ne!(sobol_owen_2d(1, 1), sobol_owen_2d(1, 2));
    }

    #[test]
    fn scrambled_sobol_points_are_uniform_across_seeds() {
        // For a fixed index, the point over random seeds is uniform on [0,1)²: mean ½ and
        // variance 1/12 in each coordinate, uncorrelated.
        let n = 50_000;
        for index in [0u32, 1, 5, 100, 12_345] {
            let (mut s, mut s2, mut sxy) = ([0.0f64; 2], [0.0f64; 2], 0.0f64);
            for seed in 0..n {
                let p = sobol_owen_2d(index, pcg_hash(seed)).map(|v| unit_f32(v) as f64);
                for c in 0..2 {
                    s[c] += p[c];
                    s2[c] += p[c] * p[c];
                }
                sxy += (p[0] - 0.5) * (p[1] - 0.5);
            }
            let se = (1.0f64 / 12.0 / n as f64).sqrt();
            for c in 0..2 {
                let mean = s[c] / n as f64;
                let var = s2[c] / n as f64 - mean * mean;
                assert!((mean - 0.5).abs() < 5.0 * se, "index {index}: mean {mean}");
                // Var of (u − ½)² is 1/180: its standard error is sqrt(1/180/n).
                assert!(
                    (var - 1.0 / 12.0).abs() < 5.0 * (1.0f64 / 180.0 / n as f64).sqrt(),
                    "index {index}: var {var}"
                );
            }
            // Cov of independent U(0,1): 0 with standard error 1/12/sqrt(n).
            assert!((sxy / n as f64).abs() < 5.0 / 12.0 / (n as f64).sqrt(), "index {index}: covariance");
        }
    }
}
