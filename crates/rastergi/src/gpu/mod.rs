//! The GPU context: adapter choice and device (here), buffers and read-backs (`buffers.rs`), the
//! declared bind groups every pass binds ([`binding`]) and the pipeline helpers it builds with
//! (`pipeline.rs`, re-exported here).

use std::fmt::Write as _;

pub mod accel;
pub mod binding;
mod buffers;
pub mod compiled;
pub mod consts;
#[cfg(test)]
mod layout_test;
pub mod limits;
mod pipeline;
pub mod profile;
pub(crate) mod shader;
pub mod structs;

pub use buffers::{READ_BACK_BLOCKS, block_on};
pub use pipeline::*;

use crate::error::{Error, Result};
use crate::gpu::profile::Profiler;

/// What the user asked for when choosing a GPU.
#[derive(Clone, Debug, Default)]
pub struct GpuOptions {
    /// Backends to consider; `None` means `WGPU_BACKEND` if set, else Vulkan/Metal/DX12.
    pub backends: Option<wgpu::Backends>,
    /// Time every pass with GPU timestamps ([`crate::gpu::profile`]), where the adapter can.
    pub profile: bool,
    /// Open the device with at most this many storage buffers per shader stage (the
    /// adapter's own limit where it is lower): [`WEB_STORAGE_BUFFERS`] gives a native device a
    /// browser's limit, so that tests check what a web page can run.
    pub max_storage_buffers: Option<u32>,
    /// Which traversal the passes' rays take ([`crate::gpu::accel`]); `None` means `RASTERGI_RAYS`
    /// if set, else the compute BVH (so that a library caller or a test gets the hardware path
    /// only where it asks: `--rays` of the front ends defaults to `auto`).
    pub rays: Option<Rays>,
    /// Count the rays every pass traces (`--count-rays`): each scene uploaded on this device
    /// then binds a counter that its shaders' `trace` adds to ([`crate::gpu_scene`]), read by
    /// [`crate::progressive::Progressive::rays_traced`]. Off by default: the counter is one
    /// atomic add per ray.
    pub count_rays: bool,
}

/// The most storage buffers per shader stage that browsers' WebGPU grants (Chrome's adapters
/// and SwiftShader report 10; the WebGPU default is 8). WebGPU counts every storage binding of
/// a pipeline layout's bind groups that is visible to the stage, used by the shader or not.
pub const WEB_STORAGE_BUFFERS: u32 = 10;

/// Re-exported so front ends need no direct wgpu dependency.
pub use wgpu::Backends;

/// Parses a backend name as accepted by `--backend` (and `WGPU_BACKEND`).
pub fn parse_backend(name: &str) -> Result<wgpu::Backends, String> {
    match name.to_ascii_lowercase().as_str() {
        "vulkan" | "vk" => Ok(wgpu::Backends::VULKAN),
        "metal" | "mtl" => Ok(wgpu::Backends::METAL),
        "dx12" | "d3d12" => Ok(wgpu::Backends::DX12),
        "gl" | "gles" | "opengl" => Ok(wgpu::Backends::GL),
        "primary" => Ok(wgpu::Backends::PRIMARY),
        "all" => Ok(wgpu::Backends::all()),
        other => Err(format!("unknown backend '{other}' (expected vulkan, metal, dx12, gl, primary or all)")),
    }
}

/// An opened device. Cloning is cheap (wgpu handles are reference counted).
#[derive(Clone, Debug)]
pub struct Gpu {
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub info: wgpu::AdapterInfo,
    /// Pass timings, when profiling was asked for and the adapter supports timestamps.
    pub profiler: Option<Profiler>,
    /// The ray path asked for ([`GpuOptions::rays`] resolved); the device has
    /// `EXPERIMENTAL_RAY_QUERY` where this is not `Compute` and the adapter offers it.
    pub rays: Rays,
    /// Rays are counted ([`GpuOptions::count_rays`]).
    pub count_rays: bool,
    /// The first error the device reported outside a call that returns one (a lost device, a
    /// GPU timeout, an allocation that failed): [`Gpu::wait`] and every readback return it.
    fault: std::sync::Arc<std::sync::Mutex<Fault>>,
    /// Releases the device's compiled objects ([`crate::gpu::compiled`]) with the last clone.
    _compiled: std::sync::Arc<crate::gpu::compiled::Release>,
}

/// What the device reported outside the calls that return errors.
#[derive(Debug, Default)]
struct Fault {
    /// The device was lost: why.
    lost: Option<String>,
    /// The first uncaptured error.
    error: Option<String>,
}

fn device_rank(t: wgpu::DeviceType) -> u32 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    }
}

impl GpuOptions {
    /// The backends to consider: as asked, else `WGPU_BACKEND`, else Vulkan/Metal/DX12.
    pub fn backends(&self) -> wgpu::Backends {
        self.backends.or_else(wgpu::Backends::from_env).unwrap_or(wgpu::Backends::PRIMARY)
    }

    /// The ray path asked for: as set, else `RASTERGI_RAYS`, else the compute BVH.
    pub fn rays(&self) -> Rays {
        self.rays.or_else(Rays::from_env).unwrap_or(Rays::Compute)
    }
}

impl Gpu {
    /// Opens the best adapter: a discrete GPU if there is one, then integrated, virtual, CPU.
    /// Blocks until the device is open (native only; [`Gpu::new_async`] everywhere).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn new(options: &GpuOptions) -> Result<Gpu> {
        pollster::block_on(Gpu::new_async(options))
    }

    /// [`Gpu::new`] as a future: what a web page awaits (the browser offers one adapter).
    pub async fn new_async(options: &GpuOptions) -> Result<Gpu> {
        let mut desc = wgpu::InstanceDescriptor::new_without_display_handle();
        desc.backends = options.backends();
        Gpu::open_async(&wgpu::Instance::new(desc), options, None).await
    }

    /// Opens the best adapter of `instance` (ranked as in [`Gpu::new`]) among those that can
    /// present to `surface`, if one is given: the one device opener of headless and window use.
    /// Blocks until the device is open (native only; [`Gpu::open_async`] everywhere).
    #[cfg(not(target_arch = "wasm32"))]
    pub fn open(instance: &wgpu::Instance, options: &GpuOptions, surface: Option<&wgpu::Surface>) -> Result<Gpu> {
        pollster::block_on(Gpu::open_async(instance, options, surface))
    }

    /// [`Gpu::open`] as a future.
    pub async fn open_async(
        instance: &wgpu::Instance,
        options: &GpuOptions,
        surface: Option<&wgpu::Surface<'_>>,
    ) -> Result<Gpu> {
        let backends = options.backends();
        let mut adapters = instance.enumerate_adapters(backends).await;
        if let Some(surface) = surface {
            adapters.retain(|a| a.is_surface_supported(surface));
        }
        adapters.sort_by_key(|a| device_rank(a.get_info().device_type));
        let adapter = adapters.into_iter().next().ok_or_else(|| {
            let what = if surface.is_some() { " that can present to the window" } else { "" };
            Error::NoAdapter(format!("{what} for backends {backends:?}"))
        })?;
        let info = adapter.get_info();
        let mut limits = adapter.limits();
        if let Some(n) = options.max_storage_buffers {
            limits.max_storage_buffers_per_shader_stage = limits.max_storage_buffers_per_shader_stage.min(n);
        }
        let timestamps = wgpu::Features::TIMESTAMP_QUERY;
        let mut required_features =
            if options.profile { adapter.features() & timestamps } else { wgpu::Features::empty() };
        let rays = options.rays();
        let ray_queries = rays != Rays::Compute && adapter.features().contains(FEATURE);
        if rays == Rays::Hardware && !ray_queries {
            return Err(not_offered(&info.name));
        }
        if ray_queries {
            required_features |= FEATURE;
        }
        if options.profile && !required_features.contains(timestamps) {
            log::warn!("{} has no timestamp queries: --profile reports wall-clock time only", info.name);
        }
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("rastergi device"),
                required_features,
                required_limits: limits,
                // SAFETY: the one experimental feature asked for is EXPERIMENTAL_RAY_QUERY, used
                // as wgpu documents it (acceleration structures built before the passes that
                // bind them, `accel::build`).
                experimental_features: if ray_queries {
                    unsafe { wgpu::ExperimentalFeatures::enabled() }
                } else {
                    wgpu::ExperimentalFeatures::disabled()
                },
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|e| Error::Device(e.to_string()))?;
        log::info!("using {} ({:?}, {:?})", info.name, info.backend, info.device_type);
        let profiler = if options.profile { Profiler::new(&device, &queue) } else { None };
        let fault = std::sync::Arc::new(std::sync::Mutex::new(Fault::default()));
        {
            let fault = fault.clone();
            device.on_uncaptured_error(std::sync::Arc::new(move |e: wgpu::Error| {
                let message: String = e.to_string().lines().map(str::trim).collect::<Vec<_>>().join(" ");
                fault.lock().unwrap_or_else(|e| e.into_inner()).error.get_or_insert(message);
            }));
        }
        {
            let fault = fault.clone();
            device.set_device_lost_callback(move |reason, message| {
                let why = if message.is_empty() { format!("{reason:?}") } else { format!("{reason:?}: {message}") };
                fault.lock().unwrap_or_else(|e| e.into_inner()).lost.get_or_insert(why);
            });
        }
        let _compiled = std::sync::Arc::new(crate::gpu::compiled::register(&device));
        Ok(Gpu { adapter, device, queue, info, profiler, rays, count_rays: options.count_rays, fault, _compiled })
    }

    /// Whether the adapter offers hardware ray queries (wgpu's `EXPERIMENTAL_RAY_QUERY`:
    /// `VK_KHR_ray_query` with acceleration structures on Vulkan, DXR 1.1 on DX12, Metal's ray
    /// intersection), in words.
    pub fn ray_query_support(&self) -> &'static str {
        if self.adapter.features().contains(wgpu::Features::EXPERIMENTAL_RAY_QUERY) {
            "offered"
        } else {
            "not offered by this adapter"
        }
    }

    /// Which ray path scenes get on this device and why, in words (`rastergi info`); the
    /// choice for one scene is `GpuScene::rays` (auto's probe runs per scene).
    pub fn ray_path_description(&self) -> String {
        use Rays;
        let has = device_has_ray_queries(&self.device);
        match self.rays {
            Rays::Compute => "compute (asked for: --rays compute)".to_owned(),
            Rays::Hardware => "hardware (asked for: --rays hardware)".to_owned(),
            Rays::Auto if has => {
                "auto: hardware, unless a start-up probe on the scene measures it slower than compute".to_owned()
            }
            Rays::Auto => "auto: compute (the adapter offers no ray queries)".to_owned(),
        }
    }

    /// A multi-line description of the adapter and the limits that matter to rastergi.
    pub fn describe(&self) -> String {
        let i = &self.info;
        let l = self.device.limits();
        let mut s = String::new();
        let _ = writeln!(s, "adapter:  {}", i.name);
        let _ = writeln!(s, "backend:  {:?}", i.backend);
        let _ = writeln!(s, "type:     {:?}", i.device_type);
        let _ = writeln!(s, "driver:   {} {}", i.driver, i.driver_info);
        let _ = writeln!(s, "ray queries: {}", self.ray_query_support());
        let _ = writeln!(s, "rays:     {}", self.ray_path_description());
        let _ = writeln!(s, "vendor:   {:#06x}  device: {:#06x}", i.vendor, i.device);
        let _ = writeln!(s, "max texture 2D:            {}", l.max_texture_dimension_2d);
        let _ = writeln!(s, "max texture 3D:            {}", l.max_texture_dimension_3d);
        let _ = writeln!(s, "max storage buffer binding: {} MiB", l.max_storage_buffer_binding_size >> 20);
        let _ = writeln!(s, "max buffer size:           {} MiB", l.max_buffer_size >> 20);
        let _ = writeln!(s, "max compute workgroup:     {} invocations", l.max_compute_invocations_per_workgroup);
        let _ = write!(s, "max storage buffers/stage: {}", l.max_storage_buffers_per_shader_stage);
        s
    }

    /// Checks that a `width × height` image with `bytes_per_pixel` of storage fits this device.
    pub fn check_image_size(&self, width: u32, height: u32, bytes_per_pixel: u64) -> Result<()> {
        let l = self.device.limits();
        if width == 0 || height == 0 {
            return Err(Error::Limits(format!(
                "image size {width}x{height} is empty; give a width and height of at least 1"
            )));
        }
        let max = l.max_texture_dimension_2d;
        if width > max || height > max {
            return Err(Error::Limits(format!(
                "image size {width}x{height} exceeds this GPU's limit of {max} pixels per side; choose a smaller --width/--height"
            )));
        }
        let bytes = width as u64 * height as u64 * bytes_per_pixel;
        let max_binding = l.max_storage_buffer_binding_size.min(l.max_buffer_size);
        if bytes > max_binding {
            return Err(Error::Limits(format!(
                "image size {width}x{height} needs a {} MiB buffer but this GPU allows {} MiB; choose a smaller --width/--height",
                bytes >> 20,
                max_binding >> 20
            )));
        }
        Ok(())
    }

    /// Blocks until all submitted work has finished. In a browser, where nothing can block,
    /// it returns at once (the browser orders the work; read-backs are awaited).
    pub fn wait(&self) -> Result<()> {
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(e.to_string()))?;
        self.check()
    }

    /// The error the device reported since it was opened, if any (see `fault`): its loss
    /// first (whatever failed after it failed for that reason).
    pub fn check(&self) -> Result<()> {
        let f = self.fault.lock().unwrap_or_else(|e| e.into_inner());
        if let Some(why) = &f.lost {
            return Err(Error::Gpu(format!(
                "the GPU device was lost ({why}); a driver reset or a GPU timeout ends a render: resume it from its last checkpoint"
            )));
        }
        match &f.error {
            Some(message) => Err(Error::Gpu(message.clone())),
            None => Ok(()),
        }
    }
}

/// What the user asked for (`--rays`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Rays {
    /// Hardware ray queries where the adapter offers them, unless a start-up probe on the
    /// scene measures them slower than the compute BVH on this device.
    #[default]
    Auto,
    /// Hardware ray queries; an error where the adapter lacks them.
    Hardware,
    /// The compute-shader BVH (every device).
    Compute,
}

impl Rays {
    pub fn name(self) -> &'static str {
        match self {
            Rays::Auto => "auto",
            Rays::Hardware => "hardware",
            Rays::Compute => "compute",
        }
    }

    /// `RASTERGI_RAYS`, if set to one of the names: the default of [`crate::gpu::GpuOptions`]
    /// where no front end chose (so the test suite can run on either path).
    pub fn from_env() -> Option<Rays> {
        std::env::var("RASTERGI_RAYS").ok().and_then(|v| parse_rays(&v).ok())
    }
}

/// Parses `auto`, `hardware` or `compute` (`--rays`).
pub fn parse_rays(name: &str) -> std::result::Result<Rays, String> {
    match name.to_ascii_lowercase().as_str() {
        "auto" => Ok(Rays::Auto),
        "hardware" | "hw" => Ok(Rays::Hardware),
        "compute" => Ok(Rays::Compute),
        other => Err(format!("unknown ray path '{other}' (expected auto, hardware or compute)")),
    }
}

/// The device feature hardware ray queries need.
pub const FEATURE: wgpu::Features = wgpu::Features::EXPERIMENTAL_RAY_QUERY;

/// Whether `device` was opened with ray queries.
pub fn device_has_ray_queries(device: &wgpu::Device) -> bool {
    device.features().contains(FEATURE)
}

/// What `--rays hardware` says where the device lacks ray queries: one line.
pub fn not_offered(adapter: &str) -> Error {
    Error::Device(format!(
        "--rays hardware: {adapter} offers no hardware ray queries (wgpu's EXPERIMENTAL_RAY_QUERY: VK_KHR_ray_query and \
         VK_KHR_acceleration_structure on Vulkan, DXR 1.1 on DX12; never in a browser); use --rays compute or auto"
    ))
}
