//! WGSL composition: a pass's shader is the shared sources (constants, sampling, scene, BVH
//! traversal; the passes add the per-frame uniforms, visible points and film writes,
//! [`crate::passes::per_pixel`]) followed by the pass's own file.
//! WGSL resolves module-scope names in any order, so the pieces are simply concatenated.
//!
//! Constants that Rust and WGSL share are written once, in Rust: [`constants`] generates
//! their WGSL declarations. Structs shared by both are checked by the layout test
//! (`layout_test.rs`), which parses every composed shader with naga.

use crate::gpu::consts::{
    CAUSTIC_CELL, ENVIRONMENT_LIGHT, FILM_DIRECT, FILM_INDIRECT, FILM_PHOTON_VIEW, LIGHT_DISTANT, LIGHT_POINT,
    LIGHT_SPOT, MATERIAL_ALPHA_BLEND, MATERIAL_ALPHA_MASK, MATERIAL_LAMBERTIAN, MATERIAL_SINGLE_SCATTERING,
    MATERIAL_TEXTURED, MATERIAL_THIN, MATERIAL_TWO_SIDED, MAX_DIRECTIONS, MAX_HOLE_CROSSINGS, MAX_SEPARATORS,
    MIN_LOOKUP_AREA, NO_TEXTURE, OFFSET_SHIFT, OFFSET_STEP, PUNCTUAL_LIGHT, REGION_SHIFT, TRIANGLE_HAS_HOLES, stream,
};

/// The scattering model's files in order (`bsdf/`: the dispatch, then its lobes and tables), for
/// [`SCENE_FILES`] and [`BSDF`].
macro_rules! bsdf_wgsl {
    () => {
        concat!(
            include_str!("../bsdf/bsdf.wgsl"),
            "\n",
            include_str!("../bsdf/microfacet.wgsl"),
            "\n",
            include_str!("../bsdf/dielectric.wgsl"),
            "\n",
            include_str!("../bsdf/layered.wgsl"),
            "\n",
            include_str!("../bsdf/diffuse.wgsl"),
            "\n",
            include_str!("../bsdf/albedo.wgsl")
        )
    };
}

pub const SAMPLING: &str = include_str!("../sampling/sampling.wgsl");
/// The scene's bind group (geometry, materials, lights and the environment) without the structs
/// it shares with Rust: a pass composes [`crate::gpu_scene::wgsl`], which puts them first. Its
/// bindings and their accessors (`gpu_scene.wgsl`), the point on a surface (`surface.wgsl`, the
/// GPU twin of `surface.rs`) and light sampling (`lights.wgsl`, of `lights.rs`) are one file
/// cut in three: they follow each other with nothing between.
pub(crate) const SCENE_FILES: &str = concat!(
    include_str!("../gpu_scene.wgsl"),
    include_str!("../surface.wgsl"),
    include_str!("../lights.wgsl"),
    "\n",
    include_str!("../textures.wgsl"),
    "\n",
    include_str!("../environment.wgsl"),
    "\n",
    bsdf_wgsl!()
);
/// The texture atlas's sampling (`atlas_sample`); the includer binds `textures` and defines
/// `atlas_entry_word` (needs [`constants`]).
pub const TEXTURES: &str = include_str!("../textures.wgsl");
/// The scattering model alone (it needs [`SAMPLING`]).
pub const BSDF: &str = bsdf_wgsl!();
/// Tracing's interface (`trace`, `occluded`, `bvh.wgsl`) with the compute path's `traverse`
/// (`bvh_compute.wgsl`); [`for_rays`] swaps the latter for the hardware one.
pub const BVH: &str = concat!(include_str!("../bvh/bvh.wgsl"), "\n", include_str!("../bvh/bvh_compute.wgsl"));
/// The compute path's `traverse`, as [`BVH`] holds it.
pub const TRAVERSE_COMPUTE: &str = include_str!("../bvh/bvh_compute.wgsl");
/// The hardware path's `traverse`: a ray query over the scene's TLAS (`accel.rs`).
pub const TRAVERSE_HARDWARE: &str = include_str!("bvh_hardware.wgsl");
/// `count_ray` as [`BVH`] holds it: counts nothing.
pub const NO_RAY_COUNT: &str = "fn count_ray() {}";
/// `count_ray` where rays are counted: one more in the scene's ray count
/// ([`crate::gpu_scene::RAY_COUNT_BINDING`]).
pub const RAY_COUNT: &str = include_str!("ray_count.wgsl");

/// WGSL declarations of the constants Rust and WGSL share, from their Rust values.
pub fn constants() -> String {
    let u32s = [
        ("MAX_DIRECTIONS", MAX_DIRECTIONS),
        ("MATERIAL_TWO_SIDED", MATERIAL_TWO_SIDED),
        ("MATERIAL_ALPHA_MASK", MATERIAL_ALPHA_MASK),
        ("MATERIAL_ALPHA_BLEND", MATERIAL_ALPHA_BLEND),
        ("MATERIAL_TEXTURED", MATERIAL_TEXTURED),
        ("MATERIAL_THIN", MATERIAL_THIN),
        ("MATERIAL_LAMBERTIAN", MATERIAL_LAMBERTIAN),
        ("MATERIAL_SINGLE_SCATTERING", MATERIAL_SINGLE_SCATTERING),
        ("MAX_HOLE_CROSSINGS", MAX_HOLE_CROSSINGS),
        ("TRIANGLE_HAS_HOLES", TRIANGLE_HAS_HOLES),
        ("TRIANGLE_ZERO_AREA", crate::gpu::consts::TRIANGLE_ZERO_AREA),
        ("NO_TEXTURE", NO_TEXTURE),
        ("ATLAS_ROW", crate::gpu::consts::ATLAS_ROW),
        ("FILM_DIRECT", FILM_DIRECT),
        ("FILM_INDIRECT", FILM_INDIRECT),
        ("FILM_PHOTON_VIEW", FILM_PHOTON_VIEW),
        ("REGION_SHIFT", REGION_SHIFT),
        ("OFFSET_SHIFT", OFFSET_SHIFT),
        ("MAX_SEPARATORS", MAX_SEPARATORS as u32),
        ("STREAM_DIRECT", stream::DIRECT),
        ("STREAM_PATH", stream::PATH),
        ("STREAM_PHOTON", stream::PHOTON),
        ("STREAM_HIT_LIGHT", stream::HIT_LIGHT),
        ("STREAM_EYE_CHAIN", stream::EYE_CHAIN),
        ("STREAM_GATHER_CHAIN", stream::GATHER_CHAIN),
        ("STREAM_GATHER_LOBE", stream::GATHER_LOBE),
        ("STREAM_EMITTER_EDGE", stream::EMITTER_EDGE),
        ("PUNCTUAL_LIGHT", PUNCTUAL_LIGHT),
        ("ENVIRONMENT_LIGHT", ENVIRONMENT_LIGHT),
        ("CAUSTIC_CELL", CAUSTIC_CELL),
        ("GUIDE_POSITIONS", crate::gpu::consts::GUIDE_POSITIONS),
        ("GUIDE_ENV_BANDS", crate::gpu::consts::GUIDE_ENV_BANDS),
        ("MAX_GUIDED_LIGHTS", crate::gpu::consts::MAX_GUIDED_LIGHTS),
        ("GUIDE_HEADER_WORDS", crate::gpu::consts::GUIDE_HEADER_WORDS),
        ("GATHER_GUIDE_BANDS", crate::gpu::consts::GATHER_GUIDE_BANDS),
        ("GATHER_GUIDE_BINS", crate::gpu::consts::GATHER_GUIDE_BINS),
        ("GATHER_GUIDE_PROBES", crate::gpu::consts::GATHER_GUIDE_PROBES),
        ("GATHER_GUIDE_DECAY", crate::gpu::consts::GATHER_GUIDE_DECAY),
        ("SKY_GUIDE_MIN_SAMPLES", crate::gpu::consts::SKY_GUIDE_MIN_SAMPLES),
        ("GATHER_GUIDE_MIN_SAMPLES", crate::gpu::consts::GATHER_GUIDE_MIN_SAMPLES),
        ("GUIDE_HEADER", crate::gpu::consts::GUIDE_HEADER),
        ("GUIDE_MARKS", crate::gpu::consts::GUIDE_MARKS),
        ("LIGHT_POINT", LIGHT_POINT),
        ("LIGHT_SPOT", LIGHT_SPOT),
        ("LIGHT_DISTANT", LIGHT_DISTANT),
        ("NO_CHILD", crate::gpu::consts::NO_CHILD),
        ("GGX_ALBEDO_N", crate::gpu::consts::GGX_ALBEDO_N as u32),
        ("GGX_ALBEDO_CELLS", (crate::gpu::consts::GGX_ALBEDO_N * crate::gpu::consts::GGX_ALBEDO_N) as u32),
        ("GLASS_ALBEDO_ETAS", crate::gpu::consts::GLASS_ETAS as u32),
        ("GLASS_ALBEDO_CELLS", crate::gpu::consts::GLASS_CELLS as u32),
    ];
    use crate::gpu::consts::GpuSceneOffsets as O;
    let word = |offset: usize| (offset / 4) as u32;
    let header = [
        ("DATA_UVS", word(std::mem::offset_of!(O, uvs))),
        ("DATA_UV_TRIANGLES", word(std::mem::offset_of!(O, uv_triangles))),
        ("DATA_NORMALS", word(std::mem::offset_of!(O, normals))),
        ("DATA_NORMAL_TRIANGLES", word(std::mem::offset_of!(O, normal_triangles))),
        ("DATA_TANGENTS", word(std::mem::offset_of!(O, tangents))),
        ("DATA_TANGENT_TRIANGLES", word(std::mem::offset_of!(O, tangent_triangles))),
        ("DATA_LIGHTS", word(std::mem::offset_of!(O, lights))),
        ("DATA_LIGHT_COUNT", word(std::mem::offset_of!(O, light_count))),
        ("DATA_PUNCTUAL", word(std::mem::offset_of!(O, punctual))),
        ("DATA_ENVIRONMENT", word(std::mem::offset_of!(O, environment))),
        ("DATA_TEXTURES", word(std::mem::offset_of!(O, textures))),
    ];
    let u32s: Vec<(&str, u32)> = u32s.into_iter().chain(header).collect();
    let f32s = [
        ("OFFSET_STEP", OFFSET_STEP),
        ("MIN_LOOKUP_AREA", MIN_LOOKUP_AREA),
        ("AIM_FRACTION", crate::gpu::consts::AIM_FRACTION),
        ("NEAR_FRACTION", crate::gpu::consts::NEAR_FRACTION),
        ("NEAR_SCALE", crate::gpu::consts::NEAR_SCALE),
        ("BOUNCE_AIM_FRACTION", crate::gpu::consts::BOUNCE_AIM_FRACTION),
        ("NEAR_FACE", crate::gpu::consts::NEAR_FACE),
        ("GUIDED_FRACTION", crate::gpu::consts::GUIDED_FRACTION),
        ("GATHER_GUIDE_FRACTION", crate::gpu::consts::GATHER_GUIDE_FRACTION),
        ("SKY_GUIDE_FRACTION", crate::gpu::consts::SKY_GUIDE_FRACTION),
        ("SKY_GUIDE_SCALE", crate::gpu::consts::SKY_GUIDE_SCALE),
        ("SKY_GUIDE_PRIOR", crate::gpu::consts::SKY_GUIDE_PRIOR),
        ("GATHER_GUIDE_PRIOR", crate::gpu::consts::GATHER_GUIDE_PRIOR),
        ("GLASS_ALBEDO_ETA_MAX", crate::gpu::consts::GLASS_ETA_MAX),
    ];
    let mut s = String::from("// Generated from the Rust constants (shader.rs).\n");
    for (name, value) in u32s {
        s += &format!("const {name}: u32 = {value}u;\n");
    }
    for (name, value) in f32s {
        s += &format!("const {name}: f32 = {value:?};\n");
    }
    s
}

/// `pieces` after the shared constants.
pub fn compose(pieces: &[&str]) -> String {
    let constants = constants();
    std::iter::once(constants.as_str()).chain(pieces.iter().copied()).collect::<Vec<_>>().join("\n")
}

/// `source` (a composed shader) for ray path `path`: unchanged for the compute path; for the
/// hardware path its compute `traverse` replaced by the ray query's and `enable wgpu_ray_query;`
/// put first. With `count`, its empty `count_ray` replaced by [`RAY_COUNT`]'s, which counts
/// every ray the shader traces in the count of that use (`--count-rays`). A shader without
/// [`BVH`] casts no rays and is returned as it is.
pub fn for_rays(
    source: &str,
    path: crate::gpu::accel::RayPath,
    count: Option<crate::gpu_scene::RayUse>,
) -> std::borrow::Cow<'_, str> {
    use std::borrow::Cow;
    if !source.contains(TRAVERSE_COMPUTE) {
        return Cow::Borrowed(source);
    }
    let mut s = Cow::Borrowed(source);
    if path == crate::gpu::accel::RayPath::Hardware {
        s = Cow::Owned(format!("enable wgpu_ray_query;\n{}", s.replacen(TRAVERSE_COMPUTE, TRAVERSE_HARDWARE, 1)));
    }
    if let Some(u) = count {
        let counting = format!("const RAY_COUNT_WORD: u32 = {}u;\n{RAY_COUNT}", 2 * u as u32);
        s = Cow::Owned(s.replacen(NO_RAY_COUNT, &counting, 1));
    }
    s
}

/// The shader module of `source`: the device's one of it ([`crate::gpu::compiled`]).
pub fn module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    crate::gpu::compiled::module(device, label, source)
}
