// Final gather from per-texel fragment lists (gather/lists.rs): each visible point projects
// into the ray view and walks its texel's list; the nearest surface in front of it along ω is
// the fragment whose triangle's plane x's ray crosses first at t > ε. The estimate is
// gather_estimate (estimator.wgsl).

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var<storage, read> heads: array<u32>;
@group(2) @binding(3) var<storage, read> nodes: array<vec2u>;
@group(2) @binding(4) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3u) {
    let gid = band_pixel(id);
    if !begin_pixel(gid.xy) { return; }
    let p = visible_point_at(gid.xy);
    // Both sides of the ray view serve: points below ω gather along −ω, whose nearest surface
    // is in the same texel's list (the projection along ±ω is the same).
    let w = gather_side(p.n, gather.direction);
    let cos_x = gather_cosine(p, w);
    if !p.ok || cos_x <= 0.0 {
        return;
    }
    let texel = ray_view_texel(p.x.pos);
    var best = 3.0e38;
    var best_tri = NO_TRIANGLE;
    var node = heads[texel.y * gather.bundle + texel.x];
    while node != 0u {
        let entry = nodes[node - 1u];
        node = entry.y;
        let tri = entry.x;
        if tri == p.x.tri {
            continue;
        }
        // Where x's ray meets the plane of the fragment's triangle: in front of x, or not a hit.
        let dist = plane_distance(tri, p.x.pos, w);
        if dist > frame.ray_epsilon && dist < best {
            best = dist;
            best_tri = tri;
        }
    }
    if best_tri == NO_TRIANGLE {
        film_add(FILM_DIRECT, gid.xy, p.weight * (escape_estimate(p, cos_x, w) / f32(gather.count)));
        return;
    }
    let pixel = pixel_index(gid.xy);
    film_add(FILM_INDIRECT, gid.xy, p.weight * (texel_estimate(p, cos_x, w, best_tri, best, pixel) / f32(gather.count)));
}
