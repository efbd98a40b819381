//! The film: per-pixel sums of the iterations' estimates, kept as separate components
//! (direct incl. emission, indirect, photon-map view) so the
//! display can show any of them without restarting, and the resolve pass that turns the sums
//! into the mean (linear, for EXR) and a display encoding (exposure, clamp, sRGB, for PNG and
//! the window).
//!
//! Accumulation is a plain f32 sum per pixel and component; after N iterations of values of
//! magnitude v, the rounding error of the sum is about N·v·2⁻²⁴ (6·10⁻⁵ relative at 1000
//! iterations), far under the Monte Carlo noise.
//!
//! **The error without a reference.** The renderer numbers its iterations in blocks (a photon
//! pass, with its own photons; else [`BLOCK_ITERATIONS`] consecutive iterations) and the film
//! keeps a second sum, B, of the iterations of odd blocks (`film_half.wgsl`). With
//! A = S − B the even blocks' sum, n_a and n_b their iteration counts, a = A/n_a and b = B/n_b
//! are independent estimates of the image with variances v/n_a and v/n_b (v per iteration),
//! so for the mean S/n, n = n_a + n_b,
//!
//! ```text
//!   E[(a − b)²] = v (1/n_a + 1/n_b)   ⇒   Var(S/n) = v/n ≈ (a − b)² · n_a n_b / n²
//! ```
//!
//! per pixel and channel ((a − b)²/4 for equal halves). Blocks of single iterations would not
//! do: the pixel jitter and the per-pixel light samples and gather directions are Owen-scrambled
//! Sobol' sequences indexed by the iteration, and the even and the odd points of such a
//! sequence lie in complementary strata (the first digit of the radical inverse), so two
//! halves split by parity differ far more than independent estimates (the Cornell box's path
//! tracer at 128², 256 iterations: estimated 19 %, true 4.7 %). Blocks of 16 consecutive
//! iterations keep each half stratified like the whole (estimated 5.2 %; 8: 6.0 %, 4: 7.3 %):
//! the estimate errs on the safe side by about a tenth. [`FilmState::error_estimate`] is the
//! square root of its mean over the pixels and channels divided by the image's mean: the
//! relative RMSE that `rastergi compare` would report against the expectation (the noise; a
//! bias shared by both halves, such as a photon map's blur within a pass, is not in it).
//!
//! Pixels that see light itself — the sky or an emitter, directly or through smooth glass and
//! mirrors, in any iteration (the direct pass and the path tracer count them in the fourth
//! channel of [`FILM_DIRECT`]) — are left out of both the mean and the variance, as the
//! comparisons against references leave emitters out: the sky through a room's windows is
//! bright and almost noise-free, and with it in the mean the estimate of a sky-lit interior
//! was about a fifth of its true error (issue 45).

use crate::error::Result;
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu::{Gpu, compute_pipeline, groups, shader};
use crate::image_io::{DisplayImage, LinearImage};

/// Iterations per block of the error estimate where no photon pass sets the blocks (see the
/// module's notes).
pub const BLOCK_ITERATIONS: u32 = 16;

/// Components accumulated per pixel: component c of pixel p at `c·W·H + p` (`film.wgsl`).
pub const COMPONENTS: u64 = 3;
pub use crate::gpu::consts::{FILM_DIRECT, FILM_INDIRECT, FILM_PHOTON_VIEW};
/// Bytes per pixel of the film's GPU storage (accumulation, its odd half, resolved copies).
pub const BYTES_PER_PIXEL: u64 = 2 * COMPONENTS * 16 + 16 + 4;

/// What the image shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Show {
    /// Emission + direct + indirect light.
    #[default]
    Full,
    /// Emission + direct light only.
    Direct,
    /// Indirect light only.
    Indirect,
    /// ρ/π · E from the photon map at the visible points.
    PhotonMap,
}

impl Show {
    pub(crate) fn code(self) -> u32 {
        match self {
            Show::Full => 0,
            Show::Direct => 1,
            Show::Indirect => 2,
            Show::PhotonMap => 3,
        }
    }
}

gpu_struct! {
    /// The resolve's uniforms (`resolve.wgsl`).
    pub(crate) struct ResolveUniforms as "Resolve" {
        pub(crate) resolution: [u32; 2],
        pub(crate) samples: u32,
        /// 0 full, 1 direct, 2 indirect, 3 photon-map view.
        pub(crate) show: u32,
        /// 2^exposure.
        pub(crate) scale: f32,
        /// Rows from the top whose sums hold one iteration more than `samples` (an iteration
        /// under way in row bands).
        pub(crate) rows_ahead: u32,
        /// The preview blended in ([`PreviewResolve`]): its size (0 × 0: none), complete
        /// iterations, rows ahead, and the weight of its mean in iterations of the film's.
        pub(crate) preview_size: [u32; 2],
        pub(crate) preview_samples: u32,
        pub(crate) preview_rows_ahead: u32,
        pub(crate) preview_weight: f32,
        /// The weight of the re-projected history ([`crate::passes::history`]) in iterations,
        /// before it fades; 0: none.
        pub(crate) history_weight: f32,
    }
}

/// The resolve pass's composed shader.
pub fn resolve_source() -> String {
    shader::compose(&[&ResolveUniforms::wgsl(), include_str!("resolve.wgsl")])
}

pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Iterations accumulated so far.
    pub samples: u32,
    /// Rows from the top that hold one iteration more than `samples`: an iteration under way
    /// in row bands ([`crate::renderer::Renderer::iterate_rows`]); every resolve counts them.
    pub rows_ahead: u32,
    /// `COMPONENTS × width × height` vec4 sums: component c of pixel p at `c·W·H + p`.
    pub accumulation: wgpu::Buffer,
    /// The sums of the iterations of odd blocks, laid out as `accumulation`; while an odd
    /// block is open it holds those of the blocks before it less the sums at its start.
    half: wgpu::Buffer,
    half_open: bool,
    /// Iterations of odd blocks so far.
    half_samples: u32,
    /// The block of the latest iteration.
    block: Option<u32>,
    half_pipelines: [wgpu::ComputePipeline; 2],
    half_bind_group: wgpu::BindGroup,
    linear: wgpu::Buffer,
    display: wgpu::Buffer,
    uniforms: wgpu::Buffer,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The resolve's layout and its `resolve_image` entry ([`ImageResolve`]).
    layout: wgpu::BindGroupLayout,
    image_pipeline: wgpu::ComputePipeline,
    /// Where the last resolve for display was a smaller image's of the same view (a moving
    /// frame's preview, [`Film::show_upscaled`]): its display buffer and size, which the
    /// display pass upscales onto this film's frame; `None` where it was this film's own.
    upscaled: std::sync::Mutex<Option<(wgpu::Buffer, [u32; 2])>>,
}

/// The image the display pass draws for a film ([`Film::display_source`]): a display buffer
/// (packed sRGB, row-major), its size in pixels, and the size of the frame it fills — the
/// film's; where the two differ the buffer is a smaller image of the same view, stretched over
/// the frame as the resolve stretches a preview (bilinear between pixel centres).
#[derive(Clone, Debug)]
pub struct DisplaySource {
    pub buffer: wgpu::Buffer,
    pub size: [u32; 2],
    pub frame: [u32; 2],
}

/// The resolve of a linear image of the film's size that is already a mean (one vec4 per
/// pixel: the denoiser's output) into the film's linear and display buffers, with the film's
/// display encoding (`resolve.wgsl`'s `resolve_image`): what the window draws then shows that
/// image. Made by [`Film::image_resolve`], encoded by [`Film::encode_resolve_image`].
pub struct ImageResolve {
    /// Its own uniforms, so that it and the film's resolve can be encoded in one submission.
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// The resolve's bind group: the film's sums (or an image) and the uniforms read, the linear
/// and display images written.
pub fn resolve_group() -> Group {
    Group::compute(
        "resolve",
        &[
            Slot::uniform::<ResolveUniforms>(0, "params"),
            Slot::read::<[f32; 4]>(1, "film"),
            Slot::write::<[f32; 4]>(2, "linear_out"),
            Slot::write::<u32>(3, "display_out"),
            Slot::read::<[f32; 4]>(4, "preview"),
            Slot::read::<[f32; 4]>(5, "history"),
        ],
    )
}

/// The resolve of a film blended with a smaller preview image of the same view and with the
/// re-projected history of the view before a move ([`Film::blend_resolve`],
/// [`Film::encode_resolve_blend`]).
pub struct BlendResolve {
    uniforms: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
}

/// What to blend into the film's resolve: a preview's film (of the same view, smaller) and the
/// weight of its mean in iterations of the film's; the history's weight.
#[derive(Clone, Copy)]
pub struct Blend<'a> {
    pub resolve: &'a BlendResolve,
    pub preview: Option<(&'a Film, f32)>,
    pub history_weight: f32,
}

/// The resolve's bind group of `uniforms` over `source` (and the sums of `preview` and the
/// re-projected `history`, or `source` again where none is blended) into `linear` and
/// `display`.
fn bind_resolve(
    gpu: &Gpu,
    layout: &wgpu::BindGroupLayout,
    (uniforms, source, preview, history): (&wgpu::Buffer, &wgpu::Buffer, Option<&wgpu::Buffer>, Option<&wgpu::Buffer>),
    (linear, display): (&wgpu::Buffer, &wgpu::Buffer),
) -> wgpu::BindGroup {
    resolve_group().bind(
        &gpu.device,
        layout,
        &[
            ("params", uniforms.as_entire_binding()),
            ("film", source.as_entire_binding()),
            ("linear_out", linear.as_entire_binding()),
            ("display_out", display.as_entire_binding()),
            ("preview", preview.unwrap_or(source).as_entire_binding()),
            ("history", history.unwrap_or(source).as_entire_binding()),
        ],
    )
}

/// The odd-iteration half's bind group: the film read, the half's sums written.
pub fn half_group() -> Group {
    Group::compute("film half", &[Slot::read::<[f32; 4]>(0, "film"), Slot::write::<[f32; 4]>(1, "half_sums")])
}

impl Film {
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Film> {
        gpu.check_image_size(width, height, COMPONENTS * 16)?;
        let pixels = width as u64 * height as u64;
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let accumulation = gpu.zeroed_buffer("film accumulation", COMPONENTS * pixels * 16, rw);
        let linear = gpu.zeroed_buffer("film linear", pixels * 16, rw);
        let display = gpu.zeroed_buffer("film display", pixels * 4, rw);
        let uniforms = gpu.zeroed_buffer(
            "resolve uniforms",
            std::mem::size_of::<ResolveUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let device = &gpu.device;
        let layout = resolve_group().layout(device);
        let bind_group = bind_resolve(gpu, &layout, (&uniforms, &accumulation, None, None), (&linear, &display));
        let module = shader::module(device, "resolve", &resolve_source());
        let pipeline = compute_pipeline(device, "resolve", &module, "main", &[&layout], &[]);
        let image_pipeline = compute_pipeline(device, "resolve image", &module, "resolve_image", &[&layout], &[]);
        let half = gpu.zeroed_buffer("film odd half", COMPONENTS * pixels * 16, rw);
        let (half_layout, half_bind_group) = half_group().layout_and_bind(
            device,
            &[("film", accumulation.as_entire_binding()), ("half_sums", half.as_entire_binding())],
        );
        let half_module = shader::module(device, "film half", include_str!("film_half.wgsl"));
        let half_pipelines = ["open_block", "close_block"]
            .map(|entry| compute_pipeline(device, "film half", &half_module, entry, &[&half_layout], &[]));
        Ok(Film {
            width,
            height,
            samples: 0,
            rows_ahead: 0,
            accumulation,
            half,
            half_open: false,
            half_samples: 0,
            block: None,
            half_pipelines,
            half_bind_group,
            linear,
            display,
            uniforms,
            pipeline,
            bind_group,
            layout,
            image_pipeline,
            upscaled: std::sync::Mutex::new(None),
        })
    }

    /// Called before the passes of each iteration add to the film, with the iteration's block
    /// (see the module's notes): opens the odd half when an odd block starts, closes it when an
    /// even one does, and counts the odd blocks' iterations.
    pub fn begin_iteration(&mut self, gpu: &Gpu, block: u32) {
        let odd = block % 2 == 1;
        if odd != self.half_open {
            let mut enc =
                gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("film half") });
            {
                let mut pass = enc.begin_compute_pass(&Default::default());
                pass.set_pipeline(&self.half_pipelines[if odd { 0 } else { 1 }]);
                pass.set_bind_group(0, &self.half_bind_group, &[]);
                let n = (COMPONENTS * self.width as u64 * self.height as u64).div_ceil(64);
                let x = n.min(65535);
                pass.dispatch_workgroups(x as u32, n.div_ceil(x) as u32, 1);
            }
            gpu.queue.submit([enc.finish()]);
            self.half_open = odd;
        }
        if odd {
            self.half_samples += 1;
        }
        self.block = Some(block);
    }

    /// The blocks begun so far (blocks are numbered from 0): the error estimate means little
    /// before each half holds a few.
    pub fn blocks(&self) -> u32 {
        self.block.map_or(0, |b| b + 1)
    }

    /// The sums and their odd half, read back (for checkpoints, merging and the error
    /// estimate).
    pub fn read_state(&self, gpu: &Gpu) -> Result<FilmState> {
        crate::gpu::block_on(self.read_state_async(gpu))
    }

    /// [`read_state`](Self::read_state) as a future (a web page's error estimate): of the
    /// film as it is now (the copies are submitted at once; the future borrows nothing).
    pub fn read_state_async(&self, gpu: &Gpu) -> impl std::future::Future<Output = Result<FilmState>> + 'static {
        let floats = |bytes: Vec<u8>| bytemuck::cast_slice::<u8, f32>(&bytes).to_vec();
        let n = (COMPONENTS * self.width as u64 * self.height as u64 * 16) as usize;
        let sums = gpu.read_buffer_async(&self.accumulation, self.accumulation.size());
        let half = gpu.read_buffer_async(&self.half, self.half.size());
        let (width, height, samples, half_samples, half_open) =
            (self.width, self.height, self.samples, self.half_samples, self.half_open);
        async move {
            let sums = floats(sums.await?[..n].to_vec());
            let mut half = floats(half.await?[..n].to_vec());
            if half_open {
                for (h, s) in half.iter_mut().zip(&sums) {
                    *h += s;
                }
            }
            Ok(FilmState { width, height, samples, half_samples, sums, half })
        }
    }

    /// Puts `state`'s sums back (a resumed render). The next odd block opens afresh.
    pub fn restore(&mut self, gpu: &Gpu, state: &FilmState) -> Result<()> {
        if (state.width, state.height) != (self.width, self.height) {
            return Err(crate::error::Error::Checkpoint(format!(
                "the checkpoint's image is {}x{}, this render's {}x{}",
                state.width, state.height, self.width, self.height
            )));
        }
        gpu.queue.write_buffer(&self.accumulation, 0, bytemuck::cast_slice(&state.sums));
        gpu.queue.write_buffer(&self.half, 0, bytemuck::cast_slice(&state.half));
        self.samples = state.samples;
        self.half_samples = state.half_samples;
        self.half_open = false;
        Ok(())
    }

    /// What the display pass draws for this film: its own display buffer (the display encoding
    /// written by [`encode_resolve`](Self::encode_resolve): one packed RGBA8 sRGB pixel,
    /// `pack4x8unorm`, per `u32`, row-major, row 0 at the top), or, where the last
    /// resolve for display was a smaller image's ([`Film::show_upscaled`]), that one's.
    pub fn display_source(&self) -> DisplaySource {
        let frame = [self.width, self.height];
        match &*self.upscaled.lock().unwrap_or_else(|e| e.into_inner()) {
            Some((buffer, size)) => DisplaySource { buffer: buffer.clone(), size: *size, frame },
            None => DisplaySource { buffer: self.display.clone(), size: frame, frame },
        }
    }

    /// The display shows `smaller`'s display buffer (a film of the same view at a smaller size,
    /// resolved for display), stretched over this film's frame, until this film's next resolve.
    /// Its linear buffer and display buffer keep what they held.
    pub fn show_upscaled(&self, smaller: &Film) {
        *self.upscaled.lock().unwrap_or_else(|e| e.into_inner()) =
            Some((smaller.display.clone(), [smaller.width, smaller.height]));
    }

    /// This film's own resolve is shown again.
    fn show_own(&self) {
        *self.upscaled.lock().unwrap_or_else(|e| e.into_inner()) = None;
    }

    /// The linear image written by the last resolve ([`Film::read_linear_buffer`] reads it):
    /// one vec4 (rgb, 1) per pixel, row-major.
    pub fn linear_buffer(&self) -> &wgpu::Buffer {
        &self.linear
    }

    /// Clears the sums (camera moved, scene changed): submitted before any later work.
    pub fn clear(&mut self, gpu: &Gpu) {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.accumulation, 0, None);
        enc.clear_buffer(&self.half, 0, None);
        gpu.queue.submit([enc.finish()]);
        self.samples = 0;
        self.rows_ahead = 0;
        self.half_open = false;
        self.half_samples = 0;
        self.block = None;
    }

    /// Encodes the resolve of the current mean into the linear and display buffers.
    pub fn encode_resolve(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, show: Show, exposure: f32) {
        let resolve = (&self.pipeline, &self.bind_group, &self.uniforms);
        let u = self.resolve_uniforms(self.samples, show, exposure);
        self.dispatch_resolve(gpu, enc, "resolve", resolve, &u);
    }

    /// The resolve into this film's buffers of its mean blended with `preview`'s and with the
    /// re-projected `history` (where given).
    pub fn blend_resolve(&self, gpu: &Gpu, preview: Option<&Film>, history: Option<&wgpu::Buffer>) -> BlendResolve {
        let uniforms = gpu.zeroed_buffer(
            "resolve preview uniforms",
            std::mem::size_of::<ResolveUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let sources = (&uniforms, &self.accumulation, preview.map(|p| &p.accumulation), history);
        let bind_group = bind_resolve(gpu, &self.layout, sources, (&self.linear, &self.display));
        BlendResolve { uniforms, bind_group }
    }

    /// Encodes the resolve of the film's mean blended with the history and a preview: at each
    /// pixel, with n = S + [y < rows ahead] the film's iterations there,
    ///
    /// ```text
    /// n · mean_film + h' · history + w' · mean_preview
    /// ────────────────────────────────────────────────,
    ///                 n + h' + w'
    ///
    /// h' = h / (1 + n/h)   where the history is valid here (0 elsewhere),
    /// w' = w / (1 + n + h')²,
    /// ```
    ///
    /// `history` the re-projected mean of the view before the move ([`crate::passes::history`],
    /// weighed as h of the film's iterations, fading as 1/n once the film has as many),
    /// `mean_preview` the preview's mean bilinearly interpolated at the pixel's centre (from
    /// its pixels that hold an iteration), w its weight (0 where no tap holds one): the
    /// preview where nothing better is known, then fading fast, since its blur is a bias that
    /// must not outlast the film's noise. The film's sums are not touched: the blend is what
    /// the window shows, and it converges to the film's mean.
    pub fn encode_resolve_blend(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        (show, exposure): (Show, f32),
        blend: Blend,
    ) {
        let resolve = (&self.pipeline, &blend.resolve.bind_group, &blend.resolve.uniforms);
        let mut u = self.resolve_uniforms(self.samples, show, exposure);
        if let Some((film, weight)) = blend.preview {
            u.preview_size = [film.width, film.height];
            u.preview_samples = film.samples;
            u.preview_rows_ahead = film.rows_ahead;
            u.preview_weight = weight;
        }
        u.history_weight = blend.history_weight;
        self.dispatch_resolve(gpu, enc, "resolve blend", resolve, &u);
    }

    /// The resolve's uniforms of the film's sums as they stand, without a preview.
    fn resolve_uniforms(&self, samples: u32, show: Show, exposure: f32) -> ResolveUniforms {
        ResolveUniforms {
            resolution: [self.width, self.height],
            samples,
            show: show.code(),
            scale: exposure.exp2(),
            rows_ahead: self.rows_ahead,
            preview_size: [0, 0],
            preview_samples: 0,
            preview_rows_ahead: 0,
            preview_weight: 0.0,
            history_weight: 0.0,
        }
    }

    /// One resolve dispatch over the image: `pipeline` with `bind_group`, whose `uniforms` get
    /// (samples, show, exposure).
    fn dispatch_resolve(
        &self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        label: &'static str,
        (pipeline, bind_group, uniforms): (&wgpu::ComputePipeline, &wgpu::BindGroup, &wgpu::Buffer),
        u: &ResolveUniforms,
    ) {
        self.show_own();
        gpu.queue.write_buffer(uniforms, 0, bytemuck::bytes_of(u));
        let mut pass = crate::gpu::profile::compute_pass(enc, gpu.profiler.as_ref(), label);
        pass.set_pipeline(pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.dispatch_workgroups(groups(self.width, 8), groups(self.height, 8), 1);
    }

    /// The resolve of `image` (a `width × height` buffer of vec4 linear values, read as
    /// `array<vec4f>`) into this film's linear and display buffers.
    pub fn image_resolve(&self, gpu: &Gpu, image: &wgpu::Buffer) -> ImageResolve {
        let uniforms = gpu.zeroed_buffer(
            "resolve image uniforms",
            std::mem::size_of::<ResolveUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let bind_group = bind_resolve(gpu, &self.layout, (&uniforms, image, None, None), (&self.linear, &self.display));
        ImageResolve { uniforms, bind_group }
    }

    /// Encodes the resolve of `image`'s source (as it stands when the encoder runs) at
    /// `exposure` into the linear and display buffers, in place of the film's mean.
    pub fn encode_resolve_image(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, image: &ImageResolve, exposure: f32) {
        let resolve = (&self.image_pipeline, &image.bind_group, &image.uniforms);
        let u = ResolveUniforms { rows_ahead: 0, ..self.resolve_uniforms(1, Show::Full, exposure) };
        self.dispatch_resolve(gpu, enc, "resolve image", resolve, &u);
    }

    /// The display buffer as the last submitted resolve left it.
    pub fn read_display_buffer(&self, gpu: &Gpu) -> Result<DisplayImage> {
        crate::gpu::block_on(self.read_display_buffer_async(gpu))
    }

    /// [`read_display_buffer`](Self::read_display_buffer) as a future, of the buffer as it is
    /// now (after the work submitted so far).
    pub fn read_display_buffer_async(
        &self,
        gpu: &Gpu,
    ) -> impl std::future::Future<Output = Result<DisplayImage>> + 'static {
        let bytes = gpu.read_buffer_async(&self.display, self.display.size());
        let (width, height) = (self.width, self.height);
        async move {
            let n = (width * height) as usize * 4;
            Ok(DisplayImage { width, height, rgba: bytes.await?[..n].to_vec() })
        }
    }

    /// The mean radiance of `show`, linear RGB.
    pub fn read_linear(&self, gpu: &Gpu, show: Show) -> Result<LinearImage> {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.encode_resolve(gpu, &mut enc, show, 0.0);
        gpu.queue.submit([enc.finish()]);
        self.read_linear_buffer(gpu)
    }

    /// The linear image as the last submitted resolve left it (what a window shows, before
    /// its exposure and display encoding: a preview's blend included).
    pub fn read_linear_buffer(&self, gpu: &Gpu) -> Result<LinearImage> {
        self.read_linear_copy(gpu, &self.linear)
    }

    /// The same of `buffer`, a copy of the linear buffer ([`Film::linear_buffer`]) made
    /// on the GPU: the image a resolve left before a later one overwrote it.
    pub fn read_linear_copy(&self, gpu: &Gpu, buffer: &wgpu::Buffer) -> Result<LinearImage> {
        let bytes = gpu.read_buffer(buffer, self.linear.size())?;
        let texels: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        let n = (self.width * self.height) as usize;
        Ok(LinearImage {
            width: self.width,
            height: self.height,
            pixels: texels[..n].iter().map(|t| [t[0], t[1], t[2]]).collect(),
        })
    }

    /// The display encoding of `show`: 2^exposure · mean, clamped to [0,1], sRGB, 8 bits.
    pub fn read_display(&self, gpu: &Gpu, show: Show, exposure: f32) -> Result<DisplayImage> {
        crate::gpu::block_on(self.read_display_async(gpu, show, exposure))
    }

    /// [`read_display`](Self::read_display) as a future (a web page's "save PNG"), of the film
    /// as it is now.
    pub fn read_display_async(
        &self,
        gpu: &Gpu,
        show: Show,
        exposure: f32,
    ) -> impl std::future::Future<Output = Result<DisplayImage>> + 'static {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.encode_resolve(gpu, &mut enc, show, exposure);
        gpu.queue.submit([enc.finish()]);
        self.read_display_buffer_async(gpu)
    }
}

/// A film's sums read back: what a checkpoint holds of the image, and what merging adds up.
#[derive(Clone, Debug, PartialEq)]
pub struct FilmState {
    pub width: u32,
    pub height: u32,
    /// Iterations in `sums`, and of them in `half` (odd blocks).
    pub samples: u32,
    pub half_samples: u32,
    /// `COMPONENTS × width × height × 4` floats, as [`Film::accumulation`].
    pub sums: Vec<f32>,
    /// The odd blocks' sums, the same layout.
    pub half: Vec<f32>,
}

impl FilmState {
    fn pixels(&self) -> usize {
        (self.width * self.height) as usize
    }

    /// The sum of `show` at pixel `p` in `data` (the resolve pass's composition).
    fn show_sum(&self, data: &[f32], show: Show, p: usize) -> [f32; 3] {
        let n = self.pixels();
        let at = |c: u32| {
            let i = 4 * (c as usize * n + p);
            [data[i], data[i + 1], data[i + 2]]
        };
        match show {
            Show::Full => {
                let (d, i) = (at(FILM_DIRECT), at(FILM_INDIRECT));
                [d[0] + i[0], d[1] + i[1], d[2] + i[2]]
            }
            Show::Direct => at(FILM_DIRECT),
            Show::Indirect => at(FILM_INDIRECT),
            Show::PhotonMap => at(FILM_PHOTON_VIEW),
        }
    }

    /// The mean of `show` (what [`Film::read_linear`] gives), computed here.
    pub fn image(&self, show: Show) -> LinearImage {
        let n = self.samples.max(1) as f32;
        let pixels = (0..self.pixels()).map(|p| self.show_sum(&self.sums, show, p).map(|v| v / n)).collect();
        LinearImage { width: self.width, height: self.height, pixels }
    }

    /// Whether any iteration's sample of pixel `p` saw light itself — the sky or an emitter's
    /// front face, directly or through smooth glass and mirrors (the fourth channel of
    /// [`FILM_DIRECT`], `film_add_seen` in film.wgsl; zero in checkpoints written before it).
    pub fn sees_light(&self, p: usize) -> bool {
        self.sums[4 * (FILM_DIRECT as usize * self.pixels() + p) + 3] > 0.0
    }

    /// The estimated relative RMSE of the full image's noise (see the module's notes), from
    /// the two halves, over the pixels that never saw light itself ([`FilmState::sees_light`]:
    /// as `rastergi compare` leaves emitters out, so that the sky through a window, bright and
    /// noise-free, neither fills the mean nor hides the room's noise; all pixels where every
    /// one did); `None` until both halves hold iterations or where the image is black.
    pub fn error_estimate(&self) -> Option<f64> {
        let (var, mean, count) = self.variance_of_mean(Show::Full)?;
        (mean > 0.0).then(|| (var / count).sqrt() / (mean / count))
    }

    /// The direct pass's estimates of one light sample's variance (summed over the channels
    /// and the iterations that drew two or more: the fourth channel of [`FILM_INDIRECT`],
    /// `film_add_light_variance` in film.wgsl), summed over the pixels that
    /// [`variance_of_mean`](Self::variance_of_mean) takes.
    pub fn light_sample_variance(&self) -> f64 {
        self.counted_pixels().map(|p| self.sums[4 * (FILM_INDIRECT as usize * self.pixels() + p) + 3] as f64).sum()
    }

    /// The pixels the error estimates take: those that never saw light itself, or all where
    /// every one did.
    fn counted_pixels(&self) -> impl Iterator<Item = usize> + '_ {
        let all_light = (0..self.pixels()).all(|p| self.sees_light(p));
        (0..self.pixels()).filter(move |&p| all_light || !self.sees_light(p))
    }

    /// The variance of `show`'s mean estimated from the two halves (see the module's notes),
    /// summed over the channels of the pixels that never saw light itself (all pixels where
    /// every one did), with the sum of the mean over them and their count (channels):
    /// (Σ var, Σ mean, count); `None` until both halves hold iterations.
    pub fn variance_of_mean(&self, show: Show) -> Option<(f64, f64, f64)> {
        let n = self.samples as f64;
        let nb = self.half_samples as f64;
        let na = n - nb;
        if na < 1.0 || nb < 1.0 {
            return None;
        }
        let (mut var, mut mean, mut count) = (0.0f64, 0.0f64, 0.0f64);
        for p in self.counted_pixels() {
            count += 3.0;
            let s = self.show_sum(&self.sums, show, p);
            let b = self.show_sum(&self.half, show, p);
            for c in 0..3 {
                let d = (s[c] as f64 - b[c] as f64) / na - b[c] as f64 / nb;
                var += d * d * na * nb / (n * n);
                mean += s[c] as f64 / n;
            }
        }
        Some((var, mean, count))
    }

    /// Adds `other`'s iterations (another seed's render of the same image): the sums and the
    /// halves add, so the merged mean weighs each by its iteration count.
    pub fn add(&mut self, other: &FilmState) {
        for (a, b) in self.sums.iter_mut().zip(&other.sums) {
            *a += b;
        }
        for (a, b) in self.half.iter_mut().zip(&other.half) {
            *a += b;
        }
        self.samples += other.samples;
        self.half_samples += other.half_samples;
    }
}
