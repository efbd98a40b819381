// The scattering model (bsdf.rs states the math; this is its twin, checked against it on the
// GPU by bsdf::eval_on_gpu). Directions are unit vectors away from the surface in the shading
// frame (z = the front face's shading normal).

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

fn schlick_weight(c: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

fn schlick(f0: vec3f, c: f32) -> vec3f {
    return f0 + (vec3f(1.0) - f0) * schlick_weight(c);
}

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

fn mirror_z(w: vec3f) -> vec3f {
    return vec3f(w.x, w.y, -w.z);
}

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

// The GGX lobe's directional albedo tables (bsdf/albedo.rs, GpuGgxAlbedo): cell k = √α·N + μ
// holds (E₁, E₅) at k and k + 1; means[j] (Ē₁, Ē₅) at √α cells j and j + 1. Read through
// the includer's ggx_cell(k), ggx_mean(j) and glass_cell(r) (the scene's from two textures,
// gpu_scene.wgsl).
struct GgxAlbedoTable {
    cells: array<vec4f, GGX_ALBEDO_CELLS>,
    means: array<vec4f, GGX_ALBEDO_N>,
    // Rough solid glass's single-scattering albedo (albedo.rs, GlassAlbedo): index
    // ((side·GLASS_ALBEDO_ETAS + η)·N + √α)·N + μ, side 1 inside; zeros where no material needs it.
    glass: array<f32, GLASS_ALBEDO_CELLS>,
}

// (E₁, E₅) of the GGX lobe at cos θ_o = mu and alpha, bilinear in (μ, √α) between cells
// (GgxAlbedo::at).
fn ggx_albedo(mu: f32, alpha: f32) -> vec2f {
    let n = GGX_ALBEDO_N;
    let tx = clamp(mu, 0.0, 1.0) * f32(n - 1u);
    let ty = sqrt(clamp(alpha, 0.0, 1.0)) * f32(n - 1u);
    let i = min(u32(tx), n - 2u);
    let j = min(u32(ty), n - 2u);
    let fx = tx - f32(i);
    let a = ggx_cell(j * n + i);
    let b = ggx_cell((j + 1u) * n + i);
    let lo = a.xy + (a.zw - a.xy) * fx;
    let hi = b.xy + (b.zw - b.xy) * fx;
    return lo + (hi - lo) * (ty - f32(j));
}

// (Ē₁, Ē₅) at alpha, linear between cells (GgxAlbedo::mean_at).
fn ggx_albedo_mean(alpha: f32) -> vec2f {
    let t = sqrt(clamp(alpha, 0.0, 1.0)) * f32(GGX_ALBEDO_N - 1u);
    let j = min(u32(t), GGX_ALBEDO_N - 2u);
    let m = ggx_mean(j);
    return m.xy + (m.zw - m.xy) * (t - f32(j));
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

// The share the layer leaves to the diffuse base (Bsdf::diffuse_share): energy-conserving,
// (1 − E_L(cos_o))(1 − E_L(cos_i)) / (1 − Ē_L).
fn diffuse_share(b: Bsdf, cos_o: f32, cos_i: f32) -> vec3f {
    if b.specular == 0.0 {
        return vec3f(1.0);
    }
    return (vec3f(1.0) - layer_albedo(b, cos_o)) * (vec3f(1.0) - layer_albedo(b, cos_i)) / (vec3f(1.0) - layer_mean_albedo(b));
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

// f(wo, wi) of the non-specular lobes: the coat's and, scaled by what it leaves, the model's
// under it (Bsdf::eval).
fn bsdf_eval(b: Bsdf, wo: vec3f, wi: vec3f, transport: u32) -> vec3f {
    let under = eval_under_coat(b, wo, wi, transport);
    if b.clearcoat <= 0.0 {
        return under;
    }
    return coat_eval(b, wo, wi) + under * coat_scale(b, wo, wi, transport);
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

// The shading frame about unit n: columns t, b, n (local = transpose · world).
fn shading_frame(n: vec3f) -> mat3x3f {
    let tb = orthonormal_basis(n);
    return mat3x3f(tb[0], tb[1], n);
}

fn to_local(f: mat3x3f, v: vec3f) -> vec3f {
    return vec3f(dot(v, f[0]), dot(v, f[1]), dot(v, f[2]));
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
