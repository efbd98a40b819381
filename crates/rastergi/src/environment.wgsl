// The environment light (environment.rs): an equirectangular map in Mitsuba's envmap
// convention, bilinear between pixels, sampled cell by cell (row, then column) by luminance
// × solid angle. Part of the scene's bind group 0.

@group(0) @binding(9) var<uniform> environment: Environment;

// Word k of the environment's data.
fn env_data(k: u32) -> f32 {
    return scene_f32(scene_offset(DATA_ENVIRONMENT) + k);
}

fn has_environment() -> bool {
    return environment.width != 0u;
}

fn env_texel(i: u32, j: u32) -> vec3f {
    let k = 3u * (j * environment.width + i % environment.width);
    return vec3f(env_data(k), env_data(k + 1u), env_data(k + 2u));
}

// (u, v) of unit direction d: u = atan2(x, −z)/2π wrapped to [0, 1), v = acos(y)/π.
fn env_uv(d: vec3f) -> vec2f {
    let u = atan2(d.x, -d.z) / (2.0 * PI);
    return vec2f(u - floor(u), acos(clamp(d.y, -1.0, 1.0)) / PI);
}

// Continuous pixel coordinates of d: columns at pixel centres, rows at the poles inclusive.
fn env_position(d: vec3f) -> vec2f {
    let uv = env_uv(d);
    let w = f32(environment.width);
    var x = uv.x - 0.5 / w;
    x = (x - floor(x)) * w;
    return vec2f(x, uv.y * f32(environment.height - 1u));
}

// The radiance arriving from direction d (Environment::eval); zero without an environment.
fn env_radiance(d: vec3f) -> vec3f {
    if !has_environment() {
        return vec3f(0.0);
    }
    let p = env_position(d);
    let i = min(u32(p.x), environment.width - 1u);
    let j = min(u32(p.y), environment.height - 2u);
    let f = p - vec2f(f32(i), f32(j));
    let top = mix(env_texel(i, j), env_texel(i + 1u, j), f.x);
    let bottom = mix(env_texel(i, j + 1u), env_texel(i + 1u, j + 1u), f.x);
    return mix(top, bottom, f.y);
}

// (cos θ_j, cos θ_{j+1}) of cell row j.
fn env_row_cosines(j: u32) -> vec2f {
    let step = PI / f32(environment.height - 1u);
    return vec2f(cos(f32(j) * step), cos(f32(j + 1u) * step));
}

fn env_cell_solid_angle(j: u32) -> f32 {
    let c = env_row_cosines(j);
    return 2.0 * PI / f32(environment.width) * (c.x - c.y);
}

// The solid-angle density of env_sample at direction d (Environment::pdf).
fn env_pdf(d: vec3f) -> f32 {
    if !has_environment() {
        return 0.0;
    }
    let p = env_position(d);
    let i = min(u32(p.x), environment.width - 1u);
    let j = min(u32(p.y), environment.height - 2u);
    return env_data(environment.cell_pmf + j * environment.width + i) / env_cell_solid_angle(j);
}

// The first index in [lo, lo + n) whose value exceeds u (an upper bound of a cdf section).
fn env_search(lo: u32, n: u32, u: f32) -> u32 {
    var a = 0u;
    var b = n - 1u;
    while a < b {
        let mid = (a + b) / 2u;
        if env_data(lo + mid) <= u {
            a = mid + 1u;
        } else {
            b = mid;
        }
    }
    return a;
}

// u's position within [lo, hi), in [0, 1).
fn env_remap(u: f32, lo: f32, hi: f32) -> f32 {
    return clamp((u - lo) / max(hi - lo, 1e-30), 0.0, 0.99999994);
}

// A direction from (u1, u2) and its solid-angle density (Environment::sample): xyz, pdf.
fn env_sample(u1: f32, u2: f32) -> vec4f {
    let w = environment.width;
    let rows = environment.height - 1u;
    let j = env_search(environment.row_cdf, rows, u1);
    var lo = 0.0;
    if j > 0u {
        lo = env_data(environment.row_cdf + j - 1u);
    }
    let r1 = env_remap(u1, lo, env_data(environment.row_cdf + j));
    let row = environment.column_cdf + j * w;
    let i = env_search(row, w, u2);
    lo = 0.0;
    if i > 0u {
        lo = env_data(row + i - 1u);
    }
    let r2 = env_remap(u2, lo, env_data(row + i));
    let phi = 2.0 * PI * (f32(i) + 0.5 + r2) / f32(w);
    let c = env_row_cosines(j);
    let cos_t = c.x - r1 * (c.x - c.y);
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let d = vec3f(sin(phi) * sin_t, cos_t, -cos(phi) * sin_t);
    return vec4f(d, env_data(environment.cell_pmf + j * w + i) / env_cell_solid_angle(j));
}
