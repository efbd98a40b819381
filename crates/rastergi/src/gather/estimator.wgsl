// The final gather's estimators (gather/estimator.rs), shared by the raster projection
// (raster.wgsl), the list walk (lists.wgsl) and the traced gather (trace.wgsl). A visible
// point gathers where it is `ok` (visible_point.wgsl).

// L(h → x) for the hit point h on triangle tri at barycentrics b, seen along w from x (zero
// from the back of a one-sided h; h's own emission is direct light at x, the direct pass's).
// E(h) is the photon map's irradiance on the side of h facing x — for a map of indirect light
// only, the map's plus the direct irradiance from one light sample with a shadow ray (sample
// j of the pixel's sequence at the first surface, hit_light_choice; the chain's stream after).
//   Lambertian h:  L = ρ_h/π · E(h).
//   Elsewhere the model splits f = f_L + f_R (bsdf_lambertian_albedo): the map answers for
//   its Lambertian part f_L = a(μ_o)/π exactly, a/π · E(h); the rest f_R = f − f_L (the
//   glossy and specular lobes, and what the cosine lobes' angular shape adds to f_L) is
//   followed: a direction drawn from the whole model (density p), weight f_R·|cos θ|/p,
//   Russian roulette by its largest channel, to the next surface, where the same holds and
//   its emission counts (light that reached h from an emitter); a ray that escapes adds the
//   sky. Punctual and distant lights, which no ray meets, add f_R·e·|cos θ| by h's light
//   sample. The estimate is unbiased for ∫f L cos θ dω at h given the map's E, so it
//   converges with the map to the path tracer's answer (issue 31; before, a glossy h was a
//   Lambertian surface of its directional albedo, bsdf_diffuse_equivalent: biased however
//   long it rendered).
// Through perfect mirrors and glass the ray goes on (one direction drawn from the BSDF at
// each, as the eye's chains do). Light that reaches x from the lights or the sky through
// smooth surfaces alone is the caustic map's (the caustics pass), so such a chain that escapes
// or meets an emitter adds nothing here. 16 surfaces at most.
fn gather_radiance(x: vec3f, w0: vec3f, tri0: u32, hit0: vec3f, b0: vec2f, pixel: u32, j: u32) -> vec3f {
    var w = w0;
    var tri = tri0;
    var hit = hit0;
    var b = b0;
    // The throughput from x's estimate to the current surface (signed: f_R may be negative),
    // from x's own segment on (inside solid glass it is attenuated).
    var weight = segment_transmittance(tri, w, distance(x, hit));
    // Whether every surface passed so far scattered by a delta lobe: then the light the chain
    // meets from the lights and the sky is the caustic map's; through rough glass or off a
    // surface the map answers for in part it is not, and the chain adds it here (no light
    // sample and no caustic photon holds that light).
    var delta_only = true;
    // Whether the light sample of the next stop is the pixel's (the first stop) or the chain's.
    var first_stop = true;
    // The density with which the last direction was drawn at a stop that took a light sample
    // (0: none, or a delta lobe), and the distance it went: emitters it meets and the sky are
    // weighted against that light sample by the power heuristic, as in the path tracer.
    var last_pdf = 0.0;
    var last_t = 0.0;
    var radiance = vec3f(0.0);
    let chains = SCENE_PASSES_RAYS && frame.eye_chains != 0u;
    var rng = rng_new(frame.seed ^ STREAM_GATHER_CHAIN, pixel, j);
    for (var k = 0u; k <= 16u; k++) {
        let s = surface_at(tri, b.x, b.y, 0.0);
        let front = dot(w, s.normal) < 0.0;
        let a = arrival(s, w);
        var la = vec3f(0.0);
        let stop = !(chains && surface_passes_rays(s));
        if stop {
            if !delta_only && front && any(s.emission > vec3f(0.0)) {
                var mis = 1.0;
                if last_pdf > 0.0 {
                    mis = power_heuristic(last_pdf, emitter_pdf_area(tri) * last_t * last_t / dot(-w, s.normal));
                }
                radiance += weight * s.emission * mis;
            }
            if !front && (s.flags & MATERIAL_TWO_SIDED) == 0u {
                return radiance;
            }
            let lambertian = surface_is_lambertian(s);
            var e = photon_irradiance(hit, tri, !front);
            // The punctual lights' direct irradiance where the map leaves it to a sample of them
            // (SampledDirect::Punctual): one of them by their cdf, with a shadow ray. It takes
            // the pixel's point of the sequence at the first stop, and f_R's sample below the
            // chain's random numbers.
            let punctual = photon_grid.sampled_direct == 2u && photon_grid.punctual_count > 0u;
            if punctual {
                var u = vec2f(rng_f32(&rng), rng_f32(&rng));
                if first_stop {
                    u = hit_light_uniforms(pixel, j);
                }
                let c = punctual_choice(u);
                let l = sample_light_at(hit + a.n * frame.ray_epsilon, c.choice);
                let cos_l = dot(a.frame[2], l.dir);
                if dot(a.n, l.dir) > 0.0 && cos_l > 0.0 && any(l.e > vec3f(0.0)) {
                    if !occluded(hit + a.n * frame.ray_epsilon, l.dir, frame.ray_epsilon, l.dist * (1.0 - 1e-4), tri, l.tri) {
                        e += l.e * (cos_l * c.mass);
                    }
                }
            }
            // The light sample: for the Lambertian part where the map holds indirect light
            // only, and for f_R where it is a punctual or distant light.
            if has_lights() && (photon_grid.sampled_direct == 1u || !lambertian) {
                var c: LightChoice;
                if first_stop && !punctual {
                    c = hit_light_choice(pixel, j);
                } else {
                    c = light_choice(rng_f32(&rng), rng_f32(&rng), rng_f32(&rng));
                }
                let l = sample_light_at(hit + a.n * frame.ray_epsilon, c);
                let cos_l = dot(a.frame[2], l.dir);
                let lit = photon_grid.sampled_direct == 1u && dot(a.n, l.dir) > 0.0 && cos_l > 0.0;
                if (lit || !lambertian) && any(l.e > vec3f(0.0)) {
                    let side = select(-a.n, a.n, dot(a.n, l.dir) >= 0.0);
                    if !occluded(hit + side * frame.ray_epsilon, l.dir, frame.ray_epsilon, l.dist * (1.0 - 1e-4), tri, l.tri) {
                        if lit {
                            e += l.e * cos_l;
                        }
                        if !lambertian {
                            radiance += weight * rest_light(a, l);
                        }
                    }
                }
            }
            first_stop = false;
            if lambertian {
                return radiance + weight * s.albedo / PI * e;
            }
            la = bsdf_lambertian_albedo(a.b, a.wo.z);
            radiance += weight * la / PI * e;
        }
        if k == 16u {
            break;
        }
        // On: a direction from the model; at a stop, weighted by f_R, with Russian roulette.
        let u = vec3f(rng_f32(&rng), rng_f32(&rng), rng_f32(&rng));
        let sc = scatter_from(s.pos, a, u, frame.ray_epsilon);
        if !sc.ok {
            break;
        }
        var wr = sc.weight;
        if !sc.delta && dot(sc.dir, a.n) > 0.0 {
            wr -= la / PI * (sc.cos / sc.pdf);
        }
        if stop || !delta_only {
            let q = min(max(max(abs(wr.x), abs(wr.y)), abs(wr.z)), 1.0);
            if rng_f32(&rng) >= q {
                break;
            }
            wr /= q;
        }
        weight *= wr;
        delta_only = delta_only && sc.delta && !stop;
        // The density of the direction for the weights against the light sample taken here
        // (only at a stop that is not Lambertian: the only ones that go on).
        last_pdf = select(0.0, sc.pdf, stop && !sc.delta && has_lights());
        let h = trace(sc.origin, sc.dir, frame.ray_epsilon, 3.0e38, tri, NO_TRIANGLE, false);
        if h.tri == NO_TRIANGLE {
            if !delta_only && has_environment() {
                var mis = 1.0;
                if last_pdf > 0.0 {
                    mis = power_heuristic(last_pdf, environment.pmf * env_pdf(sc.dir));
                }
                radiance += weight * env_radiance(sc.dir) * mis;
            }
            break;
        }
        last_t = h.t;
        weight *= segment_transmittance(h.tri, sc.dir, h.t);
        w = sc.dir;
        tri = h.tri;
        hit = sc.origin + sc.dir * h.t;
        b = vec2f(h.b1, h.b2);
    }
    return radiance;
}

// The light sample l (unoccluded) reflected by f_R = f − f_L at the arrival a
// (gather_radiance): f_R·e·|cos θ_i|, weighted against the model's sampling of the same
// direction by the power heuristic where that can find it (an emissive triangle: its area
// density to solid angle; the sky: l.pdf); a punctual or distant light has weight 1. Zero
// where the direction's geometric and shading sides disagree.
fn rest_light(a: Arrival, l: LightRay) -> vec3f {
    let wi = to_local(a.frame, l.dir);
    if (wi.z < 0.0) != (dot(a.n, l.dir) < 0.0) || wi.z == 0.0 {
        return vec3f(0.0);
    }
    var f = bsdf_eval(a.b, a.wo, wi, TRANSPORT_RADIANCE);
    if wi.z > 0.0 {
        f -= bsdf_lambertian_albedo(a.b, a.wo.z) / PI;
    }
    var mis = 1.0;
    if l.pdf > 0.0 {
        mis = power_heuristic(l.pdf, bsdf_pdf(a.b, a.wo, wi));
    } else if l.tri != NO_TRIANGLE {
        let cos_y = -dot(triangle_normal(triangles[l.tri]), l.dir);
        mis = power_heuristic(emitter_pdf_area(l.tri) * l.dist * l.dist / cos_y, bsdf_pdf(a.b, a.wo, wi));
    }
    return f * l.e * (abs(wi.z) * mis);
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

// Shared directions, bidirectional: ω uniform on the sphere, and x gathers along whichever of
// ±ω lies above its geometric surface (w = sign(n·ω)·ω, uniform on x's hemisphere, pdf
// 1/2π): f(ω_eye, w) · L(h → x) · cos θ_x · 2π, cos θ_x = gather_cosine (the shading
// normal's); f = ρ_x/π on a Lambertian surface.
fn gather_estimate(p: VisiblePoint, cos_x: f32, w: vec3f, tri: u32, hit: vec3f, b: vec2f, pixel: u32, j: u32) -> vec3f {
    return visible_f(p, w) * gather_radiance(p.x.pos, w, tri, hit, b, pixel, j) * (cos_x * 2.0 * PI);
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
    return weight * env_radiance(w) * env_gather_weight(gather_density(p, w), environment.pmf * env_light_density(p, w));
}

// escape_estimate_weighted for shared directions (pdf 1/2π): f·cos θ_x·2π.
fn escape_estimate(p: VisiblePoint, cos_x: f32, w: vec3f) -> vec3f {
    return escape_estimate_weighted(p, visible_f(p, w) * (cos_x * 2.0 * PI), w);
}

// The light sample at the gather's first hit for the pixel's direction with sample index j:
// sample j of the pixel's own Owen-scrambled Sobol' sequence (light_sample_uniforms, as the
// direct pass draws them), whose seed depends on (seed, pixel) only. j is i·K + k, so an
// iteration's K hits take an aligned block of the sequence and the iterations keep
// stratifying it; the index shuffle of sobol_owen_2d keeps it independent of the per-pixel
// directions, which use the same indices with other seeds.
fn hit_light_choice(pixel: u32, j: u32) -> LightChoice {
    return light_sample_uniforms(j, hit_light_seed(pixel));
}

// The same point j of the pixel's sequence as two uniforms (for punctual_choice).
fn hit_light_uniforms(pixel: u32, j: u32) -> vec2f {
    let p = sobol_owen_2d(j, hit_light_seed(pixel));
    return vec2f(unit_f32(p.x), unit_f32(p.y));
}

// The scramble seed of the pixel's hit-light sequence: (seed, stream::HIT_LIGHT, pixel).
fn hit_light_seed(pixel: u32) -> u32 {
    let xy = vec2u(pixel % frame.resolution.x, pixel / frame.resolution.x);
    return pixel_seed(pcg_hash(frame.seed ^ STREAM_HIT_LIGHT), xy.x, xy.y);
}

// A light sample among the punctual lights alone (the light table's entries
// [punctual_first, punctual_first + punctual_count), one run), by their share of the table's
// cdf: u.x is placed in their interval [lo, hi) and picks there, its position in the picked
// entry's interval is u1, u.y is u2. sample_light_at weighs by 1/pmf of the whole table, and
// this choice has probability pmf/(hi − lo): its estimate is scaled by `mass` = hi − lo.
struct PunctualChoice {
    choice: LightChoice,
    mass: f32,
}

fn punctual_choice(u: vec2f) -> PunctualChoice {
    let first = photon_grid.punctual_first;
    let last = first + photon_grid.punctual_count - 1u;
    var lo = 0.0;
    if first > 0u {
        lo = light_entry(first - 1u).cdf;
    }
    let hi = light_entry(last).cdf;
    let x = lo + u.x * (hi - lo);
    let e = clamp(light_pick(x), first, last);
    var below = 0.0;
    if e > 0u {
        below = light_entry(e - 1u).cdf;
    }
    let u1 = clamp((x - below) / max(light_entry(e).pmf, 1e-30), 0.0, 0.99999994);
    return PunctualChoice(LightChoice(e, u1, u.y), hi - lo);
}
