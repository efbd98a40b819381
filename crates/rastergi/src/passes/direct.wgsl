// Direct pass (direct.rs): emission, the environment seen by the eye, and next-event
// estimation with BVH shadow rays.

// Bind group 2: gbuffer_film.wgsl.

// One light sample l's estimate at visible point p (surface s, geometric normal n, its
// scattering v), xyz; w: the sample's openness V·|cos θ| (0 where it adds nothing), what the
// guided sky learns.
fn light_estimate(p: VisiblePoint, v: VisibleBsdf, l: LightRay) -> vec4f {
    let s = p.x;
    let n = p.n;
    if all(l.e == vec3f(0.0)) {
        return vec4f(0.0);
    }
    // The light's side by the geometric normal; the shading cosine must agree (light from
    // below the geometric surface counts only through glass).
    let below = dot(n, l.dir) <= 0.0;
    let wi = to_local(v.frame, l.dir);
    var f: vec3f;
    if surface_is_lambertian(s) {
        f = s.albedo / PI;
        if below || wi.z <= 0.0 {
            return vec4f(0.0);
        }
    } else {
        if (wi.z <= 0.0) != below || wi.z == 0.0 {
            return vec4f(0.0);
        }
        f = bsdf_eval(v.b, v.wo, wi, TRANSPORT_RADIANCE);
        if all(f == vec3f(0.0)) {
            return vec4f(0.0);
        }
    }
    let origin = s.pos + select(n, -n, below) * frame.ray_epsilon;
    if occluded(origin, l.dir, frame.ray_epsilon, l.dist * (1.0 - 1e-4), s.tri, l.tri) {
        return vec4f(0.0);
    }
    // The environment is also found by the gather's escaping rays (env_gather_weight).
    var mis = 1.0;
    if l.pdf > 0.0 {
        mis = 1.0 - env_gather_weight(direct_gather_density(p, l.dir), l.pdf);
    }
    return vec4f(f * l.e * (abs(wi.z) * mis), abs(wi.z));
}

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = visible_point_at(gid.xy);
    // The light reflected towards the eye, before the eye chain's weight.
    var reflected = vec3f(0.0);
    // Σ over the light samples of their estimates and of their squares (sample variance).
    var sum = vec3f(0.0);
    var squares = vec3f(0.0);
    let glass = p.seen && p.x.transmission > 0.0;
    if has_lights() && (p.ok || glass) {
        // The scattering model in the shading frame on the eye's side.
        let v = visible_bsdf(p);
        // Sample k of iteration i has index b_i + k in the pixel's own sequence (b_i the light
        // samples of the iterations before: i·L for a fixed count L), whose seed
        // depends on (seed, pixel) only: a restart replays the same light samples.
        let seed = pixel_seed(pcg_hash(frame.seed ^ STREAM_DIRECT), gid.x, gid.y);
        // The guided sky's cell of this point (sky_guide.wgsl; NO_GUIDE where it is off): its
        // environment samples come from the guided mixture where the cell has learned a
        // table, and each teaches it how open its direction is.
        let sky = sky_guide_entry(p, true);
        let sky_total = sky_guide_total(sky);
        let origin = p.x.pos + p.n * frame.ray_epsilon;
        for (var k = 0u; k < frame.light_samples; k++) {
            let index = frame.light_base + k;
            let c = light_sample_uniforms(index, seed);
            var l = sample_light_at(origin, c);
            let env = l.pdf > 0.0 && sky != NO_GUIDE;
            if env {
                l = sky_guided_light(l, vec2f(c.u1, c.u2), sky, sky_total);
            }
            let estimate = light_estimate(p, v, l);
            sum += estimate.xyz;
            squares += estimate.xyz * estimate.xyz;
            if env {
                sky_guide_learn(sky, l.dir, estimate.w);
            }
        }
        reflected += sum / f32(frame.light_samples);
    }
    let emitted = seen_emission(p, gid.xy);
    film_add_seen(FILM_DIRECT, gid.xy, emitted.radiance + p.weight * reflected, emitted.light);
    // One light sample's variance at this visible point, estimated from this iteration's k:
    // s² = (Σe² − (Σe)²/k)/(k − 1) per channel, times the path's weight², summed over the
    // channels (the light budget's D, passes/light_budget.rs).
    let k = f32(frame.light_samples);
    if frame.light_samples > 1u {
        let s2 = max(squares - sum * sum / k, vec3f(0.0)) / (k - 1.0);
        film_add_light_variance(gid.xy, dot(p.weight * p.weight, s2));
    }
}
