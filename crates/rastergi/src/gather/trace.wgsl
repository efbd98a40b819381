// Final gather by ray casting (gather/trace.rs): the nearest surface along each of the
// iteration's directions from each visible point, by BVH traversal, averaged over the
// directions. Shared directions (gather.per_pixel == 0): the uniforms' ω_k, each cast along
// whichever of ±ω_k lies above x's surface (gather_side), estimate gather_estimate. Per-pixel directions: ω_k cosine-distributed about n_x from the
// Owen-scrambled Sobol' point of index first_index + k with this pixel's scramble seed,
// estimate gather_estimate_cosine (estimator.wgsl).

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    start_alpha_stream();
    let p = visible_point_at(gid.xy);
    let pixel = gid.y * frame.resolution.x + gid.x;
    let per_pixel = gather.per_pixel != 0u;
    let seed = pixel_seed(gather.pixel_key, gid.x, gid.y);
    var sum = vec3f(0.0);
    // Rays that escape see the environment: direct light, kept with the direct pass's.
    var sky = vec3f(0.0);
    for (var k = 0u; k < gather.count && p.ok; k++) {
        var w = gather_side(p.n, gather.directions[k].xyz);
        if per_pixel {
            let u = sobol_owen_2d(gather.first_index + k, seed);
            w = cosine_hemisphere(p.ns, unit_f32(u.x), unit_f32(u.y));
        }
        let cos_x = gather_cosine(p, w);
        if cos_x <= 0.0 {
            continue;
        }
        // Nearest hit at t > ε, x's own triangle excluded (the raster gather's plane test).
        let h = trace(p.x.pos, w, frame.ray_epsilon, 3.0e38, p.x.tri, NO_TRIANGLE, false);
        if h.tri != NO_TRIANGLE {
            let hit = p.x.pos + w * h.t;
            let b = vec2f(h.b1, h.b2);
            let j = gather.first_index + k;
            if per_pixel {
                sum += gather_estimate_cosine(p, w, h.tri, hit, b, pixel, j);
            } else {
                sum += gather_estimate(p, cos_x, w, h.tri, hit, b, pixel, j);
            }
        } else {
            sky += escape_estimate(p, cos_x, w);
        }
    }
    film_add(FILM_INDIRECT, gid.xy, p.weight * (sum / f32(gather.count)));
    if has_environment() {
        film_add(FILM_DIRECT, gid.xy, p.weight * (sky / f32(gather.count)));
    }
}
