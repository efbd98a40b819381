// The eye's visible point of a G-buffer texel (gbuffer.rs): (triangle + 1, b1, b2, λ), 0 where
// nothing is seen.

struct VisiblePoint {
    // The surface at the point (meaningful where `seen`).
    x: Surface,
    // Its geometric normal on the side facing the eye.
    n: vec3f,
    // Its shading normal on that side, bent towards the eye where it faces away from it
    // (bend_towards): what every estimate at the point weighs directions by.
    ns: vec3f,
    // The eye sees a surface here.
    seen: bool,
    // The eye sees the surface's front face.
    front: bool,
    // The side facing the eye reflects: a front face, or either face of a two-sided surface.
    ok: bool,
    // Where the point is seen from: the camera, or the last specular surface of the pixel's
    // eye chain (specular.wgsl).
    eye: vec3f,
    // What the point's estimates are weighed by: 1, or the eye chain's throughput.
    weight: vec3f,
}

// The visible point of pixel xy: the G-buffer's, or where a specular chain from the eye
// replaced it (eye_paths, frame.wgsl), the one the chain found.
fn visible_point_at(xy: vec2u) -> VisiblePoint {
    var g = textureLoad(gbuffer, xy, 0);
    var eye = frame.eye;
    var weight = vec3f(1.0);
    if SCENE_PASSES_RAYS && frame.eye_chains != 0u {
        let base = 3u * (xy.y * frame.resolution.x + xy.x);
        let e = eye_paths[base];
        if e.w > 0.0 {
            eye = e.xyz;
            weight = eye_paths[base + 1u].xyz;
            g = bitcast<vec4u>(eye_paths[base + 2u]);
        }
    }
    return visible_point(g, eye, weight);
}

fn visible_point(g: vec4u, eye: vec3f, weight: vec3f) -> VisiblePoint {
    var p: VisiblePoint;
    p.eye = eye;
    p.weight = weight;
    p.seen = g.x != 0u;
    p.front = false;
    p.ok = false;
    if !p.seen {
        return p;
    }
    p.x = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
    p.front = dot(p.x.normal, eye - p.x.pos) > 0.0;
    p.n = select(-p.x.normal, p.x.normal, p.front);
    p.ns = bend_towards(select(-p.x.shading, p.x.shading, p.front), normalize(eye - p.x.pos));
    p.ok = p.front || (p.x.flags & MATERIAL_TWO_SIDED) != 0u;
    return p;
}

// The scattering model at p, in the shading frame of p.ns, with the direction to the eye
// there: a solid glass seen from inside has its relative index inverted.
struct VisibleBsdf {
    b: Bsdf,
    frame: mat3x3f,
    wo: vec3f,
}

fn visible_bsdf(p: VisiblePoint) -> VisibleBsdf {
    let sf = shading_frame(p.ns);
    var b = surface_bsdf(p.x);
    if !p.front && !b.thin {
        b.ior = 1.0 / b.ior;
    }
    return VisibleBsdf(b, sf, to_local(sf, normalize(p.eye - p.x.pos)));
}

// The cosine that weighs direction w at x in the gather: the shading normal's, where w lies
// above the geometric surface (else 0: no light from below it, and no ray into it).
fn gather_cosine(p: VisiblePoint, w: vec3f) -> f32 {
    if dot(p.n, w) <= 0.0 {
        return 0.0;
    }
    return max(dot(p.ns, w), 0.0);
}

// The density of this iteration's final gather directions at p along w (solid angle), for
// the weights of multiple importance sampling against the direct pass's light samples: 0
// where the gather counts nothing (no gather, w below the geometric surface or the shading
// normal); shared directions (frame.gather_importance = 0) are uniform on the hemisphere,
// 1/2π; per-pixel ones follow the point's own scattering, cos θ/π on a Lambertian surface,
// else bsdf_pdf (its non-specular lobes, as gather_direction draws them).
fn gather_density(p: VisiblePoint, w: vec3f) -> f32 {
    let cos_s = dot(p.ns, w);
    if frame.gather_count == 0u || dot(p.n, w) <= 0.0 || cos_s <= 0.0 {
        return 0.0;
    }
    if frame.gather_importance == 0u {
        return 1.0 / (2.0 * PI);
    }
    if surface_is_lambertian(p.x) {
        return cos_s / PI;
    }
    let v = visible_bsdf(p);
    return bsdf_pdf(v.b, v.wo, to_local(v.frame, w));
}

// The radiance emitted towards the eye at pixel xy's visible point, before the eye chain's
// weight: an emitter's front face, or the environment where the camera ray escapes (black
// without one). The direct pass adds it to the film; the denoiser's guides sum it, to keep it
// out of the filter.
fn emitted_radiance(p: VisiblePoint, xy: vec2u) -> vec3f {
    var radiance = vec3f(0.0);
    if !p.seen {
        radiance = env_radiance(camera_direction(xy));
    }
    if p.front {
        radiance = p.x.emission;
    }
    return radiance;
}

// Emitter edges (passes/emitter_edges.rs). The emission the eye sees is a pixel's integral of a
// discontinuous function: one jittered sample an iteration gets an emitter's edge pixel all or
// nothing, an error of the order of the emitter's radiance that dominates an image's first
// iterations wherever an emitter or a bright sky is in view. Where the camera rays through the
// centres of a pixel's 3 × 3 neighbourhood (not jittered: a choice that does not depend on this
// iteration's random numbers) do not all see the same light, the pixel's own emission — what
// its first surface emits towards the eye, or the environment where the ray escapes — is
// estimated by frame.emitter_edges² stratified sub-pixel rays instead,
//
//   E ≈ (1/n²) Σ_ij Le(first hit of the ray through (x + (i + ξ_i)/n, y + (j + η_j)/n)),
//
// an unbiased estimate of the same box-filtered integral as the jittered sample's; every other
// pixel keeps the sample. Behind a mirror or glass the chain's emission is reflected light and
// stays with the sample.

// What the camera ray through image point q (pixels from the top-left corner, not jittered)
// first meets, as light: key 0 where nothing emits towards the eye, 1 the environment, 2 + m
// an emitter's front face of material m; the radiance; and whether it is light itself as
// sees_light counts it (an emitter's front face, or an escape: the environment even where
// it is black).
struct SeenLight {
    key: u32,
    radiance: vec3f,
    light: bool,
}

fn light_seen_through(q: vec2f) -> SeenLight {
    // camera_ray(q') meets the image plane at q' + jitter.
    let d = camera_ray(q - frame.jitter);
    let hit = trace(frame.eye, d, 0.0, 3.0e38, NO_TRIANGLE, NO_TRIANGLE, false);
    if hit.tri == NO_TRIANGLE {
        let e = env_radiance(d);
        return SeenLight(select(0u, 1u, any(e > vec3f(0.0))), e, true);
    }
    let s = surface_at(hit.tri, hit.b1, hit.b2, 0.0);
    if dot(s.normal, frame.eye - s.pos) > 0.0 && any(s.emission > vec3f(0.0)) {
        return SeenLight(min(2u + triangles[hit.tri].material, EDGE_FLAG - 1u), s.emission, true);
    }
    return SeenLight(0u, vec3f(0.0), false);
}

// Added to a pixel's key where it lies on an emitter's edge (its 3 × 3 neighbourhood's keys
// differ), by the emitter-edges passes, which keep both in the w of the pixel's second eye-path
// slot as a float (exact below 2²⁴: keys stay below EDGE_FLAG).
const EDGE_FLAG: u32 = 0x800000u;

// The key of pixel xy's centre.
fn edge_key(xy: vec2u) -> u32 {
    return u32(eye_paths[3u * pixel_index(xy) + 1u].w) & (EDGE_FLAG - 1u);
}

// Whether pixel xy lies on an emitter's edge.
fn on_emitter_edge(xy: vec2u) -> bool {
    return u32(eye_paths[3u * pixel_index(xy) + 1u].w) >= EDGE_FLAG;
}

// What pixel xy adds before any light is reflected: the emission its visible point p sends
// to the eye, times the eye chain's throughput (emitted_radiance), its own part estimated by
// sub-pixel rays on an emitter's edge (above); and the share of the pixel that sees light
// itself in this estimate — 0 or 1 from the jittered sample (sees_light), or on an edge the
// share of the sub-pixel rays that meet light as sees_light counts it (1 where the jittered
// sample sees it through a specular chain). The direct pass adds both to the film (the share to
// FILM_DIRECT's fourth channel: a pixel on an edge of light then shows that it straddles one,
// whatever its jittered sample met); the denoiser's guides sum the same radiance (the same
// random numbers).
struct SeenEmission {
    radiance: vec3f,
    light: f32,
}

fn seen_emission(p: VisiblePoint, xy: vec2u) -> SeenEmission {
    let point = p.weight * emitted_radiance(p, xy);
    let seen = select(0.0, 1.0, sees_light(p));
    let n = frame.emitter_edges;
    if n == 0u || !on_emitter_edge(xy) {
        return SeenEmission(point, seen);
    }
    // Behind a specular chain the point's emission is reflected light: it stays.
    let chain = any(p.eye != frame.eye);
    let e = select(vec3f(0.0), point, chain);
    var state = rng_new(frame.seed ^ STREAM_EMITTER_EDGE, pixel_index(xy), frame.iteration);
    var sum = vec3f(0.0);
    var hits = 0u;
    for (var i = 0u; i < n * n; i++) {
        let cell = vec2f(f32(i % n), f32(i / n));
        let u = (cell + vec2f(rng_f32(&state), rng_f32(&state))) / f32(n);
        let s = light_seen_through(vec2f(xy) + u);
        sum += s.radiance;
        hits += select(0u, 1u, s.light);
    }
    let share = select(f32(hits) / f32(n * n), 1.0, chain && seen > 0.0);
    return SeenEmission(e + sum / f32(n * n), share);
}

// Whether the visible point is light itself, as emitted_radiance sees it: the sky where the
// camera ray (or the eye's specular chain) escapes, or an emitter's front face.
fn sees_light(p: VisiblePoint) -> bool {
    return !p.seen || (p.front && any(p.x.emission > vec3f(0.0)));
}
