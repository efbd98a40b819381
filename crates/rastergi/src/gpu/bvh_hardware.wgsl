// The hardware path's `traverse` (accel.rs): a ray query over the scene's acceleration
// structures, one instance of one BLAS whose primitive k is triangle k. The geometry is not
// opaque, so the query offers every candidate triangle here: the skipped ones are passed over,
// the others intersected again by intersect_triangle (Möller–Trumbore, as the compute path and
// the CPU twin do) and committed where that test hits in (t_min, the best t so far), so the
// hit's t and barycentrics are the compute path's to the bit.

@group(0) @binding(15) var scene_tlas: acceleration_structure;

fn traverse(o: vec3f, d: vec3f, t_min: f32, t_max: f32, skip_a: u32, skip_b: u32, skip_c: u32, any_hit: bool) -> RayHit {
    var hit = RayHit(t_max, NO_TRIANGLE, 0.0, 0.0);
    var q: ray_query;
    // A ray query's interval must be finite (t_max may be +inf: the bench's unbounded rays).
    rayQueryInitialize(&q, scene_tlas, RayDesc(RAY_FLAG_NONE, 0xffu, t_min, min(t_max, 3.0e38), o, d));
    while rayQueryProceed(&q) {
        let k = rayQueryGetCandidateIntersection(&q).primitive_index;
        if k == skip_a || k == skip_b || k == skip_c {
            continue;
        }
        let r = intersect_triangle(triangles[k], o, d);
        if r.x > t_min && r.x < hit.t {
            hit = RayHit(r.x, k, r.y, r.z);
            rayQueryConfirmIntersection(&q);
            if any_hit {
                rayQueryTerminate(&q);
            }
        }
    }
    return hit;
}
