// Direct pass (direct.rs): emission + next-event estimation with BVH shadow rays.

// Bind group 2: gbuffer_film.wgsl.

// The position of a 32-bit fraction a inside the cdf interval [lo, cdf) of light entry e,
// rescaled to [0, 1): a fresh uniform for the point on the emitter that a picked (sample
// reuse), computed on the 32-bit offset so it keeps 24 significant bits however small the
// interval. Mirrors direct::remap_in_entry.
fn remap_in_entry(a: u32, e: u32) -> f32 {
    var lo = 0.0;
    if e > 0u {
        lo = lights[e - 1u].cdf;
    }
    // lo ≤ unit_f32(a) ≤ a / 2³² (the pick), so the offset does not wrap.
    let offset = a - u32(lo * 4294967296.0);
    return min(f32(offset) / ((lights[e].cdf - lo) * 4294967296.0), 0.99999994);
}

// The light sample (u0, u1, u2) of index j for the pixel's scramble seed: one Owen-scrambled
// Sobol' point (x, y); u0 = x picks the emitter, u1 = x's position within the emitter's
// interval, u2 = y (direct::light_sample_uniforms).
fn direct_light_uniforms(j: u32, seed: u32) -> vec3f {
    let p = sobol_owen_2d(j, seed);
    let u0 = unit_f32(p.x);
    return vec3f(u0, remap_in_entry(p.x, light_pick(u0)), unit_f32(p.y));
}

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
            let u = direct_light_uniforms(frame.iteration * frame.light_samples + k, seed);
            sum += light_sample_irradiance(origin, n, s.tri, frame.ray_epsilon, u.x, u.y, u.z);
        }
        radiance += s.albedo / PI * sum / f32(frame.light_samples);
    }
    film_add(FILM_DIRECT, gid.xy, radiance);
}
