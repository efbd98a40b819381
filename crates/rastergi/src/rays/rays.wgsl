// Ray kernel of `rastergi bench rays` (rays/mod.rs): one invocation per ray, traced by `trace`
// (bvh.wgsl) exactly as the passes call it. The alpha stream keeps its seed 0 (the CPU twin's).

// origin: xyz and t_min; dir: xyz and t_max; skip_any: the triangle to skip, any hit (1).
struct Ray {
    origin: vec4f,
    dir: vec4f,
    skip_any: vec4u,
}

@group(1) @binding(0) var<storage, read> rays: array<Ray>;
@group(1) @binding(1) var<storage, read_write> hits: array<RayHit>;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3u, @builtin(num_workgroups) n: vec3u) {
    let i = gid.x + gid.y * n.x * 64u;
    if i >= arrayLength(&rays) {
        return;
    }
    let r = rays[i];
    var hit = trace(r.origin.xyz, r.dir.xyz, r.origin.w, r.dir.w, r.skip_any.x, NO_TRIANGLE, r.skip_any.y != 0u);
    if hit.tri == NO_TRIANGLE {
        hit = RayHit(0.0, NO_TRIANGLE, 0.0, 0.0);
    }
    hits[i] = hit;
}
