//! Final gather: per iteration one direction ω for all visible points at once (Hachisuka,
//! GPU Gems 2, ch. 38), found by one of two implementations of the same estimator.
//!
//! * Direction: ω_i = R · S(i), S a low-discrepancy (Halton 5, 7) sequence mapped uniformly to
//!   the sphere (pdf 1/4π) and R a random rotation drawn per restart.
//! * Nearest surface h along ω from each visible point x (t > ε, x's own triangle excluded):
//!   [`GatherMethod::Raster`] depth-peels an orthographic ray view and projects each layer onto
//!   the visible points ([`crate::gather_raster`]); [`GatherMethod::Lists`] rasterizes the ray
//!   view once into per-texel fragment lists that each visible point walks
//!   ([`crate::gather_lists`]); [`GatherMethod::Trace`] casts the ray
//!   through the BVH in a compute shader ([`crate::gather_trace`]). They differ only where a
//!   ray-view texel is crossed by a silhouette (the raster gathers take the texel's surface).
//! * Estimate (`gather.wgsl`): L_ind(x, ω) = (ρ_x/π) · L(h → x) · max(0, n_x·ω) · 4π, where
//!   L(h → x) = ρ_h/π · E(h) from the photon map on the side of h facing x (zero from the back
//!   of a one-sided surface; emission is never added: the direct pass owns it).
//!
//! Several directions per iteration share one G-buffer and direct pass (`--directions`): the
//! indirect estimate, by far the noisier, gets more samples per unit of time.
//!
//! [`GatherMethod::Auto`] lets the first iterations alternate between them and keeps the
//! fastest on this adapter; every one of those iterations counts towards the image.

use std::time::{Duration, Instant};

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, Quat, Vec2, Vec3};

use crate::error::Result;
use crate::film::Film;
use crate::frame::FrameBinding;
use crate::gather_lists::ListGather;
use crate::gather_raster::RasterGather;
use crate::gather_trace::TraceGather;
use crate::gbuffer::GBufferPass;
use crate::gpu::{Gpu, compute_pipeline};
use crate::gpu_scene::GpuScene;
use crate::photons::gpu::GpuPhotonMap;
use crate::sampling::{Rng, orthonormal_basis, radical_inverse, uniform_sphere};
use crate::scene::Aabb;
use crate::shader;

/// Most gather directions per iteration.
pub const MAX_DIRECTIONS: u32 = 16;

/// `Gather` in `gather.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct GatherUniforms {
    /// Raster: the ray view of `direction`.
    pub view_proj: [[f32; 4]; 4],
    /// Raster: the direction being peeled.
    pub direction: [f32; 3],
    pub bundle: u32,
    /// Directions this iteration: each estimate is weighted 1/count.
    pub count: u32,
    pub _pad: [u32; 3],
    /// Trace: all the iteration's directions (xyz).
    pub directions: [[f32; 4]; MAX_DIRECTIONS as usize],
}

/// One gather direction of an iteration: ω and the ray view's sub-texel offset.
#[derive(Clone, Copy, Debug)]
pub struct GatherSample {
    pub direction: Vec3,
    pub texel_jitter: Vec2,
}

/// How the nearest surface along the gather direction is found.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum GatherMethod {
    /// Time both on the first iterations and keep the faster.
    #[default]
    Auto,
    /// Depth-peeled orthographic ray view (rasterization).
    Raster,
    /// Per-texel fragment lists of the ray view in one raster pass (no read-back).
    Lists,
    /// BVH ray casting in a compute shader.
    Trace,
}

/// The implementations `Auto` chooses among, in trial order.
const CANDIDATES: [GatherMethod; 3] = [GatherMethod::Raster, GatherMethod::Lists, GatherMethod::Trace];

/// [`GatherMethod::Auto`] keeps the traced gather unless another is this many times faster.
pub const PREFER_TRACE: f64 = 1.25;

/// Iterations of each method timed by [`GatherMethod::Auto`] before it chooses.
pub const AUTO_TRIALS: u32 = 3;

/// Iterations after which [`GatherMethod::Auto`] has chosen, at most (candidates more than
/// twice as slow as the fastest are dropped after their first run).
pub const AUTO_ITERATIONS: u32 = CANDIDATES.len() as u32 * AUTO_TRIALS;

/// The gather direction of iteration `i` for a restart whose rotation is `rotation`.
pub fn gather_direction(i: u32, rotation: Quat) -> Vec3 {
    rotation * uniform_sphere(radical_inverse(i + 1, 5), radical_inverse(i + 1, 7))
}

/// A uniformly random rotation (Shoemake's method) from the stream (seed, restart).
pub fn random_rotation(seed: u32, restart: u32) -> Quat {
    let mut rng = Rng::new(seed ^ 0x5bd1e995, restart, 0);
    let (u1, u2, u3) = (rng.next_f32(), rng.next_f32(), rng.next_f32());
    let tau = std::f32::consts::TAU;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    Quat::from_xyzw(a * (tau * u2).sin(), a * (tau * u2).cos(), b * (tau * u3).sin(), b * (tau * u3).cos()).normalize()
}

/// World → ray-view clip space for direction ω over `bounds`, shifted by `jitter` texels.
pub fn ray_view_projection(bounds: &Aabb, direction: Vec3, bundle: u32, jitter: Vec2) -> Mat4 {
    let center = bounds.center();
    let radius = (0.5 * bounds.extent().length()).max(1e-6) * 1.001;
    let (_, b) = orthonormal_basis(direction);
    let eye = center + direction * 2.0 * radius;
    let view = Mat4::look_at_rh(eye, center, b);
    let proj = Mat4::orthographic_rh(-radius, radius, -radius, radius, radius, 3.0 * radius);
    let shift = Mat4::from_translation(Vec3::new(2.0 * jitter.x / bundle as f32, -2.0 * jitter.y / bundle as f32, 0.0));
    shift * proj * view
}

/// What a gather implementation's passes bind, for building them: the scene, the frame
/// uniforms, the G-buffer (visible points), the film (indirect component), the photon map and
/// the [`GatherUniforms`].
pub struct GatherSetup<'a> {
    pub scene: &'a GpuScene,
    pub frame: &'a FrameBinding,
    pub gbuffer: &'a GBufferPass,
    pub film: &'a Film,
    pub map: &'a GpuPhotonMap,
    pub uniforms: &'a wgpu::Buffer,
}

impl GatherSetup<'_> {
    /// A per-pixel compute pipeline ending in the estimator: `source` after the scene prelude,
    /// the photon-map lookup and `gather.wgsl`; bind groups scene, frame, `own`, photon map.
    pub fn estimate_pipeline(
        &self,
        device: &wgpu::Device,
        label: &str,
        source: &str,
        own: &wgpu::BindGroupLayout,
    ) -> wgpu::ComputePipeline {
        let source =
            shader::with_scene(&[include_str!("photon_map.wgsl"), include_str!("gather.wgsl"), source].join("\n"));
        let module = shader::module(device, label, &source);
        compute_pipeline(
            device,
            label,
            &module,
            "main",
            &[&self.scene.layout, &self.frame.layout, own, &self.map.layout],
        )
    }
}

/// What a gather reads when it is encoded: the scene, the frame uniforms and the photon map
/// it was built with, and the image size.
#[derive(Clone, Copy)]
pub struct GatherInputs<'a> {
    pub scene: &'a GpuScene,
    pub frame: &'a FrameBinding,
    pub map: &'a GpuPhotonMap,
    pub width: u32,
    pub height: u32,
}

impl<'a> GatherInputs<'a> {
    /// The per-pixel pipeline's bind groups around `own`: scene, frame, `own`, photon map.
    pub fn groups(&self, own: &'a wgpu::BindGroup) -> [&'a wgpu::BindGroup; 4] {
        [&self.scene.bind_group, &self.frame.bind_group, own, &self.map.bind_group]
    }
}

/// The final gather pass: the implementations behind one interface.
pub struct GatherPass {
    pub bundle: u32,
    uniforms: wgpu::Buffer,
    raster: Option<RasterGather>,
    lists: Option<ListGather>,
    trace: Option<TraceGather>,
    /// The implementation in use, once chosen.
    chosen: Option<GatherMethod>,
    /// Auto: wall-clock times of the trial iterations so far, per candidate.
    trials: Vec<(GatherMethod, Vec<Duration>)>,
}

impl GatherPass {
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        gpu: &Gpu,
        scene: &GpuScene,
        frame: &FrameBinding,
        gbuffer: &GBufferPass,
        film: &Film,
        map: &GpuPhotonMap,
        bundle: u32,
        method: GatherMethod,
    ) -> Result<GatherPass> {
        let uniforms = gpu.zeroed_buffer(
            "gather uniforms",
            std::mem::size_of::<GatherUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let setup = GatherSetup { scene, frame, gbuffer, film, map, uniforms: &uniforms };
        let wants = |m: GatherMethod| method == m || method == GatherMethod::Auto;
        let raster = wants(GatherMethod::Raster).then(|| RasterGather::new(gpu, &setup, bundle)).transpose()?;
        let lists = match wants(GatherMethod::Lists).then(|| ListGather::new(gpu, &setup, bundle)) {
            None => None,
            Some(Ok(lists)) => Some(lists),
            // Auto does without a candidate that does not fit.
            Some(Err(e)) if method == GatherMethod::Auto => {
                log::info!("gather: no fragment lists ({e})");
                None
            }
            Some(Err(e)) => return Err(e),
        };
        let trace = wants(GatherMethod::Trace).then(|| TraceGather::new(gpu, &setup));
        let chosen = (method != GatherMethod::Auto).then_some(method);
        let present = [raster.is_some(), lists.is_some(), trace.is_some()];
        let trials = CANDIDATES.iter().zip(present).filter(|(_, p)| *p).map(|(&m, _)| (m, Vec::new())).collect();
        Ok(GatherPass { bundle, uniforms, raster, lists, trace, chosen, trials })
    }

    /// The implementation in use (`Auto` while the trials run).
    pub fn method(&self) -> GatherMethod {
        self.chosen.unwrap_or(GatherMethod::Auto)
    }

    /// The uniforms for `samples` with sample `current` as the raster gather's ray view.
    fn uniforms(&self, bounds: &Aabb, samples: &[GatherSample], current: usize) -> GatherUniforms {
        let s = samples[current];
        let mut directions = [[0.0; 4]; MAX_DIRECTIONS as usize];
        for (d, s) in directions.iter_mut().zip(samples) {
            *d = s.direction.extend(0.0).into();
        }
        GatherUniforms {
            view_proj: ray_view_projection(bounds, s.direction, self.bundle, s.texel_jitter).to_cols_array_2d(),
            direction: s.direction.into(),
            bundle: self.bundle,
            count: samples.len() as u32,
            _pad: [0; 3],
            directions,
        }
    }

    /// Encodes the gather along each of `samples` (1 to [`MAX_DIRECTIONS`] directions, each
    /// estimate weighted 1/len) after the work already in `enc`, and returns the encoder to go
    /// on with (the raster gather submits to read each direction's depth complexity back).
    /// Reads: scene, frame, G-buffer, photon map. Adds to: the film's indirect component.
    pub fn encode(
        &mut self,
        gpu: &Gpu,
        enc: wgpu::CommandEncoder,
        inputs: &GatherInputs,
        samples: &[GatherSample],
    ) -> Result<wgpu::CommandEncoder> {
        assert!((1..=MAX_DIRECTIONS as usize).contains(&samples.len()), "1 to {MAX_DIRECTIONS} gather directions");
        let method = match self.chosen {
            Some(m) => m,
            None => return self.encode_trial(gpu, enc, inputs, samples),
        };
        self.encode_with(method, gpu, enc, inputs, samples)
    }

    fn encode_with(
        &self,
        method: GatherMethod,
        gpu: &Gpu,
        mut enc: wgpu::CommandEncoder,
        inputs: &GatherInputs,
        samples: &[GatherSample],
    ) -> Result<wgpu::CommandEncoder> {
        if method == GatherMethod::Raster || method == GatherMethod::Lists {
            for k in 0..samples.len() {
                if k > 0 {
                    // The previous direction's passes read the uniforms written before them.
                    gpu.queue.submit([enc.finish()]);
                    enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("gather") });
                }
                let u = self.uniforms(&inputs.scene.bounds, samples, k);
                gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
                if method == GatherMethod::Raster {
                    let raster = self.raster.as_ref().expect("the raster gather exists when chosen");
                    enc = raster.encode(gpu, enc, inputs)?;
                } else {
                    let lists = self.lists.as_ref().expect("the list gather exists when chosen");
                    lists.encode(&mut enc, inputs);
                }
            }
        } else {
            let trace = self.trace.as_ref().expect("the traced gather exists when chosen");
            let u = self.uniforms(&inputs.scene.bounds, samples, 0);
            gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
            trace.encode(&mut enc, inputs);
        }
        Ok(enc)
    }

    /// One timed trial iteration of `Auto`: the work before the gather is finished first so the
    /// gather alone is timed; after [`AUTO_TRIALS`] of each, the faster (median) is kept.
    fn encode_trial(
        &mut self,
        gpu: &Gpu,
        enc: wgpu::CommandEncoder,
        inputs: &GatherInputs,
        samples: &[GatherSample],
    ) -> Result<wgpu::CommandEncoder> {
        // The candidate with the fewest trials so far, in order.
        let k = (0..self.trials.len()).min_by_key(|&k| self.trials[k].1.len()).expect("a gather candidate");
        let method = self.trials[k].0;
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        let start = Instant::now();
        let enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("gather") });
        let enc = self.encode_with(method, gpu, enc, inputs, samples)?;
        gpu.queue.submit([enc.finish()]);
        gpu.wait()?;
        self.trials[k].1.push(start.elapsed());
        // Once every candidate has run, drop those whose fastest run is slower than twice the
        // fastest run of all: the trials cost little beyond the winner's time.
        if self.trials.iter().all(|t| !t.1.is_empty()) {
            let fastest = |t: &[Duration]| t.iter().min().copied().unwrap_or(Duration::MAX);
            let best = self.trials.iter().map(|t| fastest(&t.1)).min().unwrap_or(Duration::MAX);
            self.trials.retain(|t| fastest(&t.1) <= 2 * best);
        }
        if self.trials.iter().all(|t| t.1.len() as u32 >= AUTO_TRIALS) {
            let median = |v: &[Duration]| {
                let mut v = v.to_vec();
                v.sort();
                v[v.len() / 2]
            };
            let times: Vec<(GatherMethod, Duration)> = self.trials.iter().map(|(m, t)| (*m, median(t))).collect();
            let (fastest, t_fastest) = *times.iter().min_by_key(|(_, t)| *t).expect("a gather candidate");
            // The traced gather is exact and needs no ray-view memory: a raster gather must
            // win clearly, so that timing noise does not flip the choice between runs.
            let method = match times.iter().find(|(m, _)| *m == GatherMethod::Trace) {
                Some(&(_, t_trace)) if t_trace.as_secs_f64() <= PREFER_TRACE * t_fastest.as_secs_f64() => {
                    GatherMethod::Trace
                }
                _ => fastest,
            };
            let list: Vec<String> =
                times.iter().map(|(m, t)| format!("{m:?} {:.2} ms", t.as_secs_f64() * 1e3)).collect();
            log::info!("gather per iteration on {}: {}; using {method:?}", gpu.info.name, list.join(", "));
            self.chosen = Some(method);
            if method != GatherMethod::Raster {
                self.raster = None;
            }
            if method != GatherMethod::Lists {
                self.lists = None;
            }
            if method != GatherMethod::Trace {
                self.trace = None;
            }
        }
        Ok(gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("iteration") }))
    }
}
