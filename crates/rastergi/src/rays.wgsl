// Ray kernel of `rastergi bench rays` (rays.rs): one invocation per ray, traced by `trace`
// (bvh.wgsl) exactly as the passes call it. The alpha stream keeps its seed 0 (the CPU twin's).

struct Ray {
    origin: vec3f,
    t_min: f32,
    dir: vec3f,
    t_max: f32,
    skip: u32,
    any_hit: u32,
    _pad: vec2u,
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
    var hit = trace(r.origin, r.dir, r.t_min, r.t_max, r.skip, NO_TRIANGLE, r.any_hit != 0u);
    if hit.tri == NO_TRIANGLE {
        hit = RayHit(0.0, NO_TRIANGLE, 0.0, 0.0);
    }
    hits[i] = hit;
}
