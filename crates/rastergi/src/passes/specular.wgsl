// Specular chains from the eye (specular.rs): a pixel whose G-buffer point is a perfect mirror
// or glass continues its camera ray through such surfaces, one direction drawn from the BSDF
// at each (for smooth ones a delta lobe: Fresnel's choice between reflection and refraction),
// to the first other surface: the pixel's visible point for every later pass, with the chain's
// throughput and the last ray's origin (eye_paths, frame.wgsl). At a surface with a delta lobe
// and other lobes too (polished plastic: a smooth layer over a diffuse base) the chain goes on
// by the delta lobe with the probability pd that bsdf_sample gives it (weight f/pd), and else
// stops there with weight 1/(1 − pd), where the passes evaluate its other lobes: each
// iteration one or the other, their mean the whole. A chain that leaves the scene adds the
// environment it sees (times its throughput) to the film's direct component; one that is
// absorbed or runs past MAX_CHAIN bounces ends with throughput 0.

// Bind group 2: gbuffer_film.wgsl.

const MAX_CHAIN: u32 = 16u;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let pixel = pixel_index(gid.xy);
    let base = 3u * pixel;
    let g = textureLoad(gbuffer, gid.xy, 0);
    // The second slot's w is the emitter-edges pass's (kept from one iteration to the next).
    let edge = eye_paths[base + 1u].w;
    eye_paths[base] = vec4f(frame.eye, 0.0);
    eye_paths[base + 1u] = vec4f(1.0, 1.0, 1.0, edge);
    eye_paths[base + 2u] = bitcast<vec4f>(g);
    if g.x == 0u {
        return;
    }
    var s = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
    var rng = rng_new(frame.seed ^ STREAM_EYE_CHAIN, pixel, frame.iteration);
    var d = normalize(s.pos - frame.eye);
    var o = frame.eye;
    var throughput = vec3f(1.0);
    // The surface the chain is at: the G-buffer's (hit = g), then each one it meets.
    var hit_g = g;
    for (var k = 0u; k < MAX_CHAIN; k++) {
        var u = vec3f(rng_f32(&rng), rng_f32(&rng), rng_f32(&rng));
        if !surface_passes_rays(s) {
            let choice = surface_delta_choice(s, d, rng_f32(&rng));
            if choice.u < 0.0 {
                // The visible point: here (the G-buffer's own where k = 0 and no delta lobe).
                if k > 0u || choice.pd > 0.0 {
                    eye_paths[base] = vec4f(o, 1.0);
                    eye_paths[base + 1u] = vec4f(throughput / (1.0 - choice.pd), edge);
                    eye_paths[base + 2u] = bitcast<vec4f>(hit_g);
                }
                return;
            }
            u.x = choice.u;
        }
        let sc = scatter_at(s, d, u, frame.ray_epsilon);
        if !sc.ok || !(sc.delta || surface_passes_rays(s)) {
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
        throughput *= segment_transmittance(hit.tri, d, hit.t);
        s = surface_at(hit.tri, hit.b1, hit.b2, 0.0);
        hit_g = vec4u(hit.tri + 1u, bitcast<u32>(hit.b1), bitcast<u32>(hit.b2), 0u);
    }
    // Escaped, absorbed or too long: nothing more reaches the pixel along this chain.
    eye_paths[base] = vec4f(o, 1.0);
    eye_paths[base + 1u] = vec4f(0.0, 0.0, 0.0, edge);
    eye_paths[base + 2u] = vec4f(0.0);
}
