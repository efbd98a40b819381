//! The CPU twin of the filter (`denoise.wgsl`), the same f32 operations in the same order.

use super::*;

/// What the filter reads: the film's sums (`COMPONENTS × W × H × 4` floats) of `samples`
/// iterations and the guides' sums of `guide_samples` (`guides` as [`Guides::buffer`],
/// `extra` as [`Guides::extra`], of which only the emission's slot is read).
pub struct Input<'a> {
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub guide_samples: u32,
    pub film: &'a [f32],
    pub guides: &'a [f32],
    pub extra: &'a [f32],
    pub pixel_angle: f32,
}

fn luminance(c: [f32; 3]) -> f32 {
    // dot() in WGSL: left to right.
    c[0] * 0.2126 + c[1] * 0.7152 + c[2] * 0.0722
}

fn demodulation(a: [f32; 3]) -> [f32; 3] {
    a.map(|v| if v > DEMODULATION_MIN { v } else { 1.0 })
}

fn variance_of_mean(m1: f32, m2: f32, n: f32) -> f32 {
    if n < 2.0 {
        return VARIANCE_UNKNOWN;
    }
    (m2 - m1 * m1 / n).max(0.0) / (n * (n - 1.0))
}

fn at(data: &[f32], k: usize) -> [f32; 4] {
    [data[4 * k], data[4 * k + 1], data[4 * k + 2], data[4 * k + 3]]
}

const BINOMIAL3: [f32; 3] = [0.25, 0.5, 0.25];
const B3: [f32; 5] = [0.0625, 0.25, 0.375, 0.25, 0.0625];
const REGRESSORS: usize = 7;

fn tri(i: usize, j: usize) -> usize {
    i * (i + 1) / 2 + j
}

/// The image's guides per pixel: unit mean normal and mean distance (0 where unseen: the
/// regression fits the pixels of positive distance).
struct Geometry {
    normal: Vec<[f32; 3]>,
    depth: Vec<f32>,
}

/// Component c of pixel k of a two-component buffer (direct at k, indirect at n + k).
type Light = Vec<[f32; 4]>;

/// The 3×3 binomial blur at (x, y) of `value(k)` over the pixels k of a `w × h` image.
fn blur3(x: i32, y: i32, (w, h): (i32, i32), value: impl Fn(usize) -> f32) -> f32 {
    let (mut sum, mut wsum) = (0.0f32, 0.0f32);
    for dy in -1..=1i32 {
        for dx in -1..=1i32 {
            let (qx, qy) = (x + dx, y + dy);
            if qx >= 0 && qy >= 0 && qx < w && qy < h {
                let wt = BINOMIAL3[(dx + 1) as usize] * BINOMIAL3[(dy + 1) as usize];
                sum += wt * value((qy * w + qx) as usize);
                wsum += wt;
            }
        }
    }
    sum / wsum
}

/// One à-trous level of step `step` (`atrous` in the shader).
fn atrous(input: &Input, params: &DenoiseParams, geometry: &Geometry, src: &Light, step: i32) -> Light {
    let (w, h) = (input.width as i32, input.height as i32);
    let n = (w * h) as usize;
    // The level's luminance guide: the 3×3 binomial blur of each component's luminance
    // (both in one pass in the shader, the same sums).
    let lum: Vec<[f32; 2]> = (0..n)
        .map(|p| {
            let (x, y) = ((p as i32) % w, (p as i32) / w);
            let y_of = |v: [f32; 4]| luminance([v[0], v[1], v[2]]);
            [blur3(x, y, (w, h), |k| y_of(src[k])), blur3(x, y, (w, h), |k| y_of(src[n + k]))]
        })
        .collect();
    let mut dst = vec![[0.0f32; 4]; 2 * n];
    for y in 0..h {
        for x in 0..w {
            let p = (y * w + x) as usize;
            let (np, zp) = (geometry.normal[p], geometry.depth[p]);
            let (ld, li) = (lum[p][0], lum[p][1]);
            let sd = params.sigma_l * LUMINANCE_NOISE * blur3(x, y, (w, h), |k| src[k][3]).sqrt() + LUMINANCE_EPSILON;
            let si =
                params.sigma_l * LUMINANCE_NOISE * blur3(x, y, (w, h), |k| src[n + k][3]).sqrt() + LUMINANCE_EPSILON;
            let (mut sum_d, mut sum_i) = ([0.0f32; 3], [0.0f32; 3]);
            let (mut var_d, mut var_i, mut w_d, mut w_i) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
            for j in -2..=2i32 {
                for i in -2..=2i32 {
                    let (qx, qy) = (x + step * i, y + step * j);
                    if qx < 0 || qy < 0 || qx >= w || qy >= h {
                        continue;
                    }
                    let k = (qy * w + qx) as usize;
                    let hk = B3[(i + 2) as usize] * B3[(j + 2) as usize];
                    let (qd, qi) = (src[k], src[n + k]);
                    let mut geometric = 1.0f32;
                    if k != p {
                        let (nq, zq) = (geometry.normal[k], geometry.depth[k]);
                        let cosine = np[0] * nq[0] + np[1] * nq[1] + np[2] * nq[2];
                        let wn = if cosine > 0.0 { cosine.powf(params.sigma_n) } else { 0.0 };
                        let dist = ((i * i + j * j) as f32).sqrt();
                        let scale = zp * input.pixel_angle * step as f32 * dist;
                        let wz = (-(zp - zq).abs() / (params.sigma_z * scale + DEPTH_EPSILON)).exp();
                        geometric = wn * wz;
                    }
                    let wd = hk * geometric * (-(lum[k][0] - ld).abs() / sd).exp();
                    let wi = hk * geometric * (-(lum[k][1] - li).abs() / si).exp();
                    for c in 0..3 {
                        sum_d[c] += wd * qd[c];
                        sum_i[c] += wi * qi[c];
                    }
                    var_d += wd * wd * qd[3];
                    var_i += wi * wi * qi[3];
                    w_d += wd;
                    w_i += wi;
                }
            }
            dst[p] = [sum_d[0] / w_d, sum_d[1] / w_d, sum_d[2] / w_d, var_d / (w_d * w_d)];
            dst[n + p] = [sum_i[0] / w_i, sum_i[1] / w_i, sum_i[2] / w_i, var_i / (w_i * w_i)];
        }
    }
    dst
}

/// The first-order fit of component c at (x, y) (`fit` in the shader).
fn fit(
    input: &Input,
    params: &DenoiseParams,
    geometry: &Geometry,
    (guide, light): (&Light, &Light),
    (x, y, c): (i32, i32, usize),
) -> [f32; 3] {
    let (w, h) = (input.width as i32, input.height as i32);
    let n = (w * h) as usize;
    let p = (y * w + x) as usize;
    let (np, zp) = (geometry.normal[p], geometry.depth[p]);
    let radius = if c == 0 { params.radius_direct } else { params.radius_indirect };
    let r = radius as i32;
    let bandwidth = BANDWIDTH * radius.max(1) as f32;
    let rgb = |v: [f32; 4]| [v[0], v[1], v[2]];
    let yp = luminance(rgb(guide[c * n + p]));
    let s = params.sigma_g * blur3(x, y, (w, h), |k| light[c * n + k][3]).sqrt() + LUMINANCE_EPSILON;
    // The blocks of fit() in the shader: ann[c][r] is column c, row r.
    let (mut ann, mut aan, mut aaa) = ([[0.0f32; 3]; 3], [[0.0f32; 4]; 3], [[0.0f32; 4]; 4]);
    let (mut bn, mut ba) = ([[0.0f32; 3]; 3], [[0.0f32; 3]; 4]);
    for dy in -r..=r {
        for dx in -r..=r {
            let (qx, qy) = (x + dx, y + dy);
            if dx * dx + dy * dy > r * r || qx < 0 || qy < 0 || qx >= w || qy >= h {
                continue;
            }
            let k = (qy * w + qx) as usize;
            if k != p && geometry.depth[k] == 0.0 {
                continue;
            }
            let (nq, zq) = (geometry.normal[k], geometry.depth[k]);
            let d2 = (dx * dx + dy * dy) as f32;
            let wt = (-0.5 * d2 / (bandwidth * bandwidth)).exp()
                * (-(luminance(rgb(guide[c * n + k])) - yp).abs() / s).exp();
            let rr = r.max(1) as f32;
            let xn = [nq[0] - np[0], nq[1] - np[1], nq[2] - np[2]];
            let xa = [dx as f32 / rr, dy as f32 / rr, (zq - zp) / zp, 1.0];
            let l = rgb(light[c * n + k]);
            for col in 0..3 {
                for row in 0..3 {
                    ann[col][row] += wt * (xn[row] * xn[col]);
                    bn[col][row] += wt * (l[row] * xn[col]);
                }
                for row in 0..4 {
                    aan[col][row] += wt * (xa[row] * xn[col]);
                }
            }
            for col in 0..4 {
                for row in 0..4 {
                    aaa[col][row] += wt * (xa[row] * xa[col]);
                }
                for row in 0..3 {
                    ba[col][row] += wt * (l[row] * xa[col]);
                }
            }
        }
    }
    let mut m = [0.0f32; REGRESSORS * (REGRESSORS + 1) / 2];
    let mut b = [[0.0f32; 3]; REGRESSORS];
    for i in 0..REGRESSORS {
        b[i] = if i < 3 { bn[i] } else { ba[i - 3] };
        for j in 0..=i {
            m[tri(i, j)] = if i < 3 {
                ann[j][i]
            } else if j < 3 {
                aan[j][i - 3]
            } else {
                aaa[j - 3][i - 3]
            };
        }
    }
    let last = REGRESSORS - 1;
    let total = m[tri(last, last)];
    let mean = b[last].map(|v| v / total);
    for i in 0..last {
        m[tri(i, i)] += params.ridge * m[tri(i, i)] + RIDGE_FLOOR * total;
    }
    for j in 0..REGRESSORS {
        let mut d = m[tri(j, j)];
        let mut yv = b[j];
        for k in 0..j {
            d -= m[tri(j, k)] * m[tri(j, k)];
            for ch in 0..3 {
                yv[ch] -= m[tri(j, k)] * b[k][ch];
            }
        }
        if d.is_nan() || d <= 0.0 {
            return mean;
        }
        let l = d.sqrt();
        m[tri(j, j)] = l;
        b[j] = yv.map(|v| v / l);
        for i in j + 1..REGRESSORS {
            let mut e = m[tri(i, j)];
            for k in 0..j {
                e -= m[tri(i, k)] * m[tri(j, k)];
            }
            m[tri(i, j)] = e / l;
        }
    }
    b[last].map(|v| v / m[tri(last, last)])
}

/// The denoised image (what [`Denoiser::apply`] returns).
pub fn denoise(input: &Input, params: &DenoiseParams) -> LinearImage {
    let (w, h) = (input.width as i32, input.height as i32);
    let n = (w * h) as usize;
    let s = input.samples.max(1) as f32;
    let gs = input.guide_samples.max(1) as f32;
    let albedo = |p: usize| {
        let g = at(input.guides, p);
        [g[0] / gs, g[1] / gs, g[2] / gs]
    };
    let emission = |p: usize| {
        let e = at(input.extra, 2 * n + p);
        [e[0] / gs, e[1] / gs, e[2] / gs]
    };
    // (light rgb, variance): direct at p, indirect at n + p.
    let mut light = vec![[0.0f32; 4]; 2 * n];
    for p in 0..n {
        let a = demodulation(albedo(p));
        let m = at(input.guides, 2 * n + p);
        let g = input.guide_samples as f32;
        let (fd, fi) = (at(input.film, FILM_DIRECT as usize * n + p), at(input.film, FILM_INDIRECT as usize * n + p));
        let e = emission(p);
        let reflected = [fd[0] / s - e[0], fd[1] / s - e[1], fd[2] / s - e[2]];
        light[p] = [reflected[0] / a[0], reflected[1] / a[1], reflected[2] / a[2], variance_of_mean(m[0], m[1], g)];
        light[n + p] = [fi[0] / s / a[0], fi[1] / s / a[1], fi[2] / s / a[2], variance_of_mean(m[2], m[3], g)];
    }
    let mut geometry = Geometry { normal: vec![[0.0; 3]; n], depth: vec![0.0; n] };
    for p in 0..n {
        let (g0, g1) = (at(input.guides, p), at(input.guides, n + p));
        let len = (g1[0] * g1[0] + g1[1] * g1[1] + g1[2] * g1[2]).sqrt();
        if g1[3] > 0.0 && len > 0.0 {
            geometry.normal[p] = [g1[0] / len, g1[1] / len, g1[2] / len];
            geometry.depth[p] = g0[3] / g1[3];
        }
    }
    let mut guide = light.clone();
    for level in 0..params.levels.min(LEVELS) {
        guide = atrous(input, params, &geometry, &guide, 1 << level);
    }
    let mut fits = vec![[0.0f32; 3]; 2 * n];
    for y in 0..h {
        for x in 0..w {
            let p = (y * w + x) as usize;
            for c in 0..2 {
                let l = light[c * n + p];
                fits[c * n + p] = if geometry.depth[p] > 0.0 {
                    fit(input, params, &geometry, (&guide, &light), (x, y, c))
                } else {
                    [l[0], l[1], l[2]]
                };
            }
        }
    }
    let pixels = (0..n)
        .map(|p| {
            let (a, e) = (demodulation(albedo(p)), emission(p));
            [0, 1, 2].map(|c| a[c] * (fits[p][c] + fits[n + p][c]) + e[c])
        })
        .collect();
    LinearImage { width: input.width, height: input.height, pixels }
}

/// The raw mean of the direct and indirect components (the image the filter starts from).
pub fn raw(input: &Input) -> LinearImage {
    let n = (input.width * input.height) as usize;
    let s = input.samples.max(1) as f32;
    let pixels = (0..n)
        .map(|p| {
            let (d, i) = (at(input.film, p), at(input.film, n + p));
            [0, 1, 2].map(|c| (d[c] + i[c]) / s)
        })
        .collect();
    LinearImage { width: input.width, height: input.height, pixels }
}

/// Film sums of `COMPONENTS` components expected by [`Input::film`].
pub const FILM_COMPONENTS: u64 = COMPONENTS;
