// Direct pass (direct.rs): emission, the environment seen by the eye, and next-event
// estimation with BVH shadow rays.

// Bind group 2: gbuffer_film.wgsl.

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = visible_point_at(gid.xy);
    var radiance = emitted_radiance(p, gid.xy);
    let glass = p.seen && p.x.transmission > 0.0;
    if has_lights() && (p.ok || glass) {
        let s = p.x;
        let n = p.n;
        let lambertian = surface_is_lambertian(s);
        // The scattering model in the shading frame on the eye's side.
        let v = visible_bsdf(p);
        // Sample k of iteration i has index i·L + k in the pixel's own sequence, whose seed
        // depends on (seed, pixel) only: a restart replays the same light samples.
        let seed = pixel_seed(pcg_hash(frame.seed ^ STREAM_DIRECT), gid.x, gid.y);
        var sum = vec3f(0.0);
        for (var k = 0u; k < frame.light_samples; k++) {
            let c = light_sample_uniforms(frame.iteration * frame.light_samples + k, seed);
            let l = sample_light_at(s.pos + n * frame.ray_epsilon, c);
            if all(l.e == vec3f(0.0)) {
                continue;
            }
            // The light's side by the geometric normal; the shading cosine must agree (light
            // from below the geometric surface counts only through glass).
            let below = dot(n, l.dir) <= 0.0;
            let wi = to_local(v.frame, l.dir);
            var f: vec3f;
            if lambertian {
                f = s.albedo / PI;
                if below || wi.z <= 0.0 {
                    continue;
                }
            } else {
                if (wi.z <= 0.0) != below || wi.z == 0.0 {
                    continue;
                }
                f = bsdf_eval(v.b, v.wo, wi, TRANSPORT_RADIANCE);
                if all(f == vec3f(0.0)) {
                    continue;
                }
            }
            let origin = s.pos + select(n, -n, below) * frame.ray_epsilon;
            if occluded(origin, l.dir, frame.ray_epsilon, l.dist * (1.0 - 1e-4), s.tri, l.tri) {
                continue;
            }
            // The environment is also found by the gather's escaping rays (env_gather_weight).
            var mis = 1.0;
            if l.pdf > 0.0 {
                mis = 1.0 - env_gather_weight(direct_gather_density(p, l.dir), l.dir);
            }
            sum += f * l.e * (abs(wi.z) * mis);
        }
        radiance += sum / f32(frame.light_samples);
    }
    film_add_seen(FILM_DIRECT, gid.xy, p.weight * (radiance), select(0.0, 1.0, sees_light(p)));
}
