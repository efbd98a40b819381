// The scene, bind group 0 of every pass that reads it (gpu_scene.rs).

// What the scene holds, fixed per pipeline (GpuScene::pipeline_constants): a scene without
// it compiles without the branches that serve it (a Lambertian scene's kernels are as small
// as before materials). Some material is not Lambertian (bsdf.wgsl evaluates it):
override SCENE_BSDF: bool = true;
// Some material passes eye and gather rays (Material::passes_rays: the eye's and the
// gather's specular chains, the photon map's caustic twins):
override SCENE_PASSES_RAYS: bool = true;
// Some material reads a texture (MATERIAL_TEXTURED):
override SCENE_TEXTURES: bool = true;
// Some triangle has shading normals at its corners:
override SCENE_NORMALS: bool = true;
// Some material may let rays through (a cut-out or a stochastic surface, TRIANGLE_HAS_HOLES):
override SCENE_HOLES: bool = true;
// Some solid glass attenuates the light inside it (Material::medium):
override SCENE_MEDIA: bool = true;

// flags: TRIANGLE_HAS_HOLES where the material may let rays through.
struct Triangle {
    v0: vec3f,
    material: u32,
    v1: vec3f,
    flags: u32,
    v2: vec3f,
    // Its entry in `lights` where it emits, else NO_LIGHT (GpuTriangle::light).
    light: u32,
}

const NO_LIGHT: u32 = 0xffffffffu;

// A texture a material reads: its index in the atlas (NO_TEXTURE for none) and the affine
// map of the triangle's texture coordinates onto it, (dot(u, (uv, 1)), dot(v, (uv, 1))).
struct TextureSlot {
    u: vec3f,
    texture: u32,
    v: vec3f,
    _pad: u32,
}

// flags: MATERIAL_TWO_SIDED, MATERIAL_ALPHA_MASK, MATERIAL_ALPHA_BLEND, MATERIAL_TEXTURED
// (gpu_scene.rs). Its textures are in its record's maps, read only where the flags say.
struct Material {
    albedo: vec3f,
    flags: u32,
    emission: vec3f,
    opacity: f32,
    // The scattering model (bsdf.wgsl): perceptual roughness, α = roughness².
    metallic: f32,
    roughness: f32,
    specular: f32,
    ior: f32,
    transmission: f32,
    // σ inside solid glass (Material::medium), per channel.
    attenuation: array<f32, 3>,
    // The layer's colour at normal incidence (Material::specular_color).
    specular_color: vec3f,
    // The clear coat's weight and perceptual roughness (Material::clearcoat).
    clearcoat: f32,
    clearcoat_roughness: f32,
    _pad: array<u32, 3>,
}

// A material's textures and their parameters (gpu_scene.rs, GpuMaterialMaps).
struct MaterialMaps {
    alpha_cutoff: f32,
    normal_scale: f32,
    _pad: vec2u,
    albedo_map: TextureSlot,
    emission_map: TextureSlot,
    opacity_map: TextureSlot,
    normal_map: TextureSlot,
    // Linear: roughness × G, metallic × B.
    metal_rough_map: TextureSlot,
    // Linear: transmission × R; specular × A; sRGB: specular colour × RGB.
    transmission_map: TextureSlot,
    specular_map: TextureSlot,
    specular_color_map: TextureSlot,
    // Linear: clear coat × R; its roughness × G.
    clearcoat_map: TextureSlot,
    clearcoat_roughness_map: TextureSlot,
}

// A compressed node of the 4-wide BVH (bvh/wide.rs, WideNode): axis a's grid step is
// bitcast<f32>(byte a of exponents << 23); child i's box is origin + byte i of lo (of hi) · step;
// byte i of counts is 0 for an interior child (child[i] a node), a leaf's triangle count
// (child[i] its first triangle), or NO_CHILD & 255 for an unused slot.
struct WideNode {
    origin: vec3f,
    exponents: u32,
    lo: vec3u,
    counts: u32,
    hi: vec3u,
    _pad: u32,
    child: vec4u,
}

// A light of the distribution (lights.rs): `triangle` is the emissive triangle, or
// PUNCTUAL_LIGHT | the index of a punctual light.
struct LightEntry {
    triangle: u32,
    cdf: f32,
    pmf: f32,
    area: f32,
}

// A point, spot or distant light (lights.rs, PunctualLight).
struct PunctualLight {
    position: vec3f,
    kind: u32,
    direction: vec3f,
    cos_outer: f32,
    intensity: vec3f,
    cos_inner: f32,
    disc_centre: vec3f,
    disc_radius: f32,
}

@group(0) @binding(0) var<storage, read> triangles: array<Triangle>;
// A material and its textures (gpu_scene.rs, GpuMaterialRecord): one binding for both.
struct MaterialRecord {
    material: Material,
    maps: MaterialMaps,
}

@group(0) @binding(1) var<storage, read> materials: array<MaterialRecord>;
@group(0) @binding(2) var<storage, read> bvh_nodes: array<WideNode>;
// Every texture's mip chain at its own size, the rows of one texture (textures.wgsl).
@group(0) @binding(5) var textures: texture_2d<f32>;

// The rest of the scene in one buffer of words (one binding: WebGPU allows 10 storage buffers
// per shader stage). Its first 16 words are a header (gpu_scene.rs, GpuSceneOffsets; not a
// uniform buffer, which beside these storage buffers crashes lavapipe, Mesa 22.3, in the raster
// gather, and which buys nothing on Mesa 25: `render cornell --gather raster`, 256², 32
// iterations, 1.01× the wall time, farm-bench -n 3): word DATA_UVS … DATA_ENVIRONMENT (shader.rs's constants) is where each part starts or
// how many items it holds. After it:
// - texture coordinates of the triangles' corners, three vec2f per triangle (one zero
//   triangle when the scene has none);
// - shading normals at the corners, nine floats per triangle (zero: the triangle shades flat;
//   one zero triangle when the scene has none);
// - tangents (xyz, handedness w) at the corners for normal maps, twelve floats per triangle
//   (zero: none; one zero triangle when the scene has none);
// - the light distribution's entries (LightEntry; one zero entry when the scene has none);
// - the point, spot and distant lights (PunctualLight; one zero light when the scene has none);
// - the environment map (environment.wgsl).
@group(0) @binding(8) var<storage, read> scene_data: array<u32>;

// Word k of the header: one load (the passes read only the fields they use).
fn scene_offset(k: u32) -> u32 {
    return scene_data[k];
}

fn scene_f32(i: u32) -> f32 {
    return bitcast<f32>(scene_data[i]);
}

// Word i of the texture atlas's entries (textures.wgsl).
fn atlas_entry_word(i: u32) -> u32 {
    return scene_data[scene_offset(DATA_TEXTURES) + i];
}

fn scene_vec3(i: u32) -> vec3f {
    return vec3f(scene_f32(i), scene_f32(i + 1u), scene_f32(i + 2u));
}

fn scene_vec4(i: u32) -> vec4f {
    return vec4f(scene_f32(i), scene_f32(i + 1u), scene_f32(i + 2u), scene_f32(i + 3u));
}

// Entry e of the light distribution.
fn light_entry(e: u32) -> LightEntry {
    let i = scene_offset(DATA_LIGHTS) + 4u * e;
    return LightEntry(scene_data[i], scene_f32(i + 1u), scene_f32(i + 2u), scene_f32(i + 3u));
}

// Punctual light k.
fn punctual_light(k: u32) -> PunctualLight {
    let i = scene_offset(DATA_PUNCTUAL) + 16u * k;
    return PunctualLight(scene_vec3(i), scene_data[i + 3u], scene_vec3(i + 4u), scene_f32(i + 7u),
        scene_vec3(i + 8u), scene_f32(i + 11u), scene_vec3(i + 12u), scene_f32(i + 15u));
}

// The GGX lobe's albedo tables (bsdf/albedo.rs, GpuGgxAlbedo) as textures, read texel by texel
// (sampled textures do not count against the 10 storage buffers per stage that WebGPU grants,
// and a typed fetch costs less than its words from scene_data: mat_mix rendered 1.36× slower
// that way on lavapipe). cells and means: N × (N + 1) RGBA, cell k at (k mod N, k / N), mean j
// at (j, N). Glass: N × (rows) single-channel, cell r at (r mod N, r / N). 1 × 1 where the
// scene has no material that reads them.
@group(0) @binding(13) var ggx_cells_texture: texture_2d<f32>;
@group(0) @binding(14) var glass_albedo_texture: texture_2d<f32>;

// The GGX albedo tables' cell k, mean j and glass cell r (bsdf.wgsl's accessors).
fn ggx_cell(k: u32) -> vec4f {
    return textureLoad(ggx_cells_texture, vec2u(k % GGX_ALBEDO_N, k / GGX_ALBEDO_N), 0);
}

fn ggx_mean(j: u32) -> vec4f {
    return textureLoad(ggx_cells_texture, vec2u(j, GGX_ALBEDO_N), 0);
}

fn glass_cell(r: u32) -> f32 {
    return textureLoad(glass_albedo_texture, vec2u(r % GGX_ALBEDO_N, r / GGX_ALBEDO_N), 0).x;
}

// The random stream of stochastic opacity (passes_through): each entry point that finds
// surfaces sets it from its iteration's seed, so that the holes of a semi-transparent
// surface move from one iteration to the next.
var<private> alpha_seed: u32 = 0u;

// MATERIAL_TWO_SIDED and NO_TEXTURE: shader::constants.

// No triangle (a miss; an emitter that is not a triangle; no triangle to skip).
const NO_TRIANGLE: u32 = 0xffffffffu;

// A point on a surface: position, front-face geometric normal, shading normal (interpolated,
// in the geometric normal's hemisphere; the geometric normal where the triangle has none)
// and material: its base colour `albedo`, emission, flags and scattering model (bsdf.wgsl;
// metallic and roughness with their texture applied).
struct Surface {
    pos: vec3f,
    normal: vec3f,
    shading: vec3f,
    albedo: vec3f,
    emission: vec3f,
    flags: u32,
    tri: u32,
    metallic: f32,
    roughness: f32,
    specular: f32,
    ior: f32,
    transmission: f32,
    specular_color: vec3f,
    clearcoat: f32,
    clearcoat_roughness: f32,
}

// Vertex `vi` of the scene drawn as one non-indexed triangle list (vertex pulling in the
// raster passes): its position, its barycentrics (b1, b2) and its triangle.
struct TriangleVertex {
    pos: vec3f,
    bary: vec2f,
    tri: u32,
}

fn triangle_vertex(vi: u32) -> TriangleVertex {
    let tri = vi / 3u;
    let corner = vi % 3u;
    let t = triangles[tri];
    if corner == 1u {
        return TriangleVertex(t.v1, vec2f(1.0, 0.0), tri);
    } else if corner == 2u {
        return TriangleVertex(t.v2, vec2f(0.0, 1.0), tri);
    }
    return TriangleVertex(t.v0, vec2f(0.0, 0.0), tri);
}

fn triangle_normal(t: Triangle) -> vec3f {
    return normalize(cross(t.v1 - t.v0, t.v2 - t.v0));
}

// Texture coordinates at barycentrics (b1, b2) of triangle `tri` (PreparedScene::uv_at).
fn surface_uv(tri: u32, b1: f32, b2: f32) -> vec2f {
    let i = scene_offset(DATA_UVS) + 6u * min(tri, scene_offset(DATA_UV_TRIANGLES) - 1u);
    let uv = array<vec2f, 3>(vec2f(scene_f32(i), scene_f32(i + 1u)), vec2f(scene_f32(i + 2u), scene_f32(i + 3u)),
        vec2f(scene_f32(i + 4u), scene_f32(i + 5u)));
    return uv[0] * (1.0 - b1 - b2) + uv[1] * b1 + uv[2] * b2;
}

// The texture of slot s at the triangle's texture coordinates uv and level of detail lod.
fn slot_sample(s: TextureSlot, uv: vec2f, lod: f32) -> vec4f {
    let st = vec2f(dot(s.u, vec3f(uv, 1.0)), dot(s.v, vec3f(uv, 1.0)));
    return atlas_sample(s.texture, st, lod);
}

// The shading normal at barycentrics (b1, b2) of triangle `tri` of geometric normal n and
// material mi: its corners' normals interpolated and normalised, turned into n's hemisphere (n
// where the triangle has none or they cancel), perturbed by the material's normal map
// (PreparedScene::shading_normal_at); `textured`: the material reads some texture.
fn shading_normal(tri: u32, b1: f32, b2: f32, n: vec3f, mi: u32, textured: bool, uv: vec2f) -> vec3f {
    let w = vec3f(1.0 - b1 - b2, b1, b2);
    var ns = n;
    if SCENE_NORMALS {
        let i = scene_offset(DATA_NORMALS) + 9u * min(tri, scene_offset(DATA_NORMAL_TRIANGLES) - 1u);
        var v = vec3f(0.0);
        for (var k = 0u; k < 3u; k++) {
            v += w[k] * scene_vec3(i + 3u * k);
        }
        let len = length(v);
        if len >= 1e-6 {
            v /= len;
            ns = select(-v, v, dot(v, n) >= 0.0);
        }
    }
    if !textured {
        return ns;
    }
    let map = materials[mi].maps.normal_map;
    if map.texture == NO_TEXTURE {
        return ns;
    }
    let j = scene_offset(DATA_TANGENTS) + 12u * min(tri, scene_offset(DATA_TANGENT_TRIANGLES) - 1u);
    var t = vec4f(0.0);
    for (var k = 0u; k < 3u; k++) {
        t += w[k] * scene_vec4(j + 4u * k);
    }
    return perturb_normal(n, ns, t, slot_sample(map, uv, 0.0).rgb, materials[mi].maps.normal_scale);
}

// gpu_scene::perturb_normal: ns perturbed by the normal-map texel c in the frame (t', b, ns).
fn perturb_normal(n: vec3f, ns: vec3f, t: vec4f, c: vec3f, scale: f32) -> vec3f {
    var tangent = t.xyz - ns * dot(ns, t.xyz);
    if dot(tangent, tangent) < 1e-12 {
        return ns;
    }
    tangent = normalize(tangent);
    let bitangent = cross(ns, tangent) * select(1.0, -1.0, t.w < 0.0);
    let m = (2.0 * c - 1.0) * vec3f(scale, scale, 1.0);
    let v = tangent * m.x + bitangent * m.y + ns * m.z;
    if dot(v, v) < 1e-12 {
        return ns;
    }
    return bend_towards(normalize(v), n);
}

// The opacity α of material mi (its factor `opacity`) at texture coordinates uv
// (PreparedScene::opacity_at).
fn surface_opacity(mi: u32, opacity: f32, uv: vec2f, lod: f32) -> f32 {
    let map = materials[mi].maps.opacity_map;
    if map.texture == NO_TEXTURE {
        return opacity;
    }
    return opacity * slot_sample(map, uv, lod).a;
}

// Whether a ray (or a fragment) meeting triangle `tri` at barycentrics (b1, b2) passes through
// it (PreparedScene::passes_through): through a cut-out where α < its cutoff; through a
// stochastic surface where a uniform hashed from the point and alpha_seed is ≥ α.
fn passes_through(tri: u32, b1: f32, b2: f32, lod: f32) -> bool {
    if !SCENE_HOLES {
        return false;
    }
    let mi = triangles[tri].material;
    let m = materials[mi].material;
    if (m.flags & (MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) == 0u {
        return false;
    }
    let a = surface_opacity(mi, m.opacity, surface_uv(tri, b1, b2), lod);
    if (m.flags & MATERIAL_ALPHA_MASK) != 0u {
        return a < materials[mi].maps.alpha_cutoff;
    }
    let u = unit_f32(pcg_hash(pcg_hash(pcg_hash(tri ^ alpha_seed) ^ bitcast<u32>(b1)) ^ bitcast<u32>(b2)));
    return u >= a;
}

// The radiance emitter triangle `tri` sends from barycentrics (b1, b2) as a light sample or a
// photon sees it (PreparedScene::emitter_radiance): none from a cut-out's hole, α × its
// emission on a stochastic surface.
fn emitter_radiance(tri: u32, b1: f32, b2: f32) -> vec3f {
    let mi = triangles[tri].material;
    let m = materials[mi].material;
    if !(SCENE_TEXTURES || SCENE_HOLES) || (m.flags & (MATERIAL_TEXTURED | MATERIAL_ALPHA_MASK | MATERIAL_ALPHA_BLEND)) == 0u {
        return m.emission;
    }
    let uv = surface_uv(tri, b1, b2);
    let le = surface_emission(mi, m.emission, uv);
    if (m.flags & MATERIAL_ALPHA_MASK) != 0u {
        return select(le, vec3f(0.0), surface_opacity(mi, m.opacity, uv, 0.0) < materials[mi].maps.alpha_cutoff);
    }
    if (m.flags & MATERIAL_ALPHA_BLEND) != 0u {
        return le * surface_opacity(mi, m.opacity, uv, 0.0);
    }
    return le;
}

// The emitted radiance of material mi (its factor `emission`) at texture coordinates uv
// (PreparedScene::emission_at).
fn surface_emission(mi: u32, emission: vec3f, uv: vec2f) -> vec3f {
    let map = materials[mi].maps.emission_map;
    if map.texture == NO_TEXTURE {
        return emission;
    }
    return emission * slot_sample(map, uv, 0.0).rgb;
}

// A shading normal ns seen from direction v (unit, towards the viewer): unchanged where it
// faces v, else bent in the plane of ns and v until it is just past perpendicular to v (the
// surface seen from behind its shading normal would be black or lit from below).
fn bend_towards(ns: vec3f, v: vec3f) -> vec3f {
    let c = dot(ns, v);
    if c >= 0.0 {
        return ns;
    }
    return normalize(ns + (1e-3 - c) * v);
}

// The level of detail of material mi's albedo texture where the triangle's texture coordinates
// change by dx and dy across a pixel: those changes placed by the texture's transform.
fn albedo_lod(mi: u32, dx: vec2f, dy: vec2f) -> f32 {
    let s = materials[mi].maps.albedo_map;
    let a = mat2x2f(vec2f(s.u.x, s.v.x), vec2f(s.u.y, s.v.y));
    return texture_lod(s.texture, a * dx, a * dy);
}

// Barycentrics (b1, b2) of the point p of triangle t's plane.
fn plane_barycentrics(t: Triangle, p: vec3f) -> vec2f {
    let e1 = t.v1 - t.v0;
    let e2 = t.v2 - t.v0;
    let d = p - t.v0;
    let d11 = dot(e1, e1);
    let d12 = dot(e1, e2);
    let d22 = dot(e2, e2);
    let det = d11 * d22 - d12 * d12;
    if det == 0.0 {
        return vec2f(0.0);
    }
    let p1 = dot(d, e1);
    let p2 = dot(d, e2);
    return vec2f(d22 * p1 - d12 * p2, d11 * p2 - d12 * p1) / det;
}

// The surface at barycentrics (b1, b2) of triangle `tri`, its albedo texture (if any) read at
// level of detail `lod`, the others at level 0 (PreparedScene::albedo_at, emission_at,
// shading_normal_at).
fn surface_at(tri: u32, b1: f32, b2: f32, lod: f32) -> Surface {
    let t = triangles[tri];
    let mi = t.material;
    let m = materials[mi].material;
    let textured = SCENE_TEXTURES && (m.flags & MATERIAL_TEXTURED) != 0u;
    var uv = vec2f(0.0);
    if textured {
        uv = surface_uv(tri, b1, b2);
    }
    var s: Surface;
    s.pos = t.v0 * (1.0 - b1 - b2) + t.v1 * b1 + t.v2 * b2;
    s.normal = triangle_normal(t);
    s.shading = shading_normal(tri, b1, b2, s.normal, mi, textured, uv);
    s.albedo = m.albedo;
    s.emission = m.emission;
    if textured {
        let maps = materials[mi].maps;
        if maps.albedo_map.texture != NO_TEXTURE {
            s.albedo *= slot_sample(maps.albedo_map, uv, lod).rgb;
        }
        if maps.emission_map.texture != NO_TEXTURE {
            s.emission *= slot_sample(maps.emission_map, uv, 0.0).rgb;
        }
    }
    s.flags = m.flags;
    s.tri = tri;
    s.metallic = m.metallic;
    s.roughness = m.roughness;
    s.specular = m.specular;
    s.specular_color = m.specular_color;
    s.ior = m.ior;
    s.transmission = m.transmission;
    s.clearcoat = m.clearcoat;
    s.clearcoat_roughness = m.clearcoat_roughness;
    if textured {
        let mr_map = materials[mi].maps.metal_rough_map;
        if mr_map.texture != NO_TEXTURE {
            let mr = slot_sample(mr_map, uv, 0.0);
            s.roughness *= mr.g;
            s.metallic *= mr.b;
        }
        let t_map = materials[mi].maps.transmission_map;
        if t_map.texture != NO_TEXTURE {
            s.transmission = clamp(s.transmission * slot_sample(t_map, uv, 0.0).r, 0.0, 1.0);
        }
        let s_map = materials[mi].maps.specular_map;
        if s_map.texture != NO_TEXTURE {
            s.specular = clamp(s.specular * slot_sample(s_map, uv, 0.0).a, 0.0, 1.0);
        }
        let c_map = materials[mi].maps.specular_color_map;
        if c_map.texture != NO_TEXTURE {
            s.specular_color *= slot_sample(c_map, uv, 0.0).rgb;
        }
        let k_map = materials[mi].maps.clearcoat_map;
        if k_map.texture != NO_TEXTURE {
            s.clearcoat *= slot_sample(k_map, uv, 0.0).r;
        }
        let kr_map = materials[mi].maps.clearcoat_roughness_map;
        if kr_map.texture != NO_TEXTURE {
            s.clearcoat_roughness *= slot_sample(kr_map, uv, 0.0).g;
        }
    }
    return s;
}

// The model at a surface point (PreparedScene::bsdf_at).
fn surface_bsdf(s: Surface) -> Bsdf {
    let r = clamp(s.roughness, 0.0, 1.0);
    let rc = clamp(s.clearcoat_roughness, 0.0, 1.0);
    return Bsdf(s.albedo, clamp(s.metallic, 0.0, 1.0), r * r, s.specular, s.specular_color, s.ior, s.transmission,
        (s.flags & MATERIAL_THIN) != 0u, (s.flags & MATERIAL_SINGLE_SCATTERING) == 0u, clamp(s.clearcoat, 0.0, 1.0),
        rc * rc);
}

// Whether the surface scatters by Dirac deltas alone (a perfect mirror or smooth glass, no
// diffuse or glossy lobe): eye and gather rays continue through it (specular.wgsl,
// gather_radiance).
fn surface_purely_specular(s: Surface) -> bool {
    let b = surface_bsdf(s);
    let opaque = (1.0 - b.metallic) * (1.0 - b.transmission);
    return bsdf_is_smooth(b) && opaque <= 0.0 && !rough_coat(b);
}

// Whether eye and gather rays go on through the surface rather than stop at it: a purely
// specular one, or glass without a diffuse base, rough or smooth (its light comes from
// behind it, which a stop on its surface cannot gather; Material::passes_rays).
fn surface_passes_rays(s: Surface) -> bool {
    let opaque = (1.0 - clamp(s.metallic, 0.0, 1.0)) * (1.0 - s.transmission);
    return SCENE_PASSES_RAYS && opaque <= 0.0 && (surface_purely_specular(s) || s.transmission > 0.0);
}

// For a ray arriving along d at a surface that scatters by a delta lobe and by others too (a
// smooth specular layer over a diffuse base, a smooth partly metallic surface, a smooth clear
// coat over a rough model): the probability
// pd with which bsdf_sample picks a delta lobe there, and for a uniform u0 the first uniform of
// a scatter_at that picks the delta lobe u0 falls in where u0 < pd (−1 where u0 ≥ pd: a
// non-delta lobe). pd = 0 elsewhere (no delta lobe, or one that passes rays anyway).
struct DeltaChoice {
    pd: f32,
    u: f32,
}

fn surface_delta_choice(s: Surface, d: vec3f, u0: f32) -> DeltaChoice {
    var c = DeltaChoice(0.0, -1.0);
    if !SCENE_PASSES_RAYS || surface_is_lambertian(s) || surface_passes_rays(s) {
        return c;
    }
    let a = arrival(s, d);
    let coat_delta = a.b.clearcoat > 0.0 && !rough_coat(a.b);
    let base_delta = bsdf_is_smooth(a.b);
    if !coat_delta && !base_delta {
        return c;
    }
    let lp = lobe_probabilities(a.b, abs(a.wo.z));
    // The lobes in bsdf_sample's order: the coat (delta when smooth), then metal, layer (delta
    // when smooth), diffuse, glass.
    let pc = select(0.0, lp.coat, coat_delta);
    let p = select(vec4f(0.0), lp.under * vec4f(1.0, 1.0, 0.0, 1.0), base_delta);
    c.pd = pc + p.x + p.y + p.w;
    if u0 < pc {
        c.u = u0;
        return c;
    }
    var rest = u0 - pc;
    var start = lp.coat;
    for (var k = 0u; k < 4u; k++) {
        if rest < p[k] {
            c.u = start + rest;
            return c;
        }
        rest -= p[k];
        start += lp.under[k];
    }
    return c;
}

// Whether the surface scatters as a plain Lambertian one, f = ρ/π.
fn surface_is_lambertian(s: Surface) -> bool {
    return !SCENE_BSDF || (s.flags & MATERIAL_LAMBERTIAN) != 0u;
}

// The albedo with which a point reflects the photon map's irradiance towards wo (a unit
// vector away from the surface): ρ, or the diffuse equivalent of a glossy or specular surface
// seen from wo (bsdf_diffuse_equivalent, an approximation).
fn surface_rho(s: Surface, wo: vec3f) -> vec3f {
    if surface_is_lambertian(s) {
        return s.albedo;
    }
    return bsdf_diffuse_equivalent(surface_bsdf(s), dot(s.shading, wo));
}

// A ray arriving along d at surface s, scattered by its BSDF from three uniforms u (radiance
// transport): the new direction, its weight f·|cos|/pdf, the origin just off the surface on
// the new direction's side (eps away), and whether it was a delta lobe. `ok` is false where nothing
// scatters or the geometric and the shading side of the direction disagree. Solid glass hit
// from behind is left: its relative index inverts. (The eye's and the gather's specular
// chains; the path tracer and the photon tracer do the same with their own bookkeeping.)
struct Scatter {
    dir: vec3f,
    weight: vec3f,
    origin: vec3f,
    delta: bool,
    ok: bool,
    // The density the direction was drawn with and its |cos θ| to the shading normal.
    pdf: f32,
    cos: f32,
}

// A ray arriving along d at surface s, in the terms its BSDF is sampled in: the model with the
// relative index seen from the ray's side (solid glass hit from behind: inverted), the shading
// frame on that side (bent towards the ray), the direction back along the ray in it, and the
// geometric normal on that side.
struct Arrival {
    b: Bsdf,
    frame: mat3x3f,
    wo: vec3f,
    n: vec3f,
}

fn arrival(s: Surface, d: vec3f) -> Arrival {
    let front = dot(s.normal, d) < 0.0;
    let sf = shading_frame(bend_towards(select(-s.shading, s.shading, front), -d));
    var b = surface_bsdf(s);
    if !front && !b.thin {
        b.ior = 1.0 / b.ior;
    }
    return Arrival(b, sf, to_local(sf, -d), select(-s.normal, s.normal, front));
}

fn scatter_at(s: Surface, d: vec3f, u: vec3f, eps: f32) -> Scatter {
    return scatter_from(s.pos, arrival(s, d), u, eps);
}

// scatter_at for the arrival a at the surface point pos.
fn scatter_from(pos: vec3f, a: Arrival, u: vec3f, eps: f32) -> Scatter {
    var r: Scatter;
    r.ok = false;
    let n = a.n;
    let bs = bsdf_sample(a.b, a.wo, u, TRANSPORT_RADIANCE);
    if !bs.ok {
        return r;
    }
    r.dir = normalize(a.frame * bs.wi);
    let below = dot(n, r.dir) < 0.0;
    if (bs.wi.z < 0.0) != below || dot(n, r.dir) == 0.0 {
        return r;
    }
    r.weight = bs.weight;
    r.origin = pos + select(n, -n, below) * eps;
    r.delta = bs.delta;
    r.pdf = bs.pdf;
    r.cos = abs(bs.wi.z);
    r.ok = true;
    return r;
}

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

// A photon leaving the lights (lights.rs: LightTable::emit_photon): origin, direction, flux ×
// the photon count, and the emitter triangle to skip (NO_TRIANGLE for the other lights).
struct PhotonStart {
    origin: vec3f,
    skip: u32,
    dir: vec3f,
    flux: vec3f,
}

// A point uniform (u1, u2) on the disc of radius r, normal to `axis`, that a photon crossing
// the sphere (centre, r) along `axis` starts from.
fn disc_point(axis: vec3f, centre: vec3f, r: f32, u1: f32, u2: f32) -> vec3f {
    let tb = orthonormal_basis(axis);
    let rho = r * sqrt(u1);
    let phi = 2.0 * PI * u2;
    return centre - axis * r + (tb[0] * cos(phi) + tb[1] * sin(phi)) * rho;
}

// The start of a photon crossing the sphere (centre, r) along `axis`, aimed at the sphere
// aim = (centre, radius; radius 0: not aimed): (origin, 1/p(x)) (lights.rs: disc_start).
struct DiscStart {
    origin: vec3f,
    inv_pdf: f32,
}

fn disc_start(axis: vec3f, centre: vec3f, r: f32, aim: vec4f, u1: f32, u2: f32) -> DiscStart {
    var s: DiscStart;
    if aim.w <= 0.0 {
        s.origin = disc_point(axis, centre, r, u1, u2);
        s.inv_pdf = PI * r * r;
        return s;
    }
    let tb = orthonormal_basis(axis);
    let phi = 2.0 * PI * u2;
    let dir = tb[0] * cos(phi) + tb[1] * sin(phi);
    let d = aim.xyz - centre;
    let towards = d - axis * dot(d, axis);
    let near = aim.w * NEAR_SCALE;
    let whole = 1.0 - AIM_FRACTION - NEAR_FRACTION;
    var branch = 2u;
    if u1 < AIM_FRACTION {
        branch = 0u;
    } else if u1 < AIM_FRACTION + NEAR_FRACTION {
        branch = 1u;
    }
    var offset: vec3f;
    if branch == 0u {
        offset = towards + dir * (aim.w * sqrt(u1 / AIM_FRACTION));
    } else if branch == 1u {
        offset = towards + dir * (near * sqrt((u1 - AIM_FRACTION) / NEAR_FRACTION));
    } else {
        offset = dir * (r * sqrt((u1 - AIM_FRACTION - NEAR_FRACTION) / whole));
    }
    let from_aim = length(offset - towards);
    let in_aim = branch == 0u || from_aim <= aim.w;
    let in_near = branch <= 1u || from_aim <= near;
    let in_whole = branch == 2u || length(offset) <= r;
    let p = select(0.0, AIM_FRACTION / (PI * aim.w * aim.w), in_aim)
        + select(0.0, NEAR_FRACTION / (PI * near * near), in_near)
        + select(0.0, whole / (PI * r * r), in_whole);
    s.origin = centre - axis * r + offset;
    s.inv_pdf = 1.0 / p;
    return s;
}

// `aim`: where sun and sky photons are aimed (disc_start).
fn emit_photon(u0: f32, u1: f32, u2: f32, u3: f32, u4: f32, eps: f32, aim: vec4f) -> PhotonStart {
    var s: PhotonStart;
    let e = light_pick(u0);
    let entry = light_entry(e);
    if entry.triangle == ENVIRONMENT_LIGHT {
        // Towards the sky along the sampled direction; the photon travels the other way, from
        // the disc across the bounding sphere: L(ω)/(p(x)·pdf(ω)·pmf), 1/p(x) = πR² unaimed.
        let e = env_sample(u3, u4);
        s.dir = -e.xyz;
        let start = disc_start(s.dir, environment.disc_centre, environment.disc_radius, aim, u1, u2);
        s.origin = start.origin;
        s.flux = select(vec3f(0.0), env_radiance(e.xyz) * (start.inv_pdf / (e.w * entry.pmf)), e.w > 0.0);
        s.skip = NO_TRIANGLE;
        return s;
    }
    if (entry.triangle & PUNCTUAL_LIGHT) == 0u {
        let l = sample_light(e, u1, u2);
        // Φ = π·Le·A/pmf.
        s.flux = l.radiance * (PI / l.pdf_area);
        s.dir = cosine_hemisphere(l.normal, u3, u4);
        s.origin = l.pos + l.normal * eps;
        s.skip = l.tri;
        return s;
    }
    let p = punctual_light(entry.triangle & ~PUNCTUAL_LIGHT);
    s.skip = NO_TRIANGLE;
    if p.kind == LIGHT_POINT {
        s.origin = p.position;
        s.dir = uniform_sphere(u3, u4);
        s.flux = p.intensity * (4.0 * PI / entry.pmf);
    } else if p.kind == LIGHT_SPOT {
        s.origin = p.position;
        s.dir = cone_direction(p.direction, p.cos_outer, u3, u4);
        let solid = 2.0 * PI * (1.0 - p.cos_outer);
        s.flux = p.intensity * (spot_falloff(p, dot(p.direction, s.dir)) * solid / entry.pmf);
    } else {
        let start = disc_start(p.direction, p.disc_centre, p.disc_radius, aim, u1, u2);
        s.origin = start.origin;
        s.dir = cone_direction(p.direction, p.cos_outer, u3, u4);
        s.flux = p.intensity * (start.inv_pdf / entry.pmf);
    }
    return s;
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
