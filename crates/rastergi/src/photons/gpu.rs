//! The GPU photon tracer (`trace.wgsl`) and the photon map's GPU form.
//!
//! Accumulation: each deposit adds round(Φ_c · 2²⁴ / Φ_max) to a 64-bit fixed-point counter
//! per slot and channel, kept as two u32 words (low, high) with an explicit carry: the thread
//! whose `atomicAdd` wraps the low word adds 1 to the high word. Since a photon's flux never
//! exceeds Φ_max (see [`super`]), a deposit is at most 2²⁴ units; a counter holds 2⁶⁴ units,
//! i.e. 2⁴⁰ ≈ 10¹² full-flux deposits per slot, and each deposit is exact to 2⁻²⁵ Φ_max.
//! No float atomics, no lost flux, the same totals whatever the scheduling order.
//!
//! A resolve kernel turns the counters into the lookup texture: a 3D `rgba32float` texture
//! of size (nx, ny, 6·nz) whose texel at (x, y, z + bin·nz) holds (Φ_rgb/h², A/h²), h the cell
//! side; `map.wgsl` samples it.

use bytemuck::{Pod, Zeroable};
use glam::UVec3;

use super::{MAX_BOUNCES, PhotonSettings};
use crate::error::Result;
use crate::gpu::{Gpu, compute_pipeline, storage_entry, uniform_entry};
use crate::gpu_scene::{GpuScene, PreparedScene};
use crate::photons::map::{BINS, GridSpec, PhotonMap, surface_areas};
use crate::profile::compute_pass;
use crate::shader;

/// Fixed-point units per Φ_max.
const QUANTUM_BITS: u32 = 24;
/// Photons per dispatch: keeps each submission short (no GPU watchdog, steady progress).
const BATCH: u32 = 1 << 20;
const WORKGROUP: u32 = 64;

/// `PhotonParams` in `trace.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct PhotonParams {
    pub(crate) origin: [f32; 3],
    pub(crate) cell: f32,
    pub(crate) dims: [u32; 3],
    pub(crate) first_photon: u32,
    pub(crate) batch_size: u32,
    pub(crate) seed: u32,
    pub(crate) inv_photon_count: f32,
    /// Fixed-point units per watt: 2²⁴ / Φ_max.
    pub(crate) quantum: f32,
    pub(crate) ray_epsilon: f32,
    pub(crate) max_bounces: u32,
    pub(crate) groups_x: u32,
    pub(crate) _pad: u32,
}

/// `PhotonGrid` in `map.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PhotonGridUniforms {
    pub origin: [f32; 3],
    pub cell: f32,
    pub dims: [u32; 3],
    pub _pad: u32,
}

/// The photon tracer's composed shader (`trace.wgsl`: the trace and resolve kernels).
pub fn trace_source() -> String {
    shader::compose(&[shader::SAMPLING, shader::SCENE, shader::BVH, super::map::BIN_WGSL, include_str!("trace.wgsl")])
}

/// The photon map on the GPU, ready for lookups (bind group 3 of the passes that read it).
pub struct GpuPhotonMap {
    pub grid: GridSpec,
    pub settings: PhotonSettings,
    pub texture: wgpu::Texture,
    pub layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    /// The build's resources: the 64-bit counters and the bind group of the trace and resolve
    /// passes (which holds the cell areas); `None` once released.
    build: Option<Build>,
    quantum: f64,
    area: Vec<f64>,
    params: PhotonParams,
    params_buffer: wgpu::Buffer,
    trace_pipeline: wgpu::ComputePipeline,
    resolve_pipeline: wgpu::ComputePipeline,
    has_lights: bool,
}

struct Build {
    tally: wgpu::Buffer,
    trace_group: wgpu::BindGroup,
}

impl GpuPhotonMap {
    /// Traces `settings.count` photons on the GPU into a fresh map over the scene.
    pub fn build(
        gpu: &Gpu,
        scene: &GpuScene,
        prepared: &PreparedScene,
        settings: &PhotonSettings,
    ) -> Result<GpuPhotonMap> {
        let map = Self::new(gpu, scene, prepared, settings)?;
        map.trace(gpu, scene);
        Ok(map)
    }

    /// Allocates the map and its pipelines (the geometry's cell areas are computed here).
    pub fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        prepared: &PreparedScene,
        settings: &PhotonSettings,
    ) -> Result<GpuPhotonMap> {
        let grid = GridSpec::new(&prepared.bounds, settings.grid_resolution);
        crate::limits::check_photon_grid(&gpu.device.limits(), &grid)?;
        let slots = grid.slot_count() as u64;
        let area = surface_areas(&prepared.scene, &grid);
        let max_flux = settings.max_photon_flux(prepared);
        let quantum = if max_flux > 0.0 { (1u64 << QUANTUM_BITS) as f64 / max_flux } else { 1.0 };
        let device = &gpu.device;

        // Channel c's sums at c·region: one binding per channel.
        let channel_bytes = slots * 8;
        let region = channel_bytes.next_multiple_of(device.limits().min_storage_buffer_offset_alignment as u64);
        let tally = gpu.zeroed_buffer(
            "photon tally",
            3 * region,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        );
        let h2 = (grid.cell as f64).powi(2);
        let area_scaled: Vec<f32> = area.iter().map(|&a| (a / h2) as f32).collect();
        let area_buffer =
            gpu.storage_buffer("photon cell areas", bytemuck::cast_slice(&area_scaled), wgpu::BufferUsages::empty());
        let params_buffer = gpu.zeroed_buffer(
            "photon params",
            std::mem::size_of::<PhotonParams>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("photon map"),
            size: wgpu::Extent3d {
                width: grid.dims.x,
                height: grid.dims.y,
                depth_or_array_layers: BINS as u32 * grid.dims.z,
            },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D3,
            format: wgpu::TextureFormat::Rgba32Float,
            usage: wgpu::TextureUsages::STORAGE_BINDING
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());

        let c = wgpu::ShaderStages::COMPUTE;
        let trace_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("photon trace"),
            entries: &[
                uniform_entry::<PhotonParams>(0, c),
                storage_entry::<u32>(1, c, false),
                storage_entry::<u32>(2, c, false),
                storage_entry::<u32>(3, c, false),
                storage_entry::<f32>(4, c, true),
                wgpu::BindGroupLayoutEntry {
                    binding: 5,
                    visibility: c,
                    ty: wgpu::BindingType::StorageTexture {
                        access: wgpu::StorageTextureAccess::WriteOnly,
                        format: wgpu::TextureFormat::Rgba32Float,
                        view_dimension: wgpu::TextureViewDimension::D3,
                    },
                    count: None,
                },
            ],
        });
        let channel = |c: u64| {
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &tally,
                offset: c * region,
                size: std::num::NonZeroU64::new(channel_bytes),
            })
        };
        let trace_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("photon trace"),
            layout: &trace_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: params_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: channel(0) },
                wgpu::BindGroupEntry { binding: 2, resource: channel(1) },
                wgpu::BindGroupEntry { binding: 3, resource: channel(2) },
                wgpu::BindGroupEntry { binding: 4, resource: area_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&view) },
            ],
        });
        let module = shader::module(device, "photon trace", &trace_source());
        let layouts = [&scene.layout, &trace_layout];
        let trace_pipeline = compute_pipeline(device, "trace photons", &module, "trace_photons", &layouts);
        let resolve_pipeline = compute_pipeline(device, "resolve photon map", &module, "resolve_map", &layouts);
        let params = PhotonParams {
            origin: grid.origin.into(),
            cell: grid.cell,
            dims: grid.dims.into(),
            first_photon: 0,
            batch_size: 0,
            seed: settings.seed,
            inv_photon_count: 1.0 / settings.count.max(1) as f32,
            quantum: quantum as f32,
            ray_epsilon: prepared.ray_epsilon(),
            max_bounces: MAX_BOUNCES,
            groups_x: 0,
            _pad: 0,
        };
        let (layout, bind_group) = lookup_binding(gpu, &grid, &texture);
        Ok(GpuPhotonMap {
            grid,
            settings: *settings,
            texture,
            layout,
            bind_group,
            build: Some(Build { tally, trace_group }),
            quantum,
            area,
            params,
            params_buffer,
            trace_pipeline,
            resolve_pipeline,
            has_lights: scene.light_count > 0,
        })
    }

    /// Clears the counters, traces the photons in batches and resolves the lookup texture.
    /// Returns once the work is submitted; `Gpu::wait` waits for it.
    pub fn trace(&self, gpu: &Gpu, scene: &GpuScene) {
        let (device, grid) = (&gpu.device, &self.grid);
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("photon clear") });
        let build = self.build.as_ref().expect("trace() after release_build_buffers()");
        enc.clear_buffer(&build.tally, 0, None);
        gpu.queue.submit([enc.finish()]);
        let mut params = self.params;
        let count = self.settings.count;
        if self.has_lights {
            let mut first = 0u32;
            while first < count {
                let batch = BATCH.min(count - first);
                let groups = batch.div_ceil(WORKGROUP);
                let (gx, gy) = (groups.min(65535), groups.div_ceil(65535));
                params.first_photon = first;
                params.batch_size = batch;
                params.groups_x = gx;
                gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(&params));
                let mut enc =
                    device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("photon batch") });
                {
                    let mut pass = compute_pass(&mut enc, gpu.profiler.as_ref(), "photon trace");
                    pass.set_pipeline(&self.trace_pipeline);
                    pass.set_bind_group(0, &scene.bind_group, &[]);
                    pass.set_bind_group(1, &build.trace_group, &[]);
                    pass.dispatch_workgroups(gx, gy, 1);
                }
                gpu.queue.submit([enc.finish()]);
                first += batch;
            }
        }
        let mut enc =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("photon map resolve") });
        {
            let mut pass = compute_pass(&mut enc, gpu.profiler.as_ref(), "photon map resolve");
            pass.set_pipeline(&self.resolve_pipeline);
            pass.set_bind_group(0, &scene.bind_group, &[]);
            pass.set_bind_group(1, &build.trace_group, &[]);
            pass.dispatch_workgroups(
                grid.dims.x.div_ceil(4),
                grid.dims.y.div_ceil(4),
                (BINS as u32 * grid.dims.z).div_ceil(4),
            );
        }
        gpu.queue.submit([enc.finish()]);
    }

    /// Reads the map back from the counters (exact fixed-point sums) for tests and tools.
    pub fn read(&self, gpu: &Gpu) -> Result<PhotonMap> {
        let Some(build) = &self.build else {
            return self.read_texture(gpu);
        };
        let bytes = gpu.read_buffer(&build.tally, build.tally.size())?;
        let words: &[u32] = bytemuck::cast_slice(&bytes);
        let n = self.grid.slot_count();
        let region = words.len() / 3;
        let flux = (0..n)
            .map(|s| {
                [0, 1, 2].map(|c| {
                    let (lo, hi) = (words[c * region + 2 * s] as u64, words[c * region + 2 * s + 1] as u64);
                    ((hi << 32) | lo) as f64 / self.quantum
                })
            })
            .collect();
        Ok(PhotonMap { grid: self.grid, flux, area: self.area.clone(), flux_sq: vec![0.0; n], deposits: vec![0; n] })
    }

    /// Frees the counters and cell areas, which only [`trace`](Self::trace) needs (a third of
    /// the map's memory at 24 + 4 of its 44 bytes per slot); [`read`](Self::read) then reads
    /// the f32 lookup texture the passes use.
    pub fn release_build_buffers(&mut self) {
        self.build = None;
    }

    /// The map as the passes see it: the lookup texture's Φ/h² per slot, times h².
    fn read_texture(&self, gpu: &Gpu) -> Result<PhotonMap> {
        let texels: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&gpu.read_texture(&self.texture, 16)?);
        let h2 = (self.grid.cell as f64).powi(2);
        let n = self.grid.slot_count();
        let flux = texels.iter().map(|t| [0, 1, 2].map(|c| t[c] as f64 * h2)).collect();
        Ok(PhotonMap { grid: self.grid, flux, area: self.area.clone(), flux_sq: vec![0.0; n], deposits: vec![0; n] })
    }

    pub fn cells(&self) -> UVec3 {
        self.grid.dims
    }
}

/// The lookup bind group: the map texture and its grid placement.
fn lookup_binding(gpu: &Gpu, grid: &GridSpec, texture: &wgpu::Texture) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let u = PhotonGridUniforms { origin: grid.origin.into(), cell: grid.cell, dims: grid.dims.into(), _pad: 0 };
    let uniforms = gpu.zeroed_buffer(
        "photon grid",
        std::mem::size_of::<PhotonGridUniforms>() as u64,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    );
    gpu.queue.write_buffer(&uniforms, 0, bytemuck::bytes_of(&u));
    let vis = wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::FRAGMENT;
    let layout = gpu.device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("photon map lookup"),
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: vis,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: false },
                    view_dimension: wgpu::TextureViewDimension::D3,
                    multisampled: false,
                },
                count: None,
            },
            uniform_entry::<PhotonGridUniforms>(1, vis),
        ],
    });
    let view = texture.create_view(&Default::default());
    let bind_group = gpu.device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("photon map lookup"),
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) },
            wgpu::BindGroupEntry { binding: 1, resource: uniforms.as_entire_binding() },
        ],
    });
    (layout, bind_group)
}
