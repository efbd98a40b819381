// The compute path's `traverse` (accel.rs): the compressed 4-wide BVH walked step for step as
// intersect_wide in bvh/wide.rs (the tree the scene binds).

// The sort key of a child slot the ray does not enter.
const NOT_ENTERED: f32 = 3.0e38;

// The four bytes of w, lowest first.
fn node_bytes(w: u32) -> vec4u {
    return (vec4u(w) >> vec4u(0u, 8u, 16u, 24u)) & vec4u(255u);
}

// The corners of a compressed node's four child boxes on one axis: origin + q · step, exact
// as on the CPU (q · step is exact, the sum rounded once; WideNode::boxes).
fn node_corners(origin: f32, q: u32, step: f32) -> vec4f {
    return vec4f(origin) + vec4f(node_bytes(q)) * step;
}

// The closest (any_hit: the first found) triangle hit in (t_min, t_max) other than skip_a,
// skip_b and skip_c, holes or not: the compressed 4-wide tree (bvh/wide.rs, whose
// intersect_wide is this loop's CPU twin), each node's four boxes decoded and slab-tested at
// once; its leaves' triangles tested first (a hit shortens the ray), then its interior
// children pushed farthest first, so the nearest is walked next. Each field is read on its
// own, so the node's padding is never loaded.
fn traverse(o: vec3f, d: vec3f, t_min: f32, t_max: f32, skip_a: u32, skip_b: u32, skip_c: u32, any_hit: bool) -> RayHit {
    var hit = RayHit(t_max, NO_TRIANGLE, 0.0, 0.0);
    let inv = 1.0 / d;
    var stack: array<u32, 64>;
    var sp = 0u;
    var node = 0u;
    loop {
        let p = bvh_nodes[node].origin;
        let lo = bvh_nodes[node].lo;
        let hi = bvh_nodes[node].hi;
        let step = bitcast<vec3f>(((vec3u(bvh_nodes[node].exponents) >> vec3u(0u, 8u, 16u)) & vec3u(255u)) << vec3u(23u));
        let count = node_bytes(bvh_nodes[node].counts);
        let children = bvh_nodes[node].child;
        let t0x = (node_corners(p.x, lo.x, step.x) - o.x) * inv.x;
        let t1x = (node_corners(p.x, hi.x, step.x) - o.x) * inv.x;
        let t0y = (node_corners(p.y, lo.y, step.y) - o.y) * inv.y;
        let t1y = (node_corners(p.y, hi.y, step.y) - o.y) * inv.y;
        let t0z = (node_corners(p.z, lo.z, step.z) - o.z) * inv.z;
        let t1z = (node_corners(p.z, hi.z, step.z) - o.z) * inv.z;
        let near = max(max(min(t0x, t1x), min(t0y, t1y)), max(min(t0z, t1z), vec4f(t_min)));
        let far = min(min(max(t0x, t1x), max(t0y, t1y)), max(t0z, t1z));
        let leaves = (count != vec4u(0u)) & (count != vec4u(NO_CHILD & 255u)) & (near <= min(far, vec4f(hit.t)));
        if any(leaves) {
            for (var i = 0u; i < 4u; i++) {
                if !leaves[i] || near[i] > hit.t {
                    continue;
                }
                let first = children[i];
                for (var k = first; k < first + count[i]; k++) {
                    if k == skip_a || k == skip_b || k == skip_c {
                        continue;
                    }
                    let r = intersect_triangle(triangles[k], o, d);
                    if r.x > t_min && r.x < hit.t {
                        hit = RayHit(r.x, k, r.y, r.z);
                        if any_hit {
                            return hit;
                        }
                    }
                }
            }
        }
        // The interior children the ray enters before its current end, sorted by entry
        // distance (a sorting network on the four slots; a slot left out sorts last).
        let inner = (count == vec4u(0u)) & (near <= min(far, vec4f(hit.t)));
        var k = select(vec4f(NOT_ENTERED), near, inner);
        var c = children;
        if k.y < k.x { k = k.yxzw; c = c.yxzw; }
        if k.w < k.z { k = k.xywz; c = c.xywz; }
        if k.z < k.x { k = k.zyxw; c = c.zyxw; }
        if k.w < k.y { k = k.xwzy; c = c.xwzy; }
        if k.z < k.y { k = k.xzyw; c = c.xzyw; }
        if k.w < NOT_ENTERED { stack[sp] = c.w; sp += 1u; }
        if k.z < NOT_ENTERED { stack[sp] = c.z; sp += 1u; }
        if k.y < NOT_ENTERED { stack[sp] = c.y; sp += 1u; }
        if k.x < NOT_ENTERED {
            node = c.x;
            continue;
        }
        if sp == 0u {
            break;
        }
        sp -= 1u;
        node = stack[sp];
    }
    return hit;
}

