// Direct pass (direct.rs): emission, the environment seen by the eye, and next-event
// estimation with BVH shadow rays.

// Bind group 2: gbuffer_film.wgsl.

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    start_alpha_stream();
    let p = visible_point(textureLoad(gbuffer, gid.xy, 0));
    var radiance = vec3f(0.0);
    if !p.seen {
        // The camera ray escapes: the environment along it (black without one).
        radiance = env_radiance(camera_direction(gid.xy));
    }
    if p.front {
        radiance = p.x.emission;
    }
    if has_lights() && p.ok {
        let s = p.x;
        let n = p.n;
        let origin = s.pos + n * frame.ray_epsilon;
        // Sample k of iteration i has index i·L + k in the pixel's own sequence, whose seed
        // depends on (seed, pixel) only: a restart replays the same light samples.
        let seed = pixel_seed(pcg_hash(frame.seed ^ STREAM_DIRECT), gid.x, gid.y);
        var sum = vec3f(0.0);
        for (var k = 0u; k < frame.light_samples; k++) {
            let c = light_sample_uniforms(frame.iteration * frame.light_samples + k, seed);
            let l = sample_light_at(origin, c);
            // Light from above the geometric surface only, weighed by the shading cosine.
            let cos_x = dot(p.ns, l.dir);
            if dot(n, l.dir) <= 0.0 || cos_x <= 0.0 || all(l.e == vec3f(0.0))
                || occluded(origin, l.dir, frame.ray_epsilon, l.dist * (1.0 - 1e-4), s.tri, l.tri) {
                continue;
            }
            // The environment is also found by the gather's escaping rays (env_gather_weight).
            var mis = 1.0;
            if l.pdf > 0.0 {
                mis = 1.0 - env_gather_weight(p.ns, l.dir);
            }
            sum += l.e * (cos_x * mis);
        }
        radiance += s.albedo / PI * sum / f32(frame.light_samples);
    }
    film_add(FILM_DIRECT, gid.xy, radiance);
}
