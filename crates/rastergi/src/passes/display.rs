//! Display: draws the film's resolved display image onto a window (or any colour target),
//! with a text overlay, in one full-screen triangle (`display.wgsl`).
//!
//! The film's display buffer holds packed RGBA8 values that `resolve.wgsl` has already
//! exposed, clamped and sRGB-encoded. A target with a plain `*Unorm` format stores those
//! bytes as they are. A target with an `*Srgb` format (or a float format, which holds
//! linear values) encodes whatever the shader writes, so the shader decodes first and the
//! hardware's encode restores the film's bytes — either way the window shows exactly the
//! bytes of the PNG screenshot. [`DisplayTarget`] prefers a plain format when the surface
//! offers one.
//!
//! The overlay is a grid of ASCII characters drawn with the public-domain 8×8 bitmap font
//! of the `font8x8` crate over a darkened box in the top-left corner.

use crate::error::{Error, Result};
use crate::gpu::binding::{Group, Slot};
use crate::gpu::structs::{GpuStruct, gpu_struct};
use crate::gpu::{Gpu, shader};
use crate::passes::film::Film;

/// Re-exported so front ends can hand over a window without a direct wgpu dependency.
pub use wgpu::SurfaceTarget;

/// Most overlay columns and rows drawn; longer lines and further lines are cut.
pub const MAX_TEXT_COLS: usize = 96;
pub const MAX_TEXT_ROWS: usize = 32;

/// The display pass's shader (it reads no scene: its uniforms and its file).
pub(crate) fn source() -> String {
    [DisplayUniforms::wgsl().as_str(), include_str!("display.wgsl")].join("\n")
}

gpu_struct! {
    /// The display pass's uniforms (`display.wgsl`).
    pub(crate) struct DisplayUniforms as "Display" {
        /// Film size; 0×0 when there is no image yet (the background shows).
        pub(crate) image_size: [u32; 2],
        pub(crate) target_size: [u32; 2],
        /// 1 when the target stores linear values (an *Srgb or float format): decode first,
        /// so the hardware's encode restores the film's bytes.
        pub(crate) decode_srgb: u32,
        /// Overlay text grid: columns, rows, pixels per font texel.
        pub(crate) text_cols: u32,
        pub(crate) text_rows: u32,
        pub(crate) text_scale: u32,
        /// The size of the image in the display buffer: the film's, or a smaller image of the
        /// same view stretched over the film's frame ([`crate::passes::film::DisplaySource`]).
        pub(crate) source_size: [u32; 2],
    }
}

/// Whether a target of `format` needs the shader to decode sRGB: the hardware encodes on
/// write to `*Srgb` formats, and float formats hold linear values.
pub fn needs_decode(format: wgpu::TextureFormat) -> bool {
    use wgpu::TextureFormat as F;
    format.is_srgb() || matches!(format, F::Rgba16Float | F::Rgba32Float | F::Rg11b10Ufloat)
}

/// Pixels per font texel for a target `height` pixels tall: 1 up to 719 rows, 2 up to
/// 1079, then 3.
pub fn text_scale(height: u32) -> u32 {
    (height / 360).clamp(1, 3)
}

/// The overlay lines laid out in a `cols × rows` grid of ASCII codes (non-ASCII characters
/// become '?', short lines are padded with spaces), four characters per `u32`.
fn layout_text(lines: &[String]) -> (u32, u32, Vec<u32>) {
    let rows = lines.len().min(MAX_TEXT_ROWS);
    let cols = lines[..rows].iter().map(|l| l.chars().count()).max().unwrap_or(0).min(MAX_TEXT_COLS);
    let mut bytes = vec![b' '; (cols * rows).next_multiple_of(4).max(4)];
    for (r, line) in lines[..rows].iter().enumerate() {
        for (c, ch) in line.chars().take(cols).enumerate() {
            bytes[r * cols + c] = if ch.is_ascii() && !ch.is_ascii_control() { ch as u8 } else { b'?' };
        }
    }
    let words = bytes.chunks(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
    (cols as u32, rows as u32, words)
}

/// The glyphs of characters 0..127, two `u32` of four rows each (see `display.wgsl`).
fn font_words() -> Vec<u32> {
    font8x8::legacy::BASIC_LEGACY
        .iter()
        .flat_map(|g| [u32::from_le_bytes([g[0], g[1], g[2], g[3]]), u32::from_le_bytes([g[4], g[5], g[6], g[7]])])
        .collect()
}

/// The display pass for one target format.
pub struct DisplayPass {
    format: wgpu::TextureFormat,
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    uniforms: wgpu::Buffer,
    font: wgpu::Buffer,
    text: wgpu::Buffer,
    /// Bound in place of a film before there is one.
    no_image: wgpu::Buffer,
    /// The bind group of the image buffer drawn last (rebuilt when the film changes).
    bound: Option<(wgpu::Buffer, wgpu::BindGroup)>,
}

/// The display's bind group: the uniforms, the film's display image, the font and the
/// overlay's text, all read by the fragment shader.
pub fn group() -> Group {
    Group::new(
        "display",
        wgpu::ShaderStages::FRAGMENT,
        &[
            Slot::uniform::<DisplayUniforms>(0, "params"),
            Slot::read::<u32>(1, "image"),
            Slot::read::<u32>(2, "font"),
            Slot::read::<u32>(3, "text"),
        ],
    )
}

impl DisplayPass {
    pub fn new(gpu: &Gpu, format: wgpu::TextureFormat) -> DisplayPass {
        let device = &gpu.device;
        let layout = group().layout(device);
        let module = shader::module(device, "display", &source());
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("display"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("display"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        let uniforms = gpu.zeroed_buffer(
            "display uniforms",
            std::mem::size_of::<DisplayUniforms>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let font = gpu.storage_buffer("display font", bytemuck::cast_slice(&font_words()), wgpu::BufferUsages::empty());
        let text = gpu.zeroed_buffer(
            "display text",
            (MAX_TEXT_COLS * MAX_TEXT_ROWS) as u64,
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let no_image = gpu.zeroed_buffer("display no image", 16, wgpu::BufferUsages::STORAGE);
        DisplayPass { format, pipeline, layout, uniforms, font, text, no_image, bound: None }
    }

    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Encodes drawing `film`'s display image (as last resolved, [`Film::display_source`]: its
    /// own, or a smaller image of the same view upscaled bilinearly; the background where there
    /// is no film) scaled to fit a `target_size` target, and the `overlay` lines on top.
    /// Reads: that display buffer. Writes: `target`, whole.
    pub fn encode(
        &mut self,
        gpu: &Gpu,
        enc: &mut wgpu::CommandEncoder,
        target: &wgpu::TextureView,
        target_size: (u32, u32),
        film: Option<&Film>,
        overlay: &[String],
    ) {
        let (cols, rows, text) = layout_text(overlay);
        gpu.queue.write_buffer(&self.text, 0, bytemuck::cast_slice(&text));
        let source = film.map(Film::display_source);
        let image_size = source.as_ref().map_or([0, 0], |s| s.frame);
        let u = DisplayUniforms {
            image_size,
            source_size: source.as_ref().map_or([0, 0], |s| s.size),
            target_size: [target_size.0, target_size.1],
            decode_srgb: needs_decode(self.format) as u32,
            text_cols: cols,
            text_rows: rows,
            text_scale: text_scale(target_size.1),
        };
        gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let image = source.map_or_else(|| self.no_image.clone(), |s| s.buffer);
        if self.bound.as_ref().is_none_or(|(b, _)| *b != image) {
            let bind_group = group().bind(
                &gpu.device,
                &self.layout,
                &[
                    ("params", self.uniforms.as_entire_binding()),
                    ("image", image.as_entire_binding()),
                    ("font", self.font.as_entire_binding()),
                    ("text", self.text.as_entire_binding()),
                ],
            );
            self.bound = Some((image, bind_group));
        }
        let (_, bind_group) = self.bound.as_ref().expect("bound just above");
        let ops = wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store };
        let mut pass = crate::gpu::profile::render_pass(enc, None, "display", (target, ops), None);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// What became of a frame handed to [`DisplayTarget::present`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presented {
    Shown,
    /// The window is occluded or the swapchain timed out: nothing was shown this time.
    Skipped,
}

/// Where the display pass draws: a window's surface (or a web page's canvas), configured for
/// the device, or a texture of a window's size standing in for one ([`DisplayTarget::offscreen`]:
/// `rastergi bench frames` measures the viewer's frame loop with it, the same code as a window's
/// but for acquiring and presenting the image).
pub struct DisplayTarget {
    target: Target,
    pass: DisplayPass,
}

enum Target {
    Surface {
        surface: wgpu::Surface<'static>,
        config: wgpu::SurfaceConfiguration,
    },
    /// Nothing is presented, so no vsync.
    Texture {
        _texture: wgpu::Texture,
        view: wgpu::TextureView,
        size: (u32, u32),
    },
}

impl DisplayTarget {
    /// Creates a surface for `window` on `display` (the window system's connection, which
    /// OpenGL needs at instance creation) and opens the best device that can present to it
    /// (a discrete GPU first, as [`Gpu::new`] does), with the surface configured at
    /// `width × height` (at least 1×1). Blocks until the device is open: native only.
    #[cfg(not(target_arch = "wasm32"))]
    pub fn open<D>(
        options: &crate::gpu::GpuOptions,
        display: D,
        window: impl Into<SurfaceTarget<'static>>,
        width: u32,
        height: u32,
    ) -> Result<(Gpu, DisplayTarget)>
    where
        D: wgpu::rwh::HasDisplayHandle + std::fmt::Debug + Send + Sync + 'static,
    {
        let mut desc = wgpu::InstanceDescriptor::new_with_display_handle(Box::new(display));
        desc.backends = options.backends();
        let instance = wgpu::Instance::new(desc);
        let surface = instance
            .create_surface(window)
            .map_err(|e| Error::Gpu(format!("cannot create a surface for the window: {e}")))?;
        let gpu = Gpu::open(&instance, options, Some(&surface))?;
        let window = DisplayTarget::new(&gpu, surface, width, height)?;
        Ok((gpu, window))
    }

    /// Configures `surface` (of a window, or a web page's canvas: `SurfaceTarget::Canvas`)
    /// for `gpu`, opened for it ([`Gpu::open_async`] with the surface), at `width × height`
    /// (at least 1×1): a plain 8-bit format where the surface offers one (the shader encodes
    /// sRGB itself, [`needs_decode`]).
    pub fn new(gpu: &Gpu, surface: wgpu::Surface<'static>, width: u32, height: u32) -> Result<DisplayTarget> {
        let caps = surface.get_capabilities(&gpu.adapter);
        use wgpu::TextureFormat as F;
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| matches!(f, F::Bgra8Unorm | F::Rgba8Unorm))
            .or_else(|| caps.formats.first().copied())
            .ok_or_else(|| Error::Gpu(format!("the window surface offers no format on {}", gpu.info.name)))?;
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: width.max(1),
            height: height.max(1),
            desired_maximum_frame_latency: 2,
            present_mode: wgpu::PresentMode::AutoVsync,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        surface.configure(&gpu.device, &config);
        let pass = DisplayPass::new(gpu, format);
        log::info!("window surface format {format:?} (shader sRGB decode: {})", needs_decode(format));
        Ok(DisplayTarget { target: Target::Surface { surface, config }, pass })
    }

    /// A `width × height` RGBA8 texture standing in for a window (a plain format, as
    /// [`new`](Self::new) prefers for a surface).
    pub fn offscreen(gpu: &Gpu, width: u32, height: u32) -> Result<DisplayTarget> {
        gpu.check_image_size(width, height, 4)?;
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let texture = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("offscreen display target"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        let target = Target::Texture { _texture: texture, view, size: (width, height) };
        Ok(DisplayTarget { target, pass: DisplayPass::new(gpu, format) })
    }

    /// The format of the images drawn into (a user interface drawn over them must target it).
    pub fn format(&self) -> wgpu::TextureFormat {
        self.pass.format()
    }

    pub fn size(&self) -> (u32, u32) {
        match &self.target {
            Target::Surface { config, .. } => (config.width, config.height),
            Target::Texture { size, .. } => *size,
        }
    }

    /// Reconfigures the swapchain for a new window size; zero sizes (minimised) are ignored,
    /// and so is any size for an offscreen target (it keeps its own).
    pub fn resize(&mut self, gpu: &Gpu, width: u32, height: u32) {
        if width == 0 || height == 0 || (width, height) == self.size() {
            return;
        }
        if let Target::Surface { surface, config } = &mut self.target {
            config.width = width;
            config.height = height;
            surface.configure(&gpu.device, config);
        }
    }

    /// Submits `enc` (work the frame depends on, such as the film's resolve) followed by
    /// drawing `film` and `overlay` onto the next image, and presents it.
    pub fn present(
        &mut self,
        gpu: &Gpu,
        enc: wgpu::CommandEncoder,
        film: Option<&Film>,
        overlay: &[String],
    ) -> Result<Presented> {
        self.present_with(gpu, enc, film, overlay, |_, _, _| {})
    }

    /// [`present`](Self::present), with `draw_over` encoding more drawing (a user interface)
    /// over the image before it is shown: it gets the encoder, the image's view (whose
    /// contents it must load, not clear) and its size. It is not called when no image could
    /// be acquired.
    pub fn present_with(
        &mut self,
        gpu: &Gpu,
        mut enc: wgpu::CommandEncoder,
        film: Option<&Film>,
        overlay: &[String],
        draw_over: impl FnOnce(&mut wgpu::CommandEncoder, &wgpu::TextureView, (u32, u32)),
    ) -> Result<Presented> {
        let size = self.size();
        let (surface, config) = match &mut self.target {
            Target::Surface { surface, config } => (surface, config),
            Target::Texture { view, .. } => {
                self.pass.encode(gpu, &mut enc, view, size, film, overlay);
                draw_over(&mut enc, view, size);
                gpu.queue.submit([enc.finish()]);
                return Ok(Presented::Shown);
            }
        };
        let Some((texture, suboptimal)) = acquire(gpu, surface, config)? else {
            gpu.queue.submit([enc.finish()]);
            return Ok(Presented::Skipped);
        };
        let view = texture.texture.create_view(&Default::default());
        self.pass.encode(gpu, &mut enc, &view, size, film, overlay);
        draw_over(&mut enc, &view, size);
        gpu.queue.submit([enc.finish()]);
        gpu.queue.present(texture);
        if suboptimal {
            surface.configure(&gpu.device, config);
        }
        Ok(Presented::Shown)
    }
}

/// The surface's next image and whether it is suboptimal (show it, reconfigure after); `None`
/// where the window is occluded or the swapchain timed out. Outdated: reconfigure and try once
/// more.
fn acquire(
    gpu: &Gpu,
    surface: &wgpu::Surface<'static>,
    config: &wgpu::SurfaceConfiguration,
) -> Result<Option<(wgpu::SurfaceTexture, bool)>> {
    for _ in 0..2 {
        return match surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) => Ok(Some((t, false))),
            wgpu::CurrentSurfaceTexture::Suboptimal(t) => Ok(Some((t, true))),
            wgpu::CurrentSurfaceTexture::Outdated => {
                surface.configure(&gpu.device, config);
                continue;
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => Ok(None),
            wgpu::CurrentSurfaceTexture::Lost => Err(Error::Gpu("the window surface was lost".into())),
            wgpu::CurrentSurfaceTexture::Validation => {
                Err(Error::Gpu("acquiring the window's next image failed validation".into()))
            }
        };
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_laid_out_four_characters_per_word_and_padded() {
        let (cols, rows, words) = layout_text(&["ab".into(), "cdeé".into()]);
        assert_eq!((cols, rows), (4, 2));
        assert_eq!(words, vec![u32::from_le_bytes(*b"ab  "), u32::from_le_bytes(*b"cde?")]);
        let (cols, rows, words) = layout_text(&[]);
        assert_eq!((cols, rows, words.len()), (0, 0, 1));
        let long = vec!["x".repeat(500); 100];
        let (cols, rows, words) = layout_text(&long);
        assert_eq!((cols as usize, rows as usize), (MAX_TEXT_COLS, MAX_TEXT_ROWS));
        assert!(words.len() * 4 <= MAX_TEXT_COLS * MAX_TEXT_ROWS);
    }

    #[test]
    fn font_rows_put_the_leftmost_pixel_in_bit_0() {
        let font = font_words();
        assert_eq!(font.len(), 256);
        let row = |c: usize, y: usize| (font[2 * c + y / 4] >> (8 * (y % 4))) & 0xff;
        // The stem of 'L' is on the left and its foot is the widest row: with bit 0 the
        // leftmost pixel, the stem's rows are lit in the low bits only.
        let l = b'L' as usize;
        assert!((1..4).all(|y| row(l, y) & 0x0f != 0 && row(l, y) & 0xf0 == 0), "stem on the left");
        assert!((0..6).all(|y| row(l, 6).count_ones() > row(l, y).count_ones()), "foot widest");
        assert_eq!(row(b' ' as usize, 3), 0);
        assert!(needs_decode(wgpu::TextureFormat::Bgra8UnormSrgb) && !needs_decode(wgpu::TextureFormat::Bgra8Unorm));
    }
}
