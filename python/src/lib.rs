//! `rastergi._rastergi`: the native module of the Python package `rastergi` (see
//! `rastergi/__init__.py`, which wraps it). The render options arrive as the command line of
//! `rastergi render` (the Python wrapper turns keyword arguments into `--name value`) and are
//! parsed by the CLI's own parser ([`SceneArgs`], the library's `rastergi::session::args`), the
//! scene is loaded and the renderer built by the library's session ([`Session`]) and the
//! iterations run by its render loop ([`rastergi::session::run`]), as in `rastergi render`: the
//! options, defaults, checks, messages and images are the CLI's. The interpreter's lock is
//! released while scenes load, photons are traced, iterations run and images are read back.

use std::ops::ControlFlow;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

use anyhow::Result;
use clap::{CommandFactory, Parser, ValueEnum};
use numpy::{PyArray1, PyArray3, PyArrayMethods, PyReadonlyArray3, PyUntypedArrayMethods};
use pyo3::create_exception;
use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rastergi::error::Error;
use rastergi::gpu::GpuOptions;
use rastergi::image_io::{ImageFormat, LinearImage, display_encode, write_exr, write_png};
use rastergi::passes::film::Show;
use rastergi::progressive::Progressive;
use rastergi::scene::Camera;
use rastergi::session::args::{SceneArgs, ShowArg};
use rastergi::session::run::{Limits, Observer, run};
use rastergi::session::{Method, Session};

create_exception!(
    _rastergi,
    RastergiError,
    PyRuntimeError,
    "An error of rastergi's: a scene that cannot be loaded, a GPU that cannot be opened or failed, \
     an image file that cannot be read or written. The message is the command line's."
);

/// The options of `rastergi render` that make an image (not those that write files or stop
/// the render early): the scene's and renderer's, the iterations and the method.
#[derive(Parser, Debug)]
#[command(name = "rastergi", no_binary_name = true, disable_help_flag = true, disable_version_flag = true)]
struct RenderOptions {
    #[command(flatten)]
    scene: SceneArgs,
    /// Progressive iterations (one sample per pixel each).
    #[arg(long, default_value_t = 256)]
    iterations: u32,
    /// `gather` (photon map + final gather) or `path` (the reference path tracer).
    #[arg(long, value_enum, default_value_t = Method::Gather)]
    method: Method,
    /// Return the denoised image (`rastergi render --denoise`; gather method, full image).
    #[arg(long)]
    denoise: bool,
}

/// The error as the command line prints it, without its `error: `: one line.
fn one_line(e: &anyhow::Error) -> String {
    let message = format!("{e:#}");
    let lines: Vec<&str> = message.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
    lines.join(" ")
}

/// A Python exception for an error of rastergi: FileNotFoundError for a scene or image file
/// that does not exist, ValueError for an invalid camera, else [`RastergiError`].
fn py_err(e: anyhow::Error) -> PyErr {
    let line = one_line(&e);
    match e.downcast_ref::<Error>() {
        Some(Error::SceneFile { path, .. } | Error::ImageFile { path, .. }) if !path.exists() => {
            PyFileNotFoundError::new_err(line)
        }
        Some(Error::InvalidCamera(_)) => PyValueError::new_err(line),
        _ => RastergiError::new_err(line),
    }
}

/// A ValueError: a value the options or arguments do not allow.
fn value_err(e: anyhow::Error) -> PyErr {
    PyValueError::new_err(one_line(&e))
}

/// Parses the command line the wrapper made of the keyword arguments. clap's first paragraph
/// is the message (its usage and tips follow); an unknown option is a TypeError, as an
/// unexpected keyword argument is in Python, every other refusal a ValueError.
fn parse(argv: Vec<String>) -> PyResult<RenderOptions> {
    RenderOptions::try_parse_from(argv).map_err(|e| {
        let text = e.to_string();
        let first = text.split("\n\n").next().unwrap_or_default();
        let lines: Vec<&str> = first.lines().map(str::trim).filter(|l| !l.is_empty()).collect();
        let line = lines.join(" ");
        let line = line.strip_prefix("error: ").unwrap_or(&line).to_owned();
        match e.kind() {
            clap::error::ErrorKind::UnknownArgument => PyTypeError::new_err(line),
            _ => PyValueError::new_err(line),
        }
    })
}

/// The process's device for `options`' backends: one for every renderer made in Python, so
/// that a renderer made after another of the same shader variants reuses its compiled
/// pipelines (`rastergi::gpu::compiled`: set-up about 1 s shorter per renderer on lavapipe). A
/// device that reported an error (lost, out of memory) is replaced by a fresh one.
fn shared_gpu(options: &GpuOptions) -> Result<rastergi::gpu::Gpu> {
    static GPUS: Mutex<Vec<(String, rastergi::gpu::Gpu)>> = Mutex::new(Vec::new());
    let backends = format!("{:?}", options.backends);
    let mut gpus = GPUS.lock().unwrap_or_else(|e| e.into_inner());
    gpus.retain(|(b, gpu)| *b != backends || gpu.check().is_ok());
    if let Some((_, gpu)) = gpus.iter().find(|(b, _)| *b == backends) {
        return Ok(gpu.clone());
    }
    let gpu = rastergi::gpu::Gpu::new(options)?;
    gpus.push((backends, gpu.clone()));
    Ok(gpu)
}

/// Width and height in pixels.
type ImageSize = (u32, u32);

/// Loads the scene and builds the renderer as `rastergi render` does (the photon map traced);
/// with its image size.
fn build(o: &RenderOptions) -> Result<(Box<dyn Progressive>, ImageSize), PyErr> {
    let options = o.scene.options(o.method, o.denoise);
    o.method.check_show(options.show).map_err(|e| value_err(e.into()))?;
    if o.denoise && (o.method != Method::Gather || options.show != Show::Full) {
        return Err(PyValueError::new_err("denoise needs method='gather' and the full image (no show)"));
    }
    let session = Session::load(&options).map_err(|e| py_err(e.into()))?;
    let (width, height) = (session.settings.width, session.settings.height);
    let gpu = shared_gpu(&options.gpu).map_err(py_err)?;
    let (renderer, _) = session.renderer(&gpu, &options).map_err(|e| py_err(e.into()))?;
    renderer.wait().map_err(|e| py_err(e.into()))?;
    Ok((renderer, (width, height)))
}

/// Watches the render loop for Ctrl-C: at each of its syncs (every 8 iterations, as
/// `rastergi render`'s queue, or every one where they are slow) it takes the interpreter's
/// lock to check for signals, and stops the loop with the KeyboardInterrupt it finds.
#[derive(Default)]
struct Interrupts(Option<PyErr>);

impl Observer for Interrupts {
    fn synced(&mut self, _done: u32) -> ControlFlow<()> {
        match Python::attach(|py| py.check_signals()) {
            Ok(()) => ControlFlow::Continue(()),
            Err(e) => {
                self.0 = Some(e);
                ControlFlow::Break(())
            }
        }
    }
}

/// Runs `n` more iterations of the renderer that `renderer` gives (a [`PyRenderer`]'s lock,
/// taken with the interpreter's lock released, as everywhere) by the library's render loop;
/// Ctrl-C raises KeyboardInterrupt.
fn iterate<R>(py: Python<'_>, renderer: impl FnOnce() -> R + Send, n: u32) -> PyResult<()>
where
    R: std::ops::DerefMut<Target = Box<dyn Progressive>>,
{
    let mut interrupts = Interrupts::default();
    py.detach(|| {
        let mut renderer = renderer();
        let limits = Limits::iterations(renderer.samples().saturating_add(n));
        run(renderer.as_mut(), &limits, None, &mut interrupts)
    })
    .map_err(|e| py_err(e.into()))?;
    interrupts.0.map_or(Ok(()), Err)
}

/// A numpy float32 array (height, width, 3).
fn to_numpy(py: Python<'_>, image: LinearImage) -> PyResult<Bound<'_, PyArray3<f32>>> {
    let (w, h) = (image.width as usize, image.height as usize);
    let flat: Vec<f32> = image.pixels.into_iter().flatten().collect();
    PyArray1::from_vec(py, flat).reshape([h, w, 3])
}

/// An image from a float32 array (height, width, 3) (the wrapper makes it one).
fn from_numpy(array: &PyReadonlyArray3<f32>) -> PyResult<LinearImage> {
    let shape = array.shape();
    if shape[2] != 3 || shape[0] == 0 || shape[1] == 0 {
        return Err(PyValueError::new_err(format!(
            "an image is an array of shape (height, width, 3), got shape {shape:?}"
        )));
    }
    let v = array.as_array();
    let (h, w) = (shape[0], shape[1]);
    let pixels =
        (0..h).flat_map(|y| (0..w).map(move |x| (y, x))).map(|(y, x)| [v[[y, x, 0]], v[[y, x, 1]], v[[y, x, 2]]]);
    Ok(LinearImage { width: w as u32, height: h as u32, pixels: pixels.collect() })
}

fn parse_show(show: &str) -> PyResult<ShowArg> {
    ShowArg::from_str(&show.replace('_', "-"), true).map_err(|_| {
        PyValueError::new_err(format!(
            "invalid value '{show}' for show (possible values: full, direct, indirect, photon-map)"
        ))
    })
}

fn show_name(show: ShowArg) -> String {
    show.to_possible_value().map_or_else(String::new, |v| v.get_name().to_owned())
}

/// Renders as `rastergi render ARGV --out x.exr` does and returns the image.
#[pyfunction]
fn render<'py>(py: Python<'py>, argv: Vec<String>) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let o = parse(argv)?;
    if o.iterations == 0 {
        return Err(PyValueError::new_err("--iterations must be at least 1"));
    }
    let (mut renderer, _) = py.detach(|| build(&o))?;
    let r = &mut renderer;
    iterate(py, move || r, o.iterations)?;
    let show = o.scene.show.show();
    let denoise = o.denoise;
    let image = py
        .detach(move || match renderer.denoising().filter(|_| denoise) {
            Some(r) => r.read_denoised(&rastergi::passes::denoise::DenoiseParams::default()),
            None => renderer.read_linear(show),
        })
        .map_err(|e| py_err(e.into()))?;
    to_numpy(py, image)
}

/// The options `render` takes: (name as on the command line, takes a value, repeatable).
#[pyfunction]
fn options() -> Vec<(String, bool, bool)> {
    let command = RenderOptions::command();
    command
        .get_arguments()
        .filter_map(|a| {
            let long = a.get_long()?;
            let action = a.get_action();
            Some((long.to_owned(), action.takes_values(), matches!(action, clap::ArgAction::Append)))
        })
        .collect()
}

/// A progressive renderer that keeps its scene, photon map and image between calls.
#[pyclass(name = "Renderer", module = "rastergi._rastergi", frozen)]
struct PyRenderer {
    renderer: Mutex<Box<dyn Progressive>>,
    show: ShowArg,
    method: Method,
    width: u32,
    height: u32,
}

impl PyRenderer {
    fn lock(&self) -> MutexGuard<'_, Box<dyn Progressive>> {
        // A panic while the lock was held leaves the renderer as it was at the panic.
        self.renderer.lock().unwrap_or_else(|e| e.into_inner())
    }
}

type Vec3 = (f32, f32, f32);

fn vec3(v: glam::Vec3) -> Vec3 {
    (v.x, v.y, v.z)
}

#[pymethods]
impl PyRenderer {
    #[new]
    fn new(py: Python<'_>, argv: Vec<String>) -> PyResult<Self> {
        let o = parse(argv)?;
        let (renderer, (width, height)) = py.detach(|| build(&o))?;
        Ok(PyRenderer { renderer: Mutex::new(renderer), show: o.scene.show, method: o.method, width, height })
    }

    /// Runs `n` more iterations (one sample per pixel each).
    fn iterate(&self, py: Python<'_>, n: u32) -> PyResult<()> {
        iterate(py, || self.lock(), n)
    }

    /// The mean radiance so far of `show` (default: the renderer's).
    #[pyo3(signature = (show=None))]
    fn image<'py>(&self, py: Python<'py>, show: Option<&str>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let show = show.map(parse_show).transpose()?.unwrap_or(self.show);
        let image = py.detach(|| {
            let r = self.lock();
            if !r.has(show.show()) {
                let why = match self.method {
                    Method::Path => "the path tracer renders the full image only".to_owned(),
                    Method::Gather => {
                        "the photon map's radiance is kept only by a Renderer made with show='photon-map'".to_owned()
                    }
                };
                return Err(PyValueError::new_err(format!("show='{}': {why}", show_name(show))));
            }
            r.read_linear(show.show()).map_err(|e| py_err(e.into()))
        })?;
        to_numpy(py, image)
    }

    /// Moves the camera (`up` and `fov` default to the current camera's); the image restarts.
    #[pyo3(signature = (eye, target, up=None, fov=None))]
    fn set_camera(&self, py: Python<'_>, eye: Vec3, target: Vec3, up: Option<Vec3>, fov: Option<f32>) -> PyResult<()> {
        py.detach(|| {
            let mut r = self.lock();
            let old = r.camera();
            let v = |t: Vec3| glam::Vec3::new(t.0, t.1, t.2);
            let camera = Camera {
                eye: v(eye),
                target: v(target),
                up: up.map_or(old.up, v),
                fov_y_deg: fov.unwrap_or(old.fov_y_deg),
            };
            r.set_camera(camera).map_err(|e| py_err(e.into()))
        })
    }

    /// Discards the iterations so far.
    fn reset(&self, py: Python<'_>) {
        py.detach(|| self.lock().reset());
    }

    /// Iterations accumulated since the renderer was made or its camera last changed.
    #[getter]
    fn samples(&self, py: Python<'_>) -> u32 {
        py.detach(|| self.lock().samples())
    }

    /// The camera: (eye, target, up, vertical field of view in degrees).
    #[getter]
    fn camera(&self, py: Python<'_>) -> (Vec3, Vec3, Vec3, f32) {
        let c = py.detach(|| self.lock().camera());
        (vec3(c.eye), vec3(c.target), vec3(c.up), c.fov_y_deg)
    }

    /// The image's relative RMSE estimated without a reference, from two independent halves
    /// of the iterations (as `rastergi render --target-error`); None until it can be.
    #[getter]
    fn error_estimate(&self, py: Python<'_>) -> PyResult<Option<f64>> {
        let state = py.detach(|| self.lock().film_state()).map_err(|e| py_err(e.into()))?;
        Ok(state.error_estimate())
    }

    #[getter]
    fn width(&self) -> u32 {
        self.width
    }

    #[getter]
    fn height(&self) -> u32 {
        self.height
    }

    #[getter]
    fn method(&self) -> &'static str {
        self.method.name()
    }

    #[getter]
    fn show(&self) -> String {
        show_name(self.show)
    }
}

/// Reads an image file (.exr linear, .png decoded to linear).
#[pyfunction]
fn read_image(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyArray3<f32>>> {
    let image = py.detach(|| rastergi::image_io::read_image(&path)).map_err(|e| py_err(e.into()))?;
    to_numpy(py, image)
}

/// Writes an image file: .exr (linear f32) or .png (2^exposure, sRGB; exposure fitted as
/// `rastergi render` fits it when None).
#[pyfunction]
#[pyo3(signature = (path, image, exposure=None))]
fn write_image(py: Python<'_>, path: PathBuf, image: PyReadonlyArray3<f32>, exposure: Option<f32>) -> PyResult<()> {
    let format = ImageFormat::from_path(&path).map_err(|e| PyValueError::new_err(one_line(&e.into())))?;
    let image = from_numpy(&image)?;
    py.detach(|| match format {
        ImageFormat::Exr => write_exr(&path, &image),
        ImageFormat::Png => {
            let exposure = exposure.unwrap_or_else(|| rastergi::fit::exposure(&image));
            write_png(&path, &display_encode(&image, exposure))
        }
    })
    .map_err(|e| py_err(e.into()))
}

/// Compares two images as `rastergi compare` does; the names (paths, or "image" and
/// "reference" for arrays) are for the messages. Returns a dict of the metrics.
#[pyfunction]
#[pyo3(signature = (image, image_name, reference, reference_name, mask_emitters=None))]
fn compare<'py>(
    py: Python<'py>,
    image: PyReadonlyArray3<f32>,
    image_name: &str,
    reference: PyReadonlyArray3<f32>,
    reference_name: &str,
    mask_emitters: Option<f32>,
) -> PyResult<Bound<'py, PyDict>> {
    let (image, reference) = (from_numpy(&image)?, from_numpy(&reference)?);
    let m = py
        .detach(|| {
            use rastergi::metrics::{check_finite, metrics};
            check_finite(image_name, &image)?;
            check_finite(reference_name, &reference)?;
            metrics(&image, image_name, &reference, reference_name, mask_emitters)
        })
        .map_err(|e| value_err(e.into()))?;
    let c = &m.comparison;
    let d = PyDict::new(py);
    d.set_item("relative_rmse", c.relative_rmse)?;
    d.set_item("block_mean_error", c.block_mean_error)?;
    d.set_item("psnr", c.psnr)?;
    d.set_item("mean_ratio", (c.mean_ratio[0], c.mean_ratio[1], c.mean_ratio[2]))?;
    d.set_item("rmse", m.rmse)?;
    d.set_item("reference_mean", m.reference_mean)?;
    d.set_item("peak", m.peak)?;
    d.set_item("compared_pixels", m.compared_pixels)?;
    d.set_item("total_pixels", m.total_pixels)?;
    Ok(d)
}

#[pymodule]
fn _rastergi(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // Warnings (a scene without light, a black environment map) on stderr, as the command
    // line prints them; RUST_LOG chooses more.
    let _ = env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).try_init();
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("RastergiError", m.py().get_type::<RastergiError>())?;
    m.add_class::<PyRenderer>()?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(options, m)?)?;
    m.add_function(wrap_pyfunction!(read_image, m)?)?;
    m.add_function(wrap_pyfunction!(write_image, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    Ok(())
}
