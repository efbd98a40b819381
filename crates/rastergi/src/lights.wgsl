// Whether the scene has emitters: an empty light table is stored as one zero entry (a
// binding cannot be empty), whose pmf is 0.
fn has_lights() -> bool {
    return light_entry(0).pmf > 0.0;
}

// The light entry whose cdf interval holds u: the first with u < cdf (LightTable::pick).
fn light_pick(u: f32) -> u32 {
    var lo = 0u;
    var hi = scene_offset(DATA_LIGHT_COUNT) - 1u;
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if light_entry(mid).cdf <= u {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// The position of a 32-bit fraction a inside the cdf interval [lo, cdf) of light entry e,
// rescaled to [0, 1): a fresh uniform for the point on the emitter that a picked (sample
// reuse), computed on the 32-bit offset so it keeps 24 significant bits however small the
// interval. Mirrors direct::remap_in_entry.
fn remap_in_entry(a: u32, e: u32) -> f32 {
    var lo = 0.0;
    if e > 0u {
        lo = light_entry(e - 1u).cdf;
    }
    // lo ≤ unit_f32(a) ≤ a / 2³² (the pick), so the offset does not wrap.
    let offset = a - u32(lo * 4294967296.0);
    return min(f32(offset) / ((light_entry(e).cdf - lo) * 4294967296.0), 0.99999994);
}

// A light of the table and two uniforms for the point or direction on it.
struct LightChoice {
    entry: u32,
    u1: f32,
    u2: f32,
}

// The light sample of index j for the pixel's scramble seed: one Owen-scrambled Sobol' point
// (x, y); x picks the light, x's position within the light's interval is u1, y is u2
// (direct::light_sample_uniforms; the direct pass and the gather's exact hit light).
fn light_sample_uniforms(j: u32, seed: u32) -> LightChoice {
    let p = sobol_owen_2d(j, seed);
    let e = light_pick(unit_f32(p.x));
    return LightChoice(e, remap_in_entry(p.x, e), unit_f32(p.y));
}

// Light sample uniforms (u0, u1, u2): u0 picks the light.
fn light_choice(u0: f32, u1: f32, u2: f32) -> LightChoice {
    return LightChoice(light_pick(u0), u1, u2);
}

// The spot's falloff s(cos θ) (lights.rs: PunctualLight::falloff): a squared ramp between the
// cones, a step where they coincide; 1 for the other kinds.
fn spot_falloff(p: PunctualLight, cos_theta: f32) -> f32 {
    if p.kind != LIGHT_SPOT {
        return 1.0;
    }
    let width = p.cos_inner - p.cos_outer;
    if width <= 0.0 {
        return select(0.0, 1.0, cos_theta > p.cos_outer);
    }
    let t = clamp((cos_theta - p.cos_outer) / width, 0.0, 1.0);
    return t * t;
}

// A direction uniform within the cone of half-angle acos(cos_max) about axis (lights.rs:
// cone_direction).
fn cone_direction(axis: vec3f, cos_max: f32, u1: f32, u2: f32) -> vec3f {
    let cos_t = 1.0 - u1 * (1.0 - cos_max);
    let sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0));
    let phi = 2.0 * PI * u2;
    let tb = orthonormal_basis(axis);
    return normalize(tb[0] * (sin_t * cos(phi)) + tb[1] * (sin_t * sin(phi)) + axis * cos_t);
}

// A light sample as seen from a point x: the unit direction from x towards the light, the
// shadow ray's length (to the light's point; 3e38 for a distant light or the environment), e
// such that the estimate of the irradiance at x on a surface of normal n is e · max(0, n·dir),
// the emitter triangle (excluded from the shadow ray; NO_TRIANGLE for the others) and, for the
// environment, the sample's solid-angle density pmf · pdf(dir) (0 for the others: a BSDF
// sample never finds them, or finds them with its own weight, see the path tracer).
//   triangle: e = Le cos θ_y / (d² p_A)    point: I / (d² pmf)    spot: I s(cos θ) / (d² pmf)
//   distant:  e = E / pmf, dir uniform in its cone (E cos θ_x = L Ω cos θ_x for its radiance L)
//   environment: e = L(dir) / (pmf · pdf(dir)), dir from its distribution
struct LightRay {
    dir: vec3f,
    dist: f32,
    e: vec3f,
    tri: u32,
    pdf: f32,
}

fn sample_light_at(x: vec3f, c: LightChoice) -> LightRay {
    var r: LightRay;
    let entry = light_entry(c.entry);
    let u1 = c.u1;
    let u2 = c.u2;
    r.pdf = 0.0;
    if entry.triangle == ENVIRONMENT_LIGHT {
        let s = env_sample(u1, u2);
        r.dir = s.xyz;
        r.dist = 3.0e38;
        r.tri = NO_TRIANGLE;
        r.pdf = entry.pmf * s.w;
        r.e = select(vec3f(0.0), env_radiance(r.dir) / r.pdf, r.pdf > 0.0);
        return r;
    }
    if (entry.triangle & PUNCTUAL_LIGHT) == 0u {
        let l = sample_light(c.entry, u1, u2);
        let to_light = l.pos - x;
        let dist2 = dot(to_light, to_light);
        r.dist = sqrt(dist2);
        r.dir = to_light / r.dist;
        r.tri = l.tri;
        let cos_y = -dot(l.normal, r.dir);
        r.e = select(vec3f(0.0), l.radiance * (cos_y / (dist2 * l.pdf_area)), cos_y > 0.0);
        return r;
    }
    let p = punctual_light(entry.triangle & ~PUNCTUAL_LIGHT);
    r.tri = NO_TRIANGLE;
    if p.kind == LIGHT_DISTANT {
        r.dir = -cone_direction(p.direction, p.cos_outer, u1, u2);
        r.dist = 3.0e38;
        r.e = p.intensity / entry.pmf;
        return r;
    }
    let to_light = p.position - x;
    let dist2 = dot(to_light, to_light);
    r.dist = sqrt(dist2);
    r.dir = to_light / r.dist;
    r.e = p.intensity * (spot_falloff(p, -dot(p.direction, r.dir)) / (dist2 * entry.pmf));
    return r;
}

struct LightSample {
    pos: vec3f,
    normal: vec3f,
    radiance: vec3f,
    // Probability density of `pos` per unit area: pmf(triangle) / area(triangle).
    pdf_area: f32,
    tri: u32,
}

// Beer–Lambert inside solid glass (Material::segment_transmittance): exp(−σt) for a segment of
// length t that ends on triangle tri's back face arriving along d — it ran inside the solid
// that face bounds — and 1 elsewhere (in air, thin or clear glass). Media do not nest.
fn segment_transmittance(tri: u32, d: vec3f, t: f32) -> vec3f {
    if !SCENE_MEDIA {
        return vec3f(1.0);
    }
    let tr = triangles[tri];
    let m = materials[tr.material].material;
    let sigma = vec3f(m.attenuation[0], m.attenuation[1], m.attenuation[2]);
    if all(sigma == vec3f(0.0)) || dot(d, triangle_normal(tr)) <= 0.0 {
        return vec3f(1.0);
    }
    return exp(-sigma * t);
}

// The density per unit area with which light samples (sample_light_at) find points of the
// emissive triangle tri: pmf / area of its entry; 0 for a triangle not in the light table.
fn emitter_pdf_area(tri: u32) -> f32 {
    let e = triangles[tri].light;
    if e == NO_LIGHT {
        return 0.0;
    }
    return light_entry(e).pmf / light_entry(e).area;
}

// A point uniformly (u1, u2) on the emissive triangle of light entry `entry`.
fn sample_light(entry: u32, u1: f32, u2: f32) -> LightSample {
    let e = light_entry(entry);
    let t = triangles[e.triangle];
    let b = uniform_triangle_bary(u1, u2);
    var s: LightSample;
    s.pos = t.v0 * b.x + t.v1 * b.y + t.v2 * b.z;
    s.normal = triangle_normal(t);
    s.radiance = emitter_radiance(e.triangle, b.y, b.z);
    s.pdf_area = e.pmf / e.area;
    s.tri = e.triangle;
    return s;
}
