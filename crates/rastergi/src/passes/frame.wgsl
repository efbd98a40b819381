// Per-iteration uniforms, bind group 1 (frame.rs).

@group(1) @binding(0) var<uniform> frame: Frame;
// Per pixel, written by the specular chains (specular.wgsl) where frame.eye_chains is set:
// [3p] the origin of the ray that found the visible point (w = 1 where a chain replaced the
// G-buffer's point), [3p + 1] the chain's throughput, [3p + 2] the visible point in the
// G-buffer's format, bitcast (tri + 1, b1, b2, λ).
@group(1) @binding(1) var<storage, read_write> eye_paths: array<vec4f>;

// Starts this iteration's stream of stochastic opacity (alpha_seed, passes_through).
fn start_alpha_stream() {
    alpha_seed = pcg_hash(frame.seed ^ pcg_hash(frame.iteration));
}

// The pixel of invocation `id` of a per-pixel dispatch: the dispatch covers the rows from
// frame.band_y0 on (an iteration run as row bands; 0 for a whole iteration).
fn band_pixel(id: vec3u) -> vec3u {
    return vec3u(id.x, id.y + frame.band_y0, id.z);
}

// Begins the invocation of pixel `xy` in a pass of 8×8 workgroups: false where the workgroups
// overhang the image or the dispatch's rows (the invocation returns at once); inside, starts
// the alpha stream.
fn begin_pixel(xy: vec2u) -> bool {
    if any(xy >= frame.resolution) || xy.y >= frame.band_y0 + frame.band_rows {
        return false;
    }
    start_alpha_stream();
    return true;
}

// The row-major index of pixel `xy` in the film and the per-pixel buffers.
fn pixel_index(xy: vec2u) -> u32 {
    return xy.y * frame.resolution.x + xy.x;
}

// The unit direction of the camera ray through the point p (in pixels, from the top-left
// corner) of the jittered view. Clip (x, y, 0, 1) is the point at infinity in reversed-Z, so
// the inverse view-projection maps it to the homogeneous world point (direction, 0), the same
// ray the rasterizer's pixel sees.
fn camera_ray(p: vec2f) -> vec3f {
    let res = vec2f(frame.resolution);
    let ndc = vec2f(2.0 * p.x / res.x - 1.0, 1.0 - 2.0 * p.y / res.y);
    return normalize((frame.inv_view_proj * vec4f(ndc, 0.0, 1.0)).xyz);
}

// The camera ray through the centre of pixel `xy`.
fn camera_direction(xy: vec2u) -> vec3f {
    return camera_ray(vec2f(xy) + 0.5);
}

// The power heuristic (β = 2) weight of the strategy with density pa against pb (each the
// sample count × the density).
fn power_heuristic(pa: f32, pb: f32) -> f32 {
    let a = pa * pa;
    return a / (a + pb * pb);
}

// The environment's light along w at a visible point is estimated twice: by the direct
// pass's light samples (frame.light_samples of them, density p_light = pmf·p(w), p the
// environment's pdf or the guided sky's mixture, env_light_density) and by the final gather's
// rays that escape (frame.gather_count of them, density p_gather = gather_density). Each
// estimate is weighted by the power heuristic over both (Veach's multi-sample model), so the
// weights sum to one for every direction. This is the gather's weight; the direct pass's is
// 1 − it.
fn env_gather_weight(p_gather: f32, p_light: f32) -> f32 {
    if p_gather <= 0.0 {
        return 0.0;
    }
    return power_heuristic(f32(frame.gather_count) * p_gather, f32(frame.light_samples) * p_light);
}
