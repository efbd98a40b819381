// Final gather by ray casting (gather/trace.rs): the nearest surface along each of the
// iteration's directions from each visible point, by BVH traversal; the estimate is
// gather_estimate (estimator.wgsl), averaged over the directions.

@group(2) @binding(0) var<uniform> gather: Gather;
@group(2) @binding(1) var gbuffer: texture_2d<u32>;
@group(2) @binding(2) var<storage, read_write> film: array<vec4f>;

@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) gid: vec3u) {
    if any(gid.xy >= frame.resolution) {
        return;
    }
    let p = visible_point(textureLoad(gbuffer, gid.xy, 0));
    var sum = vec3f(0.0);
    for (var k = 0u; k < gather.count && p.ok; k++) {
        let w = gather.directions[k].xyz;
        let cos_x = dot(p.n, w);
        if cos_x <= 0.0 {
            continue;
        }
        // Nearest hit at t > ε, x's own triangle excluded (the raster gather's plane test).
        let h = trace(p.x.pos, w, frame.ray_epsilon, 3.0e38, p.x.tri, NO_TRIANGLE, false);
        if h.tri != NO_TRIANGLE {
            sum += gather_estimate(p, cos_x, w, h.tri, p.x.pos + w * h.t, vec2f(h.b1, h.b2), gid.y * frame.resolution.x + gid.x);
        }
    }
    film_add(FILM_INDIRECT, gid.xy, sum / f32(gather.count));
}
