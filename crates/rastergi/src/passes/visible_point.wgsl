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

// Whether the visible point is light itself, as emitted_radiance sees it: the sky where the
// camera ray (or the eye's specular chain) escapes, or an emitter's front face.
fn sees_light(p: VisiblePoint) -> bool {
    return !p.seen || (p.front && any(p.x.emission > vec3f(0.0)));
}
