//! Compiled GPU objects, made once per device and reused: shader modules by their source,
//! bind-group layouts by their entries, pipelines by (module, entry points, constants, layouts).
//!
//! Compiling is most of a renderer's set-up besides its first photons: on lavapipe 0.6–1.5 s
//! per renderer (the traced gather's pipeline alone 0.4–0.9 s), and a Vulkan pipeline cache
//! does not spare it (measured: lavapipe compiles again, as fast or as slow). A second
//! renderer on the same device — another seed, a resize, the viewer's or Python's next scene
//! with the same shader variants — takes its objects from here. They are immutable, so sharing
//! them is safe; a device's objects are released when the last [`crate::gpu::Gpu`] holding it
//! is dropped.
//!
//! Objects are found by the device's handle, which wgpu compares by its id within its
//! instance: two devices of two instances alive at once can compare equal. A device is
//! therefore registered when its [`crate::gpu::Gpu`] opens it, and while another registered
//! device compares equal to it, neither keeps objects (each compiles its own, as before); a
//! device that was never registered keeps none either.

use std::collections::HashMap;

/// What makes two compute pipelines the same.
#[derive(PartialEq, Eq, Hash)]
struct ComputeKey {
    module: wgpu::ShaderModule,
    entry: String,
    /// Names and bit patterns of the pipeline-overridable constants.
    constants: Vec<(String, u64)>,
    layouts: Vec<wgpu::BindGroupLayout>,
}

/// What makes two raster pipelines of [`crate::gpu::scene_raster_pipeline`] the same.
#[derive(PartialEq, Eq, Hash)]
struct RasterKey {
    module: wgpu::ShaderModule,
    fragment: String,
    target: wgpu::ColorTargetState,
    depth: Option<wgpu::TextureFormat>,
    layouts: Vec<wgpu::BindGroupLayout>,
}

/// The registered devices that compare equal to one handle, and their objects while there is
/// one device.
struct Entry {
    devices: usize,
    objects: Option<Objects>,
}

/// One device's objects.
#[derive(Default)]
struct Objects {
    modules: HashMap<String, wgpu::ShaderModule>,
    layouts: HashMap<Vec<wgpu::BindGroupLayoutEntry>, wgpu::BindGroupLayout>,
    compute: HashMap<ComputeKey, wgpu::ComputePipeline>,
    raster: HashMap<RasterKey, wgpu::RenderPipeline>,
}

#[cfg(not(target_arch = "wasm32"))]
static OBJECTS: std::sync::LazyLock<std::sync::Mutex<HashMap<wgpu::Device, Entry>>> =
    std::sync::LazyLock::new(Default::default);

/// `f` on the map of registered devices.
#[cfg(not(target_arch = "wasm32"))]
fn with_all<R>(f: impl FnOnce(&mut HashMap<wgpu::Device, Entry>) -> R) -> R {
    f(&mut OBJECTS.lock().unwrap_or_else(|e| e.into_inner()))
}

// WebGPU's handles are not Send: the page's one thread keeps its own.
#[cfg(target_arch = "wasm32")]
thread_local! {
    static OBJECTS: std::cell::RefCell<HashMap<wgpu::Device, Entry>> = Default::default();
}

#[cfg(target_arch = "wasm32")]
fn with_all<R>(f: impl FnOnce(&mut HashMap<wgpu::Device, Entry>) -> R) -> R {
    OBJECTS.with(|all| f(&mut all.borrow_mut()))
}

/// `f` on `device`'s objects, `None` where it keeps none.
fn with_objects<R>(device: &wgpu::Device, f: impl FnOnce(Option<&mut Objects>) -> R) -> R {
    with_all(|all| f(all.get_mut(device).and_then(|e| e.objects.as_mut())))
}

/// Registers `device` (see the module's text); [`Release`] undoes it.
pub fn register(device: &wgpu::Device) -> Release {
    with_all(|all| {
        let e = all.entry(device.clone()).or_insert(Entry { devices: 0, objects: Some(Objects::default()) });
        e.devices += 1;
        if e.devices > 1 {
            e.objects = None;
        }
    });
    Release(device.clone())
}

/// The object under `key` in the map `map` picks, else `make`'s, kept there where the device
/// keeps objects. `make` runs without the lock held (compiling takes up to a second).
fn reuse<K: Eq + std::hash::Hash, V: Clone>(
    device: &wgpu::Device,
    key: K,
    map: impl Fn(&mut Objects) -> &mut HashMap<K, V>,
    make: impl FnOnce() -> V,
) -> V {
    if let Some(v) = with_objects(device, |o| o.and_then(|o| map(o).get(&key).cloned())) {
        return v;
    }
    let v = make();
    with_objects(device, |o| match o {
        Some(o) => map(o).entry(key).or_insert(v).clone(),
        None => v,
    })
}

/// The shader module of `source` (`label` names it when it is made).
pub fn module(device: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    reuse(
        device,
        source.to_string(),
        |o| &mut o.modules,
        || {
            device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(label),
                source: wgpu::ShaderSource::Wgsl(source.into()),
            })
        },
    )
}

/// The bind-group layout of `entries`.
pub fn bind_group_layout(
    device: &wgpu::Device,
    label: &str,
    entries: &[wgpu::BindGroupLayoutEntry],
) -> wgpu::BindGroupLayout {
    reuse(
        device,
        entries.to_vec(),
        |o| &mut o.layouts,
        || device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries }),
    )
}

/// The compute pipeline of `module`'s `entry` with `layouts` and `constants`, made by `make`
/// if this device has none yet.
pub fn compute_pipeline(
    device: &wgpu::Device,
    module: &wgpu::ShaderModule,
    entry: &str,
    layouts: &[&wgpu::BindGroupLayout],
    constants: &[(&str, f64)],
    make: impl FnOnce() -> wgpu::ComputePipeline,
) -> wgpu::ComputePipeline {
    let key = ComputeKey {
        module: module.clone(),
        entry: entry.to_string(),
        constants: constants.iter().map(|(n, v)| (n.to_string(), v.to_bits())).collect(),
        layouts: layouts.iter().map(|&l| l.clone()).collect(),
    };
    reuse(device, key, |o| &mut o.compute, make)
}

/// The raster pipeline of `module` (fragment entry `fragment`) into `target` and `depth` with
/// `layouts`, made by `make` if this device has none yet.
pub fn raster_pipeline(
    device: &wgpu::Device,
    (module, layouts): (&wgpu::ShaderModule, &[&wgpu::BindGroupLayout]),
    fragment: &str,
    target: &wgpu::ColorTargetState,
    depth: Option<wgpu::TextureFormat>,
    make: impl FnOnce() -> wgpu::RenderPipeline,
) -> wgpu::RenderPipeline {
    let key = RasterKey {
        module: module.clone(),
        fragment: fragment.to_string(),
        target: target.clone(),
        depth,
        layouts: layouts.iter().map(|&l| l.clone()).collect(),
    };
    reuse(device, key, |o| &mut o.raster, make)
}

/// A registered device (of [`register`]): dropped with the last clone of its
/// [`crate::gpu::Gpu`], it unregisters the device and releases its objects with the last
/// registration of its handle.
#[derive(Debug)]
pub struct Release(wgpu::Device);

impl Drop for Release {
    fn drop(&mut self) {
        with_all(|all| {
            if let Some(e) = all.get_mut(&self.0) {
                e.devices -= 1;
                if e.devices == 0 {
                    all.remove(&self.0);
                }
            }
        });
    }
}

/// How many objects `device` keeps (modules, layouts, compute and raster pipelines together),
/// `None` where it keeps none.
pub fn count(device: &wgpu::Device) -> Option<usize> {
    with_objects(device, |o| o.map(|o| o.modules.len() + o.layouts.len() + o.compute.len() + o.raster.len()))
}

#[cfg(test)]
mod tests {
    use crate::gpu::{Gpu, GpuOptions};
    use crate::image_io::LinearImage;
    use crate::passes::film::Show;
    use crate::renderer::Renderer;
    use crate::settings::RenderSettings;

    /// The Cornell box at 32², 4 iterations of the traced gather, seed 3.
    fn render(gpu: &Gpu) -> LinearImage {
        let settings = RenderSettings {
            width: 32,
            height: 32,
            seed: 3,
            photons: 1 << 14,
            grid_resolution: 16,
            gather: crate::gather::GatherMethod::Trace,
            ..Default::default()
        };
        let mut r = Renderer::new(gpu, &crate::scene::cornell_box(), settings).expect("renderer");
        for _ in 0..4 {
            r.iterate().expect("iteration");
        }
        r.read_linear(Show::Full).expect("readback")
    }

    /// A renderer made of a device's reused objects renders bit for bit what one made of
    /// fresh objects renders and compiles nothing new; a dropped device's objects are released;
    /// two devices alive at once whose handles compare equal (one per instance) keep none and
    /// render alike.
    #[test]
    fn a_renderer_of_reused_objects_renders_what_a_fresh_one_does() {
        let open = || Gpu::new(&GpuOptions::default()).expect("tests need a GPU adapter (lavapipe on CI)");
        let gpu = open();
        assert_eq!(super::count(&gpu.device), Some(0), "a new device keeps objects already");
        let first = render(&gpu);
        let made = super::count(&gpu.device).expect("the device keeps objects");
        assert!(made > 0, "the renderer made no objects through the cache");
        let again = render(&gpu);
        assert_eq!(super::count(&gpu.device), Some(made), "the second renderer compiled objects of its own");
        assert!(first.pixels == again.pixels, "the image of reused objects differs from the first");
        let device = gpu.device.clone();
        drop(gpu);
        assert_eq!(super::count(&device), None, "a dropped device's objects are still kept");
        // Each Gpu opens its own instance, whose first device has the same id.
        let (a, b) = (open(), open());
        if a.device == b.device {
            assert_eq!((super::count(&a.device), super::count(&b.device)), (None, None));
        }
        assert!(render(&a).pixels == first.pixels && render(&b).pixels == first.pixels, "two devices at once");
    }
}
