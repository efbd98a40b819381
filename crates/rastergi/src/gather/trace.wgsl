// Final gather by ray casting (gather/trace.rs): the nearest surface along each of the
// iteration's directions from each visible point, by BVH traversal, averaged over the
// directions, each estimate f(ω_eye, w) cos θ_x / pdf(w) · L(h → x) (estimator.wgsl). Shared
// directions (gather.per_pixel == 0): the uniforms' ω_k, each cast along whichever of ±ω_k
// lies above x's surface (gather_side), pdf 1/2π. Per-pixel directions: drawn from x's own
// scattering (gather_direction: cosine-distributed on a Lambertian surface, by the BSDF
// elsewhere) with the Owen-scrambled Sobol' point of index first_index + k and this pixel's
// scramble seed, the lobe by a hash of (pixel, index).

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if !begin_pixel(gid.xy) { return; }
    let p = visible_point_at(gid.xy);
    let pixel = pixel_index(gid.xy);
    let per_pixel = gather.per_pixel != 0u;
    let seed = pixel_seed(gather.pixel_key, gid.x, gid.y);
    var sum = vec3f(0.0);
    // Rays that escape see the environment: direct light, kept with the direct pass's.
    var sky = vec3f(0.0);
    for (var k = 0u; k < gather.count && p.ok; k++) {
        let j = gather.first_index + k;
        // The direction and the estimator's factor f cos θ_x / pdf.
        var w: vec3f;
        var weight = vec3f(0.0);
        if per_pixel {
            let u = sobol_owen_2d(j, seed);
            var lobe = rng_new(frame.seed ^ STREAM_GATHER_LOBE, pixel, j);
            let d = gather_direction(p, vec2f(unit_f32(u.x), unit_f32(u.y)), rng_f32(&lobe));
            w = d.w;
            weight = d.weight;
        } else {
            // Uniform on the hemisphere: pdf 1/2π.
            w = gather_side(p.n, gather.directions[k].xyz);
            let cos_x = gather_cosine(p, w);
            if cos_x > 0.0 {
                weight = visible_f(p, w) * (cos_x * 2.0 * PI);
            }
        }
        if all(weight == vec3f(0.0)) {
            continue;
        }
        // Nearest hit at t > ε, x's own triangle excluded (the raster gather's plane test).
        let h = trace(p.x.pos, w, frame.ray_epsilon, 3.0e38, p.x.tri, NO_TRIANGLE, false);
        if h.tri != NO_TRIANGLE {
            sum += weight * gather_radiance(p.x.pos, w, h.tri, p.x.pos + w * h.t, vec2f(h.b1, h.b2), pixel, j);
        } else {
            sky += escape_estimate_weighted(p, weight, w);
        }
    }
    film_add(FILM_INDIRECT, gid.xy, p.weight * (sum / f32(gather.count)));
    if has_environment() {
        film_add(FILM_DIRECT, gid.xy, p.weight * (sky / f32(gather.count)));
    }
}
