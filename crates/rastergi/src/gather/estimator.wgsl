// The final gather's estimators (gather/estimator.rs), shared by the raster projection
// (raster.wgsl), the list walk (lists.wgsl) and the traced gather (trace.wgsl). A visible
// point gathers where it is `ok` (visible_point.wgsl).

// L(h → x) for the hit point h on triangle tri at barycentrics b, seen along w from x:
// ρ_h/π · E(h) on the side of h facing x (ρ_h the diffuse equivalent of a glossy or
// specular h seen from x: bsdf_diffuse_equivalent, an approximation), zero from the back of a one-sided h. E(h) is the
// photon map's, or — for a map of indirect light only — the map's plus the direct irradiance
// from one light sample with a shadow ray (hit_direct): sample j (the gather direction's
// sample index) of the pixel's sequence.
fn gather_radiance(w0: vec3f, tri0: u32, hit0: vec3f, b0: vec2f, pixel: u32, j: u32) -> vec3f {
    var w = w0;
    var tri = tri0;
    var hit = hit0;
    var b = b0;
    // Through perfect mirrors and glass the ray goes on (one direction drawn from the BSDF at
    // each, as the eye's chains do) to the first other surface. Light that reaches x from the
    // lights or the sky through smooth surfaces alone is the caustic map's (the caustics pass),
    // so such a chain that escapes or meets an emitter adds nothing here.
    var weight = vec3f(1.0);
    // Whether every surface passed so far scattered by a delta lobe: then the light the chain
    // meets from the lights and the sky is the caustic map's; through rough glass it is not,
    // and the chain adds it here (no light sample finds it).
    var delta_only = true;
    var seen = vec3f(0.0);
    if SCENE_PASSES_RAYS && frame.eye_chains != 0u {
        var rng = rng_new(frame.seed ^ STREAM_GATHER_CHAIN, pixel, j);
        for (var k = 0u; ; k++) {
            let s = surface_at(tri, b.x, b.y, 0.0);
            if !surface_passes_rays(s) {
                if !delta_only && dot(s.normal, w) < 0.0 {
                    seen = weight * s.emission;
                }
                break;
            }
            if k == 16u {
                return vec3f(0.0);
            }
            let sc = scatter_at(s, w, vec3f(rng_f32(&rng), rng_f32(&rng), rng_f32(&rng)), frame.ray_epsilon);
            if !sc.ok {
                return vec3f(0.0);
            }
            weight *= sc.weight;
            delta_only = delta_only && sc.delta;
            let o = sc.origin;
            let wi = sc.dir;
            let h = trace(o, wi, frame.ray_epsilon, 3.0e38, tri, NO_TRIANGLE, false);
            if h.tri == NO_TRIANGLE {
                return select(weight * env_radiance(wi), vec3f(0.0), delta_only);
            }
            w = wi;
            tri = h.tri;
            hit = o + wi * h.t;
            b = vec2f(h.b1, h.b2);
        }
    }
    let t = triangles[tri];
    let n_h = triangle_normal(t);
    let front_h = dot(w, n_h) < 0.0;
    if !front_h && (materials[t.material].flags & MATERIAL_TWO_SIDED) == 0u {
        return vec3f(0.0);
    }
    // ρ_h at the hit point itself, unfiltered (level 0), like every secondary point.
    let s_h = surface_at(tri, b.x, b.y, 0.0);
    var e = photon_irradiance(hit, tri, !front_h);
    if photon_grid.indirect_only != 0u {
        let ns_h = bend_towards(select(-s_h.shading, s_h.shading, front_h), -w);
        e += hit_direct(hit, select(-n_h, n_h, front_h), ns_h, tri, pixel, j);
    }
    return seen + weight * surface_rho(s_h, -w) / PI * e;
}

// f(ω_eye, w) at the visible point x: ρ_x/π for a Lambertian surface, else the BSDF's
// non-specular lobes (bsdf.wgsl) in the shading frame of p.ns.
fn visible_f(p: VisiblePoint, w: vec3f) -> vec3f {
    if surface_is_lambertian(p.x) {
        return p.x.albedo / PI;
    }
    let v = visible_bsdf(p);
    return bsdf_eval(v.b, v.wo, to_local(v.frame, w), TRANSPORT_RADIANCE);
}

// The cosine that weighs direction w at x: the shading normal's, where w lies above the
// geometric surface (else 0: no light from below it, and no ray into it).
fn gather_cosine(p: VisiblePoint, w: vec3f) -> f32 {
    if dot(p.n, w) <= 0.0 {
        return 0.0;
    }
    return max(dot(p.ns, w), 0.0);
}

// Shared directions, bidirectional: ω uniform on the sphere, and x gathers along whichever of
// ±ω lies above its geometric surface (w = sign(n·ω)·ω, uniform on x's hemisphere, pdf
// 1/2π): f(ω_eye, w) · L(h → x) · cos θ_x · 2π, cos θ_x = gather_cosine (the shading
// normal's); f = ρ_x/π on a Lambertian surface.
fn gather_estimate(p: VisiblePoint, cos_x: f32, w: vec3f, tri: u32, hit: vec3f, b: vec2f, pixel: u32, j: u32) -> vec3f {
    return visible_f(p, w) * gather_radiance(w, tri, hit, b, pixel, j) * (cos_x * 2.0 * PI);
}

// The side of shared direction ω that x gathers along: ω, or −ω where ω lies below x's surface.
fn gather_side(n: vec3f, w: vec3f) -> vec3f {
    return select(-w, w, dot(n, w) >= 0.0);
}

// A per-pixel gather direction at x, drawn from x's own scattering: w, the estimator's factor
// f(ω_eye, w) cos θ_x / pdf(w) (zero where w counts nothing: below the geometric surface or the
// shading normal, or a specular lobe drawn — the eye's chains follow those), and pdf(w).
struct GatherDirection {
    w: vec3f,
    weight: vec3f,
    pdf: f32,
}

// The direction of Sobol' point u (two uniforms) and uniform `lobe` at x: on a Lambertian
// surface cosine-distributed about the shading normal (pdf cos θ_x/π, the cosine cancels:
// weight ρ_x; `lobe` unused); elsewhere drawn by bsdf_sample (the lobe chosen by `lobe`, the
// direction within it by u), whose weight and density cover its non-specular lobes —
// importance sampling of f cos θ_x, so a glossy lobe gathers where it reflects.
fn gather_direction(p: VisiblePoint, u: vec2f, lobe: f32) -> GatherDirection {
    var d = GatherDirection(p.ns, vec3f(0.0), 0.0);
    if surface_is_lambertian(p.x) {
        d.w = cosine_hemisphere(p.ns, u.x, u.y);
        d.pdf = max(dot(p.ns, d.w), 0.0) / PI;
        if gather_cosine(p, d.w) > 0.0 {
            d.weight = p.x.albedo;
        }
        return d;
    }
    let v = visible_bsdf(p);
    let s = bsdf_sample(v.b, v.wo, vec3f(lobe, u.x, u.y), TRANSPORT_RADIANCE);
    if !s.ok || s.delta {
        return d;
    }
    d.w = v.frame * s.wi;
    d.pdf = s.pdf;
    if gather_cosine(p, d.w) > 0.0 {
        d.weight = s.weight;
    }
    return d;
}

// A gather ray from x along w that escapes the scene sees the environment: its estimate
// weight · L_env(w) (weight = f cos θ_x / pdf of the direction's strategy), weighted against
// the direct pass's environment samples (env_gather_weight). It is direct light, so the
// gathers add it to the film's direct component (with the direct pass's share: Show::Direct
// is all of the direct light, Show::Indirect the light from surfaces).
fn escape_estimate_weighted(p: VisiblePoint, weight: vec3f, w: vec3f) -> vec3f {
    if !has_environment() {
        return vec3f(0.0);
    }
    return weight * env_radiance(w) * env_gather_weight(gather_density(p, w), w);
}

// escape_estimate_weighted for shared directions (pdf 1/2π): f·cos θ_x·2π.
fn escape_estimate(p: VisiblePoint, cos_x: f32, w: vec3f) -> vec3f {
    return escape_estimate_weighted(p, visible_f(p, w) * (cos_x * 2.0 * PI), w);
}

// Direct irradiance at h (side normal n, shading normal ns) from one light sample (light_sample_irradiance):
// sample j of the pixel's own Owen-scrambled Sobol' sequence (light_sample_uniforms, as the
// direct pass draws them), whose seed depends on (seed, pixel) only. j is the gather
// direction's sample index i·K + k, so an iteration's K hits take an aligned block of the
// sequence and the iterations keep stratifying it; the index shuffle of sobol_owen_2d keeps
// it independent of the per-pixel directions, which use the same indices with other seeds.
fn hit_direct(h: vec3f, n: vec3f, ns: vec3f, tri: u32, pixel: u32, j: u32) -> vec3f {
    if !has_lights() {
        return vec3f(0.0);
    }
    let xy = vec2u(pixel % frame.resolution.x, pixel / frame.resolution.x);
    let seed = pixel_seed(pcg_hash(frame.seed ^ STREAM_HIT_LIGHT), xy.x, xy.y);
    let c = light_sample_uniforms(j, seed);
    return light_sample_irradiance(h + n * frame.ray_epsilon, n, ns, tri, frame.ray_epsilon, c);
}
