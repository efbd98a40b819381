// The dielectric lobe, glass (dielectric.rs): exact Fresnel, refraction, solid and thin glass,
// rough and smooth, with the rough glass's energy compensation.

fn fresnel_dielectric(cos_in: f32, eta_in: f32) -> f32 {
    var c = cos_in;
    var eta = eta_in;
    if c < 0.0 {
        c = -c;
        eta = 1.0 / eta;
    }
    let sin2_t = max(1.0 - c * c, 0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = sqrt(max(1.0 - sin2_t, 0.0));
    let r_parl = (eta * c - cos_t) / (eta * c + cos_t);
    let r_perp = (c - eta * cos_t) / (c + eta * cos_t);
    return 0.5 * (r_parl * r_parl + r_perp * r_perp);
}

fn slab_reflectance(r: f32) -> f32 {
    if r >= 1.0 {
        return 1.0;
    }
    return 2.0 * r / (1.0 + r);
}

// w refracted through h for the relative index of the side h faces; w = 0 under total internal
// reflection. Returns (direction, η' used).
fn refract_through(w: vec3f, h_in: vec3f, eta_in: f32) -> vec4f {
    var c = dot(h_in, w);
    var eta = eta_in;
    var h = h_in;
    if c < 0.0 {
        eta = 1.0 / eta;
        c = -c;
        h = -h;
    }
    let sin2_t = max(1.0 - c * c, 0.0) / (eta * eta);
    if sin2_t >= 1.0 {
        return vec4f(0.0);
    }
    let cos_t = sqrt(1.0 - sin2_t);
    return vec4f(-w / eta + (c / eta - cos_t) * h, eta);
}

// E_g of glass for flux arriving from w (GlassAlbedo::at, trilinear; Bsdf::glass_single_albedo:
// a thin slab's is E₁).
fn glass_single_albedo(b: Bsdf, w: vec3f) -> f32 {
    let mu = abs(w.z);
    if b.thin {
        return ggx_albedo(mu, b.alpha).x;
    }
    let n = GGX_ALBEDO_N;
    let tx = clamp(mu, 0.0, 1.0) * f32(n - 1u);
    let ty = sqrt(clamp(b.alpha, 0.0, 1.0)) * f32(n - 1u);
    // A relative index below 1: the glass seen from inside (arrival inverts η there).
    var eta = b.ior;
    var inside = w.z < 0.0;
    if eta < 1.0 {
        eta = 1.0 / eta;
        inside = !inside;
    }
    let tz = clamp((eta - 1.0) / (GLASS_ALBEDO_ETA_MAX - 1.0), 0.0, 1.0) * f32(GLASS_ALBEDO_ETAS - 1u);
    let i = min(u32(tx), n - 2u);
    let j = min(u32(ty), n - 2u);
    let k = min(u32(tz), GLASS_ALBEDO_ETAS - 2u);
    let fx = tx - f32(i);
    let fy = ty - f32(j);
    var side = 0u;
    if inside {
        side = GLASS_ALBEDO_ETAS;
    }
    var e = array<f32, 2>();
    for (var d = 0u; d < 2u; d++) {
        let r0 = ((side + k + d) * n + j) * n + i;
        let r1 = r0 + n;
        let lo = glass_cell(r0) + (glass_cell(r0 + 1u) - glass_cell(r0)) * fx;
        let hi = glass_cell(r1) + (glass_cell(r1 + 1u) - glass_cell(r1)) * fx;
        e[d] = lo + (hi - lo) * fy;
    }
    return e[0] + (e[1] - e[0]) * (tz - f32(k));
}

// Whether rough glass's lobes are divided by E_g of the direction the light leaves by
// (Bsdf::glass_compensates).
fn glass_compensates(b: Bsdf) -> bool {
    return b.multiple_scattering && !bsdf_is_smooth(b) && b.transmission > 0.0;
}

// A thin slab's pair (Bsdf::thin_pair): ω_o and ω_i on ω_o's side, ω_i reflected through
// the surface where transmitted (ir), their half vector, whether ω_i is reflected, and R'.
struct ThinPair {
    o: vec3f,
    ir: vec3f,
    h: vec3f,
    reflected: bool,
    r: f32,
}

fn thin_pair(b: Bsdf, wo: vec3f, wi: vec3f) -> ThinPair {
    let o = select(wo, -wo, wo.z < 0.0);
    let i = select(wi, -wi, wo.z < 0.0);
    let reflected = i.z > 0.0;
    let ir = select(mirror_z(i), i, reflected);
    let h = normalize(o + ir);
    return ThinPair(o, ir, h, reflected, slab_reflectance(fresnel_dielectric(dot(o, h), b.ior)));
}

// The generalized half vector of a solid glass's pair (wo, wi) and η' (Bsdf::solid_half):
// (h, η'), or η' = 0 where the pair has none.
fn glass_half(b: Bsdf, wo: vec3f, wi: vec3f) -> vec4f {
    let reflected = wo.z * wi.z > 0.0;
    var etap = 1.0;
    if !reflected {
        etap = select(1.0 / b.ior, b.ior, wo.z > 0.0);
    }
    var h = wi * etap + wo;
    if dot(h, h) == 0.0 {
        return vec4f(0.0);
    }
    h = normalize(h);
    h = select(h, -h, h.z < 0.0);
    if dot(h, wi) * wi.z < 0.0 || dot(h, wo) * wo.z < 0.0 {
        return vec4f(0.0);
    }
    return vec4f(h, etap);
}

// The glass's f, compensated: divided by E_g of the direction the light leaves by (wo for
// radiance, wi for importance; Bsdf::glass_eval).
fn glass_eval(b: Bsdf, wo: vec3f, wi: vec3f, transport: u32) -> vec3f {
    let f = glass_single_eval(b, wo, wi, transport);
    if !glass_compensates(b) || all(f == vec3f(0.0)) {
        return f;
    }
    let view = select(wi, wo, transport == TRANSPORT_RADIANCE);
    return f / max(glass_single_albedo(b, view), 1e-3);
}

fn glass_single_eval(b: Bsdf, wo: vec3f, wi: vec3f, transport: u32) -> vec3f {
    if bsdf_is_smooth(b) || wo.z == 0.0 || wi.z == 0.0 {
        return vec3f(0.0);
    }
    let a = b.alpha;
    if b.thin {
        let t = thin_pair(b, wo, wi);
        let w = select((1.0 - t.r) * b.base, vec3f(t.r), t.reflected);
        return w * ggx_d(t.h, a) * ggx_g1(t.o, t.h, a) * ggx_g1(t.ir, t.h, a) / (4.0 * t.o.z * t.ir.z);
    }
    let he = glass_half(b, wo, wi);
    if he.w == 0.0 {
        return vec3f(0.0);
    }
    let h = he.xyz;
    let etap = he.w;
    let f = fresnel_dielectric(dot(wo, h), b.ior);
    let dg = ggx_d(h, a) * ggx_g1(wo, h, a) * ggx_g1(wi, h, a);
    if wo.z * wi.z > 0.0 {
        return vec3f(dg * f / abs(4.0 * wo.z * wi.z));
    }
    let s = dot(wi, h) + dot(wo, h) / etap;
    let denom = s * s * wi.z * wo.z;
    var ft = dg * (1.0 - f) * abs(dot(wi, h) * dot(wo, h) / denom);
    if transport == TRANSPORT_RADIANCE {
        ft /= etap * etap;
    }
    return ft * b.base;
}

fn glass_pdf(b: Bsdf, wo: vec3f, wi: vec3f) -> f32 {
    if bsdf_is_smooth(b) || wo.z == 0.0 || wi.z == 0.0 {
        return 0.0;
    }
    let a = b.alpha;
    if b.thin {
        let t = thin_pair(b, wo, wi);
        return vndf_pdf(t.o, t.h, a) / (4.0 * abs(dot(t.o, t.h))) * select(1.0 - t.r, t.r, t.reflected);
    }
    let he = glass_half(b, wo, wi);
    if he.w == 0.0 {
        return 0.0;
    }
    let h = he.xyz;
    let r = fresnel_dielectric(dot(wo, h), b.ior);
    if wo.z * wi.z > 0.0 {
        return vndf_pdf(wo, h, a) / (4.0 * abs(dot(wo, h))) * r;
    }
    let s = dot(wi, h) + dot(wo, h) / he.w;
    return vndf_pdf(wo, h, a) * abs(dot(wi, h)) / (s * s) * (1.0 - r);
}

fn sample_glass(b: Bsdf, wo: vec3f, u0: f32, u1: f32, u2: f32, p: f32, transport: u32) -> BsdfSample {
    let scale = (1.0 - b.metallic) * b.transmission;
    if bsdf_is_smooth(b) {
        // The coat's share is alike for wo and the mirrored or passing wi (|cos| equal).
        let reflected = scale * coat_scale(b, wo, wo, transport);
        if b.thin {
            let r = slab_reflectance(fresnel_dielectric(abs(wo.z), b.ior));
            if u0 < r {
                return BsdfSample(mirror_z(-wo), vec3f(reflected / p), p * r, true, true);
            }
            return BsdfSample(-wo, reflected * b.base / p, p * (1.0 - r), true, true);
        }
        let r = fresnel_dielectric(wo.z, b.ior);
        if u0 < r {
            return BsdfSample(mirror_z(-wo), vec3f(reflected / p), p * r, true, true);
        }
        let t = refract_through(wo, vec3f(0.0, 0.0, 1.0), b.ior);
        if t.w == 0.0 {
            return no_sample();
        }
        var w = scale * coat_scale(b, wo, t.xyz, transport) * b.base / p;
        if transport == TRANSPORT_RADIANCE {
            w /= t.w * t.w;
        }
        return BsdfSample(t.xyz, w, p * (1.0 - r), true, true);
    }
    var wi: vec3f;
    if b.thin {
        let side = select(1.0, -1.0, wo.z < 0.0);
        let o = wo * side;
        let h = vndf_sample(o, b.alpha, u1, u2);
        let ir = reflect_about(o, h);
        if ir.z <= 0.0 {
            return no_sample();
        }
        let r = slab_reflectance(fresnel_dielectric(dot(o, h), b.ior));
        wi = select(mirror_z(ir), ir, u0 < r) * side;
    } else {
        let h = vndf_sample(wo, b.alpha, u1, u2);
        let r = fresnel_dielectric(dot(wo, h), b.ior);
        if u0 < r {
            wi = reflect_about(wo, h);
            if wi.z * wo.z <= 0.0 {
                return no_sample();
            }
        } else {
            let t = refract_through(wo, h, b.ior);
            if t.w == 0.0 || t.z * wo.z >= 0.0 {
                return no_sample();
            }
            wi = t.xyz;
        }
    }
    return finish_sample(b, wo, wi, transport);
}
