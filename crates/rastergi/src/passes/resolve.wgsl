// Resolve (film.rs): mean of the accumulated sums, blended with a preview's where one is
// given → linear RGB and display RGBA8 (`main`);
// or a linear image that is already a mean, such as the denoiser's, → the same two
// (`resolve_image`, with `film` bound to that image: one vec4 per pixel).

@group(0) @binding(0) var<uniform> params: Resolve;
@group(0) @binding(1) var<storage, read> film: array<vec4f>;
@group(0) @binding(2) var<storage, read_write> linear_out: array<vec4f>;
@group(0) @binding(3) var<storage, read_write> display_out: array<u32>;
// A preview's sums (a smaller image of the same view, the film's layout), blended in where
// params.preview_size is not 0 × 0; the film's own sums otherwise, unread.
@group(0) @binding(4) var<storage, read> preview: array<vec4f>;
// The history of the view before a camera move, re-projected (history.wgsl: rgb, w = 1 where
// valid, 2 where valid until the film has an iteration), blended in where
// params.history_weight > 0.
@group(0) @binding(5) var<storage, read> history: array<vec4f>;

// The film's layout, without the frame: `film_add` is not used here.
fn film_slot(component: u32, pixel: u32, n_pixels: u32) -> u32 {
    return component * n_pixels + pixel;
}

// The sRGB transfer function (IEC 61966-2-1).
fn srgb_encode(c: vec3f) -> vec3f {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3f(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3f(0.0031308));
}

// The display encoding of a linear value: 2^exposure · value, clamped, sRGB, 8 bits.
fn display_encode(mean: vec3f) -> u32 {
    let display = srgb_encode(clamp(mean * params.scale, vec3f(0.0), vec3f(1.0)));
    return pack4x8unorm(vec4f(display, 1.0));
}

// The sum of the shown component (the direct light, the indirect light, the photon-map view,
// or the first two added) at `pixel` of the film (its layout, `n` pixels). Only the planes
// shown are read: on a CPU adapter each load costs more than the arithmetic around it.
fn shown_film(pixel: u32, n: u32) -> vec3f {
    switch params.show {
        case 1u: { return film[film_slot(FILM_DIRECT, pixel, n)].rgb; }
        case 2u: { return film[film_slot(FILM_INDIRECT, pixel, n)].rgb; }
        case 3u: { return film[film_slot(FILM_PHOTON_VIEW, pixel, n)].rgb; }
        default: { return film[film_slot(FILM_DIRECT, pixel, n)].rgb + film[film_slot(FILM_INDIRECT, pixel, n)].rgb; }
    }
}

// The same of the preview's sums (rgb), with how much of its samples saw light (w: the direct
// component's fourth channel: per iteration 0 or 1, or on an emitter's edge the share of the
// pixel's sub-pixel rays that met light).
fn shown_preview(pixel: u32, n: u32) -> vec4f {
    let direct = preview[film_slot(FILM_DIRECT, pixel, n)];
    switch params.show {
        case 1u: { return direct; }
        case 2u: { return vec4f(preview[film_slot(FILM_INDIRECT, pixel, n)].rgb, direct.w); }
        case 3u: { return vec4f(preview[film_slot(FILM_PHOTON_VIEW, pixel, n)].rgb, direct.w); }
        default: { return vec4f(direct.rgb + preview[film_slot(FILM_INDIRECT, pixel, n)].rgb, direct.w); }
    }
}

// The preview at the centre of film pixel `xy`: its mean, bilinear over its pixels that hold
// an iteration and, where `own` ≥ 0 (the film pixel's share of light, known), whose share of
// light is the same; the share of the four taps' weight so taken; and whether the taps that
// hold an iteration straddle an edge of light (their shares of light differ).
struct PreviewTaps {
    mean: vec3f,
    weight: f32,
    edge: bool,
}

fn preview_mean(xy: vec2u, own: f32) -> PreviewTaps {
    let size = params.preview_size;
    let n = size.x * size.y;
    // The film pixel's centre in the preview's pixels, less ½: the taps' corner.
    let p = (vec2f(xy) + 0.5) * vec2f(size) / vec2f(params.resolution) - 0.5;
    let base = floor(p);
    let f = p - base;
    var sum = vec3f(0.0);
    var weight = 0.0;
    var light = vec2f(1.0, 0.0);
    for (var k = 0u; k < 4u; k++) {
        let o = vec2f(f32(k & 1u), f32(k >> 1u));
        let q = vec2u(clamp(base + o, vec2f(0.0), vec2f(size) - 1.0));
        let w = select(1.0 - f.x, f.x, o.x > 0.0) * select(1.0 - f.y, f.y, o.y > 0.0);
        let samples = params.preview_samples + select(0u, 1u, q.y < params.preview_rows_ahead);
        if samples > 0u && w > 0.0 {
            let v = shown_preview(q.y * size.x + q.x, n);
            let share = v.w / f32(samples);
            if own < 0.0 || share == own {
                sum += w * v.rgb / f32(samples);
                weight += w;
            }
            light = vec2f(min(light.x, share), max(light.y, share));
        }
    }
    if weight == 0.0 {
        return PreviewTaps(vec3f(0.0), 0.0, light.x < light.y);
    }
    return PreviewTaps(sum / weight, weight, light.x < light.y);
}

// The film's iterations at pixel xy (one more in the rows an iteration under way in bands has
// reached) and how much of their samples saw light itself — an emitter's front face, the sky:
// the direct component's fourth channel sums it (shown_preview).
fn light_count(xy: vec2u) -> vec2f {
    let n = params.samples + select(0u, 1u, xy.y < params.rows_ahead);
    let seen = film[film_slot(FILM_DIRECT, xy.y * params.resolution.x + xy.x, params.resolution.x * params.resolution.y)].w;
    return vec2f(seen, f32(n));
}

// Whether the film's samples show an edge of light at pixel xy: the shares of its 3 × 3
// neighbourhood's pixels (within the image) that hold an iteration differ from its own
// (compared as seen·n' ≠ seen'·n: exact, as the shares are multiples of the sub-pixel rays'
// 1/n² and nothing is blended past 256 iterations). Unrolled, each
// neighbour clamped to the image (which repeats pixels of the neighbourhood): a loop whose
// bounds vary by pixel costs a CPU adapter more than its loads.
fn film_light_edge(xy: vec2u, c: vec2f) -> bool {
    let hi = vec2i(params.resolution) - 1;
    var edge = false;
    for (var k = 0u; k < 9u; k++) {
        let q = light_count(vec2u(clamp(vec2i(xy) + vec2i(i32(k % 3u), i32(k / 3u)) - 1, vec2i(0), hi)));
        edge = edge || (q.y > 0.0 && q.x * c.y != c.x * q.y);
    }
    return edge;
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= params.resolution) {
        return;
    }
    let pixel = gid.y * params.resolution.x + gid.x;
    let n = params.resolution.x * params.resolution.y;
    // The film's iterations at this pixel: one more in the rows an iteration under way in
    // bands has reached.
    var total = shown_film(pixel, n);
    let iterations = f32(params.samples + select(0u, 1u, gid.y < params.rows_ahead));
    var weight = iterations;
    // Where the film's samples show an edge of an emitter or of the sky, its own estimate —
    // the emission supersampled there (emitter_edges.rs) — beats what is re-projected or
    // upscaled from another image, whose pixels straddle the edge elsewhere: once the film
    // has an iteration there, neither is blended in.
    let blending = params.history_weight > 0.0 || (params.preview_size.x > 0u && params.preview_weight > 0.0);
    let own = light_count(gid.xy);
    let edge = blending && iterations > 0.0 && film_light_edge(gid.xy, own);
    // Whether the view before the move is kept here (re-projected: the same side of the same
    // triangle at a point a fraction of a pixel away).
    var kept = false;
    if params.history_weight > 0.0 && !edge {
        // The history's weight h fades as 1/(1 + n/h) with the film's n iterations here; a
        // pixel the old view saw at an edge of light (w = 2) only until the film has one.
        let h = history[pixel];
        let valid = h.w == 1.0 || (h.w == 2.0 && iterations == 0.0);
        let w = select(0.0, params.history_weight, valid) / (1.0 + iterations / params.history_weight);
        total += w * h.rgb;
        weight += w;
        kept = valid;
    }
    if params.preview_size.x > 0u && params.preview_weight > 0.0 && !edge {
        // The preview's weight fades as (1 + n + h')⁻²: all of the image where nothing else
        // is known, a quarter of its weight at the first iteration, then gone before its blur
        // (a bias) could outlast the film's noise (which falls as 1/n). A preview pixel that
        // straddles an edge of light holds the emitter's or the sky's radiance (hundreds of
        // times the image's) over its whole area, which its upsampling spreads over window
        // pixels that do not see it: where the film's samples here agree with their
        // neighbours' on how much light they see (no edge), only the taps that see as much are
        // taken; where the film has no iteration here, taps that straddle an edge are left
        // out where the view before the move is kept (as sharp as the window's), and are all
        // there is otherwise.
        let share = select(-1.0, own.x / own.y, iterations > 0.0);
        let p = preview_mean(gid.xy, share);
        if share >= 0.0 || !(p.edge && kept) {
            let w = params.preview_weight * p.weight / ((1.0 + weight) * (1.0 + weight));
            total += w * p.mean;
            weight += w;
        }
    }
    let mean = select(total / weight, vec3f(0.0), weight == 0.0);
    linear_out[pixel] = vec4f(mean, 1.0);
    display_out[pixel] = display_encode(mean);
}

@compute @workgroup_size(8, 8)
fn resolve_image(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= params.resolution) {
        return;
    }
    let pixel = gid.y * params.resolution.x + gid.x;
    let mean = film[pixel].rgb;
    linear_out[pixel] = vec4f(mean, 1.0);
    display_out[pixel] = display_encode(mean);
}
