// Direct pass (direct.rs): emission + next-event estimation with BVH shadow rays.

// Bind group 2: gbuffer_film.wgsl.

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    let p = visible_point(textureLoad(gbuffer, gid.xy, 0));
    var radiance = vec3f(0.0);
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
            let u = light_sample_uniforms(frame.iteration * frame.light_samples + k, seed);
            sum += light_sample_irradiance(origin, n, s.tri, frame.ray_epsilon, u.x, u.y, u.z);
        }
        radiance += s.albedo / PI * sum / f32(frame.light_samples);
    }
    film_add(FILM_DIRECT, gid.xy, radiance);
}
