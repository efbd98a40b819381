// GGX microfacets (microfacet.rs): the distribution, Smith's masking, visible-normal sampling,
// Schlick's Fresnel term, and the conductor's multiple-scattering compensation.

fn schlick_weight(c: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

fn schlick(f0: vec3f, c: f32) -> vec3f {
    return f0 + (vec3f(1.0) - f0) * schlick_weight(c);
}

fn ggx_d(h: vec3f, alpha: f32) -> f32 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = h.z * h.z * (a2 - 1.0) + 1.0;
    return a2 / (PI * t * t);
}

fn ggx_g1(w: vec3f, h: vec3f, alpha: f32) -> f32 {
    if dot(w, h) * w.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    return 2.0 * abs(w.z) / (abs(w.z) + sqrt(a2 + (1.0 - a2) * w.z * w.z));
}

fn vndf_pdf(w: vec3f, h: vec3f, alpha: f32) -> f32 {
    if w.z == 0.0 {
        return 0.0;
    }
    return ggx_g1(w, h, alpha) * abs(dot(w, h)) * ggx_d(h, alpha) / abs(w.z);
}

fn vndf_sample(w_in: vec3f, alpha: f32, u1: f32, u2: f32) -> vec3f {
    let w = select(w_in, -w_in, w_in.z < 0.0);
    let vh = normalize(vec3f(alpha * w.x, alpha * w.y, w.z));
    let len2 = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3f(1.0, 0.0, 0.0);
    if len2 > 0.0 {
        t1 = vec3f(-vh.y, vh.x, 0.0) / sqrt(len2);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u1);
    let phi = 2.0 * PI * u2;
    let p1 = r * cos(phi);
    let s = 0.5 * (1.0 + vh.z);
    let p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * r * sin(phi);
    let nh = t1 * p1 + t2 * p2 + vh * sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0));
    return normalize(vec3f(alpha * nh.x, alpha * nh.y, max(nh.z, 1e-6)));
}

fn reflect_about(w: vec3f, h: vec3f) -> vec3f {
    return 2.0 * dot(w, h) * h - w;
}

fn mirror_z(w: vec3f) -> vec3f {
    return vec3f(w.x, w.y, -w.z);
}

// Whether the metal has its multiple-scattering lobe (Bsdf::compensates).
fn bsdf_compensates(b: Bsdf) -> bool {
    return b.multiple_scattering && !bsdf_is_smooth(b) && b.metallic > 0.0;
}

// F_ms = F̄²Ē/(1 − F̄(1 − Ē)), F̄ = c + (1 − c)/21, Ē = Ē₁(α) (Bsdf::ms_fresnel); zero where off.
fn ms_fresnel(b: Bsdf) -> vec3f {
    if !bsdf_compensates(b) {
        return vec3f(0.0);
    }
    let e_avg = ggx_albedo_mean(b.alpha).x;
    let f_avg = b.base + (vec3f(1.0) - b.base) / 21.0;
    return f_avg * f_avg * e_avg / (vec3f(1.0) - f_avg * (1.0 - e_avg));
}

// 1 − E₁(cos, α) (Bsdf::ms_loss).
fn ms_loss(b: Bsdf, c: f32) -> f32 {
    return max(1.0 - ggx_albedo(c, b.alpha).x, 0.0);
}

// M_ms = F_ms(1 − E₁(μ_o))(1 − E₁(μ_i)) / (π(1 − Ē₁)) (Bsdf::ms_eval).
fn ms_eval(b: Bsdf, cos_o: f32, cos_i: f32) -> vec3f {
    if !bsdf_compensates(b) {
        return vec3f(0.0);
    }
    let e_avg = ggx_albedo_mean(b.alpha).x;
    return ms_fresnel(b) * (ms_loss(b, cos_o) * ms_loss(b, cos_i) / (PI * max(1.0 - e_avg, 1e-6)));
}
