// Final gather from per-texel fragment lists (gather_lists.rs): each visible point projects
// into the ray view and walks its texel's list; the nearest surface in front of it along ω is
// the fragment whose triangle's plane x's ray crosses first at t > ε. The estimate is
// gather_estimate (gather.wgsl).

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var<storage, read> heads: array<u32>;
@group(2) @binding(3) var<storage, read> nodes: array<vec2u>;
@group(2) @binding(4) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    let w = gather.direction;
    let p = gather_point(textureLoad(gbuffer, gid.xy, 0));
    let cos_x = dot(p.n, w);
    if !p.ok || cos_x <= 0.0 {
        return;
    }
    // Shadow-map style projection of x into the ray view.
    let clip = gather.view_proj * vec4f(p.x.pos, 1.0);
    let uv = vec2f(0.5 * clip.x + 0.5, 0.5 - 0.5 * clip.y) * f32(gather.bundle);
    let texel = vec2u(clamp(vec2i(floor(uv)), vec2i(0), vec2i(i32(gather.bundle) - 1)));
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
        let t = triangles[tri];
        let n_h = triangle_normal(t);
        let denom = dot(w, n_h);
        if abs(denom) < 1e-8 {
            continue;
        }
        // Where x's ray meets the plane of the fragment's triangle: in front of x, or not a hit.
        let dist = dot(t.v0 - p.x.pos, n_h) / denom;
        if dist > frame.ray_epsilon && dist < best {
            best = dist;
            best_tri = tri;
        }
    }
    if best_tri == NO_TRIANGLE {
        return;
    }
    let hit = p.x.pos + w * best;
    let b = plane_barycentrics(triangles[best_tri], hit);
    let pixel = gid.y * frame.resolution.x + gid.x;
    let n_pixels = frame.resolution.x * frame.resolution.y;
    film[n_pixels + pixel] += vec4f(gather_estimate(p, cos_x, w, best_tri, hit, b) / f32(gather.count), 0.0);
}
