// The layers (layered.rs): the specular layer of a dielectric over its diffuse base and the
// clear coat over everything.

// f₀ of the dielectric, ((η − 1)/(η + 1))² (Bsdf::ior_f0).
fn ior_f0(b: Bsdf) -> f32 {
    let r = (b.ior - 1.0) / (b.ior + 1.0);
    return r * r;
}

// The layer's F₀ = min(f₀·colour, 1) (Bsdf::layer_f0).
fn layer_f0(b: Bsdf) -> vec3f {
    return min(ior_f0(b) * b.specular_color, vec3f(1.0));
}

fn layer_fresnel(b: Bsdf, c: f32) -> vec3f {
    return b.specular * schlick(layer_f0(b), c);
}

// The specular layer's directional albedo E_L(cos) (Bsdf::layer_albedo).
fn layer_albedo(b: Bsdf, c: f32) -> vec3f {
    if bsdf_is_smooth(b) {
        return layer_fresnel(b, c);
    }
    let f0 = layer_f0(b);
    let e = ggx_albedo(c, b.alpha);
    return b.specular * (f0 * e.x + (vec3f(1.0) - f0) * e.y);
}

// The layer's cosine-weighted mean albedo Ē_L (Bsdf::layer_mean_albedo).
fn layer_mean_albedo(b: Bsdf) -> vec3f {
    let f0 = layer_f0(b);
    if bsdf_is_smooth(b) {
        return b.specular * (f0 + (vec3f(1.0) - f0) / 21.0);
    }
    let m = ggx_albedo_mean(b.alpha);
    return b.specular * (f0 * m.x + (vec3f(1.0) - f0) * m.y);
}

// Whether a coat with a glossy (not perfectly specular) lobe lies on top (Bsdf::rough_coat).
fn rough_coat(b: Bsdf) -> bool {
    return b.clearcoat > 0.0 && b.clearcoat_alpha >= SMOOTH_ALPHA;
}

// The coat's directional albedo k·E_k(|cos|), kF_k when smooth, 0 without one
// (Bsdf::coat_albedo).
fn coat_albedo(b: Bsdf, cos_in: f32) -> f32 {
    if b.clearcoat <= 0.0 {
        return 0.0;
    }
    let c = min(abs(cos_in), 1.0);
    if b.clearcoat_alpha < SMOOTH_ALPHA {
        return b.clearcoat * schlick(vec3f(COAT_F0), c).x;
    }
    let e = ggx_albedo(c, b.clearcoat_alpha);
    return b.clearcoat * (COAT_F0 * e.x + (1.0 - COAT_F0) * e.y);
}

// The share of the model under the coat, 1 − k·E_k(μ_v): μ_v of wo for radiance, of wi for
// importance (Bsdf::coat_scale).
fn coat_scale(b: Bsdf, wo: vec3f, wi: vec3f, transport: u32) -> f32 {
    let view = select(wi, wo, transport == TRANSPORT_RADIANCE);
    return 1.0 - coat_albedo(b, view.z);
}

// The coat's glossy lobe on wo's side (Bsdf::coat_eval).
fn coat_eval(b: Bsdf, wo: vec3f, wi: vec3f) -> vec3f {
    if !rough_coat(b) {
        return vec3f(0.0);
    }
    let o = select(wo, -wo, wo.z < 0.0);
    let i = select(wi, -wi, wo.z < 0.0);
    if o.z <= 0.0 || i.z <= 0.0 {
        return vec3f(0.0);
    }
    let h = normalize(o + i);
    let a = b.clearcoat_alpha;
    let spec = ggx_d(h, a) * ggx_g1(o, h, a) * ggx_g1(i, h, a) / (4.0 * o.z * i.z);
    return vec3f(b.clearcoat * schlick(vec3f(COAT_F0), dot(o, h)).x * spec);
}

fn eval_under_coat(b: Bsdf, wo: vec3f, wi: vec3f, transport: u32) -> vec3f {
    var f = vec3f(0.0);
    let opaque = (1.0 - b.metallic) * (1.0 - b.transmission);
    if b.transmission > 0.0 && b.metallic < 1.0 {
        f += (1.0 - b.metallic) * b.transmission * glass_eval(b, wo, wi, transport);
    }
    let o = select(wo, -wo, wo.z < 0.0);
    let i = select(wi, -wi, wo.z < 0.0);
    if o.z <= 0.0 || i.z <= 0.0 {
        return f;
    }
    let h = normalize(o + i);
    let vh = dot(o, h);
    f += opaque * b.base * (diffuse_share(b, o.z, i.z) / PI);
    f += b.metallic * ms_eval(b, o.z, i.z);
    if !bsdf_is_smooth(b) {
        let a = b.alpha;
        let spec = ggx_d(h, a) * ggx_g1(o, h, a) * ggx_g1(i, h, a) / (4.0 * o.z * i.z);
        f += spec * (b.metallic * schlick(b.base, vh) + opaque * layer_fresnel(b, vh));
    }
    return f;
}
