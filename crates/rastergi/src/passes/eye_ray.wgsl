// The camera ray's texture footprint where the visible point is found by casting the camera
// ray (the path tracer's first hit, the ray-cast G-buffer: gbuffer_trace.wgsl) rather than by
// rasterizing, which measures it with screen-space derivatives.

// Texture coordinates where the ray (o, d) meets the plane of triangle `tri`.
fn plane_uv(tri: u32, o: vec3f, d: vec3f) -> vec2f {
    let t = triangles[tri];
    let n = cross(t.v1 - t.v0, t.v2 - t.v0);
    let b = plane_barycentrics(t, o + d * (dot(t.v0 - o, n) / dot(d, n)));
    return surface_uv(tri, b.x, b.y);
}

// The texture level of detail at the camera ray's hit on `tri` through pixel `xy`: the rays
// through the next pixel to the right and below meet the triangle's plane at texture
// coordinates that differ by what the G-buffer's screen-space derivatives measure (ray
// differentials, Igehy 1999).
fn primary_lod(tri: u32, xy: vec2u) -> f32 {
    let p = vec2f(xy) + 0.5;
    let uv = plane_uv(tri, frame.eye, camera_ray(p));
    let dx = plane_uv(tri, frame.eye, camera_ray(p + vec2f(1.0, 0.0))) - uv;
    let dy = plane_uv(tri, frame.eye, camera_ray(p + vec2f(0.0, 1.0))) - uv;
    let lod = albedo_lod(triangles[tri].material, dx, dy);
    return select(lod, 32.0, lod != lod);
}
