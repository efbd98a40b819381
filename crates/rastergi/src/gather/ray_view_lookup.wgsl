// A visible point's lookup in the ray view (gather/ray_view.rs), for the raster gathers'
// compute passes: the texel it projects to and the plane test of the texel's triangle.

// The ray-view texel that x projects to, like a shadow-map lookup.
fn ray_view_texel(x: vec3f) -> vec2u {
    let clip = gather.view_proj * vec4f(x, 1.0);
    let uv = vec2f(0.5 * clip.x + 0.5, 0.5 - 0.5 * clip.y) * f32(gather.bundle);
    return vec2u(clamp(vec2i(floor(uv)), vec2i(0), vec2i(i32(gather.bundle) - 1)));
}

// plane_distance where the ray runs parallel to the plane: below any real distance.
const PLANE_PARALLEL: f32 = -3.0e38;

// Distance along ω from x to the plane of triangle tri (negative: the plane crosses x's line
// behind x), PLANE_PARALLEL where the ray runs parallel to it (a texel's surface counts where
// x's ray crosses its plane at t > ε).
fn plane_distance(tri: u32, x: vec3f, w: vec3f) -> f32 {
    let t = triangles[tri];
    let n_h = triangle_normal(t);
    let denom = dot(w, n_h);
    if abs(denom) < 1e-8 {
        return PLANE_PARALLEL;
    }
    return dot(t.v0 - x, n_h) / denom;
}

// Whether barycentrics b (of a plane crossing) lie on the triangle, with a margin of 10⁻⁴
// for rounding: a crossing off the triangle means the texel's surface is not what x's ray
// meets (a silhouette crosses the texel), and the gather traces that ray instead.
fn on_triangle(b: vec2f) -> bool {
    let m = 1e-4;
    return b.x >= -m && b.y >= -m && b.x + b.y <= 1.0 + m;
}

// The exact nearest hit along ω from x (BVH), for the rays a texel cannot answer: the
// estimate; where the ray escapes, zero, and the environment's estimate goes to the pixel's
// direct light (as every escaping gather ray's does).
fn traced_estimate(p: VisiblePoint, cos_x: f32, w: vec3f, pixel: u32, j: u32) -> vec3f {
    let h = trace(p.x.pos, w, frame.ray_epsilon, 3.0e38, p.x.tri, NO_TRIANGLE, false);
    if h.tri == NO_TRIANGLE {
        let texel = vec2u(pixel % frame.resolution.x, pixel / frame.resolution.x);
        film_add(FILM_DIRECT, texel, p.weight * (escape_estimate(p, cos_x, w) / f32(gather.count)));
        return vec3f(0.0);
    }
    return gather_estimate(p, cos_x, w, h.tri, p.x.pos + w * h.t, vec2f(h.b1, h.b2), pixel, j);
}

// The estimate for the texel surface tri whose plane x's ray crosses at distance dist: at
// that crossing where it lies on the triangle, else by tracing the ray (traced_estimate).
// The ray view's direction has sample index first_index + current (the hit's light sample).
fn texel_estimate(p: VisiblePoint, cos_x: f32, w: vec3f, tri: u32, dist: f32, pixel: u32) -> vec3f {
    let hit = p.x.pos + w * dist;
    let b = plane_barycentrics(triangles[tri], hit);
    let j = gather.first_index + gather.current;
    if on_triangle(b) {
        return gather_estimate(p, cos_x, w, tri, hit, b, pixel, j);
    }
    return traced_estimate(p, cos_x, w, pixel, j);
}
