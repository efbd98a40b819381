//! Progressive photon passes: the photon map is re-traced during rendering with fresh random
//! numbers, in cells that shrink with the pass count, so that the map's bias and its noise both
//! go to zero as the render goes on (a grid version of progressive photon mapping's radius
//! reduction, Hachisuka et al. 2008; Knaus and Zwicker 2011).
//!
//! * Pass k = 0, 1, 2, … traces N photons from the stream (seed, photon, k) — the first pass
//!   a quarter of them ([`first_pass_photons`]), so the first image is not kept waiting — and
//!   lasts `pass_iterations` iterations of the image; every iteration reads the map of its
//!   pass, and the image is the mean over all iterations.
//! * Schedule: pass k uses r_k = round(r₀ · (k + 1)^((1 − α)/2)) cells along the longest axis,
//!   cell area h_k² ∝ (k + 1)^−(1−α), with α = [`ALPHA`] = 2/3; the factor is rounded down to a
//!   power of 2^(1/8) ([`pass_resolution`]), so that the layout, made on the CPU, is made anew
//!   at a few passes only (logarithmically many).
//! * Iterations per pass: fitted ([`fitted_pass_iterations`]) or balanced by measurement
//!   ([`super::budget`]).
//! * Why it converges: the map's bias at a point is a blur over about a cell, O(h_k), → 0;
//!   its variance per slot is ∝ 1/(N·h_k²) ∝ (k + 1)^(1−α), and the mean over K passes of
//!   independent maps has variance ∝ K^−2 Σ (k + 1)^(1−α) ∝ K^−α → 0. The iterations average
//!   the passes' estimates (a Cesàro mean), so the image's error from the map goes to zero too.
//! * A grid finer than the GPU binds is not refused: [`MapLayout::within`] keeps the finest
//!   that fits, and the schedule stops refining there (the map's noise still averages out).
//! * `passes = 1` is one fixed map, traced before the first iteration, as the seed describes.

use super::PhotonSettings;
use super::gpu::GpuPhotonMap;
use super::guide::PhotonGuide;
use super::map::MapLayout;
use super::map::PhotonRegion;
use crate::error::Result;
use crate::gpu::Gpu;
use crate::gpu_scene::GpuScene;
use crate::surface::PreparedScene;
use glam::Vec3;

/// The schedule's α: cell area ∝ pass^−(1−α).
pub const ALPHA: f64 = 2.0 / 3.0;
/// Iterations per photon pass by default: 0, fitted by [`fitted_pass_iterations`].
pub const DEFAULT_PASS_ITERATIONS: u32 = 0;

/// Iterations per photon pass for `photons` photons per pass and a `pixels`-pixel image:
/// 4·photons/pixels, at least 16. Tracing a photon costs about what one pixel's iteration
/// costs (lavapipe, Cornell box: 3.4 µs per photon, 4.1 µs per pixel with 4 gather
/// directions), so the passes take about a fifth of the render's time, whatever the image
/// size; the count depends on the settings alone, so a seed still gives one image.
pub fn fitted_pass_iterations(photons: u32, pixels: u64) -> u32 {
    ((4 * photons as u64).div_ceil(pixels.max(1))).clamp(16, u32::MAX as u64) as u32
}

/// Photons of the first of several passes: a quarter of the others' (at least 2¹⁶, at most
/// all of them), so the first image waits for a quarter of the tracing; its noisier map is
/// one pass among many in the image's mean.
pub fn first_pass_photons(count: u32) -> u32 {
    (count / 4).max(count.min(1 << 16))
}

/// Steps of the schedule per doubling of the resolution: the cells shrink in steps of
/// 2^(1/8) (9 %) along each axis, so a new layout is made at passes 1, 2, 4, 7, 13, 22, 37, 63,
/// … (a factor of 1.68 apart) rather than at almost every pass of the first hundred.
pub const RESOLUTION_STEPS_PER_DOUBLING: f64 = 8.0;

/// Grid resolution of pass `pass` (0-based) for a first pass of `first` cells:
/// first · (k + 1)^((1 − α)/2), the factor rounded down to a power of 2^(1/8).
pub fn pass_resolution(first: u32, pass: u32) -> u32 {
    let growth = ((pass + 1) as f64).log2() * 0.5 * (1.0 - ALPHA);
    let step = (growth * RESOLUTION_STEPS_PER_DOUBLING + 1e-9).floor() / RESOLUTION_STEPS_PER_DOUBLING;
    ((first as f64) * 2f64.powf(step)).round() as u32
}

/// Whether the camera's region `new` asks for another map than one refined over `old`: less
/// than [`REGION_KEPT`] of its volume lies in `old`, or it is a quarter of `old`'s or less
/// (cells four times as fine and more would fit it); a region where there was none or none
/// where there was one.
pub fn region_moved(old: Option<&PhotonRegion>, new: Option<&PhotonRegion>) -> bool {
    let volume = |a: Vec3| f64::from(a.x.max(0.0)) * f64::from(a.y.max(0.0)) * f64::from(a.z.max(0.0));
    match (old, new) {
        (None, None) => false,
        (Some(o), Some(n)) => {
            let inside = volume(n.bounds.max.min(o.bounds.max) - n.bounds.min.max(o.bounds.min));
            let (vn, vo) = (volume(n.bounds.extent()), volume(o.bounds.extent()));
            inside < REGION_KEPT * vn || 4.0 * vn <= vo
        }
        _ => true,
    }
}

/// The share of the camera's new region that must lie in the refined one for the map to stay.
pub const REGION_KEPT: f64 = 0.75;

/// The photon map of the current pass and what the next pass needs.
pub struct PhotonPasses {
    prepared: PreparedScene,
    settings: PhotonSettings,
    /// Passes in all (0: no limit).
    passes: u32,
    pass_iterations: u32,
    pass: u32,
    iterations_in_pass: u32,
    /// The finest resolution the GPU binds, once a pass has hit it.
    finest: Option<u32>,
    map: GpuPhotonMap,
    /// Where the map is read, and where the sun's and the sky's photons start to land there.
    guide: PhotonGuide,
    /// Whether a new pass is traced in steps beside the current one ([`Self::set_stepped`]).
    stepped: bool,
    /// The next pass, while it is traced in steps.
    pending: Option<Pending>,
    /// Seconds the first pass's tracing took (the GPU waited for), where it was timed: of
    /// several passes, where the GPU can be waited for ([`crate::gpu::READ_BACK_BLOCKS`]).
    first_seconds: Option<f64>,
}

/// The next pass traced a step at a time ([`PhotonPasses::trace_step`]) while the iterations
/// go on reading the current map.
struct Pending {
    /// Its map where the schedule asks for finer cells; `None`: the current map's counters
    /// (its lookup values stay the current pass's until the pass resolves).
    map: Option<GpuPhotonMap>,
    /// Photons of the pass, and those traced so far.
    count: u32,
    traced: u32,
}

impl PhotonPasses {
    /// Traces pass 0 (`settings.grid_resolution` cells) and keeps what later passes need; the
    /// guide buffer holds the gather guide's cells over `field` where the gather is guided.
    pub fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        prepared: PreparedScene,
        settings: PhotonSettings,
        passes: u32,
        pass_iterations: u32,
        field: Option<crate::gather::guide::GuideField>,
    ) -> Result<PhotonPasses> {
        // Passes to come: a coarse first pass, so the first image comes as fast as it can.
        let first = if passes == 1 { settings.count } else { first_pass_photons(settings.count) };
        let layout = MapLayout::within(
            &prepared.scene,
            &prepared.bounds,
            settings.grid_resolution,
            settings.region.as_ref(),
            &gpu.device.limits(),
        )?;
        // The guide marks the cells of the first grid, wherever later passes refine it.
        let lights = super::guide::guided_lights(&prepared.lights);
        let guide = PhotonGuide::new(gpu, layout.grid, &lights, settings.guided && passes != 1, field);
        let mut map = GpuPhotonMap::with_layout(gpu, scene, &prepared, &settings, layout, &guide)?;
        // Timed for the photon budget's start-up ([`super::budget::startup_scale`]).
        let timed = passes != 1 && crate::gpu::READ_BACK_BLOCKS;
        if timed {
            gpu.wait()?;
        }
        let began = web_time::Instant::now();
        map.trace_photons(gpu, scene, 0, first);
        let first_seconds = if timed {
            gpu.wait()?;
            Some(began.elapsed().as_secs_f64())
        } else {
            None
        };
        if passes == 1 {
            // One fixed map: rendering reads the lookup values alone.
            map.release_build_buffers();
        }
        Ok(PhotonPasses {
            prepared,
            settings,
            passes,
            pass_iterations: pass_iterations.max(1),
            pass: 0,
            iterations_in_pass: 0,
            finest: None,
            map,
            guide,
            stepped: false,
            pending: None,
            first_seconds,
        })
    }

    pub fn map(&self) -> &GpuPhotonMap {
        &self.map
    }

    /// The current pass (0-based).
    pub fn pass(&self) -> u32 {
        self.pass
    }

    /// The iterations the current pass has had.
    pub fn iterations_in_pass(&self) -> u32 {
        self.iterations_in_pass
    }

    /// Whether the map changes during the render (more than one pass).
    pub fn progressive(&self) -> bool {
        self.passes != 1
    }

    /// Continues a render that stopped `iterations_in_pass` iterations into pass `pass` (a
    /// checkpoint's): the map of that pass is traced as the render had it — its cells by the
    /// schedule, its photons from the stream (seed, photon, pass) — and the next iterations
    /// follow the schedule from there.
    pub fn resume_at(&mut self, gpu: &Gpu, scene: &GpuScene, pass: u32, iterations_in_pass: u32) -> Result<()> {
        if pass > 0 && !(self.passes == 0 || pass < self.passes) {
            return Err(crate::error::Error::Checkpoint(format!(
                "the checkpoint is in photon pass {pass} of a render with {} passes",
                self.passes
            )));
        }
        if pass > 0 {
            let wanted = pass_resolution(self.settings.grid_resolution, pass);
            let layout = self.layout(gpu, wanted)?;
            let got = layout.grid.dims.max_element();
            self.finest = (got < wanted).then_some(got);
            let current = self.map.grid().dims.max_element();
            if got != current {
                let settings = PhotonSettings { grid_resolution: got, ..self.settings };
                self.map = GpuPhotonMap::with_layout(gpu, scene, &self.prepared, &settings, layout, &self.guide)?;
            }
            self.map.trace_pass(gpu, scene, pass);
        }
        self.pass = pass;
        self.iterations_in_pass = iterations_in_pass;
        self.pending = None;
        Ok(())
    }

    /// The map's layout at `resolution` cells along the longest axis (fewer where the GPU's
    /// limits ask), over the scene with its photon region.
    fn layout(&self, gpu: &Gpu, resolution: u32) -> Result<MapLayout> {
        MapLayout::within(
            &self.prepared.scene,
            &self.prepared.bounds,
            resolution,
            self.settings.region.as_ref(),
            &gpu.device.limits(),
        )
    }

    /// Iterations the current pass lasts.
    pub fn pass_iterations(&self) -> u32 {
        self.pass_iterations
    }

    /// Sets how many iterations passes last from the current one on (the photon budget's
    /// choice: [`super::budget`]).
    pub fn set_pass_iterations(&mut self, iterations: u32) {
        self.pass_iterations = iterations.max(1);
    }

    /// The photons of the current pass (the first of several has a quarter of them).
    pub fn pass_photons(&self) -> u32 {
        if self.pass == 0 && self.passes != 1 { first_pass_photons(self.settings.count) } else { self.settings.count }
    }

    /// Seconds the first pass's tracing took, where it was timed.
    pub fn first_pass_seconds(&self) -> Option<f64> {
        self.first_seconds
    }

    /// The photons of the pass after the current one.
    pub fn next_pass_photons(&self) -> u32 {
        self.settings.count
    }

    /// Whether the next [`advance`](Self::advance) starts a new pass.
    pub fn pass_ends(&self) -> bool {
        let more = self.passes == 0 || self.pass + 1 < self.passes;
        more && self.iterations_in_pass >= self.pass_iterations
    }

    /// Traces each new pass in steps beside the current one (an interactive view, whose frames
    /// must stay short: [`trace_step`](Self::trace_step)) or at once (`false`, the default).
    /// Not where the photons are guided (what the guide learns of a pass is tied to its map).
    pub fn set_stepped(&mut self, on: bool) {
        self.stepped = on && self.progressive() && !self.settings.guided;
    }

    /// Whether the passes are traced in steps.
    pub fn stepped(&self) -> bool {
        self.stepped
    }

    /// The next pass's photons traced so far and in all, while it is traced in steps.
    pub fn pending(&self) -> Option<(u32, u32)> {
        self.pending.as_ref().map(|p| (p.traced, p.count))
    }

    /// Called before each iteration: once the current pass has had its iterations, traces the
    /// next one (a new layout where the schedule asks for finer cells) — or, traced in steps,
    /// begins it and goes on with the current one until it is done. Returns whether the map
    /// changed.
    pub fn advance(&mut self, gpu: &Gpu, scene: &GpuScene) -> Result<bool> {
        if !self.pass_ends() || self.pending.is_some() {
            self.iterations_in_pass += 1;
            return Ok(false);
        }
        if self.stepped {
            let map = self.next_map(gpu, scene, self.pass + 1)?;
            let target = map.as_ref().unwrap_or(&self.map);
            target.begin_trace(gpu);
            self.pending = Some(Pending { map, count: self.settings.count, traced: 0 });
            self.iterations_in_pass += 1;
            return Ok(false);
        }
        self.pass += 1;
        self.iterations_in_pass = 1;
        if let Some(map) = self.next_map(gpu, scene, self.pass)? {
            self.map = map;
        }
        self.map.trace_pass(gpu, scene, self.pass);
        Ok(true)
    }

    /// The scene as the passes trace it.
    pub fn prepared(&self) -> &PreparedScene {
        &self.prepared
    }

    /// The region whose cells are refined ([`PhotonSettings::region`]).
    pub fn region(&self) -> Option<&PhotonRegion> {
        self.settings.region.as_ref()
    }

    /// Moves the refined region to `region` (the camera went where the map is coarse): where
    /// the passes are traced in steps and none is under way, the next pass begins at once,
    /// over a layout with the new region, and replaces the current map when it is all traced
    /// ([`trace_step`](Self::trace_step)); the passes after it keep the region. Returns
    /// whether it began.
    pub fn refit(&mut self, gpu: &Gpu, scene: &GpuScene, region: Option<PhotonRegion>) -> Result<bool> {
        if !self.stepped || self.pending.is_some() || !region_moved(self.settings.region.as_ref(), region.as_ref()) {
            return Ok(false);
        }
        self.settings.region = region;
        let resolution = self.map.grid().dims.max_element().max(self.settings.grid_resolution);
        let layout = self.layout(gpu, resolution)?;
        let settings = PhotonSettings { grid_resolution: layout.grid.dims.max_element(), ..self.settings };
        let map = GpuPhotonMap::with_layout(gpu, scene, &self.prepared, &settings, layout, &self.guide)?;
        map.begin_trace(gpu);
        self.pending = Some(Pending { map: Some(map), count: self.settings.count, traced: 0 });
        Ok(true)
    }

    /// Traces up to `photons` more of the pass under way in steps; once all are, resolves it
    /// and makes it the current pass (its first iteration is the next). Returns whether it
    /// did; nothing where no pass is under way in steps.
    pub fn trace_step(&mut self, gpu: &Gpu, scene: &GpuScene, photons: u32) -> bool {
        let Some(p) = &mut self.pending else { return false };
        let pass = self.pass + 1;
        let target = p.map.as_ref().unwrap_or(&self.map);
        let n = photons.max(1).min(p.count - p.traced);
        target.trace_batch(gpu, scene, (pass, p.count), p.traced, n);
        p.traced += n;
        if p.traced < p.count {
            return false;
        }
        target.resolve(gpu, scene, (pass, p.count));
        if let Some(map) = self.pending.take().and_then(|p| p.map) {
            self.map = map;
        }
        self.pass = pass;
        self.iterations_in_pass = 0;
        true
    }

    /// The map of pass `pass` where its cells differ from the current map's (allocated, not
    /// traced), after learning what the last pass's photons found where the guide asks.
    fn next_map(&mut self, gpu: &Gpu, scene: &GpuScene, pass: u32) -> Result<Option<GpuPhotonMap>> {
        let wanted = pass_resolution(self.settings.grid_resolution, pass);
        let wanted = self.finest.map_or(wanted, |f| wanted.min(f));
        let current = self.map.grid().dims.max_element();
        let mut next = None;
        if wanted > current {
            let layout = self.layout(gpu, wanted)?;
            let got = layout.grid.dims.max_element();
            if got < wanted {
                self.finest = Some(got);
            }
            if got > current {
                let settings = PhotonSettings { grid_resolution: got, ..self.settings };
                next = Some(GpuPhotonMap::with_layout(gpu, scene, &self.prepared, &settings, layout, &self.guide)?);
                log::info!("photon pass {pass}: {got} cells along the longest axis");
            }
        }
        // What the last pass's photons found, learned before this pass's start.
        let (photons, useful) = self.guide.learn(gpu)?;
        if photons > 0 {
            log::info!(
                "photon guide: the last pass's {photons} sun and sky photons landed {useful} times where the map is read ({:.3} each)",
                useful as f64 / photons as f64
            );
        }
        Ok(next)
    }

    /// The photon guide (where the map is read, what the passes learned).
    pub fn guide(&self) -> &PhotonGuide {
        &self.guide
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_fitted_cadence_is_four_photons_per_pixel_and_at_least_sixteen_iterations() {
        assert_eq!(fitted_pass_iterations(1 << 20, 256 * 256), 64);
        assert_eq!(fitted_pass_iterations(1 << 20, 128 * 128), 256);
        assert_eq!(fitted_pass_iterations(1 << 20, 1920 * 1080), 16);
        assert_eq!(first_pass_photons(1 << 20), 1 << 18);
        assert_eq!(first_pass_photons(1 << 16), 1 << 16);
        assert_eq!(first_pass_photons(1000), 1000);
    }

    #[test]
    fn the_schedule_shrinks_cell_area_as_pass_to_the_minus_one_third() {
        assert_eq!(pass_resolution(64, 0), 64);
        // (k + 1)^(1/6): 64 passes halve the cell side, 4096 quarter it.
        assert_eq!(pass_resolution(64, 63), 128);
        assert_eq!(pass_resolution(64, 4095), 256);
        let mut last = 0;
        let mut changes = 0;
        for k in 0..1000 {
            let r = pass_resolution(32, k);
            assert!(r >= last);
            // Within one step (9 %) below the exact schedule.
            let exact = 32.0 * ((k + 1) as f64).powf(1.0 / 6.0);
            assert!(
                r as f64 <= exact + 0.5 && r as f64 >= exact / 2f64.powf(1.0 / 8.0) - 0.5,
                "pass {k}: {r} against {exact}"
            );
            changes += (r != last) as u32;
            last = r;
        }
        // The first pass, then every factor of 2^(6/8) in passes: 1, 2, 4, 7, 13, … 860.
        assert_eq!(changes, 14);
    }
}
