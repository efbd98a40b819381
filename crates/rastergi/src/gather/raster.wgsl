// Final gather projection (gather/raster.rs): each peeled layer projected onto the eye's
// visible points; the estimate is gather_estimate (estimator.wgsl).

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var layer: texture_2d<u32>;
// Per eye pixel: 1 once its gather ray for this direction is resolved (hit, miss or no
// contribution), so nearer layers no longer count.
@group(2) @binding(3) var<storage, read_write> found: array<u32>;
@group(2) @binding(4) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    let pixel = gid.y * frame.resolution.x + gid.x;
    if found[pixel] != 0u {
        return;
    }
    let w = gather.direction;
    let p = visible_point(textureLoad(gbuffer, gid.xy, 0));
    let cos_x = dot(p.n, w);
    if !p.ok || cos_x <= 0.0 {
        found[pixel] = 1u;
        return;
    }
    let l = textureLoad(layer, ray_view_texel(p.x.pos), 0);
    if l.x == 0u {
        // Nothing at this texel in this layer, hence in no nearer layer: the ray escapes.
        found[pixel] = 1u;
        return;
    }
    let tri = l.x - 1u;
    if tri == p.x.tri {
        return;
    }
    // Where x's ray meets the plane of the layer's triangle: in front of x, or not a hit.
    let dist = plane_distance(tri, p.x.pos, w);
    if dist <= frame.ray_epsilon {
        return;
    }
    found[pixel] = 1u;
    film_add(FILM_INDIRECT, gid.xy, texel_estimate(p, cos_x, w, tri, dist, pixel) / f32(gather.count));
}
