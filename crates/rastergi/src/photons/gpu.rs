//! The GPU photon tracer (`trace.wgsl`) and the photon map's GPU form.
//!
//! Slots: the [`MapLayout`] (grid, every triangle's plane, the slot table and areas) is built
//! on the CPU from the geometry and uploaded; a deposit finds its slot by searching the table
//! (`table.wgsl`) for (cell of the hit, plane key of the side hit in that cell).
//!
//! Accumulation: each deposit adds round(Φ_c · 2²⁴ / Φ_max) to a 64-bit fixed-point counter
//! per slot and channel, kept as two u32 words (low, high) with an explicit carry: the thread
//! whose `atomicAdd` wraps the low word adds 1 to the high word. Since a photon's flux never
//! exceeds Φ_max (see [`super`]), a deposit is at most 2²⁴ units; a counter holds 2⁶⁴ units,
//! i.e. 2⁴⁰ ≈ 10¹² full-flux deposits per slot, and each deposit is exact to 2⁻²⁵ Φ_max.
//! No float atomics, no lost flux, the same totals whatever the scheduling order.
//!
//! A resolve kernel turns the counters into the lookup values: per table entry (Φ_rgb/h²,
//! A/h²), h the cell side; `map.wgsl` reads them with the table's keys and the plane keys.

use glam::UVec3;

use super::map::{GridSpec, MapLayout, PhotonMap, TrianglePlane};
use super::{MAX_BOUNCES, PhotonSettings};
use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::profile::compute_pass;
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu::{Gpu, shader};
use crate::gpu_scene::GpuScene;
use crate::surface::PreparedScene;

/// Fixed-point units per Φ_max.
const QUANTUM_BITS: u32 = 24;
/// Photons per dispatch: keeps each submission short (no GPU watchdog, steady progress).
const BATCH: u32 = 1 << 20;
const WORKGROUP: u32 = 64;

gpu_struct! {
    /// A [`GridSpec`]'s two levels (read by `table.wgsl`): coarse cells of side `cell` from
    /// `origin`, `dims` per axis; the coarse cells fine_lo ..< fine_hi split into factor³ cells
    /// of side fine_cell, indexed from fine_base (factor 1: none).
    pub struct GridLevels as "GridLevels" {
        pub origin: [f32; 3],
        pub cell: f32,
        pub dims: [u32; 3],
        /// Fine cells per coarse cell and axis; 1: no fine level.
        pub factor: u32,
        /// The refined coarse cells, fine_lo ..< fine_hi, and the fine cells' side.
        pub fine_lo: [u32; 3],
        pub fine_cell: f32,
        pub fine_hi: [u32; 3],
        /// The index of the first fine cell (after every coarse one).
        pub fine_base: u32,
    }
}

impl From<&GridSpec> for GridLevels {
    fn from(g: &GridSpec) -> GridLevels {
        let fine = g.fine();
        GridLevels {
            origin: g.origin.into(),
            cell: g.cell,
            dims: g.dims.into(),
            factor: g.refine.factor.max(1),
            fine_lo: g.refine.lo.into(),
            fine_cell: fine.map_or(g.cell, |f| f.cell),
            fine_hi: g.refine.hi.into(),
            fine_base: fine.map_or(0, |f| f.base),
        }
    }
}

gpu_struct! {
    /// The photon tracer's uniforms (`trace.wgsl`).
    pub(crate) struct PhotonParams as "PhotonParams" {
        pub(crate) grid: GridLevels,
        /// Where sun and sky photons are aimed: (centre, radius), radius 0 for nowhere.
        pub(crate) aim: [f32; 4],
        pub(crate) first_photon: u32,
        pub(crate) batch_size: u32,
        pub(crate) seed: u32,
        pub(crate) inv_photon_count: f32,
        /// Fixed-point units per watt: 2²⁴ / Φ_max.
        pub(crate) quantum: f32,
        pub(crate) ray_epsilon: f32,
        pub(crate) max_bounces: u32,
        pub(crate) groups_x: u32,
        /// Table capacity − 1 and the longest probe of any slot (`table.wgsl`).
        pub(crate) mask: u32,
        pub(crate) max_probe: u32,
        /// The photon pass: the second key of every photon's random stream.
        pub(crate) pass_index: u32,
        /// The separators' table: capacity − 1 and the longest probe.
        pub(crate) sep_mask: u32,
        pub(crate) sep_max_probe: u32,
        /// Whose photons deposit from their second surface on ([`super::SampledDirect`]'s code:
        /// 0 none, 1 all, 2 the punctual lights').
        pub(crate) first_deposit: u32,
        /// Where the separators' records and the cells' separator flags start in `slot_keys`
        /// ([`table_entries`]).
        pub(crate) records: u32,
        pub(crate) cell_flags: u32,
        /// The photon guide's grid (its cells' marks: where the map is read), where its
        /// counters and its table start, and its bins ([`super::guide`]).
        pub(crate) marks: GridLevels,
        pub(crate) guide_counters: u32,
        pub(crate) guide_bins: u32,
        pub(crate) guide_table: u32,
        pub(crate) _pad: u32,
    }
}

gpu_struct! {
    /// The photon map's lookup uniforms (`map.wgsl`, bind group 3 of the passes that read the
    /// map).
    pub struct PhotonGridUniforms as "PhotonGrid" {
        pub grid: GridLevels,
        /// Table capacity − 1, the longest probe, and the same for the separators' table.
        pub mask: u32,
        pub max_probe: u32,
        pub sep_mask: u32,
        pub sep_max_probe: u32,
        /// Whose direct light the readers take from a light sample, the map holding the rest
        /// ([`super::SampledDirect`]'s code: 0 none, 1 every light's, 2 the punctual lights').
        pub sampled_direct: u32,
        /// Where the separators' records and the cells' separator flags start in `slot_keys`
        /// ([`table_entries`]).
        pub records: u32,
        pub cell_flags: u32,
        /// The grid's cells (both levels): the flags' runs are this many bits long.
        pub cells: u32,
        /// The photon guide's grid, whose cells a lookup marks ([`super::guide`]).
        pub marks: GridLevels,
        /// The punctual lights' entries in the light table, `punctual_count` from
        /// `punctual_first` (the light samples of [`super::SampledDirect::Punctual`]).
        pub punctual_first: u32,
        pub punctual_count: u32,
        pub _pad0: u32,
        pub _pad1: u32,
    }
}

/// The slot table's search in WGSL (`table.wgsl`: `find_slot`, the twin of
/// [`super::map::SlotTable::find`]), after the structs it reads. The GPU needs no bins: it reads
/// every triangle's plane keys.
pub fn table_wgsl() -> String {
    [GridLevels::wgsl().as_str(), &TrianglePlane::wgsl(), include_str!("table.wgsl")].join("\n")
}

/// The map's lookup in WGSL (`photon_irradiance`, bind group 3, `map/map.wgsl`), after the
/// table's search and the lookup's uniforms.
pub fn lookup_wgsl() -> String {
    [table_wgsl().as_str(), &PhotonGridUniforms::wgsl(), include_str!("map/map.wgsl")].join("\n")
}

/// The photon tracer's composed shader (`trace.wgsl`: the trace and resolve kernels).
pub fn trace_source() -> String {
    let (scene, table, params) = (crate::gpu_scene::wgsl(), table_wgsl(), PhotonParams::wgsl());
    shader::compose(&[
        shader::SAMPLING,
        &scene,
        shader::BVH,
        &table,
        &params,
        include_str!("emit.wgsl"),
        include_str!("trace.wgsl"),
    ])
}

/// Bytes per table entry on the GPU while rendering (key 8, lookup value 16) and, while the
/// map is built, besides (counters 24, area 4).
pub const ENTRY_BYTES: u64 = 24;
pub const BUILD_ENTRY_BYTES: u64 = 28;

/// The photon map on the GPU, ready for lookups (bind group 3 of the passes that read it).
pub struct GpuPhotonMap {
    pub layout: MapLayout,
    pub settings: PhotonSettings,
    /// Per table entry: (Φ_rgb/h², A/h²).
    pub slots: wgpu::Buffer,
    pub bind_layout: wgpu::BindGroupLayout,
    pub bind_group: wgpu::BindGroup,
    /// The build's resources: the 64-bit counters and the bind group of the trace and resolve
    /// passes (which holds the slot areas); `None` once released.
    build: Option<Build>,
    quantum: f64,
    params: PhotonParams,
    params_buffer: wgpu::Buffer,
    trace_pipeline: wgpu::ComputePipeline,
    resolve_pipeline: wgpu::ComputePipeline,
    has_lights: bool,
    /// The guide buffer the map's passes mark and learn into, and the gather guide's cells
    /// there (0: none) ([`super::guide::PhotonGuide`]).
    pub guide: wgpu::Buffer,
    pub guide_cells: u32,
}

struct Build {
    tally: wgpu::Buffer,
    /// The trace's and the resolve's bindings (group 1).
    trace_group: wgpu::BindGroup,
    resolve_group: wgpu::BindGroup,
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

    /// [`build`](Self::build), tracing pass 0 with `count` photons (see
    /// [`trace_photons`](Self::trace_photons)).
    pub fn build_with(
        gpu: &Gpu,
        scene: &GpuScene,
        prepared: &PreparedScene,
        settings: &PhotonSettings,
        count: u32,
    ) -> Result<GpuPhotonMap> {
        let map = Self::new(gpu, scene, prepared, settings)?;
        map.trace_photons(gpu, scene, 0, count);
        Ok(map)
    }

    /// Lays the map out over the scene (the slots and their areas, on the CPU) and allocates
    /// it and its pipelines.
    pub fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        prepared: &PreparedScene,
        settings: &PhotonSettings,
    ) -> Result<GpuPhotonMap> {
        let layout = MapLayout::within(
            &prepared.scene,
            &prepared.bounds,
            settings.grid_resolution,
            settings.region.as_ref(),
            &gpu.device.limits(),
        )?;
        // A map of its own: no guided lights, no cells marked.
        let guide = super::guide::PhotonGuide::new(gpu, layout.grid, &[], false, None);
        Self::with_layout(gpu, scene, prepared, settings, layout, &guide)
    }

    /// Allocates the map for `layout` and its pipelines, its photons started and its lookups
    /// marked as `guide` says.
    pub fn with_layout(
        gpu: &Gpu,
        scene: &GpuScene,
        prepared: &PreparedScene,
        settings: &PhotonSettings,
        layout: MapLayout,
        guide: &super::guide::PhotonGuide,
    ) -> Result<GpuPhotonMap> {
        let grid = layout.grid;
        let capacity = layout.table.capacity() as u64;
        let max_flux = settings.max_photon_flux(prepared);
        let quantum = if max_flux > 0.0 { (1u64 << QUANTUM_BITS) as f64 / max_flux } else { 1.0 };
        let device = &gpu.device;

        // Channel c's sums at c·region: one binding per channel.
        let channel_bytes = capacity * 8;
        let region = channel_bytes.next_multiple_of(device.limits().min_storage_buffer_offset_alignment as u64);
        let tally = gpu.zeroed_buffer(
            "photon tally",
            3 * region,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        );
        let h2 = (grid.cell as f64).powi(2);
        let area_scaled: Vec<f32> = layout.area.iter().map(|&a| (a / h2) as f32).collect();
        let area_buffer =
            gpu.storage_buffer("photon slot areas", bytemuck::cast_slice(&area_scaled), wgpu::BufferUsages::empty());
        // The slots' keys, the separators' keys and records, the cells' flags (one binding:
        // table.wgsl).
        let sep = &layout.separators;
        let (all_keys, records, cell_flags) = table_entries(&layout);
        let keys =
            gpu.storage_buffer("photon table keys", bytemuck::cast_slice(&all_keys), wgpu::BufferUsages::empty());
        // Never empty: a scene without triangles still binds one entry.
        let planes = if layout.planes.is_empty() {
            vec![TrianglePlane::new(glam::Vec3::ZERO, glam::Vec3::ZERO)]
        } else {
            layout.planes.clone()
        };
        let planes = gpu.storage_buffer("photon planes", bytemuck::cast_slice(&planes), wgpu::BufferUsages::empty());
        let (sep_mask, sep_max_probe) = (sep.table.capacity() as u32 - 1, sep.table.max_probe);
        let slots = gpu.zeroed_buffer(
            "photon map slots",
            capacity * 16,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        );
        let params_buffer = gpu.zeroed_buffer(
            "photon params",
            std::mem::size_of::<PhotonParams>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );

        let channel = |c: u64| {
            wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                buffer: &tally,
                offset: c * region,
                size: std::num::NonZeroU64::new(channel_bytes),
            })
        };
        let counters = [
            ("params", params_buffer.as_entire_binding()),
            ("tally_r", channel(0)),
            ("tally_g", channel(1)),
            ("tally_b", channel(2)),
        ];
        let trace_only = [
            ("slot_keys", keys.as_entire_binding()),
            ("planes", planes.as_entire_binding()),
            ("photon_guide", guide.buffer.as_entire_binding()),
        ];
        let resolve_only = [("slot_area", area_buffer.as_entire_binding()), ("slots_out", slots.as_entire_binding())];
        let trace_resources: Vec<_> = counters.iter().cloned().chain(trace_only).collect();
        let (trace_layout, trace_group) = trace_group().layout_and_bind(device, &trace_resources);
        let resolve_resources: Vec<_> = counters.into_iter().chain(resolve_only).collect();
        let (resolve_layout, resolve_group) = resolve_group().layout_and_bind(device, &resolve_resources);
        let module = scene.module(device, "photon trace", &trace_source(), crate::gpu_scene::RayUse::Photons);
        let trace_pipeline =
            scene.compute_pipeline(device, "trace photons", &module, "trace_photons", &[&scene.layout, &trace_layout]);
        let resolve_pipeline = scene.compute_pipeline(
            device,
            "resolve photon map",
            &module,
            "resolve_map",
            &[&scene.layout, &resolve_layout],
        );
        let mask = capacity as u32 - 1;
        let max_probe = layout.table.max_probe;
        let (guide_counters, guide_table) = super::guide::guide_offsets(guide.mark_words, guide.bins());
        let params = PhotonParams {
            grid: GridLevels::from(&grid),
            aim: settings.aim().map_or([0.0; 4], |a| [a.centre.x, a.centre.y, a.centre.z, a.radius]),
            first_photon: 0,
            batch_size: 0,
            seed: settings.seed,
            inv_photon_count: 1.0 / settings.count.max(1) as f32,
            quantum: quantum as f32,
            ray_epsilon: prepared.ray_epsilon(),
            max_bounces: MAX_BOUNCES,
            groups_x: 0,
            mask,
            max_probe,
            pass_index: 0,
            sep_mask,
            sep_max_probe,
            first_deposit: settings.sampled_direct as u32,
            records,
            cell_flags,
            marks: guide.marked_grid(),
            guide_counters,
            guide_bins: guide.bins(),
            guide_table,
            _pad: 0,
        };
        let (punctual_first, punctual_count) = prepared.lights.punctual_run();
        let grid_uniforms = PhotonGridUniforms {
            grid: GridLevels::from(&grid),
            mask,
            max_probe,
            sep_mask,
            sep_max_probe,
            sampled_direct: settings.sampled_direct as u32,
            records,
            cell_flags,
            cells: grid.cell_count() as u32,
            marks: guide.marked_grid(),
            punctual_first,
            punctual_count,
            _pad0: 0,
            _pad1: 0,
        };
        let buffers = [&slots, &keys, &planes, &guide.buffer];
        let (bind_layout, bind_group) = lookup_binding(gpu, &grid_uniforms, buffers);
        Ok(GpuPhotonMap {
            layout,
            settings: *settings,
            slots,
            bind_layout,
            bind_group,
            build: Some(Build { tally, trace_group, resolve_group }),
            quantum,
            params,
            params_buffer,
            trace_pipeline,
            resolve_pipeline,
            has_lights: scene.light_count > 0,
            guide: guide.buffer.clone(),
            guide_cells: guide.field.as_ref().map_or(0, |f| f.capacity),
        })
    }

    pub fn grid(&self) -> &GridSpec {
        &self.layout.grid
    }

    /// Clears the counters, traces the photons of pass 0 in batches and resolves the lookup
    /// values. Returns once the work is submitted; `Gpu::wait` waits for it.
    pub fn trace(&self, gpu: &Gpu, scene: &GpuScene) {
        self.trace_pass(gpu, scene, 0);
    }

    /// [`trace`](Self::trace) with the photons of `pass`: fresh random numbers (the stream
    /// (seed ⊕ photon stream, photon index, pass)), the settings' count of them.
    pub fn trace_pass(&self, gpu: &Gpu, scene: &GpuScene, pass: u32) {
        self.trace_photons(gpu, scene, pass, self.settings.count);
    }

    /// Pass `pass` with `count` photons, each carrying 1/count of the emitted power. Fewer
    /// photons than the settings' carry more flux each than the fixed point's Φ_max: k times
    /// fewer make deposits of up to k·2²⁴ units, which the 64-bit counters hold as well.
    pub fn trace_photons(&self, gpu: &Gpu, scene: &GpuScene, pass: u32, count: u32) {
        self.begin_trace(gpu);
        self.trace_batch(gpu, scene, (pass, count), 0, count);
        self.resolve(gpu, scene, (pass, count));
    }

    /// The first step of a pass traced in steps ([`trace_photons`](Self::trace_photons) is
    /// the three at once): clears the counters. The lookup values stay those of the last
    /// resolve until the pass's [`resolve`](Self::resolve), so the map can be read meanwhile.
    pub fn begin_trace(&self, gpu: &Gpu) {
        let mut enc =
            gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("photon clear") });
        let build = self.build.as_ref().expect("trace() after release_build_buffers()");
        enc.clear_buffer(&build.tally, 0, None);
        gpu.queue.submit([enc.finish()]);
    }

    /// Traces photons `first .. first + n` of pass `pass` of `count` photons into the counters
    /// (in dispatches of at most `BATCH`). Photon i's random numbers depend on (seed, i, pass)
    /// only and the counters are integer sums, so a pass traced in any steps is bit for bit
    /// the pass traced at once.
    pub fn trace_batch(&self, gpu: &Gpu, scene: &GpuScene, (pass, count): (u32, u32), first: u32, n: u32) {
        if !self.has_lights {
            return;
        }
        let build = self.build.as_ref().expect("trace() after release_build_buffers()");
        let mut params = self.pass_params(pass, count);
        let end = first.saturating_add(n).min(count);
        let mut first = first;
        while first < end {
            let batch = BATCH.min(end - first);
            params.first_photon = first;
            params.batch_size = batch;
            self.dispatch(gpu, scene, &mut params, batch, (&self.trace_pipeline, &build.trace_group), "photon trace");
            first += batch;
        }
    }

    /// The last step: resolves the counters into the lookup values the passes read.
    pub fn resolve(&self, gpu: &Gpu, scene: &GpuScene, (pass, count): (u32, u32)) {
        let build = self.build.as_ref().expect("trace() after release_build_buffers()");
        let mut params = self.pass_params(pass, count);
        let items = self.layout.table.capacity() as u32;
        self.dispatch(
            gpu,
            scene,
            &mut params,
            items,
            (&self.resolve_pipeline, &build.resolve_group),
            "photon map resolve",
        );
    }

    /// The trace's and the resolve's parameters of pass `pass` with `count` photons, each
    /// carrying 1/count of the emitted power. Fewer photons than the settings' carry more flux
    /// each than the fixed point's Φ_max: k times fewer make deposits of up to k·2²⁴ units,
    /// which the 64-bit counters hold as well.
    fn pass_params(&self, pass: u32, count: u32) -> PhotonParams {
        PhotonParams { pass_index: pass, inv_photon_count: 1.0 / count.max(1) as f32, ..self.params }
    }

    /// One dispatch of `items` invocations of `pipeline` with `group`, submitted.
    fn dispatch(
        &self,
        gpu: &Gpu,
        scene: &GpuScene,
        params: &mut PhotonParams,
        items: u32,
        (pipeline, group): (&wgpu::ComputePipeline, &wgpu::BindGroup),
        label: &'static str,
    ) {
        let groups = items.div_ceil(WORKGROUP);
        let (gx, gy) = (groups.min(65535), groups.div_ceil(65535));
        params.groups_x = gx;
        gpu.queue.write_buffer(&self.params_buffer, 0, bytemuck::bytes_of(params));
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        {
            let mut pass = compute_pass(&mut enc, gpu.profiler.as_ref(), label);
            pass.set_pipeline(pipeline);
            pass.set_bind_group(0, &scene.bind_group, &[]);
            pass.set_bind_group(1, group, &[]);
            pass.dispatch_workgroups(gx, gy, 1);
        }
        gpu.queue.submit([enc.finish()]);
    }

    /// Reads the map back: from the counters (exact fixed-point sums) while they exist, else
    /// from the lookup values the passes read (f32), for tests and tools.
    pub fn read(&self, gpu: &Gpu) -> Result<PhotonMap> {
        let n = self.layout.table.capacity();
        let flux = match &self.build {
            Some(build) => {
                let bytes = gpu.read_buffer(&build.tally, build.tally.size())?;
                let words: &[u32] = bytemuck::cast_slice(&bytes);
                let region = words.len() / 3;
                (0..n)
                    .map(|s| {
                        [0, 1, 2].map(|c| {
                            let (lo, hi) = (words[c * region + 2 * s] as u64, words[c * region + 2 * s + 1] as u64);
                            ((hi << 32) | lo) as f64 / self.quantum
                        })
                    })
                    .collect()
            }
            None => {
                let bytes = gpu.read_buffer(&self.slots, self.slots.size())?;
                let values: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
                let h2 = (self.layout.grid.cell as f64).powi(2);
                values.iter().map(|v| [0, 1, 2].map(|c| v[c] as f64 * h2)).collect()
            }
        };
        Ok(PhotonMap { layout: self.layout.clone(), flux, flux_sq: vec![0.0; n], deposits: vec![0; n], dropped: 0 })
    }

    /// Frees the counters and slot areas, which only [`trace`](Self::trace) needs (28 of the
    /// 52 bytes per table entry); [`read`](Self::read) then reads the f32 lookup values the
    /// passes use.
    pub fn release_build_buffers(&mut self) {
        self.build = None;
    }

    pub fn cells(&self) -> UVec3 {
        self.layout.grid.dims
    }
}

/// The map's table as one buffer of `[u32; 2]` entries (`slot_keys` in WGSL, `table.wgsl`): the
/// slots' keys (the table's capacity), the separators' keys (theirs), each separator entry's
/// record (its [`super::map::MAX_SEPARATORS`] planes, 8 entries of f32 bits), and two bits per
/// cell of the grid (64 cells an entry, each kind in a run of its own): the cell holds
/// separators of some slot, and the cell holds some slot (a lookup searches neither the
/// separators nor the slots of a cell whose flag says it has none: the air above a floor).
/// With the records' and the flags' first entries. One binding for
/// all of them: a browser grants 10 storage buffers to a shader stage, and the traced gather
/// and the photon tracer had used them all.
pub fn table_entries(layout: &MapLayout) -> (Vec<[u32; 2]>, u32, u32) {
    let sep = &layout.separators;
    let mut entries: Vec<[u32; 2]> = layout.table.keys.iter().chain(&sep.table.keys).copied().collect();
    let records = entries.len() as u32;
    for record in &sep.planes {
        let words: &[u32] = bytemuck::cast_slice(record);
        entries.extend(words.chunks_exact(2).map(|w| [w[0], w[1]]));
    }
    let cell_flags = entries.len() as u32;
    let words = (layout.grid.cell_count() as usize).div_ceil(64).max(1);
    let flags = |keys: &[[u32; 2]]| {
        let mut flags = vec![[0u32; 2]; words];
        for k in keys.iter().filter(|k| k[0] != super::table::EMPTY) {
            let cell = (k[0] & !crate::gpu::consts::CAUSTIC_CELL) as usize;
            flags[cell / 64][(cell % 64) / 32] |= 1 << (cell % 32);
        }
        flags
    };
    entries.extend(flags(&sep.table.keys));
    entries.extend(flags(&layout.table.keys));
    (entries, records, cell_flags)
}

/// The lookup bind group: the slots' values, the table's keys, the plane keys and the grid.
fn lookup_binding(
    gpu: &Gpu,
    u: &PhotonGridUniforms,
    [slots, keys, planes, guide]: [&wgpu::Buffer; 4],
) -> (wgpu::BindGroupLayout, wgpu::BindGroup) {
    let uniforms = gpu.zeroed_buffer(
        "photon grid",
        std::mem::size_of::<PhotonGridUniforms>() as u64,
        wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
    );
    gpu.queue.write_buffer(&uniforms, 0, bytemuck::bytes_of(u));
    let resources = [
        ("photon_slots", slots.as_entire_binding()),
        ("photon_grid", uniforms.as_entire_binding()),
        ("slot_keys", keys.as_entire_binding()),
        ("planes", planes.as_entire_binding()),
        ("photon_guide", guide.as_entire_binding()),
    ];
    lookup_group().layout_and_bind(&gpu.device, &resources)
}

/// The photon map's counters (its tally, one channel a binding) and parameters, bound to both
/// entry points of the photon shader.
const COUNTERS: [Slot; 4] = [
    Slot::uniform::<PhotonParams>(0, "params"),
    Slot::write::<u32>(1, "tally_r"),
    Slot::write::<u32>(2, "tally_g"),
    Slot::write::<u32>(3, "tally_b"),
];

/// The tracing's bind group 1: the counters written, the table's keys and the planes read.
/// Two groups over the shader's bindings, each with what its entry point reads: with the
/// scene's, one group of all of them would bind 12 storage buffers, beyond a browser's 10 per
/// stage.
pub fn trace_group() -> Group {
    let mut g = Group::compute("photon trace", &COUNTERS);
    g.slots.extend([
        Slot::read::<[u32; 2]>(6, "slot_keys"),
        Slot::read::<TrianglePlane>(7, "planes"),
        Slot::write::<u32>(8, "photon_guide"),
    ]);
    g
}

/// The resolve's bind group 1: the counters and the slots' areas read, the slots written.
pub fn resolve_group() -> Group {
    let mut g = Group::compute("photon resolve", &COUNTERS);
    g.slots.extend([Slot::read::<f32>(4, "slot_area"), Slot::write::<[f32; 4]>(5, "slots_out")]);
    g
}

/// The lookup's bind group (3 in the per-pixel passes, where the gather binds it): the
/// slots' values, the grid, the table's keys and the planes, all read.
pub fn lookup_group() -> Group {
    Group::new(
        "photon map lookup",
        wgpu::ShaderStages::COMPUTE | wgpu::ShaderStages::FRAGMENT,
        &[
            Slot::read::<[f32; 4]>(0, "photon_slots"),
            Slot::uniform::<PhotonGridUniforms>(1, "photon_grid"),
            Slot::read::<[u32; 2]>(2, "slot_keys"),
            Slot::read::<TrianglePlane>(3, "planes"),
            Slot::write::<u32>(4, "photon_guide").only(wgpu::ShaderStages::COMPUTE),
        ],
    )
}
