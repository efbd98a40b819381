// The denoiser's filter (denoise/mod.rs): prepare (film sums and guides → demodulated reflected
// light and the variance of its mean, per component), the guide: one à-trous level per
// dispatch (step params.step), the regression (a weighted first-order fit around every
// pixel, weighted by the guide), compose (remodulate, add the components and the emission).
// Buffers `src`, `dst` and `light` hold (light rgb, variance) of the direct component of pixel
// p at p and of the indirect at W·H + p. The CPU twin is denoise::cpu; keep the two the same
// operations.

@group(0) @binding(0) var<uniform> params: Denoise;
@group(0) @binding(1) var<storage, read> film: array<vec4f>;
@group(0) @binding(2) var<storage, read> guides: array<vec4f>;
// The guides' second buffer: slot 2 holds the sums of the emission the eye sees.
@group(0) @binding(3) var<storage, read> extra: array<vec4f>;
@group(0) @binding(4) var<storage, read> src: array<vec4f>;
@group(0) @binding(5) var<storage, read_write> dst: array<vec4f>;
@group(0) @binding(6) var<storage, read_write> image: array<vec4f>;
// The level's luminance guide: (direct, indirect) luminance of `src` blurred 3×3.
@group(0) @binding(7) var<storage, read_write> lum: array<vec2f>;
// What prepare wrote: the unfiltered light and its variance, for the regression.
@group(0) @binding(8) var<storage, read_write> light: array<vec4f>;

// A dispatch covers the rows [row0, row_end) of its pass (the whole image, or one band of a
// filter run across frames): invocation `id` is the pixel `id` + (0, row0).
fn band_pixel(id: vec3u) -> vec3u {
    return vec3u(id.x, id.y + params.row0, 0u);
}

fn pixel_count() -> u32 {
    return params.resolution.x * params.resolution.y;
}

// The mean albedo of pixel p over the guides' iterations (0 where unseen).
fn mean_albedo(p: u32) -> vec3f {
    return guides[p].rgb / f32(max(params.guide_samples, 1u));
}

// The mean emission the eye sees at pixel p over the guides' iterations.
fn mean_emission(p: u32) -> vec3f {
    return extra[2u * pixel_count() + p].rgb / f32(max(params.guide_samples, 1u));
}

// The variance of the mean of n values with sum m1 and sum of squares m2: the sample
// variance over n. Unknown (VARIANCE_UNKNOWN) below two values.
fn variance_of_mean(m1: f32, m2: f32, n: f32) -> f32 {
    if n < 2.0 {
        return VARIANCE_UNKNOWN;
    }
    return max(m2 - m1 * m1 / n, 0.0) / (n * (n - 1.0));
}

@compute @workgroup_size(8, 8)
fn prepare(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if gid.x >= params.resolution.x || gid.y >= params.row_end {
        return;
    }
    let n = pixel_count();
    let p = gid.y * params.resolution.x + gid.x;
    let s = f32(max(params.samples, 1u));
    let a = demodulation(mean_albedo(p));
    let m = guides[2u * n + p];
    let g = f32(params.guide_samples);
    let reflected = film[FILM_DIRECT * n + p].rgb / s - mean_emission(p);
    let direct = vec4f(reflected / a, variance_of_mean(m.x, m.y, g));
    let indirect = vec4f(film[FILM_INDIRECT * n + p].rgb / s / a, variance_of_mean(m.z, m.w, g));
    dst[p] = direct;
    dst[n + p] = indirect;
    light[p] = direct;
    light[n + p] = indirect;
}

// The guides of pixel p: unit mean normal (0 where never seen) and mean distance.
struct Guide {
    normal: vec3f,
    depth: f32,
}

fn guide(p: u32) -> Guide {
    let n = pixel_count();
    let g0 = guides[p];
    let g1 = guides[n + p];
    var out: Guide;
    out.normal = vec3f(0.0);
    out.depth = 0.0;
    let len = length(g1.xyz);
    if g1.w > 0.0 && len > 0.0 {
        out.normal = g1.xyz / len;
        out.depth = g0.w / g1.w;
    }
    return out;
}

const BINOMIAL3 = array<f32, 3>(0.25, 0.5, 0.25);

// What `blur3` blurs, per component (direct, indirect): the luminances of `src`, the
// variances of `src` (its w) or the variances of `light` (its w).
const BLUR_LUMINANCE: u32 = 0u;
const BLUR_VARIANCE: u32 = 1u;
const BLUR_LIGHT_VARIANCE: u32 = 2u;

fn blur_value(k: u32, n: u32, what: u32) -> vec2f {
    switch what {
        case BLUR_LUMINANCE: {
            return vec2f(luminance(src[k].rgb), luminance(src[n + k].rgb));
        }
        case BLUR_VARIANCE: {
            return vec2f(src[k].w, src[n + k].w);
        }
        default: {
            return vec2f(light[k].w, light[n + k].w);
        }
    }
}

// `what` (direct, indirect) at pixel xy blurred by the 3×3 binomial kernel, clamped to the
// image (the weights inside it renormalised).
fn blur3(xy: vec2i, what: u32) -> vec2f {
    let n = pixel_count();
    let res = vec2i(params.resolution);
    var sum = vec2f(0.0);
    var wsum = 0.0;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let q = xy + vec2i(dx, dy);
            if all(q >= vec2i(0)) && all(q < res) {
                let w = BINOMIAL3[dx + 1] * BINOMIAL3[dy + 1];
                sum += w * blur_value(u32(q.y * res.x + q.x), n, what);
                wsum += w;
            }
        }
    }
    return sum / wsum;
}

// The luminance guide of the level: the luminances of `src` blurred by the 3×3 binomial
// kernel, so that the edge-stopping compares local means, not single noisy values.
@compute @workgroup_size(8, 8)
fn blur_luminance(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if gid.x >= params.resolution.x || gid.y >= params.row_end {
        return;
    }
    lum[gid.y * params.resolution.x + gid.x] = blur3(vec2i(gid.xy), BLUR_LUMINANCE);
}

const B3 = array<f32, 5>(0.0625, 0.25, 0.375, 0.25, 0.0625);

@compute @workgroup_size(8, 8)
fn atrous(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if gid.x >= params.resolution.x || gid.y >= params.row_end {
        return;
    }
    let n = pixel_count();
    let res = vec2i(params.resolution);
    let xy = vec2i(gid.xy);
    let p = gid.y * params.resolution.x + gid.x;
    let gp = guide(p);
    let ld = lum[p].x;
    let li = lum[p].y;
    let variance = blur3(xy, BLUR_VARIANCE);
    let sd = params.sigma_l * LUMINANCE_NOISE * sqrt(variance.x) + LUMINANCE_EPSILON;
    let si = params.sigma_l * LUMINANCE_NOISE * sqrt(variance.y) + LUMINANCE_EPSILON;
    var sum_d = vec3f(0.0);
    var sum_i = vec3f(0.0);
    var var_d = 0.0;
    var var_i = 0.0;
    var w_d = 0.0;
    var w_i = 0.0;
    let step = i32(params.step);
    for (var j = -2; j <= 2; j++) {
        for (var i = -2; i <= 2; i++) {
            let q = xy + step * vec2i(i, j);
            if any(q < vec2i(0)) || any(q >= res) {
                continue;
            }
            let k = u32(q.y * res.x + q.x);
            let h = B3[i + 2] * B3[j + 2];
            let qd = src[k];
            let qi = src[n + k];
            var geometric = 1.0;
            if k != p {
                let gq = guide(k);
                let cosine = dot(gp.normal, gq.normal);
                let wn = select(0.0, pow(cosine, params.sigma_n), cosine > 0.0);
                let scale = gp.depth * params.pixel_angle * f32(step) * length(vec2f(f32(i), f32(j)));
                let wz = exp(-abs(gp.depth - gq.depth) / (params.sigma_z * scale + DEPTH_EPSILON));
                geometric = wn * wz;
            }
            let wd = h * geometric * exp(-abs(lum[k].x - ld) / sd);
            let wi = h * geometric * exp(-abs(lum[k].y - li) / si);
            sum_d += wd * qd.rgb;
            sum_i += wi * qi.rgb;
            var_d += wd * wd * qd.w;
            var_i += wi * wi * qi.w;
            w_d += wd;
            w_i += wi;
        }
    }
    dst[p] = vec4f(sum_d / w_d, var_d / (w_d * w_d));
    dst[n + p] = vec4f(sum_i / w_i, var_i / (w_i * w_i));
}

// Regressors of the first-order fit: the change of normal (x_n), then the offset (dx, dy)/r,
// the relative change of distance and last the constant (x_a), whose coefficient is the fit
// at the pixel.
const REGRESSORS: u32 = 7u;
// The lower triangle of the REGRESSORS² normal matrix, row by row.
const TRIANGLE: u32 = 28u;

fn tri(i: u32, j: u32) -> u32 {
    return i * (i + 1u) / 2u + j;
}

// The fit of component c at pixel xy (module notes, denoise/mod.rs): Σ w x xᵀ β = Σ w x L over
// the disc of radius r, w = exp(−d²/(2 (BANDWIDTH r)²)) · exp(−|Y(G_q) − Y(G_p)| / s), G the
// guide (`src`), s = σ_g · √(g₃ ⊛ σ²)(p), solved by Cholesky with the ridge on the diagonal.
// The sums are kept in blocks of fixed shape (x_n x_nᵀ, x_a x_nᵀ, x_a x_aᵀ, L x_nᵀ, L x_aᵀ),
// which stay in registers, and unpacked once into the triangle.
fn fit(xy: vec2i, c: u32) -> vec3f {
    let n = pixel_count();
    let res = vec2i(params.resolution);
    let p = u32(xy.y * res.x + xy.x);
    let gp = guide(p);
    let radius = select(params.radius_indirect, params.radius_direct, c == 0u);
    let r = i32(radius);
    let bandwidth = BANDWIDTH * f32(max(radius, 1u));
    let yp = luminance(src[c * n + p].rgb);
    let s = params.sigma_g * sqrt(blur3(xy, BLUR_LIGHT_VARIANCE)[c]) + LUMINANCE_EPSILON;
    var ann = mat3x3f();
    var aan = mat3x4f();
    var aaa = mat4x4f();
    var bn = mat3x3f();
    var ba = mat4x3f();
    for (var dy = -r; dy <= r; dy++) {
        for (var dx = -r; dx <= r; dx++) {
            let q = xy + vec2i(dx, dy);
            if dx * dx + dy * dy > r * r || any(q < vec2i(0)) || any(q >= res) {
                continue;
            }
            let k = u32(q.y * res.x + q.x);
            let gq = guide(k);
            if k != p && gq.depth == 0.0 {
                continue;
            }
            let d2 = f32(dx * dx + dy * dy);
            let w = exp(-0.5 * d2 / (bandwidth * bandwidth)) * exp(-abs(luminance(src[c * n + k].rgb) - yp) / s);
            let xn = gq.normal - gp.normal;
            let xa = vec4f(
                f32(dx) / f32(max(r, 1)),
                f32(dy) / f32(max(r, 1)),
                (gq.depth - gp.depth) / gp.depth,
                1.0,
            );
            let l = light[c * n + k].rgb;
            ann += w * mat3x3f(xn * xn.x, xn * xn.y, xn * xn.z);
            aan += w * mat3x4f(xa * xn.x, xa * xn.y, xa * xn.z);
            aaa += w * mat4x4f(xa * xa.x, xa * xa.y, xa * xa.z, xa * xa.w);
            bn += w * mat3x3f(l * xn.x, l * xn.y, l * xn.z);
            ba += w * mat4x3f(l * xa.x, l * xa.y, l * xa.z, l * xa.w);
        }
    }
    var m: array<f32, TRIANGLE>;
    var b: array<vec3f, REGRESSORS>;
    for (var i = 0u; i < REGRESSORS; i++) {
        if i < 3u {
            b[i] = bn[i];
        } else {
            b[i] = ba[i - 3u];
        }
        for (var j = 0u; j <= i; j++) {
            var v: f32;
            if i < 3u {
                v = ann[j][i];
            } else if j < 3u {
                v = aan[j][i - 3u];
            } else {
                v = aaa[j - 3u][i - 3u];
            }
            m[tri(i, j)] = v;
        }
    }
    // The ridge: each regressor's weighted square grows by `ridge` of itself and a tiny part
    // of the total weight (a regressor that never varies gets a zero coefficient).
    let mean = b[REGRESSORS - 1u] / m[tri(REGRESSORS - 1u, REGRESSORS - 1u)];
    for (var i = 0u; i < REGRESSORS - 1u; i++) {
        m[tri(i, i)] += params.ridge * m[tri(i, i)] + RIDGE_FLOOR * m[tri(REGRESSORS - 1u, REGRESSORS - 1u)];
    }
    // Cholesky, m = L Lᵀ in place, and the forward substitution L y = b; the constant is last,
    // so its coefficient is y_last / L_last,last. A pivot that is not positive (rounding in a
    // degenerate window) falls back to the weighted mean.
    for (var j = 0u; j < REGRESSORS; j++) {
        var d = m[tri(j, j)];
        var y = b[j];
        for (var k = 0u; k < j; k++) {
            d -= m[tri(j, k)] * m[tri(j, k)];
            y -= m[tri(j, k)] * b[k];
        }
        if !(d > 0.0) {
            return mean;
        }
        let l = sqrt(d);
        m[tri(j, j)] = l;
        b[j] = y / l;
        for (var i = j + 1u; i < REGRESSORS; i++) {
            var e = m[tri(i, j)];
            for (var k = 0u; k < j; k++) {
                e -= m[tri(i, k)] * m[tri(j, k)];
            }
            m[tri(i, j)] = e / l;
        }
    }
    return b[REGRESSORS - 1u] / m[tri(REGRESSORS - 1u, REGRESSORS - 1u)];
}

// The regression of both components: `src` holds the guide (the last à-trous level), `light`
// the unfiltered light; writes the fits to `dst`. A pixel where nothing is seen (no distance)
// keeps its light (0: its emission is added at compose); such neighbours are left out.
@compute @workgroup_size(8, 8)
fn regress(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if gid.x >= params.resolution.x || gid.y >= params.row_end {
        return;
    }
    let n = pixel_count();
    let p = gid.y * params.resolution.x + gid.x;
    for (var c = 0u; c < 2u; c++) {
        var out = light[c * n + p].rgb;
        if guide(p).depth > 0.0 {
            out = fit(vec2i(gid.xy), c);
        }
        dst[c * n + p] = vec4f(out, 0.0);
    }
}

@compute @workgroup_size(8, 8)
fn compose(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if gid.x >= params.resolution.x || gid.y >= params.row_end {
        return;
    }
    let n = pixel_count();
    let p = gid.y * params.resolution.x + gid.x;
    let a = demodulation(mean_albedo(p));
    image[p] = vec4f(a * (src[p].rgb + src[n + p].rgb) + mean_emission(p), 1.0);
}
