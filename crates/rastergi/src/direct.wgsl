// Direct pass (direct.rs): emission + next-event estimation with BVH shadow rays.

// Bind group 2: gbuffer_film.wgsl.

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    let pixel = gid.y * frame.resolution.x + gid.x;
    let p = visible_point(textureLoad(gbuffer, gid.xy, 0));
    var radiance = vec3f(0.0);
    if p.front {
        radiance = p.x.emission;
    }
    if has_lights() && p.ok {
        let s = p.x;
        let n = p.n;
        let origin = s.pos + n * frame.ray_epsilon;
        var rng = rng_new(frame.seed ^ STREAM_DIRECT, pixel, frame.iteration);
        var sum = vec3f(0.0);
        for (var k = 0u; k < frame.light_samples; k++) {
            let u0 = rng_f32(&rng);
            let u1 = rng_f32(&rng);
            let u2 = rng_f32(&rng);
            sum += light_sample_irradiance(origin, n, s.tri, frame.ray_epsilon, u0, u1, u2);
        }
        radiance += s.albedo / PI * sum / f32(frame.light_samples);
    }
    film_add(FILM_DIRECT, gid.xy, radiance);
}
