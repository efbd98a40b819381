// The final gather's estimators (gather/estimator.rs), shared by the raster projection
// (raster.wgsl), the list walk (lists.wgsl) and the traced gather (trace.wgsl). A visible
// point gathers where it is `ok` (visible_point.wgsl).

// L(h → x) for the hit point h on triangle tri at barycentrics b, seen along w from x:
// ρ_h/π · E(h) on the side of h facing x, zero from the back of a one-sided h.
fn gather_radiance(w: vec3f, tri: u32, hit: vec3f, b: vec2f) -> vec3f {
    let t = triangles[tri];
    let n_h = triangle_normal(t);
    let front_h = dot(w, n_h) < 0.0;
    if !front_h && (materials[t.material].flags & MATERIAL_TWO_SIDED) == 0u {
        return vec3f(0.0);
    }
    // ρ_h at the hit point itself, unfiltered (level 0), like every secondary point.
    let albedo_h = surface_at(tri, b.x, b.y, 0.0).albedo;
    return albedo_h / PI * photon_irradiance(hit, tri, !front_h);
}

// Shared directions, uniform on the sphere (pdf 1/4π): (ρ_x/π) · L(h → x) · cos θ_x · 4π,
// cos θ_x = n·ω > 0.
fn gather_estimate(p: VisiblePoint, cos_x: f32, w: vec3f, tri: u32, hit: vec3f, b: vec2f) -> vec3f {
    return p.x.albedo / PI * gather_radiance(w, tri, hit, b) * (cos_x * 4.0 * PI);
}

// Per-pixel directions, cosine-distributed about n_x (pdf cos θ_x/π): the cosine and the π
// cancel, ρ_x · L(h → x).
fn gather_estimate_cosine(p: VisiblePoint, w: vec3f, tri: u32, hit: vec3f, b: vec2f) -> vec3f {
    return p.x.albedo * gather_radiance(w, tri, hit, b);
}
