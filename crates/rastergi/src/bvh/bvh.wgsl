// Ray tracing's one interface, trace / occluded (the twins of Bvh::intersect / Bvh::occluded in
// bvh/mod.rs: the same hits), over `traverse`, which one of two files defines (gpu/accel.rs): the
// compute BVH (bvh_compute.wgsl) or the hardware ray query (bvh_hardware.wgsl).

struct RayHit {
    t: f32,
    tri: u32,
    b1: f32,
    b2: f32,
}

// Möller–Trumbore; returns (t, b1, b2) or t = -1 when the ray misses the triangle.
fn intersect_triangle(t: Triangle, o: vec3f, d: vec3f) -> vec3f {
    let e1 = t.v1 - t.v0;
    let e2 = t.v2 - t.v0;
    let p = cross(d, e2);
    let det = dot(e1, p);
    if abs(det) < 1e-20 {
        return vec3f(-1.0, 0.0, 0.0);
    }
    let inv_det = 1.0 / det;
    let s = o - t.v0;
    let b1 = dot(s, p) * inv_det;
    if b1 < 0.0 || b1 > 1.0 {
        return vec3f(-1.0, 0.0, 0.0);
    }
    let q = cross(s, e1);
    let b2 = dot(d, q) * inv_det;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return vec3f(-1.0, 0.0, 0.0);
    }
    return vec3f(dot(e2, q) * inv_det, b1, b2);
}

// Closest hit in (t_min, t_max), skipping triangles skip_a and skip_b and the points where a
// material lets the ray through (passes_through: cut-outs and stochastic opacity); any_hit:
// stop at the first. Returns tri = NO_TRIANGLE on a miss.
// The traversal itself counts every triangle as solid (its loop stays free of texture reads,
// which cost lavapipe a third of the traced gather's time even where no triangle has holes);
// a hit on a hole continues the ray from there, and an any-hit query that meets a hole walks
// the ray hit by hit from its start instead (an any hit is not the nearest).
fn trace(o: vec3f, d: vec3f, t_min: f32, t_max: f32, skip_a: u32, skip_b: u32, any_hit: bool) -> RayHit {
    count_ray();
    var lo = t_min;
    var passed = NO_TRIANGLE;
    var first = any_hit;
    for (var k = 0u; k < MAX_HOLE_CROSSINGS; k++) {
        let hit = traverse(o, d, lo, t_max, skip_a, skip_b, passed, first);
        if !SCENE_HOLES || hit.tri == NO_TRIANGLE || (triangles[hit.tri].flags & TRIANGLE_HAS_HOLES) == 0u
            || !passes_through(hit.tri, hit.b1, hit.b2, 0.0) {
            return hit;
        }
        if first {
            first = false;
        } else {
            lo = hit.t;
            passed = hit.tri;
        }
    }
    // More holes in a row than MAX_HOLE_CROSSINGS: the ray counts as stopped there.
    return traverse(o, d, lo, t_max, skip_a, skip_b, passed, false);
}

// Counts one query of `trace` where rays are counted (`--count-rays`): shader::for_rays then
// puts the counting one (gpu/ray_count.wgsl) in place of this empty body.
fn count_ray() {}

fn occluded(o: vec3f, d: vec3f, t_min: f32, t_max: f32, skip_a: u32, skip_b: u32) -> bool {
    return trace(o, d, t_min, t_max, skip_a, skip_b, true).tri != NO_TRIANGLE;
}

// One sample of next-event estimation: the irradiance at `origin` (just off triangle tri,
// geometric normal n, shading normal ns on the same side) from the light sample c
// (sample_light_at): e · cos θ_x with the shading cosine — for an emitter point y with area
// density p_A, Le · cos θ_x · cos θ_y / (|y − x|² p_A) — zero from below the geometric surface
// and where the segment (from t = eps) is occluded.
fn light_sample_irradiance(origin: vec3f, n: vec3f, ns: vec3f, tri: u32, eps: f32, c: LightChoice) -> vec3f {
    let l = sample_light_at(origin, c);
    let cos_x = dot(ns, l.dir);
    if dot(n, l.dir) <= 0.0 || cos_x <= 0.0 || all(l.e == vec3f(0.0))
        || occluded(origin, l.dir, eps, l.dist * (1.0 - 1e-4), tri, l.tri) {
        return vec3f(0.0);
    }
    return l.e * cos_x;
}
