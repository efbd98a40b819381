//! The constants that Rust and WGSL share, declared once here (a leaf module: it imports
//! nothing) and re-exported by the modules they belong to; [`crate::gpu::shader::constants`]
//! generates their WGSL declarations, so no shader restates a value.

/// Most gather directions per iteration ([`crate::gather`]).
pub const MAX_DIRECTIONS: u32 = 16;

/// Material flag: the back face reflects too ([`crate::gpu_scene`]).
pub const MATERIAL_TWO_SIDED: u32 = 1;
/// Material flag: a cut-out, holes where α < the cutoff ([`crate::scene::AlphaMode::Mask`]).
pub const MATERIAL_ALPHA_MASK: u32 = 2;
/// Material flag: stochastic opacity α ([`crate::scene::AlphaMode::Blend`]).
pub const MATERIAL_ALPHA_BLEND: u32 = 4;
/// Material flag: it reads some texture (so its points need texture coordinates).
pub const MATERIAL_TEXTURED: u32 = 8;
/// Material flag: thin-walled glass ([`crate::bsdf::Bsdf::thin`]).
pub const MATERIAL_THIN: u32 = 16;
/// Material flag: it scatters as a plain Lambertian surface (f = ρ/π), the fast path.
pub const MATERIAL_LAMBERTIAN: u32 = 32;
/// Material flag: rough metal without its multiple-scattering compensation
/// ([`crate::bsdf::Bsdf::multiple_scattering`] off).
pub const MATERIAL_SINGLE_SCATTERING: u32 = 64;
/// Most holes a ray passes through before it counts as stopped (`trace` in `bvh.wgsl`).
pub const MAX_HOLE_CROSSINGS: u32 = 256;
/// A texture slot without a texture.
pub const NO_TEXTURE: u32 = u32::MAX;
/// Triangle flag ([`crate::gpu_scene::GpuTriangle::flags`]): its material may have holes, so
/// a ray that meets it asks the material whether it passes.
pub const TRIANGLE_HAS_HOLES: u32 = 1;
/// Triangle flag: its corners are collinear (zero area, exactly: the cross product of its
/// edges is zero in f32), so no raster pass draws it (`raster_vertex`).
pub const TRIANGLE_ZERO_AREA: u32 = 2;

/// Light-table entry bit of a point, spot or distant light ([`crate::lights`]); the other
/// bits index the punctual lights.
pub const PUNCTUAL_LIGHT: u32 = 1 << 31;
/// Light-table entry of the environment ([`crate::environment`]): the punctual bit with
/// every other bit set, which no punctual index reaches.
pub const ENVIRONMENT_LIGHT: u32 = u32::MAX - 1;
/// Punctual light kinds ([`crate::lights::PunctualLight::kind`]).
pub const LIGHT_POINT: u32 = 0;
pub const LIGHT_SPOT: u32 = 1;
pub const LIGHT_DISTANT: u32 = 2;

/// Film component: emission + direct light (the path tracer's full image) ([`crate::passes::film`]).
pub const FILM_DIRECT: u32 = 0;
/// Film component: indirect light from the final gather.
pub const FILM_INDIRECT: u32 = 1;
/// Film component: the photon-map view.
pub const FILM_PHOTON_VIEW: u32 = 2;

/// Plane offsets of the photon map's slots are rounded to this many cell sides
/// ([`crate::photons::map`]).
pub const OFFSET_STEP: f32 = 0.125;
/// Photon-map lookups leave out slots of less than this many cell faces h² of area
/// ([`crate::photons::map::PhotonMap::irradiance_on_plane`]).
pub const MIN_LOOKUP_AREA: f32 = 1e-4;
/// How near a face of its cell (in cells) a photon's hit point is taken to lie on it: there
/// its deposit may go to the neighbour across the face
/// ([`crate::photons::map::MapLayout::deposit_slot`]); f32 rounding errs by about 10⁻⁷.
pub const NEAR_FACE: f32 = 1e-4;
/// The fraction of sun and sky photons aimed at the photon region ([`crate::lights::disc_start`]):
/// half.
pub const AIM_FRACTION: f32 = 0.5;
/// The fraction aimed at the region's surroundings, a disc [`NEAR_SCALE`] times as wide
/// (the sunlit ground outside a window, whose light the room reflects): a quarter. The last
/// quarter covers the whole scene.
pub const NEAR_FRACTION: f32 = 0.25;
/// The surroundings' disc radius over the aim's.
pub const NEAR_SCALE: f32 = 4.0;
/// The fraction of Lambertian bounces outside the aim's sphere drawn towards it
/// ([`crate::photons::lambertian_bounce`]): half.
pub const BOUNCE_AIM_FRACTION: f32 = 0.5;
/// Position bins per side of a guided light's disc ([`crate::photons::guide`]).
pub const GUIDE_POSITIONS: u32 = 64;
/// Bands (of equal solid angle, in cos θ about +Y) and sectors of φ of the sky's direction bins
/// for guided photons ([`crate::photons::guide`]).
pub const GUIDE_ENV_BANDS: u32 = 8;
/// The share of a learned direction's photons drawn from the guide's table.
pub const GUIDED_FRACTION: f32 = 0.75;
/// The most lights whose photons are guided (the sky and up to three distant lights).
pub const MAX_GUIDED_LIGHTS: u32 = 4;
/// Words of a guided light's header in the guide's table.
pub const GUIDE_HEADER_WORDS: u32 = 4;
/// Direction bins of the gather's guide ([`crate::gather::guide`]): rows of the cosine warp's
/// square (sin²θ), and as many columns (φ); their product (also the guided sky's most blocks).
pub const GATHER_GUIDE_BANDS: u32 = 16;
pub const GATHER_GUIDE_BINS: u32 = GATHER_GUIDE_BANDS * GATHER_GUIDE_BANDS;
/// The guide table's share g of the guided gather's mixture density.
pub const GATHER_GUIDE_FRACTION: f32 = 0.5;
/// Samples a cell's gather table counts before it guides.
pub const GATHER_GUIDE_MIN_SAMPLES: u32 = 2 * GATHER_GUIDE_BINS;
/// Pseudo-samples of the cell's mean radiance in each bin of its gather table.
pub const GATHER_GUIDE_PRIOR: f32 = 4.0;
/// Entries a search of the gather guide's cells probes at most.
pub const GATHER_GUIDE_PROBES: u32 = 32;
/// A gather guide cell whose bins counted this many samples has its sums and counts halved.
pub const GATHER_GUIDE_DECAY: u32 = 1 << 15;
/// The share of the direct pass's environment samples drawn from the guided sky's table where
/// a visible point's cell has learned one ([`crate::passes::sky_guide`]).
pub const SKY_GUIDE_FRACTION: f32 = 0.5;
/// Fixed-point units of the guided sky's learned openness (visibility × cosine, in [0, 1]).
pub const SKY_GUIDE_SCALE: f32 = 1024.0;
/// The samples a cell's sky table must have learned before it guides (fewer give a table of
/// noise: the ground seen far through a window, a few samples a cell, measured 2–3× the
/// variance).
pub const SKY_GUIDE_MIN_SAMPLES: u32 = 256;
/// Pseudo-samples of the cell's mean openness added to each block's (a block seen by few
/// samples keeps near the cell's mean instead of 0 or 1).
pub const SKY_GUIDE_PRIOR: f32 = 4.0;
/// The first word of the guide buffer's header, and of its marks (after the header).
pub const GUIDE_HEADER: u32 = 0;
pub const GUIDE_MARKS: u32 = 16;
/// Bit of a slot's cell index that marks the caustic twin of the slot ([`crate::photons::map`]):
/// the flux of photons that reached it through specular surfaces alone.
pub const CAUSTIC_CELL: u32 = 1 << 31;
/// Most separators of one photon-map slot (each doubles its regions).
pub const MAX_SEPARATORS: usize = 4;
/// Bit offset of the region in a slot's plane key (the orientation bin below it, < 64).
pub const REGION_SHIFT: u32 = 6;
/// Bit offset of the plane offset in a plane key (the region's [`MAX_SEPARATORS`] bits below
/// it): 22 bits of signed steps, ±2²¹ eighths of a cell.
pub const OFFSET_SHIFT: u32 = REGION_SHIFT + MAX_SEPARATORS as u32;

/// The random streams: every stream key is `seed ^ id` with one of these ids, so no two
/// passes draw correlated numbers. WGSL gets the ids it uses from [`crate::gpu::shader::constants`].
pub mod stream {
    /// The key of the direct pass's per-pixel light-sample scramble seeds (not keyed by the
    /// restart: an Owen-scrambled Sobol' sequence per pixel, indexed by sample).
    pub const DIRECT: u32 = 0x0d1ec7;
    /// Paths of the reference path tracer, keyed (pixel, iteration).
    pub const PATH: u32 = 0x9a7b1d;
    /// Photons, keyed (photon index, pass): the GPU tracer and its CPU twin share it.
    pub const PHOTON: u32 = 0x9e3779b9;
    /// The scramble of the shared gather directions, keyed (restart).
    pub const GATHER_SHARED: u32 = 0x5bd1e995;
    /// The key of the per-pixel gather directions' scramble seeds, keyed (restart).
    pub const GATHER_PIXEL: u32 = 0x3c6ef372;
    /// The light samples at gather hits (`HitLight::Exact`): the key of the pixels' Sobol'
    /// scramble seeds (not the restart's).
    pub const HIT_LIGHT: u32 = 0xa54ff53a;
    /// The specular chains from the eye, keyed (pixel, iteration).
    pub const EYE_CHAIN: u32 = 0x1f83d9ab;
    /// The final gather's rays through specular surfaces, keyed (pixel, sample index).
    pub const GATHER_CHAIN: u32 = 0x5be0cd19;
    /// The lobe chosen by a per-pixel gather direction at a non-Lambertian visible point,
    /// keyed (pixel, sample index).
    pub const GATHER_LOBE: u32 = 0x510e527f;
    /// The ray view's sub-texel offset, keyed (direction index, restart).
    pub const TEXEL_JITTER: u32 = 0x7e1a5;
    /// The sub-pixel rays of the emission seen at an emitter's edge, keyed (pixel, iteration).
    pub const EMITTER_EDGE: u32 = 0x9b05688c;
    /// The scramble seed of the pixel jitter's Owen-scrambled Sobol' sequence (hashed, not a
    /// stream).
    pub const PIXEL_JITTER: u32 = 0x6a09e667;
}

/// Marks an unused child slot of a wide BVH node ([`crate::bvh::wide`]).
pub const NO_CHILD: u32 = u32::MAX;

/// Cells of the GGX albedo table along μ and along α ([`crate::bsdf::albedo`]).
pub const GGX_ALBEDO_N: usize = 32;
/// η values of the rough glass's albedo table ([`crate::bsdf::albedo`]).
pub const GLASS_ETAS: usize = 32;
/// The glass table's cells: two sides × [`GLASS_ETAS`] × N (√α) × N (μ).
pub const GLASS_CELLS: usize = 2 * GLASS_ETAS * GGX_ALBEDO_N * GGX_ALBEDO_N;

/// The largest η the glass table holds (η is clamped to [1, GLASS_ETA_MAX] there).
pub const GLASS_ETA_MAX: f32 = 3.0;

/// Texels per row of the texture atlas's texture ([`crate::textures`]).
pub const ATLAS_ROW: u32 = 4096;

/// `SceneOffsets` in `gpu_scene.wgsl`: where each part of the scene's data buffer
/// (`scene_data`, `gpu_scene::SceneData`) starts, in 32-bit words, and how many items some hold. It is
/// the buffer's header, its first 16 words (field i is word i).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub struct GpuSceneOffsets {
    /// Texture coordinates: two words per corner, three corners per triangle.
    pub uvs: u32,
    pub uv_triangles: u32,
    /// Shading normals: nine words per triangle.
    pub normals: u32,
    pub normal_triangles: u32,
    /// Tangents (xyz, handedness): twelve words per triangle.
    pub tangents: u32,
    pub tangent_triangles: u32,
    /// The light distribution's entries ([`crate::lights::LightEntry`], four words each).
    pub lights: u32,
    pub light_count: u32,
    /// The point, spot and distant lights ([`crate::lights::PunctualLight`], sixteen words each).
    pub punctual: u32,
    /// The environment map's data ([`crate::environment::Environment::gpu_data`]).
    pub environment: u32,
    /// The texture atlas's entries ([`crate::textures::AtlasEntry`], four words each).
    pub textures: u32,
    pub _pad: [u32; 5],
}
