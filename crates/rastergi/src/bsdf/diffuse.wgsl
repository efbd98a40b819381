// The diffuse lobe (diffuse.rs): the base's share under a specular layer, and the Lambertian
// stand-ins the photon map is read with.

// The share the layer leaves to the diffuse base (Bsdf::diffuse_share): energy-conserving,
// (1 − E_L(cos_o))(1 − E_L(cos_i)) / (1 − Ē_L).
fn diffuse_share(b: Bsdf, cos_o: f32, cos_i: f32) -> vec3f {
    if b.specular == 0.0 {
        return vec3f(1.0);
    }
    return (vec3f(1.0) - layer_albedo(b, cos_o)) * (vec3f(1.0) - layer_albedo(b, cos_i)) / (vec3f(1.0) - layer_mean_albedo(b));
}

// The albedo a(μ_o) of the model's Lambertian part f_L = a/π, which the photon map answers
// for exactly at the gather's hits (Bsdf::lambertian_albedo): the cosine lobes' albedo,
// (1 − m)(1 − t)(1 − E_L(μ_o))·c + m·F_ms·(1 − E₁(μ_o)), under a coat × (1 − k·E_k(μ_o)).
fn bsdf_lambertian_albedo(b: Bsdf, cos_o_in: f32) -> vec3f {
    let cos_o = min(abs(cos_o_in), 1.0);
    let opaque = (1.0 - b.metallic) * (1.0 - b.transmission);
    var base = vec3f(1.0);
    if b.specular != 0.0 {
        base = vec3f(1.0) - layer_albedo(b, cos_o);
    }
    let a = opaque * base * b.base + b.metallic * ms_fresnel(b) * ms_loss(b, cos_o);
    return a * (1.0 - coat_albedo(b, cos_o));
}

// The albedo of a Lambertian surface standing in for b where the photon map is read at a
// visible point (photon_view.wgsl; the gather's hits follow the glossy lobes), seen from ω_o at cosine cos_o (Bsdf::diffuse_equivalent): the
// directional albedo of the metal and of the opaque dielectric, the hemispherical reflectance
// F̄ for glass.
fn bsdf_diffuse_equivalent(b: Bsdf, cos_o_in: f32) -> vec3f {
    let cos_o = min(abs(cos_o_in), 1.0);
    let f0 = ior_f0(b);
    let mean_f = f0 + (1.0 - f0) / 21.0;
    let opaque = (1.0 - b.metallic) * (1.0 - b.transmission);
    var metal = schlick(b.base, cos_o);
    if !bsdf_is_smooth(b) {
        let e = ggx_albedo(cos_o, b.alpha);
        metal = b.base * e.x + (vec3f(1.0) - b.base) * e.y + ms_fresnel(b) * ms_loss(b, cos_o);
    }
    let layer = layer_albedo(b, cos_o);
    let dielectric = layer + (vec3f(1.0) - layer) * b.base;
    let under = b.metallic * metal + opaque * dielectric + vec3f((1.0 - b.metallic) * b.transmission * mean_f);
    let coat = coat_albedo(b, cos_o);
    return vec3f(coat) + (1.0 - coat) * under;
}
