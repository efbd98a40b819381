// Final gather estimator (gather.rs), shared by the raster projection (gather_project.wgsl)
// and the traced gather (gather_trace.wgsl).

struct Gather {
    // Raster: the ray view of `direction`, the direction being peeled.
    view_proj: mat4x4f,
    direction: vec3f,
    bundle: u32,
    // Directions this iteration; each estimate is weighted 1/count.
    count: u32,
    // Trace: all of them (xyz).
    directions: array<vec4f, 16>,
}

// A visible point that gathers: the surface and its normal on the side facing the eye.
struct GatherPoint {
    x: Surface,
    n: vec3f,
    // False where nothing is gathered: no surface, or the back of a one-sided surface.
    ok: bool,
}

fn gather_point(g: vec4u) -> GatherPoint {
    var p: GatherPoint;
    p.ok = false;
    if g.x == 0u {
        return p;
    }
    p.x = surface_at(g.x - 1u, bitcast<f32>(g.y), bitcast<f32>(g.z), bitcast<f32>(g.w));
    let front = dot(p.x.normal, frame.eye - p.x.pos) > 0.0;
    p.n = select(-p.x.normal, p.x.normal, front);
    p.ok = front || (p.x.flags & MATERIAL_TWO_SIDED) != 0u;
    return p;
}

// The ray-view texel that x projects to, like a shadow-map lookup (raster gathers).
fn ray_view_texel(x: vec3f) -> vec2u {
    let clip = gather.view_proj * vec4f(x, 1.0);
    let uv = vec2f(0.5 * clip.x + 0.5, 0.5 - 0.5 * clip.y) * f32(gather.bundle);
    return vec2u(clamp(vec2i(floor(uv)), vec2i(0), vec2i(i32(gather.bundle) - 1)));
}

// Distance along ω from x to the plane of triangle tri; negative when the ray runs parallel to
// it (raster gathers: a texel's surface counts where x's ray crosses its plane at t > ε).
fn plane_distance(tri: u32, x: vec3f, w: vec3f) -> f32 {
    let t = triangles[tri];
    let n_h = triangle_normal(t);
    let denom = dot(w, n_h);
    if abs(denom) < 1e-8 {
        return -1.0;
    }
    return dot(t.v0 - x, n_h) / denom;
}

// (ρ_x/π) · L(h → x) · cos θ_x · 4π for the hit point h on triangle tri at barycentrics b,
// cos θ_x = n·ω > 0: L(h → x) = ρ_h/π · E(h) on the side of h facing x, zero from the back of
// a one-sided h.
fn gather_estimate(p: GatherPoint, cos_x: f32, w: vec3f, tri: u32, hit: vec3f, b: vec2f) -> vec3f {
    let t = triangles[tri];
    let n_h = triangle_normal(t);
    let front_h = dot(w, n_h) < 0.0;
    if !front_h && (materials[t.material].flags & MATERIAL_TWO_SIDED) == 0u {
        return vec3f(0.0);
    }
    // ρ_h at the hit point itself, unfiltered (level 0), like every secondary point.
    let albedo_h = surface_at(tri, b.x, b.y, 0.0).albedo;
    let radiance_h = albedo_h / PI * photon_irradiance(hit, select(-n_h, n_h, front_h));
    return p.x.albedo / PI * radiance_h * (cos_x * 4.0 * PI);
}
