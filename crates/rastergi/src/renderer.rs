//! The progressive renderer: owns the passes and runs one iteration at a time.
//! [`Renderer::iterate`] is the pipeline, top to bottom.

use glam::Vec2;

use crate::direct::DirectPass;
use crate::error::Result;
use crate::film::{Film, Show};
use crate::frame::{FrameBinding, FrameUniforms, pixel_jitter, view_projection};
use crate::gbuffer::GBufferPass;
use crate::gpu::Gpu;
use crate::gpu_scene::{GpuScene, PreparedScene};
use crate::image_io::{DisplayImage, LinearImage};
use crate::photon_view::PhotonViewPass;
use crate::photons::PhotonSettings;
use crate::photons::gpu::GpuPhotonMap;
use crate::scene::{Camera, Scene};

/// Settings of a render.
#[derive(Clone, Debug)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    pub seed: u32,
    /// Light samples per pixel per iteration in the direct pass.
    pub light_samples: u32,
    /// Photons traced into the photon map (0: no photon map, no indirect light).
    pub photons: u32,
    /// Photon grid cells along the scene's longest axis.
    pub grid_resolution: u32,
    /// Also accumulate the photon-map view (`Show::PhotonMap`).
    pub show_photon_map: bool,
}

impl Default for RenderSettings {
    fn default() -> Self {
        let p = PhotonSettings::default();
        Self {
            width: 256,
            height: 256,
            seed: 0,
            light_samples: 1,
            photons: p.count,
            grid_resolution: p.grid_resolution,
            show_photon_map: false,
        }
    }
}

pub struct Renderer {
    gpu: Gpu,
    settings: RenderSettings,
    camera: Camera,
    scene: GpuScene,
    frame: FrameBinding,
    gbuffer: GBufferPass,
    direct: DirectPass,
    photon_map: Option<GpuPhotonMap>,
    photon_view: Option<PhotonViewPass>,
    film: Film,
}

impl Renderer {
    pub fn new(gpu: &Gpu, scene: &Scene, settings: RenderSettings) -> Result<Renderer> {
        scene.validate()?;
        let (width, height) = (settings.width, settings.height);
        gpu.check_image_size(width, height, crate::film::COMPONENTS * 16)?;
        let prepared = PreparedScene::new(scene);
        let film = Film::new(gpu, width, height)?;
        let gpu_scene = GpuScene::new(gpu, &prepared);
        let frame = FrameBinding::new(gpu);
        let gbuffer = GBufferPass::new(gpu, &gpu_scene, &frame, width, height);
        let direct = DirectPass::new(gpu, &gpu_scene, &frame, &gbuffer, &film);
        let photon_settings =
            PhotonSettings { count: settings.photons, seed: settings.seed, grid_resolution: settings.grid_resolution };
        let photon_map = (settings.photons > 0)
            .then(|| GpuPhotonMap::build(gpu, &gpu_scene, &prepared, &photon_settings))
            .transpose()?;
        let photon_view = match &photon_map {
            Some(map) if settings.show_photon_map => {
                Some(PhotonViewPass::new(gpu, &gpu_scene, &frame, &gbuffer, &film, map))
            }
            _ => None,
        };
        Ok(Renderer {
            gpu: gpu.clone(),
            settings,
            camera: scene.camera,
            scene: gpu_scene,
            frame,
            gbuffer,
            direct,
            photon_map,
            photon_view,
            film,
        })
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    pub fn camera(&self) -> Camera {
        self.camera
    }

    /// Iterations accumulated since the last reset.
    pub fn samples(&self) -> u32 {
        self.film.samples
    }

    /// Moves the camera; the image starts converging again.
    pub fn set_camera(&mut self, camera: Camera) -> Result<()> {
        camera.validate()?;
        self.camera = camera;
        self.reset();
        Ok(())
    }

    /// Discards the accumulated iterations.
    pub fn reset(&mut self) {
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        self.film.clear(&mut enc);
        self.gpu.queue.submit([enc.finish()]);
    }

    fn frame_uniforms(&self, iteration: u32) -> FrameUniforms {
        let (w, h) = (self.settings.width, self.settings.height);
        let b = self.scene.bounds;
        let near = 1e-4 * b.extent().length().max(1e-3);
        let jitter: Vec2 = pixel_jitter(iteration, self.settings.seed);
        FrameUniforms {
            view_proj: view_projection(&self.camera, w, h, near, jitter).to_cols_array_2d(),
            eye: self.camera.eye.into(),
            iteration,
            resolution: [w, h],
            seed: self.settings.seed,
            light_samples: self.settings.light_samples.max(1),
            ray_epsilon: self.scene.ray_epsilon,
            _pad: [0; 3],
        }
    }

    /// One progressive iteration: one new estimate per pixel, added to the film.
    pub fn iterate(&mut self) {
        let (w, h) = (self.settings.width, self.settings.height);
        let iteration = self.film.samples;
        self.frame.write(&self.gpu, &self.frame_uniforms(iteration));
        let mut enc =
            self.gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("iteration") });
        // 1. Eye pass: the visible point of each pixel, at this iteration's jitter.
        self.gbuffer.encode(&mut enc, &self.scene, &self.frame);
        // 2. Emission + direct light with soft shadows → film (direct component).
        self.direct.encode(&mut enc, &self.scene, &self.frame, w, h);
        // 3. Indirect light plugs in here: the final gather reads the photon map (built once
        //    per scene) and adds one gather sample per visible point → film (indirect).
        // Debug view: the photon map's radiance at the visible points → film (photon view).
        if let (Some(view), Some(map)) = (&self.photon_view, &self.photon_map) {
            view.encode(&mut enc, &self.scene, &self.frame, map, w, h);
        }
        self.gpu.queue.submit([enc.finish()]);
        self.film.samples += 1;
    }

    /// Blocks until the submitted iterations have finished on the GPU.
    pub fn wait(&self) -> Result<()> {
        self.gpu.wait()
    }

    /// The photon map, if the render has one.
    pub fn photon_map(&self) -> Option<&GpuPhotonMap> {
        self.photon_map.as_ref()
    }

    pub fn read_linear(&self, show: Show) -> Result<LinearImage> {
        self.film.read_linear(&self.gpu, show)
    }

    pub fn read_display(&self, show: Show, exposure: f32) -> Result<DisplayImage> {
        self.film.read_display(&self.gpu, show, exposure)
    }

    /// Raw G-buffer texels `(triangle + 1, b1 bits, b2 bits, 0)`, row by row (for tests and tools).
    pub fn read_gbuffer(&self) -> Result<Vec<[u32; 4]>> {
        let (w, h) = (self.settings.width, self.settings.height);
        let row = (w * 16).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = self.gpu.zeroed_buffer(
            "gbuffer readback",
            (row * h) as u64,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let mut enc = self.gpu.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            self.gbuffer.texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: Some(h) },
            },
            wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
        );
        self.gpu.queue.submit([enc.finish()]);
        let bytes = self.gpu.read_buffer(&buffer, buffer.size())?;
        let mut out = Vec::with_capacity((w * h) as usize);
        for y in 0..h as usize {
            let r: &[[u32; 4]] = bytemuck::cast_slice(&bytes[y * row as usize..y * row as usize + w as usize * 16]);
            out.extend_from_slice(r);
        }
        Ok(out)
    }
}
