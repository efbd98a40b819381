//! The scene on the GPU: triangles in BVH order, materials, BVH nodes, the light table, the
//! environment map and the albedo textures with the triangles' texture coordinates, bound together as bind group 0 of
//! every pass that reads the scene (`gpu_scene.wgsl`).

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use crate::bvh::wide::WideNode;
use crate::error::Result;
use crate::gpu::accel::{RayPath, Rays, SceneAccel};
use wgpu::util::DeviceExt;

use crate::environment::{Environment, GpuEnvironment};
use crate::gpu::Gpu;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::limits::check_storage_buffer;
use crate::gpu::shader;
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::lights::{LightEntry, PunctualLight};
use crate::scene::{Aabb, AlphaMode, Material, TextureRef, UvTransform};
use crate::surface::PreparedScene;
use crate::textures::AtlasEntry;

gpu_struct! {
    /// `Triangle` in WGSL.
    pub struct GpuTriangle as "Triangle" {
        pub v0: [f32; 3],
        pub material: u32,
        pub v1: [f32; 3],
        /// [`TRIANGLE_HAS_HOLES`] where the material may let rays through.
        pub flags: u32,
        pub v2: [f32; 3],
        /// The triangle's entry in the light table where it emits, else [`NO_LIGHT`]: the density
        /// with which light samples find its points, for multiple importance sampling.
        pub light: u32,
    }
}

/// [`GpuTriangle::light`] of a triangle that is not in the light table.
pub const NO_LIGHT: u32 = u32::MAX;

gpu_struct! {
    /// `TextureSlot` in WGSL: a texture a material reads, its index in the texture
    /// atlas ([`NO_TEXTURE`] for none) and the rows (`u`, `v`) of its [`UvTransform`].
    pub struct GpuTextureSlot as "TextureSlot" {
        pub u: [f32; 3],
        pub texture: u32,
        pub v: [f32; 3],
        pub _pad: u32,
    }
}

impl GpuTextureSlot {
    pub fn new(slot: Option<TextureRef>) -> GpuTextureSlot {
        let (texture, t) = slot.map_or((NO_TEXTURE, UvTransform::IDENTITY), |t| (t.texture as u32, t.transform));
        GpuTextureSlot { u: t.0[0], texture, v: t.0[1], _pad: 0 }
    }
}

gpu_struct! {
    /// `Material` in WGSL: what every surface point reads of
    /// [`crate::scene::Material`], its flags ([`MATERIAL_TWO_SIDED`], [`MATERIAL_ALPHA_MASK`],
    /// [`MATERIAL_ALPHA_BLEND`], [`MATERIAL_TEXTURED`]) and its opacity factor. Its textures are
    /// in [`GpuMaterialMaps`], read only where the flags say: loading them with every material
    /// cost 30 % of the gather on lavapipe (it gathers every word of every lane).
    pub struct GpuMaterial as "Material" {
        pub albedo: [f32; 3],
        pub flags: u32,
        pub emission: [f32; 3],
        pub opacity: f32,
        /// The scattering model ([`crate::bsdf::Bsdf`]; `Material`'s fields of the same names):
        /// perceptual roughness, α = roughness².
        pub metallic: f32,
        pub roughness: f32,
        pub specular: f32,
        pub ior: f32,
        pub transmission: f32,
        /// [`Material::medium`]: σ inside solid glass, per channel (three floats, not a
        /// 16-byte-aligned vector).
        pub attenuation: [f32; 3] as "array<f32, 3>",
        /// [`Material::specular_color`].
        pub specular_color: [f32; 3],
        /// [`Material::clearcoat`], [`Material::clearcoat_roughness`].
        pub clearcoat: f32,
        pub clearcoat_roughness: f32,
        pub _pad: [u32; 3],
    }
}

gpu_struct! {
    /// `MaterialMaps` in WGSL: a material's textures and their parameters, at the
    /// material's index.
    pub struct GpuMaterialMaps as "MaterialMaps" {
        pub alpha_cutoff: f32,
        pub normal_scale: f32,
        pub _pad: [u32; 2],
        pub albedo_map: GpuTextureSlot,
        pub emission_map: GpuTextureSlot,
        pub opacity_map: GpuTextureSlot,
        pub normal_map: GpuTextureSlot,
        /// Linear: roughness × G, metallic × B.
        pub metal_rough_map: GpuTextureSlot,
        /// transmissionTexture (R), specularTexture (A), specularColorTexture (RGB).
        pub transmission_map: GpuTextureSlot,
        pub specular_map: GpuTextureSlot,
        pub specular_color_map: GpuTextureSlot,
        /// clearcoatTexture (R), clearcoatRoughnessTexture (G).
        pub clearcoat_map: GpuTextureSlot,
        pub clearcoat_roughness_map: GpuTextureSlot,
    }
}

/// The scene's WGSL, bind group 0 of every pass that reads it: the structs it shares with Rust
/// (generated, [`crate::gpu::structs`]), then [`shader::SCENE_FILES`]: its bindings and
/// accessors, the point on a surface, light sampling, the textures, the environment and the
/// BSDF.
pub fn wgsl() -> String {
    let structs = [
        GpuTriangle::wgsl(),
        GpuTextureSlot::wgsl(),
        GpuMaterial::wgsl(),
        GpuMaterialMaps::wgsl(),
        GpuMaterialRecord::wgsl(),
        WideNode::wgsl(),
        LightEntry::wgsl(),
        PunctualLight::wgsl(),
        GpuEnvironment::wgsl(),
        AtlasEntry::wgsl(),
    ];
    [structs.concat().as_str(), shader::SCENE_FILES].join("\n")
}

pub use crate::gpu::consts::GpuSceneOffsets;

/// The scene's bind group 0, read by every pass: triangles, materials, the texture atlas, the
/// scene data (coordinates, normals, tangents, lights, environment), the environment's
/// uniforms, the albedo tables; the BVH (or, with `tlas`, the hardware's acceleration
/// structure) for the compute passes. The BVH serves compute passes only: the raster stages
/// (which pull vertices and discard holes) see three storage buffers of the scene, well under
/// the count at which lavapipe (Mesa 22.3) silently loses fragment writes (11 storage buffers
/// in a fragment stage, though it reports 32: the fragment lists' gather lost 10 % of its
/// estimates, tests/gather.rs).
pub fn group(tlas: bool, count_rays: bool) -> Group {
    let compute = wgpu::ShaderStages::COMPUTE;
    let mut g = Group::new(
        "scene",
        wgpu::ShaderStages::VERTEX_FRAGMENT | compute,
        &[
            Slot::read::<GpuTriangle>(0, "triangles"),
            Slot::read::<GpuMaterialRecord>(1, "materials"),
            Slot::read::<WideNode>(2, "bvh_nodes").only(compute),
            Slot::float_texture(5, "textures"),
            Slot::read::<u32>(8, "scene_data"),
            Slot::uniform::<GpuEnvironment>(9, "environment").only(compute),
            Slot::float_texture(13, "ggx_cells_texture").only(compute),
            Slot::float_texture(14, "glass_albedo_texture").only(compute),
        ],
    );
    if tlas {
        g.slots.push(Slot::tlas(crate::gpu::accel::TLAS_BINDING, "scene_tlas").only(compute));
    }
    if count_rays {
        g.slots.push(Slot::write::<u32>(RAY_COUNT_BINDING, "ray_count").only(compute));
    }
    g
}

/// The ray counts' binding in the scene's group where rays are counted
/// ([`crate::gpu::GpuOptions::count_rays`]; `gpu/ray_count.wgsl`): for each [`RayUse`], two
/// words, the low and the high half of its rays traced.
pub const RAY_COUNT_BINDING: u32 = 16;

/// The ray counts' size: two words for each [`RayUse`].
const RAY_COUNT_BYTES: u64 = 3 * 8;

/// What a shader's rays are counted as (`--count-rays`): each pass says so where it composes
/// its shader ([`GpuScene::module`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RayUse {
    /// The eye's: camera rays past mirrors and glass, the direct light's shadow rays, the
    /// emitters' edges; the path tracer's every ray; the ray kernel's.
    Eye = 0,
    /// The final gather's rays and the shadow rays at their hits.
    Gather = 1,
    /// The photons' flights.
    Photons = 2,
}

/// The rays a scene's passes have traced, by use ([`GpuScene::rays_traced`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RaysTraced {
    pub eye: u64,
    pub gather: u64,
    pub photons: u64,
}

impl RaysTraced {
    pub fn total(&self) -> u64 {
        self.eye + self.gather + self.photons
    }

    /// The rays traced since `before`.
    pub fn since(&self, before: &RaysTraced) -> RaysTraced {
        RaysTraced {
            eye: self.eye - before.eye,
            gather: self.gather - before.gather,
            photons: self.photons - before.photons,
        }
    }
}

/// The GGX albedo tables as gpu_scene.wgsl reads them: the cells and means, N × (N + 1)
/// RGBA32F, and the rough glass's, N × (cells / N) R32F. Computed and filled only where some
/// material is not Lambertian (SCENE_BSDF), the glass's only where some material is rough
/// solid glass; 1 × 1 zeros otherwise.
fn albedo_textures(gpu: &Gpu, has_bsdfs: bool, glass: bool) -> (wgpu::TextureView, wgpu::TextureView) {
    use crate::bsdf::albedo::N;
    let texture = |label: &str, format: wgpu::TextureFormat, (w, h): (usize, usize), data: &[u8]| {
        let t = gpu.device.create_texture_with_data(
            &gpu.queue,
            &wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: w as u32, height: h as u32, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            },
            wgpu::util::TextureDataOrder::LayerMajor,
            data,
        );
        t.create_view(&Default::default())
    };
    let (rgba, r) = (wgpu::TextureFormat::Rgba32Float, wgpu::TextureFormat::R32Float);
    if !has_bsdfs {
        let zeros = [0u8; 16];
        return (texture("ggx albedo", rgba, (1, 1), &zeros), texture("glass albedo", r, (1, 1), &zeros[..4]));
    }
    let table = crate::bsdf::ggx_albedo().gpu(glass);
    let cells: Vec<[f32; 4]> = table.cells.iter().chain(&table.means).copied().collect();
    let ggx = texture("ggx albedo", rgba, (N, N + 1), bytemuck::cast_slice(&cells));
    let glass = if glass {
        texture("glass albedo", r, (N, table.glass.len() / N), bytemuck::cast_slice(&table.glass[..]))
    } else {
        texture("glass albedo", r, (1, 1), &[0u8; 4])
    };
    (ggx, glass)
}

/// The scene's data buffer as it is filled: each part appended as 32-bit words.
#[derive(Default)]
struct SceneData {
    words: Vec<u32>,
}

impl SceneData {
    /// Appends `items` and returns the word at which they start.
    fn push<T: Pod>(&mut self, items: &[T]) -> u32 {
        let at = self.words.len() as u32;
        self.words.extend_from_slice(bytemuck::cast_slice(items));
        at
    }
}

gpu_struct! {
    /// `MaterialRecord` in WGSL: a material and its textures, one binding for both.
    pub struct GpuMaterialRecord as "MaterialRecord" {
        pub material: GpuMaterial,
        pub maps: GpuMaterialMaps,
    }
}

impl GpuMaterial {
    pub fn new(m: &Material) -> (GpuMaterial, GpuMaterialMaps) {
        let (alpha, alpha_cutoff) = match m.alpha_mode {
            AlphaMode::Opaque => (0, 0.0),
            AlphaMode::Mask { cutoff } => (MATERIAL_ALPHA_MASK, cutoff),
            AlphaMode::Blend => (MATERIAL_ALPHA_BLEND, 0.0),
        };
        let material = GpuMaterial {
            albedo: m.albedo.into(),
            flags: if m.two_sided { MATERIAL_TWO_SIDED } else { 0 }
                | alpha
                | if m.texture_refs().next().is_some() { MATERIAL_TEXTURED } else { 0 }
                | if m.thin { MATERIAL_THIN } else { 0 }
                | if m.is_lambertian() { MATERIAL_LAMBERTIAN } else { 0 }
                | if m.multiple_scattering { 0 } else { MATERIAL_SINGLE_SCATTERING },
            emission: m.emission.into(),
            opacity: m.opacity,
            metallic: m.metallic,
            roughness: m.roughness,
            specular: m.specular,
            ior: m.ior,
            transmission: m.transmission,
            attenuation: m.medium().into(),
            specular_color: m.specular_color.into(),
            clearcoat: m.clearcoat,
            clearcoat_roughness: m.clearcoat_roughness,
            _pad: [0; 3],
        };
        let maps = GpuMaterialMaps {
            alpha_cutoff,
            normal_scale: m.normal_scale,
            _pad: [0; 2],
            albedo_map: GpuTextureSlot::new(
                m.albedo_texture.map(|texture| TextureRef { texture, transform: m.albedo_transform }),
            ),
            emission_map: GpuTextureSlot::new(m.emission_texture),
            opacity_map: GpuTextureSlot::new(m.opacity_texture),
            normal_map: GpuTextureSlot::new(m.normal_texture),
            metal_rough_map: GpuTextureSlot::new(m.metal_rough_texture),
            transmission_map: GpuTextureSlot::new(m.transmission_texture),
            specular_map: GpuTextureSlot::new(m.specular_texture),
            specular_color_map: GpuTextureSlot::new(m.specular_color_texture),
            clearcoat_map: GpuTextureSlot::new(m.clearcoat_texture),
            clearcoat_roughness_map: GpuTextureSlot::new(m.clearcoat_roughness_texture),
        };
        (material, maps)
    }
}

pub use crate::gpu::consts::{
    MATERIAL_ALPHA_BLEND, MATERIAL_ALPHA_MASK, MATERIAL_LAMBERTIAN, MATERIAL_SINGLE_SCATTERING, MATERIAL_TEXTURED,
    MATERIAL_THIN, MATERIAL_TWO_SIDED, NO_TEXTURE, TRIANGLE_HAS_HOLES,
};

pub struct GpuScene {
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    pub triangle_count: u32,
    pub light_count: u32,
    pub bounds: Aabb,
    pub ray_epsilon: f32,
    pub emitted_power: Vec3,
    /// Σ area and Σ perimeter of the triangles (bounds on what a projection of them covers).
    pub total_area: f64,
    pub total_perimeter: f64,
    /// Whether the eye's rays continue through specular surfaces here
    /// ([`Material::passes_rays`], [`Material::has_delta_lobe`]).
    pub eye_chains: bool,
    /// Whether light reaches surfaces through mirrors and glass here ([`Material::passes_rays`]):
    /// the photon map's caustic twins and the caustics pass.
    pub caustics: bool,
    /// Whether some material is not Lambertian ([`Material::is_lambertian`]).
    pub has_bsdfs: bool,
    /// Some material reads a texture (`SCENE_TEXTURES`).
    pub has_textures: bool,
    /// Some triangle has shading normals at its corners (`SCENE_NORMALS`).
    pub has_normals: bool,
    /// Some material may let rays through: a cut-out or a stochastic surface (`SCENE_HOLES`).
    pub has_holes: bool,
    /// Some solid glass attenuates the light inside it (`SCENE_MEDIA`, [`Material::medium`]).
    pub has_media: bool,
    /// The traversal this scene's passes are built with ([`GpuScene::module`], `accel.rs`).
    pub rays: RayPath,
    /// Why [`Self::rays`] was chosen, in words (`rastergi info`, the render's log).
    pub rays_why: String,
    /// The acceleration structures, bound at `accel::TLAS_BINDING`, where the device has ray
    /// queries and the compute path was not asked for.
    pub accel: Option<SceneAccel>,
    /// The rays traced so far by use, where they are counted ([`RAY_COUNT_BINDING`]).
    pub ray_count: Option<wgpu::Buffer>,
}

impl GpuScene {
    /// The rays this scene's passes have traced since it was uploaded, where the device counts
    /// them ([`crate::gpu::GpuOptions::count_rays`]): every query of `trace` (a shadow ray, a
    /// gather ray, a photon's flight, an eye ray past a mirror …, whichever traversal answers
    /// it), by use. Waits for the GPU.
    pub fn rays_traced(&self, gpu: &Gpu) -> Result<Option<RaysTraced>> {
        let Some(buffer) = &self.ray_count else { return Ok(None) };
        let words = gpu.read_buffer(buffer, RAY_COUNT_BYTES)?;
        let w: &[u32] = bytemuck::cast_slice(&words);
        let count = |u: RayUse| u64::from(w[2 * u as usize]) | u64::from(w[2 * u as usize + 1]) << 32;
        Ok(Some(RaysTraced { eye: count(RayUse::Eye), gather: count(RayUse::Gather), photons: count(RayUse::Photons) }))
    }

    /// The values of the scene's pipeline-overridable constants (`gpu_scene.wgsl`), for every
    /// pipeline whose shader reads the scene: a scene without glossy or specular materials,
    /// or without surfaces that pass rays, gets kernels without the branches that serve them
    /// (the same results: those branches are never taken there; smaller kernels run faster).
    pub fn pipeline_constants(&self) -> [(&'static str, f64); 6] {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        [
            ("SCENE_BSDF", flag(self.has_bsdfs)),
            ("SCENE_PASSES_RAYS", flag(self.eye_chains)),
            ("SCENE_TEXTURES", flag(self.has_textures)),
            ("SCENE_NORMALS", flag(self.has_normals)),
            ("SCENE_HOLES", flag(self.has_holes)),
            ("SCENE_MEDIA", flag(self.has_media)),
        ]
    }

    /// A compute pipeline for `module`'s entry point `entry` (a shader that reads this scene),
    /// with bind groups `layouts`, specialized to this scene ([`Self::pipeline_constants`]).
    pub fn compute_pipeline(
        &self,
        device: &wgpu::Device,
        label: &str,
        module: &wgpu::ShaderModule,
        entry: &str,
        layouts: &[&wgpu::BindGroupLayout],
    ) -> wgpu::ComputePipeline {
        crate::gpu::compute_pipeline(device, label, module, entry, layouts, &self.pipeline_constants())
    }

    /// A shader module of `source` (a composed shader that reads this scene) on this scene's
    /// ray path ([`crate::gpu::shader::for_rays`]), its rays counted as `used` where they are
    /// counted.
    pub fn module(&self, device: &wgpu::Device, label: &str, source: &str, used: RayUse) -> wgpu::ShaderModule {
        self.module_for(device, label, source, self.rays, used)
    }

    /// [`Self::module`] on ray path `path` (the hardware one needs [`Self::accel`]).
    pub fn module_for(
        &self,
        device: &wgpu::Device,
        label: &str,
        source: &str,
        path: RayPath,
        used: RayUse,
    ) -> wgpu::ShaderModule {
        let count = self.ray_count.as_ref().map(|_| used);
        crate::gpu::shader::module(device, label, &crate::gpu::shader::for_rays(source, path, count))
    }

    /// Uploads `prepared`, after checking that its buffers fit the device (see [`crate::gpu::limits`]),
    /// on the ray path that `--rays` asked for (auto: hardware where offered): the first half of
    /// [`GpuScene::new`], whose start-up probe then chooses under auto (`rays/probe.rs`).
    pub(crate) fn upload(gpu: &Gpu, prepared: &PreparedScene) -> Result<GpuScene> {
        let limits = gpu.device.limits();
        check_scene(&limits, &prepared.scene)?;
        let nodes = prepared.bvh.wide();
        check_bvh_nodes(&limits, nodes.len())?;
        let s = &prepared.scene;
        let has_bsdfs = !s.materials.iter().all(Material::is_lambertian);
        let mut light_of = vec![NO_LIGHT; s.triangles.len()];
        for (k, e) in prepared.lights.entries.iter().enumerate() {
            if let Some(l) = light_of.get_mut(e.triangle as usize) {
                *l = k as u32;
            }
        }
        let triangles: Vec<GpuTriangle> = s
            .triangles
            .iter()
            .zip(&s.material_ids)
            .zip(&light_of)
            .map(|((t, &m), &light)| GpuTriangle {
                v0: t[0].into(),
                material: m,
                v1: t[1].into(),
                flags: if s.materials[m as usize].has_holes() { TRIANGLE_HAS_HOLES } else { 0 }
                    | if (t[1] - t[0]).cross(t[2] - t[0]) == glam::Vec3::ZERO {
                        crate::gpu::consts::TRIANGLE_ZERO_AREA
                    } else {
                        0
                    },
                v2: t[2].into(),
                light,
            })
            .collect();
        let materials: Vec<GpuMaterialRecord> = s
            .materials
            .iter()
            .map(|m| {
                let (material, maps) = GpuMaterial::new(m);
                GpuMaterialRecord { material, maps }
            })
            .collect();
        // One triangle's worth of zeros when the scene has no texture coordinates: a binding
        // cannot be empty, and `surface_uv` clamps its index into the buffer.
        let uvs: Vec<[f32; 2]> = if s.uvs.is_empty() {
            vec![[0.0; 2]; 3]
        } else {
            s.uvs.iter().flat_map(|t| t.map(|uv| uv.to_array())).collect()
        };
        // Nine zeros (one flat triangle) when the scene has no shading normals.
        let normals: Vec<f32> = if s.normals.is_empty() {
            vec![0.0; 9]
        } else {
            s.normals.iter().flat_map(|t| t.iter().flat_map(|n| n.to_array())).collect()
        };
        // Twelve zeros (one triangle without tangents) when the scene has none.
        let tangents: Vec<f32> = if s.tangents.is_empty() {
            vec![0.0; 12]
        } else {
            s.tangents.iter().flat_map(|t| t.iter().flat_map(|v| v.to_array())).collect()
        };
        let texture_view = prepared.textures.upload(gpu);
        let atlas_entries = prepared.textures.gpu_entries();
        let lights: Vec<LightEntry> = prepared.lights.entries.clone();
        // A binding cannot be empty: one zero light where the scene has none.
        let mut punctual = prepared.lights.punctual.clone();
        if punctual.is_empty() {
            punctual.push(bytemuck::Zeroable::zeroed());
        }
        let env = s.environment.as_deref();
        let env_data = env.map_or(vec![0.0f32; 4], Environment::gpu_data);
        crate::gpu::limits::check_storage_buffer(
            &limits,
            "the environment map",
            env_data.len() as u64,
            4,
            "use a smaller --env image",
        )?;
        let (disc_centre, disc_radius) = prepared.lights.disc;
        let env_uniform = GpuEnvironment::new(env, disc_centre, disc_radius, prepared.lights.environment_pmf);
        // Everything but the triangles, materials and BVH in one buffer of words (SceneData):
        // WebGPU allows 10 storage buffers per shader stage, and a gather pass binds the
        // scene, the visible points, the film and the photon map.
        // The header (GpuSceneOffsets) comes first; it is written once the offsets are known.
        let mut data = SceneData { words: vec![0; std::mem::size_of::<GpuSceneOffsets>() / 4] };
        let no_light = [LightEntry::zeroed()];
        let offsets = GpuSceneOffsets {
            uvs: data.push(&uvs),
            uv_triangles: (uvs.len() / 3) as u32,
            normals: data.push(&normals),
            normal_triangles: (normals.len() / 9) as u32,
            tangents: data.push(&tangents),
            tangent_triangles: (tangents.len() / 12) as u32,
            // One zero entry where the scene has no lights: light_count ≥ 1, pmf 0.
            lights: data.push(if lights.is_empty() { &no_light[..] } else { &lights[..] }),
            light_count: lights.len().max(1) as u32,
            punctual: data.push(&punctual),
            environment: data.push(&env_data),
            textures: data.push(&atlas_entries),
            ..GpuSceneOffsets::default()
        };
        data.words[..size_of::<GpuSceneOffsets>() / 4].copy_from_slice(bytemuck::cast_slice(&[offsets]));
        crate::gpu::limits::check_storage_buffer(
            &limits,
            "the scene's texture coordinates, normals, tangents, lights and environment map",
            data.words.len() as u64,
            4,
            "use a smaller --env image or a scene with fewer triangles",
        )?;
        let none = wgpu::BufferUsages::empty();
        // Ray queries where the device has them and the compute path was not asked for: the
        // triangles are then also the BLAS's vertices (accel::build).
        let ray_queries = gpu.rays != Rays::Compute && crate::gpu::accel::device_has_ray_queries(&gpu.device);
        if gpu.rays == Rays::Hardware && !ray_queries {
            return Err(crate::gpu::accel::not_offered(&gpu.info.name));
        }
        let blas_input = if ray_queries { wgpu::BufferUsages::BLAS_INPUT } else { none };
        let buffers = [
            gpu.storage_buffer("scene triangles", bytemuck::cast_slice(&triangles), blas_input),
            gpu.storage_buffer("scene materials", bytemuck::cast_slice(&materials), none),
            gpu.storage_buffer("scene bvh nodes", bytemuck::cast_slice(&nodes), none),
            gpu.storage_buffer("scene data", bytemuck::cast_slice(&data.words), none),
        ];
        let env_uniform_buffer = gpu.device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("scene environment"),
            contents: bytemuck::bytes_of(&env_uniform),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let accel = if ray_queries && !triangles.is_empty() {
            Some(crate::gpu::accel::build(gpu, &buffers[0], triangles.len() as u32)?)
        } else {
            None
        };
        let ray_count = gpu.count_rays.then(|| {
            let usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
            gpu.zeroed_buffer("scene ray count", RAY_COUNT_BYTES, usage)
        });
        let group = group(accel.is_some(), ray_count.is_some());
        let layout = group.layout(&gpu.device);
        let (ggx_cells, glass) = albedo_textures(gpu, has_bsdfs, s.materials.iter().any(Material::needs_glass_table));
        let mut resources = vec![
            ("triangles", buffers[0].as_entire_binding()),
            ("materials", buffers[1].as_entire_binding()),
            ("bvh_nodes", buffers[2].as_entire_binding()),
            ("textures", wgpu::BindingResource::TextureView(&texture_view)),
            ("scene_data", buffers[3].as_entire_binding()),
            ("environment", env_uniform_buffer.as_entire_binding()),
            ("ggx_cells_texture", wgpu::BindingResource::TextureView(&ggx_cells)),
            ("glass_albedo_texture", wgpu::BindingResource::TextureView(&glass)),
        ];
        if let Some(a) = &accel {
            resources.push(("scene_tlas", wgpu::BindingResource::AccelerationStructure(&a.tlas)));
        }
        if let Some(b) = &ray_count {
            resources.push(("ray_count", b.as_entire_binding()));
        }
        let bind_group = group.bind(&gpu.device, &layout, &resources);
        let (rays, rays_why) = match (gpu.rays, &accel) {
            (Rays::Compute, _) => (RayPath::Compute, "asked for (--rays compute)".to_owned()),
            (_, Some(_)) if gpu.rays == Rays::Hardware => (RayPath::Hardware, "asked for (--rays hardware)".to_owned()),
            // Auto: hardware until the probe below says otherwise.
            (_, Some(_)) => (RayPath::Hardware, String::new()),
            (_, None) if ray_queries => (RayPath::Compute, "the scene has no triangles".to_owned()),
            (_, None) => (RayPath::Compute, format!("{} offers no hardware ray queries", gpu.info.name)),
        };
        let scene = GpuScene {
            layout,
            bind_group,
            triangle_count: triangles.len() as u32,
            light_count: lights.len() as u32,
            bounds: prepared.bounds,
            ray_epsilon: prepared.ray_epsilon(),
            emitted_power: prepared.lights.power,
            total_area: s.triangles.iter().map(|t| crate::scene::triangle_area(t) as f64).sum(),
            total_perimeter: s
                .triangles
                .iter()
                .map(|t| (t[0].distance(t[1]) + t[1].distance(t[2]) + t[2].distance(t[0])) as f64)
                .sum(),
            eye_chains: s.materials.iter().any(|m| m.passes_rays() || m.has_delta_lobe()),
            caustics: s.materials.iter().any(Material::passes_rays),
            has_bsdfs,
            has_textures: s.materials.iter().any(|m| m.texture_refs().next().is_some()),
            has_normals: !s.normals.is_empty(),
            has_holes: s.materials.iter().any(Material::has_holes),
            has_media: s.materials.iter().any(|m| m.medium() != Vec3::ZERO),
            rays,
            rays_why,
            accel,
            ray_count,
        };
        Ok(scene)
    }
}

const FEWER_TRIANGLES: &str =
    "use a scene with fewer triangles (or a GPU with larger storage buffers: `rastergi info` shows the limit)";

/// The scene's buffers (`gpu_scene.rs`) that the triangle, material and emitter counts fix:
/// checked before the BVH is built, so an impossible scene fails at once.
pub fn check_scene_buffers(limits: &wgpu::Limits, triangles: usize, materials: usize, lights: usize) -> Result<()> {
    let fewer = FEWER_TRIANGLES;
    let triangle_stride = std::mem::size_of::<GpuTriangle>() as u64;
    let material_stride = std::mem::size_of::<GpuMaterialRecord>() as u64;
    let light_stride = std::mem::size_of::<crate::lights::LightEntry>() as u64;
    let what = format!("the scene's {triangles} triangles");
    check_storage_buffer(limits, &what, triangles as u64, triangle_stride, fewer)?;
    // `3 · triangles` vertices are drawn by one non-indexed draw call.
    if triangles as u64 * 3 > u32::MAX as u64 {
        return Err(crate::error::Error::Limits(format!(
            "{what} are more than one draw call can hold (1 431 655 765); {fewer}"
        )));
    }
    check_storage_buffer(limits, "the scene's materials", materials as u64, material_stride, "use fewer materials")?;
    check_storage_buffer(limits, "the scene's emissive triangles", lights as u64, light_stride, "use fewer emitters")
}

/// [`check_scene_buffers`] for `scene`, with its triangle count bounding its emitters'.
pub fn check_scene(limits: &wgpu::Limits, scene: &crate::scene::Scene) -> Result<()> {
    check_scene_buffers(limits, scene.triangles.len(), scene.materials.len(), scene.triangles.len())
}

/// The wide BVH's node buffer, once the BVH is built (about one node per four leaves).
pub fn check_bvh_nodes(limits: &wgpu::Limits, nodes: usize) -> Result<()> {
    let stride = std::mem::size_of::<WideNode>() as u64;
    check_storage_buffer(limits, &format!("the scene's {nodes} BVH nodes"), nodes as u64, stride, FEWER_TRIANGLES)
}

#[cfg(test)]
mod limit_tests {
    use super::*;

    use crate::gpu::limits::test_limits as limits;

    #[test]
    fn a_scene_whose_triangles_exceed_the_binding_limit_is_refused_with_the_sizes() {
        // 48 bytes per triangle: 128 MiB hold 2 796 202 triangles.
        let l = limits(128);
        assert!(check_scene_buffers(&l, 2_796_202, 10, 2).is_ok());
        let e = check_scene_buffers(&l, 2_796_203, 10, 2).unwrap_err().to_string();
        println!("{e}");
        assert!(e.contains("2796203 triangles") && e.contains("fewer triangles"), "{e}");
        // One triangle over: the sizes in bytes, since both round to 128 MiB.
        assert!(e.contains("134217744 bytes") && e.contains("134217728 bytes"), "{e}");
        // 64 bytes per compressed node: 128 MiB hold 2 097 152 nodes.
        assert!(check_bvh_nodes(&l, 2_097_152).is_ok());
        let e = check_bvh_nodes(&l, 2_097_153).unwrap_err().to_string();
        assert!(e.contains("2097153 BVH nodes") && e.contains("134217728 bytes"), "{e}");
    }
}
