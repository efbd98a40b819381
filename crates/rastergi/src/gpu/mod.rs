//! The GPU context: adapter choice, device, and small helpers every pass uses.

use std::fmt::Write as _;

pub mod accel;
pub mod compiled;
pub mod consts;
#[cfg(test)]
mod layout_test;
pub mod limits;
pub mod profile;
pub(crate) mod shader;

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
        Ok(Gpu { adapter, device, queue, info, profiler, rays, fault, _compiled })
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

    /// A storage buffer initialised with `data`.
    pub fn storage_buffer(&self, label: &str, data: &[u8], extra: wgpu::BufferUsages) -> wgpu::Buffer {
        // Zero-sized bindings are invalid: keep at least 16 bytes.
        let size = (data.len() as u64).max(16).next_multiple_of(4);
        let buffer = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | extra,
            mapped_at_creation: true,
        });
        // Not mappable only on a lost device: the buffer is invalid then, and the next wait
        // reports the loss (Gpu::check).
        if let Ok(mut view) = buffer.get_mapped_range_mut(..) {
            view.slice(..data.len()).copy_from_slice(data);
        }
        buffer.unmap();
        buffer
    }

    /// A zero-initialised buffer.
    pub fn zeroed_buffer(&self, label: &str, size: u64, usage: wgpu::BufferUsages) -> wgpu::Buffer {
        self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: size.max(16).next_multiple_of(4),
            usage,
            mapped_at_creation: false,
        })
    }

    /// Copies `size` bytes from the start of `buffer` (which needs COPY_SRC) back to the CPU.
    /// Blocks until the GPU has finished: natively only; a web page awaits
    /// [`read_buffer_async`](Self::read_buffer_async) (see [`block_on`]).
    pub fn read_buffer(&self, buffer: &wgpu::Buffer, size: u64) -> Result<Vec<u8>> {
        block_on(self.read_buffer_async(buffer, size))
    }

    /// [`read_buffer`](Self::read_buffer) as a future. The copy is submitted at once (the
    /// future holds no borrow: it reads the buffer as it is now). Natively the future waits for
    /// the GPU in `device.poll`; in a browser `map_async` answers only once control has
    /// returned to the event loop, so the future is pending until then.
    pub fn read_buffer_async(
        &self,
        buffer: &wgpu::Buffer,
        size: u64,
    ) -> impl std::future::Future<Output = Result<Vec<u8>>> + 'static {
        let staging = self.zeroed_buffer("readback", size, wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST);
        let mut enc = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("readback") });
        enc.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([enc.finish()]);
        let (tx, rx) = futures_channel::oneshot::channel();
        staging.map_async(wgpu::MapMode::Read, ..size, move |r| {
            let _ = tx.send(r);
        });
        let gpu = self.clone();
        async move {
            // A no-op on WebGPU, where the browser maps the buffer on its own.
            gpu.device.poll(wgpu::PollType::wait_indefinitely()).map_err(|e| Error::Gpu(e.to_string()))?;
            let mapped = rx.await;
            gpu.check()?;
            mapped
                .map_err(|_| Error::Gpu("the GPU dropped a read-back before it finished".into()))?
                .map_err(|e| Error::Gpu(format!("mapping a readback buffer failed: {e}")))?;
            let data = staging.get_mapped_range(..size).map_err(|e| Error::Gpu(e.to_string()))?.to_vec();
            staging.unmap();
            Ok(data)
        }
    }

    /// Copies every texel of mip level 0 of `texture` (which needs COPY_SRC) back to the CPU:
    /// `texel_bytes` per texel, rows and layers tightly packed (the copy's row padding dropped).
    pub fn read_texture(&self, texture: &wgpu::Texture, texel_bytes: u32) -> Result<Vec<u8>> {
        let size = texture.size();
        let (w, rows) = (size.width, size.height * size.depth_or_array_layers);
        let tight = (w * texel_bytes) as usize;
        let row = (w * texel_bytes).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = self.zeroed_buffer(
            "texture readback",
            row as u64 * rows as u64,
            wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let mut enc = self.device.create_command_encoder(&Default::default());
        enc.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(row),
                    rows_per_image: Some(size.height),
                },
            },
            size,
        );
        self.queue.submit([enc.finish()]);
        let bytes = self.read_buffer(&buffer, buffer.size())?;
        Ok(bytes.chunks(row as usize).take(rows as usize).flat_map(|r| &r[..tight]).copied().collect())
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

/// Runs a read-back's future to its end. Natively it blocks (the future waits for the GPU in
/// `device.poll`). A browser cannot block: there the answer arrives only after control returns
/// to its event loop, so a future that is not ready at once is an error that names the
/// asynchronous twin to await instead.
pub fn block_on<T>(future: impl std::future::Future<Output = Result<T>>) -> Result<T> {
    #[cfg(not(target_arch = "wasm32"))]
    {
        pollster::block_on(future)
    }
    #[cfg(target_arch = "wasm32")]
    {
        let mut future = std::pin::pin!(future);
        let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
        match future.as_mut().poll(&mut cx) {
            std::task::Poll::Ready(r) => r,
            std::task::Poll::Pending => Err(Error::Gpu(
                "a read-back from the GPU cannot block in a web page; await its asynchronous twin (read_buffer_async, read_state_async, read_display_async)".into(),
            )),
        }
    }
}

impl Gpu {
    /// Runs `module`'s entry point `main` (`@workgroup_size(64)`, bind group 0 = `resources` on
    /// a layout of `entries`) over `n` invocations, submits and waits for nothing: the GPU side
    /// of a CPU twin's test, read back with [`Gpu::read_buffer`].
    pub fn run_once(
        &self,
        label: &str,
        module: &wgpu::ShaderModule,
        entries: &[wgpu::BindGroupLayoutEntry],
        resources: &[wgpu::BindingResource],
        n: u32,
    ) {
        let layout = bind_group_layout(&self.device, label, entries);
        let group = bind_group(&self.device, label, &layout, resources);
        let pipeline = compute_pipeline(&self.device, label, module, "main", &[&layout], &[]);
        let mut enc = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        {
            let mut pass =
                enc.begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some(label), timestamp_writes: None });
            pass.set_pipeline(&pipeline);
            pass.set_bind_group(0, &group, &[]);
            pass.dispatch_workgroups(groups(n, 64), 1, 1);
        }
        self.queue.submit([enc.finish()]);
    }
}

/// Bind-group-layout entry for a storage buffer holding `T`s (an array of them or one): wgpu
/// refuses a bound buffer smaller than one `T`, and a shader whose type there is larger.
pub fn storage_entry<T>(binding: u32, visibility: wgpu::ShaderStages, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: min_size::<T>(),
        },
        count: None,
    }
}

/// The size of `T` as a binding's minimum size.
fn min_size<T>() -> Option<std::num::NonZeroU64> {
    std::num::NonZeroU64::new(std::mem::size_of::<T>() as u64)
}

/// Bind-group-layout entry for a texture of `sample_type` and `dimension`, not multisampled.
fn texture_entry(
    binding: u32,
    visibility: wgpu::ShaderStages,
    sample_type: wgpu::TextureSampleType,
    view_dimension: wgpu::TextureViewDimension,
) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Texture { sample_type, view_dimension, multisampled: false },
        count: None,
    }
}

/// Bind-group-layout entry for a 2D unsigned-integer texture (the G-buffer, ray-view layers).
pub fn uint_texture_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    texture_entry(binding, visibility, wgpu::TextureSampleType::Uint, wgpu::TextureViewDimension::D2)
}

/// Bind-group-layout entry for a 2D float texture read texel by texel (`textureLoad`; the GGX
/// albedo tables).
pub fn float_table_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    let sample_type = wgpu::TextureSampleType::Float { filterable: false };
    texture_entry(binding, visibility, sample_type, wgpu::TextureViewDimension::D2)
}

/// Runs `pipeline` once per pixel of a `width × height` image (8×8 workgroups) with bind
/// groups 0, 1, … set to `bind_groups`.
pub fn dispatch_pixels(
    pass: &mut wgpu::ComputePass,
    pipeline: &wgpu::ComputePipeline,
    bind_groups: &[&wgpu::BindGroup],
    width: u32,
    height: u32,
) {
    pass.set_pipeline(pipeline);
    for (i, g) in bind_groups.iter().enumerate() {
        pass.set_bind_group(i as u32, *g, &[]);
    }
    pass.dispatch_workgroups(groups(width, 8), groups(height, 8), 1);
}

/// Bind-group-layout entry for a uniform buffer holding a `T`: wgpu refuses a bound buffer
/// smaller than `T` and a shader whose struct there is larger.
pub fn uniform_entry<T>(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: min_size::<T>(),
        },
        count: None,
    }
}

/// A bind group layout of `entries` (each names its binding): the device's one of them
/// ([`crate::gpu::compiled`]).
pub fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    crate::gpu::compiled::bind_group_layout(device, label, entries)
}

/// Bind-group-layout entry for an unfiltered float 2D texture read with `textureLoad` (the
/// scene's texture atlas, `textures.rs`).
pub fn atlas_texture_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    let sample_type = wgpu::TextureSampleType::Float { filterable: false };
    texture_entry(binding, visibility, sample_type, wgpu::TextureViewDimension::D2)
}

/// Bind group whose entries are `resources`, at bindings 0, 1, 2, … (the order of the
/// layout's entries and of the shader's `@binding`s).
pub fn bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    resources: &[wgpu::BindingResource],
) -> wgpu::BindGroup {
    let entries: Vec<wgpu::BindGroupEntry> = resources
        .iter()
        .enumerate()
        .map(|(i, r)| wgpu::BindGroupEntry { binding: i as u32, resource: r.clone() })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}

/// Bind group whose entries are `buffers` bound whole, at bindings 0, 1, 2, …
pub fn buffer_bind_group(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    let resources: Vec<wgpu::BindingResource> = buffers.iter().map(|b| b.as_entire_binding()).collect();
    bind_group(device, label, layout, &resources)
}

/// A pipeline layout of bind groups 0, 1, … = `layouts`.
pub fn pipeline_layout(device: &wgpu::Device, label: &str, layouts: &[&wgpu::BindGroupLayout]) -> wgpu::PipelineLayout {
    let layouts: Vec<Option<&wgpu::BindGroupLayout>> = layouts.iter().map(|&l| Some(l)).collect();
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &layouts,
        immediate_size: 0,
    })
}

/// A render pipeline that draws every triangle of the scene by vertex pulling (`vs_main` of
/// `shader.0`, no vertex buffers, no culling) with bind groups `shader.1`, fragment stage `fs`
/// into one colour `target`; with `depth`, a depth test of that format that keeps the larger
/// depth (the eye's reversed Z; the ray view's back-to-front peel).
pub fn scene_raster_pipeline(
    device: &wgpu::Device,
    label: &str,
    shader: (&wgpu::ShaderModule, &[&wgpu::BindGroupLayout]),
    fs: &str,
    target: wgpu::ColorTargetState,
    depth: Option<wgpu::TextureFormat>,
) -> wgpu::RenderPipeline {
    let (module, layouts) = shader;
    crate::gpu::compiled::raster_pipeline(device, shader, fs, &target, depth, || {
        let layout = pipeline_layout(device, label, layouts);
        let start = web_time::Instant::now();
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            vertex: wgpu::VertexState {
                module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
            depth_stencil: depth.map(|format| wgpu::DepthStencilState {
                format,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module,
                entry_point: Some(fs),
                compilation_options: Default::default(),
                targets: &[Some(target.clone())],
            }),
            multiview_mask: None,
            cache: None,
        });
        log::debug!("pipeline {label} ({fs}) created in {:.2} s", start.elapsed().as_secs_f64());
        pipeline
    })
}

/// A compute pipeline for `module`'s entry point `entry`, with bind groups `layouts` and values
/// for the shader's pipeline-overridable constants (`override` declarations; none: `&[]`), e.g.
/// [`crate::gpu_scene::GpuScene::pipeline_constants`]: the device's one of them, compiled on
/// first use ([`crate::gpu::compiled`]).
pub fn compute_pipeline(
    device: &wgpu::Device,
    label: &str,
    module: &wgpu::ShaderModule,
    entry: &str,
    layouts: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
) -> wgpu::ComputePipeline {
    crate::gpu::compiled::compute_pipeline(device, module, entry, layouts, constants, || {
        let layout = pipeline_layout(device, label, layouts);
        let start = web_time::Instant::now();
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(label),
            layout: Some(&layout),
            module,
            entry_point: Some(entry),
            compilation_options: wgpu::PipelineCompilationOptions { constants, ..Default::default() },
            cache: None,
        });
        log::debug!("pipeline {label} ({entry}) created in {:.2} s", start.elapsed().as_secs_f64());
        pipeline
    })
}

/// Number of workgroups of `size` needed to cover `n` items.
pub fn groups(n: u32, size: u32) -> u32 {
    n.div_ceil(size)
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
