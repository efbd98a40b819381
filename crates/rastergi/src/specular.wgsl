// Specular chains from the eye (specular.rs): a pixel whose G-buffer point is a perfect mirror
// or glass continues its camera ray through such surfaces, one direction drawn from the BSDF
// at each (for smooth ones a delta lobe: Fresnel's choice between reflection and refraction),
// to the first other surface: the pixel's visible point for every later pass, with the chain's
// throughput and the last ray's origin (eye_paths, frame.wgsl). A chain that leaves the scene
// adds the environment it sees (times its throughput) to the film's direct component; one that
// is absorbed or runs past MAX_CHAIN bounces ends with throughput 0.

// Bind group 2: gbuffer_film.wgsl.

const MAX_CHAIN: u32 = 16u;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    start_alpha_stream();
    let pixel = gid.y * frame.resolution.x + gid.x;
    let base = 3u * pixel;
    let g = textureLoad(gbuffer, gid.xy, 0);
    eye_paths[base] = vec4f(frame.eye, 0.0);
    eye_paths[base + 1u] = vec4f(1.0, 1.0, 1.0, 0.0);
    eye_paths[base + 2u] = bitcast<vec4f>(g);
    if g.x == 0u {
        return;
    }
    var s = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
    if !surface_passes_rays(s) {
        return;
    }
    var rng = rng_new(frame.seed ^ STREAM_EYE_CHAIN, pixel, frame.iteration);
    var d = normalize(s.pos - frame.eye);
    var o = frame.eye;
    var throughput = vec3f(1.0);
    for (var k = 0u; k < MAX_CHAIN; k++) {
        let sc = scatter_at(s, d, vec3f(rng_f32(&rng), rng_f32(&rng), rng_f32(&rng)), frame.ray_epsilon);
        if !sc.ok {
            break;
        }
        throughput *= sc.weight;
        o = sc.origin;
        d = sc.dir;
        let hit = trace(o, d, frame.ray_epsilon, 3.0e38, s.tri, NO_TRIANGLE, false);
        if hit.tri == NO_TRIANGLE {
            film_add(FILM_DIRECT, gid.xy, throughput * env_radiance(d));
            break;
        }
        s = surface_at(hit.tri, hit.b1, hit.b2, 0.0);
        if !surface_passes_rays(s) {
            eye_paths[base] = vec4f(o, 1.0);
            eye_paths[base + 1u] = vec4f(throughput, 0.0);
            eye_paths[base + 2u] = bitcast<vec4f>(vec4u(hit.tri + 1u, bitcast<u32>(hit.b1), bitcast<u32>(hit.b2), 0u));
            return;
        }
    }
    // Escaped, absorbed or too long: nothing more reaches the pixel along this chain.
    eye_paths[base] = vec4f(o, 1.0);
    eye_paths[base + 1u] = vec4f(0.0);
    eye_paths[base + 2u] = vec4f(0.0);
}
