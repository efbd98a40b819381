//! Random numbers and sampling routines, bit-for-bit twins of `sampling.wgsl`.
//!
//! The generator is PCG-RXS-M-XS on 32 bits (O'Neill 2014). Streams are keyed by a hash of
//! (seed, a, b) — e.g. (seed, pixel, iteration) or (seed, photon, batch) — so every sample
//! is reproducible from `--seed` and independent of scheduling.

use glam::Vec3;

pub use crate::consts::stream;

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

/// A direction about the unit normal n with pdf cos θ / π (Malley's method).
pub fn cosine_hemisphere(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * std::f32::consts::PI * u2;
    let (t, b) = orthonormal_basis(n);
    (t * (r * phi.cos()) + b * (r * phi.sin()) + n * (1.0 - u1).max(0.0).sqrt()).normalize()
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

#[cfg(test)]
mod tests {
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
}
