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

const NO_LIGHT: u32 = 0xffffffffu;

@group(0) @binding(0) var<storage, read> triangles: array<Triangle>;
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

