//! The denoiser: a weighted first-order regression (as NFOR, Bitterli et al. 2016, and
//! weighted local regression denoisers do) of the accumulated image on the visible points'
//! mean distance and normal, with weights from an edge-avoiding à-trous wavelet filter of the
//! image itself (Dammertz et al. 2010, with the luminance weights of SVGF, Schied et al. 2017)
//! scaled by the per-pixel standard deviation of the mean; demodulated by the mean albedo,
//! with the emission the eye sees taken out and added back unfiltered. It runs on the film's
//! sums when the image is read (not per iteration) and leaves the sums alone: the raw image
//! is always there.
//!
//! **Guides** ([`Guides`], `denoise_guides.wgsl`). After every pass of an iteration has added
//! to the film, a per-pixel pass adds the visible point's albedo ρ (times the eye chain's
//! throughput behind mirrors and glass), distance z from the camera, shading normal and
//! coverage to sums; the emission E_k the direct pass added (an emitter's front face, the
//! environment where the camera ray escapes); and the first two moments of the iteration's
//! demodulated luminance `l_k = Y(Δ_k / a_k)` per component (the reflected direct light
//! Δ_k − E_k, the indirect light), where Δ_k is what iteration k added (the film's sum less
//! its sum after iteration k − 1, kept in the guides), a_k the iteration's albedo with
//! channels ≤ [`DEMODULATION_MIN`] replaced by 1, Y the Rec. 709 luminance. These sums are
//! also the albedo and normal outputs for external denoisers ([`GuideState::albedo`],
//! [`GuideState::normal`]).
//!
//! **The variance.** With m₁ = Σ l_k, m₂ = Σ l_k² over n iterations, the variance of the mean
//! is estimated by the sample variance over n,
//!
//! ```text
//!   σ² = (m₂ − m₁²/n) / (n (n − 1)).
//! ```
//!
//! The film's two halves (film.rs) give the same quantity without the per-iteration moments
//! but need two blocks of 16 iterations or photon passes each before they say anything; a
//! denoiser is wanted most before that, at 16 iterations of one block. Where the iterations'
//! samples are stratified (Sobol') σ² over-estimates the variance of the mean and the filter
//! errs on the side of smoothing. Either way σ² falls as 1/n.
//!
//! **The filter** (`denoise.wgsl`, CPU twin [`cpu`]). Per component c (direct, indirect) the
//! light is L = (S_c/n − [c = direct] Ē) / a, a the mean albedo's demodulation, Ē the mean
//! emission.
//!
//! 1. *The guide* G: L and σ² filtered by [`DenoiseParams::levels`] (2; at most [`LEVELS`])
//!    levels of the 5×5 B3-spline kernel h = (1, 4, 6, 4, 1)/16 with holes, step 2^i at
//!    level i:
//!
//!    ```text
//!      L'(p) = Σ_q w(p,q) L(q) / Σ_q w(p,q),   σ'²(p) = Σ_q w(p,q)² σ²(q) / (Σ_q w(p,q))²
//!      w(p,q) = h(q−p) · w_n · w_z · w_l
//!      w_n = max(0, n_p·n_q)^σ_n
//!      w_z = exp(−|z_p − z_q| / (σ_z · z_p · θ · |q − p|))      θ: a pixel's angle
//!      w_l = exp(−|Ȳ_p − Ȳ_q| / (σ_l · c · √(g₃ ⊛ σ²)(p) + ε)),   Ȳ = g₃ ⊛ Y(L)
//!    ```
//!
//!    (w = h at q = p; g₃ the 3×3 binomial blur, `blur_luminance`; c = [`LUMINANCE_NOISE`],
//!    the standard deviation of Ȳ_p − Ȳ_q in units of one pixel's, so σ_l counts standard
//!    deviations of what is compared.) The depth weight compares the distance's change with
//!    what a surface facing the camera changes over |q − p| pixels: σ_z = 4 lets planes
//!    through up to about 76° from the view direction and stops at silhouettes.
//! 2. *The regression* (`regress`): at every pixel p where a surface is seen, over the disc
//!    of radius r (r_direct = 5, r_indirect = 9 pixels) of pixels q where one is seen,
//!
//!    ```text
//!      β = argmin Σ_q w_q (L(q) − βᵀx_q)² + λ Σ_j A_jj β_j²,     L̂(p) = β_const
//!      x_q = ((q − p)/r, (z_q − z_p)/z_p, n_q − n_p, 1)
//!      w_q = exp(−|q − p|² / (2 (b r)²)) · exp(−|Y(G_q) − Y(G_p)| / (σ_g √(g₃ ⊛ σ²)(p)))
//!    ```
//!
//!    (b = [`BANDWIDTH`], A = Σ w x xᵀ, λ the ridge, σ_g = 1), solved by Cholesky with the
//!    constant last, so that its coefficient is the last forward substitution's. A pixel on
//!    an edge or a corner is a mixture of what its samples saw, and its mean distance and
//!    normal are the same mixture: the fit follows it, where a weighted mean (the guide
//!    itself) would replace it by its neighbours'; and the offset terms follow the light's
//!    gradients across the window without the bias of a mean. The guide's weights keep
//!    shadows and light of different brightness apart. On the Cornell box at 16 iterations
//!    (128², against the reference) the guide alone reached 0.0295; the regression 0.0236.
//! 3. The result is a · (L̂_direct + L̂_indirect) + Ē.
//!
//! **Convergence.** σ² → 0 as n grows, so w_q → 0 for every q whose guide differs from p's:
//! the fit tends to p's own value wherever the image has any detail, and in flat regions it
//! fits equal values. The denoised image converges to the raw one; the denoiser adds no bias
//! in the limit (tests/denoise.rs: a synthetic image to 4096 iterations; the Cornell box at
//! 1024, where the denoised image differs from the raw one by less than the raw image's
//! noise).

use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu::{Gpu, compute_pipeline, groups, shader};
use crate::gpu_scene::GpuScene;
use crate::image_io::LinearImage;
use crate::passes::film::{COMPONENTS, FILM_DIRECT, FILM_INDIRECT, Film};
use crate::passes::frame::FrameBinding;
use crate::passes::gbuffer::{GBUFFER_FILM_WGSL, GBufferPass, GroupThree, PixelPass, PixelShader};
use crate::passes::{FrameContext, IterationPass};
use crate::scene::Camera;

/// Guide slots per pixel: slot k of pixel p at `k·W·H + p` (vec4 each): 0 albedo sum and
/// distance sum, 1 normal sum and coverage count, 2 the moments (m₁, m₂) of the direct and
/// the indirect component. A second buffer keeps the film's direct and indirect sums at the
/// last iteration (two slots); the two stay under the largest binding where the film does
/// (48 bytes a pixel: 1920×1080 in lavapipe's 128 MiB).
pub const GUIDE_SLOTS: u64 = 3;
/// À-trous levels (steps 1, 2, 4, 8, 16: a 125-pixel-wide footprint).
pub const LEVELS: u32 = 5;
/// Albedo channels at most this are not divided by (emitters, the background, black).
pub const DEMODULATION_MIN: f32 = 0.01;
/// The variance where fewer than two iterations give none: the luminance weight is 1.
pub const VARIANCE_UNKNOWN: f32 = 1.0e20;
/// ε of the luminance weight: where σ² = 0 only equal luminances are averaged.
pub const LUMINANCE_EPSILON: f32 = 1.0e-10;
/// The standard deviation of the difference of two pixels' 3×3-binomial-blurred luminances
/// in units of one pixel's: √(2 Σ w²) = √2 · 3/8 for independent pixels of equal variance.
pub const LUMINANCE_NOISE: f32 = std::f32::consts::SQRT_2 * 0.375;
/// Guards the depth weight's division at distance 0.
pub const DEPTH_EPSILON: f32 = 1.0e-12;
/// The regression's spatial weight: a Gaussian of standard deviation this fraction of the
/// window's radius.
pub const BANDWIDTH: f32 = 0.6;
/// Added to every non-constant regressor's diagonal as a fraction of the total weight, so
/// that one that does not vary in the window (a plane's normal) gets a zero coefficient.
pub const RIDGE_FLOOR: f32 = 1.0e-12;
/// The second guide buffer's slots: the film's direct and indirect sums at the last iteration,
/// and the sums of the emission the eye sees.
pub const EXTRA_SLOTS: u64 = 3;

/// When a window that shows the denoised image filters it again ([`Schedule`]): once the image
/// holds this factor more iterations than at the last filter...
pub const SCHEDULE_GROWTH: u32 = 2;
/// ...or this many seconds after it, if the image has new iterations since...
pub const SCHEDULE_INTERVAL: f64 = 1.0;
/// ...but the latter never before the last filter's measured time over this share has passed
/// since it began: between doublings the filter takes at most this share of the window's time.
pub const SCHEDULE_SHARE: f64 = 0.25;

/// When an interactive window (`rastergi view`, the web page) runs the filter again while it
/// shows the denoised image. The filter costs far more than an iteration where the GPU is slow
/// (0.9 s at 256² on lavapipe), so not every frame: at once where nothing is denoised yet or
/// the image restarted (fewer iterations than at the last filter), then when the iterations
/// have grown by [`SCHEDULE_GROWTH`] (log₂ n filters in all) or [`SCHEDULE_INTERVAL`] has
/// passed — the latter, where the window measured what the last filter took
/// ([`Schedule::took`]), not before that time over [`SCHEDULE_SHARE`] has passed since it
/// began: at 1280 × 720 on lavapipe a filter takes 1.5 s, which a one-second interval repeated
/// after every iteration (57 % of the window's time), for an image one iteration better.
/// Doublings, log₂ n of them, stay due at once. Between filters the window resolves the
/// last denoised image (an exposure change needs no filter). Times are seconds from any fixed
/// origin.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Schedule {
    /// The iterations and the time of the last filter; `None`: none is on the window.
    last: Option<(u32, f64)>,
    /// The seconds the last measured filter took (0 until one is).
    cost: f64,
}

impl Schedule {
    /// Whether the image at `samples` iterations is due a filter at time `now`.
    pub fn due(&self, samples: u32, now: f64) -> bool {
        match self.last {
            None => true,
            // Fewer iterations: the image restarted since.
            Some((last, _)) if samples < last => true,
            Some((last, at)) => {
                let since = now - at;
                samples != last
                    && (samples >= last.saturating_mul(SCHEDULE_GROWTH)
                        || since >= SCHEDULE_INTERVAL.max(self.cost / SCHEDULE_SHARE))
            }
        }
    }

    /// The last filter took `seconds` (on the GPU, or the frame's time beside its work): the
    /// next waits for it over [`SCHEDULE_SHARE`]. Kept across [`Schedule::clear`] (the device
    /// and the image size make it), replaced at every measurement.
    pub fn took(&mut self, seconds: f64) {
        self.cost = seconds.max(0.0);
    }

    /// The seconds the last measured filter took (0 until one is).
    pub fn cost(&self) -> f64 {
        self.cost
    }

    /// The filter ran on the image at `samples` iterations at time `now`.
    pub fn ran(&mut self, samples: u32, now: f64) {
        self.last = Some((samples, now));
    }

    /// Whether a filter ran since the last [`Schedule::clear`]: the denoised image is of the
    /// current view.
    pub fn filtered(&self) -> bool {
        self.last.is_some()
    }

    /// The window no longer shows a denoised image: the next is filtered at once.
    pub fn clear(&mut self) {
        self.last = None;
    }
}

/// The filter's parameters (module notes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DenoiseParams {
    /// Luminance: standard deviations of the mean at which the weight is 1/e.
    pub sigma_l: f32,
    /// Normal: the exponent of the cosine.
    pub sigma_n: f32,
    /// Depth: the slope (distance change per pixel over distance × pixel angle) at which the
    /// weight is 1/e per pixel.
    pub sigma_z: f32,
    /// À-trous levels of the guide, 0 to [`LEVELS`] (more are capped).
    pub levels: u32,
    /// The regression's window radius in pixels for the direct component.
    pub radius_direct: u32,
    /// The regression's window radius in pixels for the indirect component.
    pub radius_indirect: u32,
    /// The regression's guide weight: standard deviations of the mean at which it is 1/e.
    pub sigma_g: f32,
    /// The regression's ridge, a fraction of each regressor's weighted square.
    pub ridge: f32,
}

impl Default for DenoiseParams {
    fn default() -> Self {
        Self {
            sigma_l: 1.5,
            sigma_n: 128.0,
            sigma_z: 4.0,
            levels: 2,
            radius_direct: 5,
            radius_indirect: 9,
            sigma_g: 1.0,
            ridge: 1.0e-3,
        }
    }
}

gpu_struct! {
    /// The filter's uniforms, one buffer per dispatch (`denoise.wgsl`).
    pub(crate) struct DenoiseUniforms as "Denoise" {
        pub(crate) resolution: [u32; 2],
        /// Iterations in the film's sums and in the guides' (fewer after a resume).
        pub(crate) samples: u32,
        pub(crate) guide_samples: u32,
        /// The à-trous level's step in pixels.
        pub(crate) step: u32,
        /// The edge-stopping functions' widths ([`DenoiseParams`]).
        pub(crate) sigma_l: f32,
        pub(crate) sigma_n: f32,
        pub(crate) sigma_z: f32,
        /// 2 tan(fov_y/2) / height: a pixel's angle at the image's centre.
        pub(crate) pixel_angle: f32,
        /// The regression's window radius in pixels, per component.
        pub(crate) radius_direct: u32,
        pub(crate) radius_indirect: u32,
        /// The regression's guide weight: standard deviations of the mean at which it is 1/e.
        pub(crate) sigma_g: f32,
        /// The regression's ridge: a fraction of each regressor's own weighted square.
        pub(crate) ridge: f32,
        /// The rows the dispatch covers: [row0, row_end) (a band of a filter run in steps).
        pub(crate) row0: u32,
        pub(crate) row_end: u32,
        pub(crate) _pad: u32,
    }
}

/// A pixel's angle at the image's centre for `camera` at `height` rows: 2 tan(fov/2)/height.
pub fn pixel_angle(camera: &Camera, height: u32) -> f32 {
    2.0 * (0.5 * camera.fov_y_deg.to_radians()).tan() / height.max(1) as f32
}

/// The WGSL declarations of the denoiser's constants, from their Rust values.
fn constants() -> String {
    format!(
        "const DEMODULATION_MIN: f32 = {DEMODULATION_MIN:?};\nconst VARIANCE_UNKNOWN: f32 = {VARIANCE_UNKNOWN:?};\n\
         const LUMINANCE_EPSILON: f32 = {LUMINANCE_EPSILON:?};\nconst LUMINANCE_NOISE: f32 = {LUMINANCE_NOISE:?};\nconst DEPTH_EPSILON: f32 = {DEPTH_EPSILON:?};\n\
         const BANDWIDTH: f32 = {BANDWIDTH:?};\nconst RIDGE_FLOOR: f32 = {RIDGE_FLOOR:?};\n{}",
        include_str!("denoise_common.wgsl")
    )
}

/// The guides pass's composed shader.
pub fn guides_source() -> String {
    crate::passes::per_pixel(&[GBUFFER_FILM_WGSL, &constants(), include_str!("denoise_guides.wgsl")])
}

/// The filter's composed shader.
pub fn filter_source() -> String {
    shader::compose(&[&constants(), &DenoiseUniforms::wgsl(), include_str!("denoise.wgsl")])
}

/// The accumulated guides of a render (module notes): a per-pixel pass after the iteration's
/// other passes.
pub struct Guides {
    pub buffer: wgpu::Buffer,
    /// [`EXTRA_SLOTS`] slots: the film's direct and indirect sums at the last iteration, the
    /// sums of the emission the eye sees.
    pub extra: wgpu::Buffer,
    pass: PixelPass,
    /// Iterations in the sums (fewer than the film's after a resume).
    pub samples: u32,
    width: u32,
    height: u32,
}

impl IterationPass for Guides {
    /// Reads: the visible points, the film. Writes: the guides. After the iteration's passes.
    fn encode(&mut self, enc: &mut wgpu::CommandEncoder, ctx: &FrameContext) -> Result<()> {
        self.pass.encode(enc, ctx)?;
        // An iteration counts once its last row band is in.
        if ctx.y0 + ctx.rows >= ctx.height {
            self.samples += 1;
        }
        Ok(())
    }
}

/// The guides pass's bind group 3: the guides and the previous sums, both accumulated.
pub fn guides_group() -> Group {
    Group::compute("denoiser guides", &[Slot::write::<[f32; 4]>(0, "guides"), Slot::write::<[f32; 4]>(1, "previous")])
}

/// The filter's bind group: the film, the guides and the previous sums read; each dispatch
/// reads `src` and writes `dst` (ping-pong), the image, luminance and unfiltered light.
pub fn filter_group() -> Group {
    Group::compute(
        "denoiser",
        &[
            Slot::uniform::<DenoiseUniforms>(0, "params"),
            Slot::read::<[f32; 4]>(1, "film"),
            Slot::read::<[f32; 4]>(2, "guides"),
            Slot::read::<[f32; 4]>(3, "extra"),
            Slot::read::<[f32; 4]>(4, "src"),
            Slot::write::<[f32; 4]>(5, "dst"),
            Slot::write::<[f32; 4]>(6, "image"),
            Slot::write::<[f32; 2]>(7, "lum"),
            Slot::write::<[f32; 4]>(8, "light"),
        ],
    )
}

impl Guides {
    pub fn new(gpu: &Gpu, (scene, frame): (&GpuScene, &FrameBinding), gbuffer: &GBufferPass, film: &Film) -> Guides {
        let pixels = film.width as u64 * film.height as u64;
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let buffer = gpu.zeroed_buffer("denoiser guides", GUIDE_SLOTS * pixels * 16, rw);
        let extra = gpu.zeroed_buffer("denoiser previous sums and emission", EXTRA_SLOTS * pixels * 16, rw);
        let (layout, bind_group) = guides_group().layout_and_bind(
            &gpu.device,
            &[("guides", buffer.as_entire_binding()), ("previous", extra.as_entire_binding())],
        );
        let source = guides_source();
        let shader = PixelShader { label: "denoiser guides", source: &source, entry: "accumulate_guides" };
        let pass = PixelPass::new(gpu, (scene, frame), (gbuffer, film), shader, GroupThree::Own(&layout, bind_group));
        Guides { buffer, extra, pass, samples: 0, width: film.width, height: film.height }
    }

    /// Clears the sums (with the film's).
    pub fn clear(&mut self, gpu: &Gpu) {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.buffer, 0, None);
        enc.clear_buffer(&self.extra, 0, None);
        gpu.queue.submit([enc.finish()]);
        self.samples = 0;
    }

    /// Starts the guides afresh on a film restored with sums (a resumed render): the
    /// iterations' values are taken from those sums on (the mean emission from the guides'
    /// iterations, the film's from all).
    pub fn restart_from(&mut self, gpu: &Gpu, film: &Film) {
        self.clear(gpu);
        let component = self.width as u64 * self.height as u64 * 16;
        debug_assert_eq!((FILM_DIRECT, FILM_INDIRECT), (0, 1));
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.copy_buffer_to_buffer(&film.accumulation, 0, &self.extra, 0, 2 * component);
        gpu.queue.submit([enc.finish()]);
    }

    /// The sums read back.
    pub fn read(&self, gpu: &Gpu) -> Result<GuideState> {
        let n = (GUIDE_SLOTS * self.width as u64 * self.height as u64 * 16) as usize;
        let bytes = gpu.read_buffer(&self.buffer, self.buffer.size())?;
        Ok(GuideState {
            width: self.width,
            height: self.height,
            samples: self.samples,
            sums: bytemuck::cast_slice::<u8, f32>(&bytes[..n]).to_vec(),
        })
    }
}

/// The guides' sums read back.
#[derive(Clone, Debug, PartialEq)]
pub struct GuideState {
    pub width: u32,
    pub height: u32,
    /// Iterations in the sums.
    pub samples: u32,
    /// `GUIDE_SLOTS × W × H × 4` floats (see [`GUIDE_SLOTS`]).
    pub sums: Vec<f32>,
}

impl GuideState {
    fn slot(&self, k: usize, p: usize) -> [f32; 4] {
        let i = 4 * (k * (self.width * self.height) as usize + p);
        [self.sums[i], self.sums[i + 1], self.sums[i + 2], self.sums[i + 3]]
    }

    /// The mean albedo of the visible points (times the eye chains' throughput; 0 where
    /// nothing is seen): the albedo AOV of external denoisers.
    pub fn albedo(&self) -> LinearImage {
        let n = self.samples.max(1) as f32;
        let pixels = (0..(self.width * self.height) as usize)
            .map(|p| {
                let g = self.slot(0, p);
                [g[0] / n, g[1] / n, g[2] / n]
            })
            .collect();
        LinearImage { width: self.width, height: self.height, pixels }
    }

    /// The mean shading normal (world space, unit, facing the eye; 0 where nothing is seen):
    /// the normal AOV of external denoisers.
    pub fn normal(&self) -> LinearImage {
        let pixels = (0..(self.width * self.height) as usize)
            .map(|p| {
                let g = self.slot(1, p);
                let len = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
                if len > 0.0 { [g[0] / len, g[1] / len, g[2] / len] } else { [0.0; 3] }
            })
            .collect();
        LinearImage { width: self.width, height: self.height, pixels }
    }
}

/// The filter on the GPU: its buffers for one image size, bound to a film's sums and guides.
pub struct Denoiser {
    width: u32,
    height: u32,
    /// One uniform buffer per dispatch: prepare, the levels, the regression, compose.
    uniforms: Vec<wgpu::Buffer>,
    /// Bind groups per dispatch (the ping-pong of `src` and `dst`).
    groups: Vec<wgpu::BindGroup>,
    pipelines: Pipelines,
    image: wgpu::Buffer,
    levels: u32,
}

struct Pipelines {
    prepare: wgpu::ComputePipeline,
    blur_luminance: wgpu::ComputePipeline,
    atrous: wgpu::ComputePipeline,
    regress: wgpu::ComputePipeline,
    compose: wgpu::ComputePipeline,
}

impl Denoiser {
    /// A filter with a guide of up to `levels` à-trous levels over the film sums `film` (as
    /// [`Film::accumulation`]) and the guide sums `guides` and `extra` (as [`Guides::buffer`]
    /// and [`Guides::extra`]) of a `width × height` image.
    pub fn new(
        gpu: &Gpu,
        (width, height): (u32, u32),
        film: &wgpu::Buffer,
        (guides, extra): (&wgpu::Buffer, &wgpu::Buffer),
        levels: u32,
    ) -> Self {
        let device = &gpu.device;
        let pixels = width as u64 * height as u64;
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let ping = [0, 1].map(|_| gpu.zeroed_buffer("denoiser light", 2 * pixels * 16, rw));
        let light = gpu.zeroed_buffer("denoiser unfiltered light", 2 * pixels * 16, rw);
        let image = gpu.zeroed_buffer("denoised image", pixels * 16, rw);
        let lum = gpu.zeroed_buffer("denoiser luminance", pixels * 8, rw);
        let group = filter_group();
        let layout = group.layout(device);
        let dispatches = levels as usize + 3;
        let uniforms: Vec<wgpu::Buffer> = (0..dispatches)
            .map(|_| {
                gpu.zeroed_buffer(
                    "denoiser uniforms",
                    std::mem::size_of::<DenoiseUniforms>() as u64,
                    wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                )
            })
            .collect();
        // Dispatch d writes ping[d % 2] from ping[(d + 1) % 2]: prepare writes ping[0] (and
        // `light`), level i (d = i + 1) reads ping[i % 2], the regression reads the last
        // level's output, compose reads the regression's.
        let groups = (0..dispatches)
            .map(|d| {
                let (src, dst) = (&ping[(d + 1) % 2], &ping[d % 2]);
                let names = ["params", "film", "guides", "extra", "src", "dst", "image", "lum", "light"];
                let buffers = [&uniforms[d], film, guides, extra, src, dst, &image, &lum, &light];
                let resources: Vec<_> = names.into_iter().zip(buffers.map(|b| b.as_entire_binding())).collect();
                group.bind(device, &layout, &resources)
            })
            .collect();
        let module = shader::module(device, "denoiser", &filter_source());
        let pipeline = |entry| compute_pipeline(device, "denoiser", &module, entry, &[&layout], &[]);
        let pipelines = Pipelines {
            prepare: pipeline("prepare"),
            blur_luminance: pipeline("blur_luminance"),
            atrous: pipeline("atrous"),
            regress: pipeline("regress"),
            compose: pipeline("compose"),
        };
        Denoiser { width, height, uniforms, groups, pipelines, image, levels }
    }

    /// The filter's dispatches for `params`, in order ([`Denoiser::encode_rows`]): prepare,
    /// the luminance blur and the à-trous pass of each level, the regression, compose.
    pub fn stages(&self, params: &DenoiseParams) -> usize {
        2 * params.levels.min(self.levels) as usize + 3
    }

    /// Encodes the filter of the sums of `samples` film iterations and `guide_samples` guide
    /// iterations into the denoised image. `params.levels` is capped at the levels the
    /// denoiser was made for.
    pub fn encode(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        samples: (u32, u32),
        pixel_angle: f32,
        params: &DenoiseParams,
    ) {
        for stage in 0..self.stages(params) {
            self.encode_rows(gpu, enc, samples, pixel_angle, params, (stage, 0..self.height));
        }
    }

    /// Encodes the rows `rows` of dispatch `stage` of the filter ([`Denoiser::encode`]'s
    /// arguments). A filter run in steps (a window that gives it a frame's time at a time)
    /// encodes every row of a stage before the next stage, each step in a submission of its
    /// own (the uniforms of a dispatch are written when it is encoded), with the film and
    /// the guides unchanged from the first to the last: the denoised image is then bit for
    /// bit [`Denoiser::encode`]'s (every pixel's value depends on the stage before only).
    pub fn encode_rows(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        (samples, guide_samples): (u32, u32),
        pixel_angle: f32,
        params: &DenoiseParams,
        (stage, rows): (usize, std::ops::Range<u32>),
    ) {
        let levels = params.levels.min(self.levels) as usize;
        let rows = rows.start..rows.end.min(self.height);
        if rows.is_empty() || stage >= self.stages(params) {
            return;
        }
        // Dispatch d runs with group d (src ping[(d + 1) % 2], dst ping[d % 2]) and its own
        // uniforms: prepare (0) writes ping[0], level i (d = i + 1: its luminance blur, then
        // its à-trous pass) reads ping[i % 2], the regression (d = levels + 1) reads the last
        // level's output ping[levels % 2], and compose (d = levels + 2) reads the regression's.
        let p = &self.pipelines;
        let (d, pipeline, step) = match stage {
            0 => (0, &p.prepare, 0),
            s if s <= 2 * levels => {
                let i = (s - 1) / 2;
                (i + 1, if (s - 1) % 2 == 0 { &p.blur_luminance } else { &p.atrous }, 1 << i)
            }
            s if s == 2 * levels + 1 => (levels + 1, &p.regress, 0),
            _ => (levels + 2, &p.compose, 0),
        };
        let uniform = DenoiseUniforms {
            resolution: [self.width, self.height],
            samples,
            guide_samples,
            step,
            sigma_l: params.sigma_l,
            sigma_n: params.sigma_n,
            sigma_z: params.sigma_z,
            pixel_angle,
            radius_direct: params.radius_direct,
            radius_indirect: params.radius_indirect,
            sigma_g: params.sigma_g,
            ridge: params.ridge,
            row0: rows.start,
            row_end: rows.end,
            _pad: 0,
        };
        gpu.queue.write_buffer(&self.uniforms[d], 0, bytemuck::bytes_of(&uniform));
        let mut pass = crate::gpu::profile::compute_pass(enc, gpu.profiler.as_ref(), "denoise");
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, &self.groups[d], &[]);
        pass.dispatch_workgroups(groups(self.width, 8), groups(rows.end - rows.start, 8), 1);
    }

    /// The denoised image's buffer (`width × height` vec4, linear RGB and 1), as the last
    /// submitted [`encode`](Self::encode) left it: the source of the film's
    /// [`ImageResolve`](crate::passes::film::ImageResolve) for the window.
    pub fn image(&self) -> &wgpu::Buffer {
        &self.image
    }

    /// The denoised image read back (after [`encode`](Self::encode) was submitted).
    pub fn read(&self, gpu: &Gpu) -> Result<LinearImage> {
        let bytes = gpu.read_buffer(&self.image, self.image.size())?;
        let texels: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let n = (self.width * self.height) as usize;
        Ok(LinearImage {
            width: self.width,
            height: self.height,
            pixels: texels[..n].iter().map(|t| [t[0], t[1], t[2]]).collect(),
        })
    }

    /// Filters and reads back in one step.
    pub fn apply(
        &self,
        gpu: &Gpu,
        samples: (u32, u32),
        pixel_angle: f32,
        params: &DenoiseParams,
    ) -> Result<LinearImage> {
        let mut enc = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("denoise") });
        self.encode(gpu, &mut enc, samples, pixel_angle, params);
        gpu.queue.submit([enc.finish()]);
        self.read(gpu)
    }
}

/// The bytes per pixel of the denoiser's GPU storage (guides, previous sums and emission,
/// ping-pong, unfiltered light, image, luminance).
pub const BYTES_PER_PIXEL: u64 = GUIDE_SLOTS * 16 + EXTRA_SLOTS * 16 + 2 * 2 * 16 + 2 * 16 + 16 + 8;
/// The largest of the denoiser's buffers per pixel (the guides and the extra sums; the
/// ping-pong buffers 32).
pub const LARGEST_BUFFER_PER_PIXEL: u64 = GUIDE_SLOTS * 16;

pub mod cpu;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schedule_filters_again_when_the_iterations_double_or_a_second_has_passed() {
        let t = 100.0;
        assert!(Schedule::default().due(0, t), "nothing denoised on the window yet");
        let mut s = Schedule::default();
        s.ran(8, t);
        assert!(!s.due(8, t + 10.0 * SCHEDULE_INTERVAL), "no new iterations, no new filter");
        assert!(!s.due(15, t + SCHEDULE_INTERVAL / 2.0));
        assert!(s.due(16, t + SCHEDULE_INTERVAL / 2.0), "doubled");
        assert!(s.due(9, t + SCHEDULE_INTERVAL), "a second later");
        assert!(s.due(3, t), "restarted: fewer iterations");
        s.clear();
        assert!(s.due(8, t), "cleared: filtered at once");
    }

    /// A filter measured at 1.5 s (1280 × 720 on lavapipe) is not run again before 6 s have
    /// passed since it began unless the iterations doubled: between doublings, at most a
    /// quarter of the window's time.
    #[test]
    fn the_schedule_gives_the_filter_at_most_its_share_of_the_time() {
        let (t, cost) = (100.0, 1.5);
        let mut s = Schedule::default();
        s.ran(8, t);
        s.took(cost);
        let wait = cost / SCHEDULE_SHARE;
        assert!(s.due(16, t + SCHEDULE_INTERVAL), "doubled");
        assert!(!s.due(15, t + SCHEDULE_INTERVAL), "a second passed, but within the filter's share");
        assert!(!s.due(9, t + wait - 0.01));
        assert!(s.due(9, t + wait), "a second passed, and the filter's share");
        assert!(s.due(16, t + wait));
        assert!(!s.due(8, t + 10.0 * wait), "no new iterations, no new filter");
        assert!(s.due(3, t), "restarted: filtered at once");
        s.clear();
        assert!(s.due(8, t), "cleared: filtered at once");
        s.ran(8, t);
        assert!(!s.due(9, t + SCHEDULE_INTERVAL), "the cost is kept across a clear");
        // Over a run of iterations (0.5 s each), each filter but a doubling begins at least
        // cost / share after the last began.
        let (mut s, mut now, mut samples, mut starts) = (Schedule::default(), 0.0, 1u32, Vec::new());
        while now < 100.0 {
            if s.due(samples, now) {
                s.ran(samples, now);
                s.took(cost);
                starts.push((now, samples));
                now += cost;
            }
            now += 0.5;
            samples += 1;
        }
        assert!(starts.len() > 10);
        let spaced = |w: &[(f64, u32)]| w[1].1 >= 2 * w[0].1 || w[1].0 - w[0].0 >= wait;
        assert!(starts.windows(2).all(spaced), "filters (seconds, iterations) {starts:?}");
    }
}
