// Reference path tracer (path_tracer.rs): one path per pixel per iteration, next-event
// estimation and BSDF sampling combined by multiple importance sampling (power heuristic).

// Film: component 0 of the accumulation receives the whole radiance estimate.
@group(2) @binding(0) var<storage, read_write> film: array<vec4f>;
@group(2) @binding(1) var<uniform> params: PathParams;
// (triangle + 1, b1 bits, b2 bits, 0) of the primary hit, written by `primary_hits` only.
@group(2) @binding(2) var<storage, read_write> visibility: array<vec4u>;

const FAR: f32 = 1e30;

// Density per unit area with which `sample_light` picks a point on an emitter of radiance le.
fn light_pdf_area(le: vec3f) -> f32 {
    return (le.r + le.g + le.b) / params.light_weight;
}

// One sample of the radiance arriving at `origin` from direction −dir (see path_tracer.rs
// for the estimator), for the camera ray through pixel `xy`. Textures are read filtered over
// the pixel's footprint at the first hit and unfiltered (level 0) at every later one. Random
// numbers per scattering event: 3 (light), 3 (BSDF), 1 (roulette).
//
// The fourth channel is 1 where the path meets the sky or an emitter's front face after smooth
// (delta) bounces only, the camera's light-seen flag (film_add_seen), else 0.
fn path_radiance(origin: vec3f, dir: vec3f, xy: vec2u, rng: ptr<function, u32>) -> vec4f {
    var radiance = vec3f(0.0);
    var seen = 0.0;
    var delta_chain = true;
    var throughput = vec3f(1.0);
    var o = origin;
    var d = dir;
    var t_min = 0.0;
    var skip = NO_TRIANGLE;
    // Solid-angle density of d under BSDF sampling; 0 for the camera ray (no light strategy).
    var last_pdf = 0.0;
    for (var bounce = 0u; ; bounce++) {
        let hit = trace(o, d, t_min, FAR, skip, NO_TRIANGLE, false);
        if hit.tri == NO_TRIANGLE {
            // The environment, weighted against the light sample at the previous vertex.
            if has_environment() {
                var w = 1.0;
                if last_pdf > 0.0 {
                    w = power_heuristic(last_pdf, environment.pmf * env_pdf(d));
                }
                radiance += throughput * env_radiance(d) * w;
            }
            seen = select(seen, 1.0, delta_chain);
            break;
        }
        throughput *= segment_transmittance(hit.tri, d, hit.t);
        var lod = 0.0;
        if bounce == 0u && frame.texture_footprint != 0u
            && (materials[triangles[hit.tri].material].material.flags & MATERIAL_TEXTURED) != 0u {
            lod = primary_lod(hit.tri, xy);
        }
        let s = surface_at(hit.tri, hit.b1, hit.b2, lod);
        let cos_in = -dot(s.normal, d);
        let front = cos_in > 0.0;
        // Emission of the front face, weighted against the light sample taken at the previous
        // vertex, which could have produced the same point with density p_light.
        if front && any(s.emission > vec3f(0.0)) {
            var w = 1.0;
            if last_pdf > 0.0 {
                let p_light = light_pdf_area(materials[triangles[hit.tri].material].material.emission) * hit.t * hit.t / cos_in;
                w = power_heuristic(last_pdf, p_light);
            }
            radiance += throughput * s.emission * w;
            seen = select(seen, 1.0, delta_chain);
        }
        // The back of a one-sided surface absorbs; glass is entered and left by either face.
        let glass = s.transmission > 0.0;
        if !front && (s.flags & MATERIAL_TWO_SIDED) == 0u && !glass {
            break;
        }
        if bounce >= params.max_bounces {
            break;
        }
        // The geometric normal on the side hit, and the shading frame on that side, bent
        // towards where the path came from: directions whose geometric and shading sides
        // disagree (light from below the surface, paths into it) do not count. Hit from
        // behind, a solid glass is left: its relative index inverts.
        let n = select(-s.normal, s.normal, front);
        let ns = bend_towards(select(-s.shading, s.shading, front), -d);
        let sf = shading_frame(ns);
        var b = surface_bsdf(s);
        if !front && !b.thin {
            b.ior = 1.0 / b.ior;
        }
        let wo = to_local(sf, -d);

        // Next-event estimation: a point y on the emitters, weighted against BSDF sampling.
        let u0 = rng_f32(rng);
        let u1 = rng_f32(rng);
        let u2 = rng_f32(rng);
        if params.light_count > 0u {
            let l = sample_light_at(s.pos + n * frame.ray_epsilon, light_choice(u0, u1, u2));
            let wi = to_local(sf, l.dir);
            let below = dot(n, l.dir) < 0.0;
            let x = s.pos + select(n, -n, below) * frame.ray_epsilon;
            let f = bsdf_eval(b, wo, wi, TRANSPORT_RADIANCE);
            if (wi.z < 0.0) == below && wi.z != 0.0 && any(f > vec3f(0.0)) && any(l.e > vec3f(0.0))
                && !occluded(x, l.dir, frame.ray_epsilon, l.dist * (1.0 - 1e-4), s.tri, l.tri) {
                // Against BSDF sampling where it could have found the same point: an emissive
                // triangle, its area density → solid angle at x, from the same formula as the
                // emitter hits above so that the two weights sum to one exactly. A punctual or
                // distant light is found by light samples only (weight 1); the environment
                // by BSDF samples that escape too.
                let p_bsdf = bsdf_pdf(b, wo, wi);
                var mis = 1.0;
                if l.pdf > 0.0 {
                    mis = power_heuristic(l.pdf, p_bsdf);
                } else if l.tri != NO_TRIANGLE {
                    let t = triangles[l.tri];
                    let cos_y = -dot(triangle_normal(t), l.dir);
                    let to_solid_angle = l.dist * l.dist / cos_y;
                    mis = power_heuristic(light_pdf_area(materials[t.material].material.emission) * to_solid_angle, p_bsdf);
                }
                radiance += throughput * f * l.e * (abs(wi.z) * mis);
            }
        }

        // Scattering: a direction from the BSDF, then Russian roulette by its weight.
        let v = vec3f(rng_f32(rng), rng_f32(rng), rng_f32(rng));
        let u_rr = rng_f32(rng);
        let bs = bsdf_sample(b, wo, v, TRANSPORT_RADIANCE);
        if !bs.ok {
            break;
        }
        let dir_world = sf * bs.wi;
        let below = dot(n, dir_world) < 0.0;
        if (bs.wi.z < 0.0) != below || dot(n, dir_world) == 0.0 {
            break;
        }
        var q = 1.0;
        if bounce >= params.rr_start {
            q = min(max(max(bs.weight.r, bs.weight.g), bs.weight.b), 1.0);
        }
        if u_rr >= q {
            break;
        }
        throughput *= bs.weight / q;
        // A specular bounce gives emitters it finds weight 1 (no light sample finds them).
        last_pdf = select(bs.pdf, 0.0, bs.delta);
        delta_chain = delta_chain && bs.delta;
        d = normalize(dir_world);
        o = s.pos + select(n, -n, below) * frame.ray_epsilon;
        t_min = frame.ray_epsilon;
        skip = s.tri;
    }
    return vec4f(radiance, seen);
}

// One path per pixel through this iteration's jittered pixel position, added to the film.
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if !begin_pixel(gid.xy) { return; }
    let pixel = pixel_index(gid.xy);
    var rng = rng_new(frame.seed ^ STREAM_PATH, pixel, frame.iteration);
    let r = path_radiance(frame.eye, camera_direction(gid.xy), gid.xy, &rng);
    // The path tracer has one component: the full image (resolved by Show::Full).
    film_add_seen(FILM_DIRECT, gid.xy, r.rgb, r.a);
}

// The first surface hit by each camera ray, in the G-buffer's format (gbuffer.wgsl).
@compute @workgroup_size(8, 8)
fn primary_hits(@builtin(global_invocation_id) gid: vec3u) {
    if !begin_pixel(gid.xy) { return; }
    let pixel = pixel_index(gid.xy);
    let hit = trace(frame.eye, camera_direction(gid.xy), 0.0, FAR, NO_TRIANGLE, NO_TRIANGLE, false);
    var v = vec4u(0u);
    if hit.tri != NO_TRIANGLE {
        v = vec4u(hit.tri + 1u, bitcast<u32>(hit.b1), bitcast<u32>(hit.b2), 0u);
    }
    visibility[pixel] = v;
}
