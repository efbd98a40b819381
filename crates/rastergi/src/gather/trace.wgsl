// Final gather by ray casting (gather/trace.rs): the nearest surface along each of the
// iteration's directions from each visible point, by BVH traversal, averaged over the
// directions, each estimate f(ω_eye, w) cos θ_x / pdf(w) · L(h → x) (estimator.wgsl). Shared
// directions (gather.per_pixel == 0): the uniforms' ω_k, each cast along whichever of ±ω_k
// lies above x's surface (gather_side), pdf 1/2π. Per-pixel directions: drawn from x's own
// scattering (gather_direction: cosine-distributed on a Lambertian surface, by the BSDF
// elsewhere) with the Owen-scrambled Sobol' point of index first_index + k and this pixel's
// scramble seed, the lobe by a hash of (pixel, index); with the gather guide, on a Lambertian
// surface whose cell has learned, by one warp of the same point from the mixture of the cosine
// and the cell's table (guide.wgsl), and every ray's finding added to that table.

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = visible_point_at(gid.xy);
    let pixel = pixel_index(gid.xy);
    let per_pixel = gather.per_pixel != 0u;
    let seed = pixel_seed(gather.pixel_key, gid.x, gid.y);
    var sum = vec3f(0.0);
    // Rays that escape see the environment: direct light, kept with the direct pass's.
    var sky = vec3f(0.0);
    // The guide's cell of this visible point (guide.wgsl): what its rays learn goes there, and
    // where it has learned something, its directions are drawn from the guided mixture.
    var entry = NO_GUIDE;
    var total = 0.0;
    if per_pixel && frame.gather_guided != 0u && p.ok {
        entry = gather_guide_entry(gather_guide_key(p.x.pos, p.ns), true);
        total = gather_guide_total(entry);
    }
    // The guided sky's cell (sky_guide.wgsl): the escaping rays are weighed against the
    // direct pass's environment density there.
    var sky_entry = NO_GUIDE;
    var sky_total = 0.0;
    if p.ok {
        sky_entry = sky_guide_entry(p, false);
        sky_total = sky_guide_total(sky_entry);
    }
    for (var k = 0u; k < gather.count && p.ok; k++) {
        let j = gather.first_index + k;
        // The direction, the estimator's factor f cos θ_x / pdf, and the pdf the sky's two
        // estimates are weighed with.
        var w: vec3f;
        var weight = vec3f(0.0);
        var density = 0.0;
        if per_pixel {
            let s = sobol_owen_2d(j, seed);
            let u = vec2f(unit_f32(s.x), unit_f32(s.y));
            if gather_guided_at(p, total) {
                // One warp of the mixture of the cosine and the guide's table (guide.wgsl):
                // the pixel's own Sobol' points, still stratified.
                w = gather_guide_sample(entry, total, p.ns, u);
                density = guided_gather_density(p, entry, total, w);
                let cos_x = gather_cosine(p, w);
                if density > 0.0 && cos_x > 0.0 {
                    weight = visible_f(p, w) * (cos_x / density);
                }
            } else {
                var lobe = rng_new(frame.seed ^ STREAM_GATHER_LOBE, pixel, j);
                let d = gather_direction(p, u, rng_f32(&lobe));
                w = d.w;
                weight = d.weight;
                density = gather_density(p, w);
            }
        } else {
            // Uniform on the hemisphere: pdf 1/2π.
            w = gather_side(p.n, gather.directions[k].xyz);
            let cos_x = gather_cosine(p, w);
            if cos_x > 0.0 {
                weight = visible_f(p, w) * (cos_x * 2.0 * PI);
            }
            density = gather_density(p, w);
        }
        if all(weight == vec3f(0.0)) {
            continue;
        }
        // Nearest hit at t > ε, x's own triangle excluded (the raster gather's plane test).
        let h = trace(p.x.pos, w, frame.ray_epsilon, 3.0e38, p.x.tri, NO_TRIANGLE, false);
        if h.tri != NO_TRIANGLE {
            let found = gather_radiance(p.x.pos, w, h.tri, p.x.pos + w * h.t, vec2f(h.b1, h.b2), pixel, j);
            sum += weight * found;
            // The light of surfaces this ray found, for the guide (its luminance).
            gather_guide_learn(entry, p.ns, w, (found.r + found.g + found.b) / 3.0);
        } else {
            // An escaping ray brings no light from surfaces: the guide learns a zero there.
            gather_guide_learn(entry, p.ns, w, 0.0);
        }
        if h.tri == NO_TRIANGLE && has_environment() {
            let p_light = environment.pmf * sky_density(sky_entry, sky_total, w);
            sky += weight * env_radiance(w) * env_gather_weight(density, p_light);
        }
    }
    film_add(FILM_INDIRECT, gid.xy, p.weight * (sum / f32(gather.count)));
    if has_environment() {
        film_add(FILM_DIRECT, gid.xy, p.weight * (sky / f32(gather.count)));
    }
}
