// Random numbers and sampling: bit-for-bit twins of sampling/mod.rs.

const PI: f32 = 3.14159265358979;

fn pcg_hash(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The stream for key (seed, a, b); mirrors Rng::new.
fn rng_new(seed: u32, a: u32, b: u32) -> u32 {
    return pcg_hash(a ^ pcg_hash(b ^ pcg_hash(seed)));
}

fn rng_next(state: ptr<function, u32>) -> u32 {
    let s = *state;
    *state = s * 747796405u + 2891336453u;
    let word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (word >> 22u) ^ word;
}

// Uniform in [0, 1) with 24 bits.
fn rng_f32(state: ptr<function, u32>) -> f32 {
    return f32(rng_next(state) >> 8u) * (1.0 / 16777216.0);
}

// Orthonormal basis completing the unit normal n (Duff et al. 2017): returns (t, b).
// A direction uniformly distributed over the unit sphere (pdf 1/4π); mirrors uniform_sphere.
fn uniform_sphere(u1: f32, u2: f32) -> vec3f {
    let z = 1.0 - 2.0 * u1;
    let r = sqrt(max(1.0 - z * z, 0.0));
    let phi = 2.0 * PI * u2;
    return vec3f(r * cos(phi), r * sin(phi), z);
}

fn orthonormal_basis(n: vec3f) -> array<vec3f, 2> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return array<vec3f, 2>(
        vec3f(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        vec3f(b, sign + n.y * n.y * a, -n.y),
    );
}

// Direction about n with pdf cos θ / π.
fn cosine_hemisphere(n: vec3f, u1: f32, u2: f32) -> vec3f {
    let r = sqrt(u1);
    let phi = 2.0 * PI * u2;
    let tb = orthonormal_basis(n);
    return normalize(tb[0] * (r * cos(phi)) + tb[1] * (r * sin(phi)) + n * sqrt(max(1.0 - u1, 0.0)));
}

// A direction uniform in the cone about `axis` with 1 − cos θ_max = one_minus_cos (pdf
// 1/(2π·one_minus_cos)); mirrors uniform_cone.
fn uniform_cone(axis: vec3f, one_minus_cos: f32, u1: f32, u2: f32) -> vec3f {
    let a = u1 * one_minus_cos;
    let sin_t = sqrt(max(a * (2.0 - a), 0.0));
    let phi = 2.0 * PI * u2;
    let tb = orthonormal_basis(axis);
    return normalize(tb[0] * (sin_t * cos(phi)) + tb[1] * (sin_t * sin(phi)) + axis * (1.0 - a));
}

// Barycentrics (b0, b1, b2) of a uniform point on a triangle (pdf 1/area).
fn uniform_triangle_bary(u1: f32, u2: f32) -> vec3f {
    let su = sqrt(u1);
    let b0 = 1.0 - su;
    let b1 = u2 * su;
    return vec3f(b0, b1, 1.0 - b0 - b1);
}

// The 2D Sobol' sequence at index i as 32-bit fractions (dimension 0: bits reversed;
// dimension 1: polynomial x + 1); mirrors sobol_2d.
fn sobol_2d(i: u32) -> vec2u {
    var y = 0u;
    var v = 1u << 31u;
    for (var j = i; j != 0u; j >>= 1u) {
        if (j & 1u) != 0u {
            y ^= v;
        }
        v ^= v >> 1u;
    }
    return vec2u(reverseBits(i), y);
}

// Laine–Karras-style hash: bit k depends on the seed and the bits up to k only.
fn lk_permutation(x0: u32, seed: u32) -> u32 {
    var x = x0;
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16u) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

// Owen scramble of the fraction x / 2^32; mirrors owen_scramble.
fn owen_scramble(x: u32, seed: u32) -> u32 {
    return reverseBits(lk_permutation(reverseBits(x), seed));
}

// The Owen-scrambled 2D Sobol' point of `index` for `seed` (index shuffled, then each
// coordinate scrambled); mirrors sobol_owen_2d.
fn sobol_owen_2d(index: u32, seed: u32) -> vec2u {
    let shuffled = owen_scramble(index, pcg_hash(seed ^ 0x0b2f5a31u));
    let p = sobol_2d(shuffled);
    return vec2u(owen_scramble(p.x, pcg_hash(seed ^ 0x68e31da4u)), owen_scramble(p.y, pcg_hash(seed ^ 0xb5c18b27u)));
}

// A 32-bit fraction as f32 in [0, 1) (its top 24 bits); mirrors unit_f32.
fn unit_f32(x: u32) -> f32 {
    return f32(x >> 8u) * (1.0 / 16777216.0);
}

// The scramble seed of pixel (x, y) for a frame's key; mirrors pixel_seed.
fn pixel_seed(key: u32, x: u32, y: u32) -> u32 {
    return pcg_hash(x ^ pcg_hash(y ^ key));
}
