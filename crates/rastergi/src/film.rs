//! The film: per-pixel sums of the iterations' estimates, kept as separate components
//! (direct incl. emission, indirect, photon-map view) so the
//! display can show any of them without restarting, and the resolve pass that turns the sums
//! into the mean (linear, for EXR) and a display encoding (exposure, clamp, sRGB, for PNG and
//! the window).
//!
//! Accumulation is a plain f32 sum per pixel and component; after N iterations of values of
//! magnitude v, the rounding error of the sum is about N·v·2⁻²⁴ (6·10⁻⁵ relative at 1000
//! iterations), far under the Monte Carlo noise.

use bytemuck::{Pod, Zeroable};

use crate::error::Result;
use crate::gpu::{Gpu, buffer_bind_group, compute_pipeline, groups, storage_entry, uniform_entry};
use crate::image_io::{DisplayImage, LinearImage};
use crate::shader;

/// Components accumulated per pixel: component c of pixel p at `c·W·H + p` (`film.wgsl`).
pub const COMPONENTS: u64 = 3;
pub use crate::consts::{FILM_DIRECT, FILM_INDIRECT, FILM_PHOTON_VIEW};
/// Bytes per pixel of the film's GPU storage (accumulation + resolved copies).
pub const BYTES_PER_PIXEL: u64 = COMPONENTS * 16 + 16 + 4;

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
    fn code(self) -> u32 {
        match self {
            Show::Full => 0,
            Show::Direct => 1,
            Show::Indirect => 2,
            Show::PhotonMap => 3,
        }
    }
}

/// `Resolve` in `resolve.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub(crate) struct ResolveUniforms {
    pub(crate) resolution: [u32; 2],
    pub(crate) samples: u32,
    pub(crate) show: u32,
    /// 2^exposure.
    pub(crate) scale: f32,
    pub(crate) _pad: [u32; 3],
}

/// The resolve pass's composed shader.
pub fn resolve_source() -> String {
    shader::compose(&[include_str!("resolve.wgsl")])
}

pub struct Film {
    pub width: u32,
    pub height: u32,
    /// Iterations accumulated so far.
    pub samples: u32,
    /// `COMPONENTS × width × height` vec4 sums: component c of pixel p at `c·W·H + p`.
    pub accumulation: wgpu::Buffer,
    linear: wgpu::Buffer,
    display: wgpu::Buffer,
    uniforms: wgpu::Buffer,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
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
        let c = wgpu::ShaderStages::COMPUTE;
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("resolve"),
            entries: &[
                uniform_entry::<ResolveUniforms>(0, c),
                storage_entry::<[f32; 4]>(1, c, true),
                storage_entry::<[f32; 4]>(2, c, false),
                storage_entry::<u32>(3, c, false),
            ],
        });
        let bind_group = buffer_bind_group(device, "resolve", &layout, &[&uniforms, &accumulation, &linear, &display]);
        let module = shader::module(device, "resolve", &resolve_source());
        let pipeline = compute_pipeline(device, "resolve", &module, "main", &[&layout]);
        Ok(Film { width, height, samples: 0, accumulation, linear, display, uniforms, pipeline, bind_group })
    }

    /// The display encoding written by [`encode_resolve`](Self::encode_resolve): one packed
    /// RGBA8 sRGB pixel (`pack4x8unorm`) per `u32`, row-major, row 0 at the top.
    pub fn display_buffer(&self) -> &wgpu::Buffer {
        &self.display
    }

    /// Clears the sums (camera moved, scene changed): submitted before any later work.
    pub fn clear(&mut self, gpu: &Gpu) {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        enc.clear_buffer(&self.accumulation, 0, None);
        gpu.queue.submit([enc.finish()]);
        self.samples = 0;
    }

    /// Encodes the resolve of the current mean into the linear and display buffers.
    pub fn encode_resolve(&self, gpu: &Gpu, enc: &mut wgpu::CommandEncoder, show: Show, exposure: f32) {
        let u = ResolveUniforms {
            resolution: [self.width, self.height],
            samples: self.samples,
            show: show.code(),
            scale: exposure.exp2(),
            _pad: [0; 3],
        };
        gpu.queue.write_buffer(&self.uniforms, 0, bytemuck::bytes_of(&u));
        let mut pass = crate::profile::compute_pass(enc, gpu.profiler.as_ref(), "resolve");
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(groups(self.width, 8), groups(self.height, 8), 1);
    }

    /// The mean radiance of `show`, linear RGB.
    pub fn read_linear(&self, gpu: &Gpu, show: Show) -> Result<LinearImage> {
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.encode_resolve(gpu, &mut enc, show, 0.0);
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.read_buffer(&self.linear, self.linear.size())?;
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
        let mut enc = gpu.device.create_command_encoder(&Default::default());
        self.encode_resolve(gpu, &mut enc, show, exposure);
        gpu.queue.submit([enc.finish()]);
        let bytes = gpu.read_buffer(&self.display, self.display.size())?;
        let n = (self.width * self.height) as usize * 4;
        Ok(DisplayImage { width: self.width, height: self.height, rgba: bytes[..n].to_vec() })
    }
}
