// The scattering model's dispatch (mod.rs states the math; this is its twin, checked against it on
// the GPU by bsdf::gpu_check::on_gpu): the model, its lobes' probabilities, evaluation, density and
// sampling. The lobes are in microfacet.wgsl, dielectric.wgsl, layered.wgsl and diffuse.wgsl, the
// albedo tables in albedo.wgsl (shader::BSDF puts them together). Directions are unit vectors
// away from the surface in the shading frame (z = the front face's shading normal).

const SMOOTH_ALPHA: f32 = 1e-3;
const COAT_F0: f32 = 0.04;
const TRANSPORT_RADIANCE: u32 = 0u;
const TRANSPORT_IMPORTANCE: u32 = 1u;

struct Bsdf {
    base: vec3f,
    metallic: f32,
    alpha: f32,
    specular: f32,
    // The layer's colour at normal incidence: F₀ = min(f₀(η)·colour, 1) (Bsdf::specular_color).
    specular_color: vec3f,
    ior: f32,
    transmission: f32,
    thin: bool,
    // The rough metal's energy compensation (Bsdf::multiple_scattering).
    multiple_scattering: bool,
    // The clear coat over the rest: its weight k and GGX α (0 weight: none).
    clearcoat: f32,
    clearcoat_alpha: f32,
}

struct BsdfSample {
    wi: vec3f,
    weight: vec3f,
    pdf: f32,
    delta: bool,
    // False where nothing was sampled.
    ok: bool,
}

fn bsdf_is_smooth(b: Bsdf) -> bool {
    return b.alpha < SMOOTH_ALPHA;
}

fn mean3(c: vec3f) -> f32 {
    return (c.x + c.y + c.z) / 3.0;
}

// The probabilities of picking the coat and each lobe under it (metal, layer,
// cosine-distributed: diffuse base and the metal's multiple scattering, glass) for |cos θ_o|
// (Bsdf::lobe_probabilities).
struct LobeProbabilities {
    coat: f32,
    under: vec4f,
}

fn lobe_probabilities(b: Bsdf, cos_o: f32) -> LobeProbabilities {
    let m = b.metallic;
    let opaque = (1.0 - m) * (1.0 - b.transmission);
    let fs = layer_fresnel(b, cos_o);
    let w = vec4f(m * mean3(schlick(b.base, cos_o)), opaque * mean3(fs),
        opaque * mean3((vec3f(1.0) - fs) * b.base) + m * mean3(ms_fresnel(b)) * ms_loss(b, cos_o), (1.0 - m) * b.transmission);
    let sum = w.x + w.y + w.z + w.w;
    var coat = 0.0;
    if b.clearcoat > 0.0 {
        coat = b.clearcoat * schlick(vec3f(COAT_F0), cos_o).x;
    }
    let under = sum * (1.0 - coat);
    let total = coat + under;
    if total <= 0.0 {
        return LobeProbabilities(0.0, vec4f(0.0));
    }
    return LobeProbabilities(coat / total, w * (under / total / max(sum, 1.17549435e-38)));
}

// f(wo, wi) of the non-specular lobes: the coat's and, scaled by what it leaves, the model's
// under it (Bsdf::eval).
fn bsdf_eval(b: Bsdf, wo: vec3f, wi: vec3f, transport: u32) -> vec3f {
    let under = eval_under_coat(b, wo, wi, transport);
    if b.clearcoat <= 0.0 {
        return under;
    }
    return coat_eval(b, wo, wi) + under * coat_scale(b, wo, wi, transport);
}

// The density with which bsdf_sample draws wi (its non-specular lobes; Bsdf::pdf).
fn bsdf_pdf(b: Bsdf, wo: vec3f, wi: vec3f) -> f32 {
    let lp = lobe_probabilities(b, abs(wo.z));
    let p = lp.under;
    var pdf = p.w * glass_pdf(b, wo, wi);
    let o = select(wo, -wo, wo.z < 0.0);
    let i = select(wi, -wi, wo.z < 0.0);
    if o.z <= 0.0 || i.z <= 0.0 {
        return pdf;
    }
    pdf += p.z * i.z / PI;
    let h = normalize(o + i);
    if !bsdf_is_smooth(b) {
        pdf += (p.x + p.y) * vndf_pdf(o, h, b.alpha) / (4.0 * dot(o, h));
    }
    if rough_coat(b) {
        pdf += lp.coat * vndf_pdf(o, h, b.clearcoat_alpha) / (4.0 * dot(o, h));
    }
    return pdf;
}

fn no_sample() -> BsdfSample {
    return BsdfSample(vec3f(0.0), vec3f(0.0), 0.0, false, false);
}

// The sample of a non-specular direction wi: its weight f·|cos θ_i|/pdf.
fn finish_sample(b: Bsdf, wo: vec3f, wi: vec3f, transport: u32) -> BsdfSample {
    let pdf = bsdf_pdf(b, wo, wi);
    if pdf <= 0.0 {
        return no_sample();
    }
    return BsdfSample(wi, bsdf_eval(b, wo, wi, transport) * (abs(wi.z) / pdf), pdf, false, true);
}

// A direction for wo from three uniforms (Bsdf::sample).
fn bsdf_sample(b: Bsdf, wo: vec3f, u: vec3f, transport: u32) -> BsdfSample {
    if wo.z == 0.0 {
        return no_sample();
    }
    let lp = lobe_probabilities(b, abs(wo.z));
    let side = select(1.0, -1.0, wo.z < 0.0);
    let o = wo * side;
    // u0 < the coat's probability picks the coat.
    if u.x < lp.coat {
        if !rough_coat(b) {
            let w = b.clearcoat * schlick(vec3f(COAT_F0), o.z).x / lp.coat;
            return BsdfSample(vec3f(-o.x, -o.y, o.z) * side, vec3f(w), lp.coat, true, true);
        }
        let wc = reflect_about(o, vndf_sample(o, b.clearcoat_alpha, u.y, u.z));
        if wc.z <= 0.0 {
            return no_sample();
        }
        return finish_sample(b, wo, wc * side, transport);
    }
    let p = lp.under;
    var u0 = u.x - lp.coat;
    var lobe = 4u;
    for (var k = 0u; k < 4u; k++) {
        if p[k] > 0.0 {
            lobe = k;
            if u0 < p[k] {
                break;
            }
            u0 -= p[k];
        }
    }
    if lobe == 4u {
        return no_sample();
    }
    let pl = p[lobe];
    u0 = clamp(u0 / pl, 0.0, 0.99999994);
    if lobe == 3u {
        return sample_glass(b, wo, u0, u.y, u.z, pl, transport);
    }
    var wi: vec3f;
    if lobe == 2u {
        wi = cosine_hemisphere(vec3f(0.0, 0.0, 1.0), u.y, u.z);
    } else if bsdf_is_smooth(b) {
        var w = (1.0 - b.metallic) * (1.0 - b.transmission) * layer_fresnel(b, o.z);
        if lobe == 0u {
            w = b.metallic * schlick(b.base, o.z);
        }
        let wr = vec3f(-o.x, -o.y, o.z) * side;
        return BsdfSample(wr, w * coat_scale(b, wo, wr, transport) / pl, pl, true, true);
    } else {
        wi = reflect_about(o, vndf_sample(o, b.alpha, u.y, u.z));
    }
    if wi.z <= 0.0 {
        return no_sample();
    }
    return finish_sample(b, wo, wi * side, transport);
}

// The shading frame about unit n: columns t, b, n (local = transpose · world).
fn shading_frame(n: vec3f) -> mat3x3f {
    let tb = orthonormal_basis(n);
    return mat3x3f(tb[0], tb[1], n);
}

fn to_local(f: mat3x3f, v: vec3f) -> vec3f {
    return vec3f(dot(v, f[0]), dot(v, f[1]), dot(v, f[2]));
}
