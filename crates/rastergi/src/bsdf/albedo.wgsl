// The GGX and glass albedo tables (albedo.rs), read through the includer's accessors.

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
