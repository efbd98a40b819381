//! `rastergi render`.

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

use anyhow::Result;
use clap::{Args, ValueEnum};
use glam::Vec3;
use indicatif::{ProgressBar, ProgressStyle};
use rastergi::film::Show;
use rastergi::gpu::{Backends, Gpu, GpuOptions, parse_backend};
use rastergi::image_io::{ImageFormat, write_exr, write_png};
use rastergi::renderer::{RenderSettings, Renderer};
use rastergi::scene::{Scene, cornell_box, load_obj};

#[derive(Args, Clone, Debug)]
pub struct GpuArgs {
    /// Graphics backend: vulkan, metal, dx12, gl (default: WGPU_BACKEND, else the platform's primary).
    #[arg(long, value_parser = parse_backend)]
    backend: Option<Backends>,
}

#[derive(Copy, Clone, Debug, ValueEnum)]
enum ShowArg {
    /// Emission + direct + indirect light.
    Full,
    /// Emission + direct light.
    Direct,
    /// Indirect light only.
    Indirect,
    /// The photon map's radiance ρ/π·E at the visible points.
    PhotonMap,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene: `cornell` (built in) or a Wavefront .obj file.
    scene: String,
    #[arg(long, default_value_t = 256)]
    width: u32,
    #[arg(long, default_value_t = 256)]
    height: u32,
    /// Progressive iterations (one sample per pixel each).
    #[arg(long, default_value_t = 256)]
    iterations: u32,
    /// Output image: .exr (linear radiance, f32 RGB) or .png (exposure, sRGB).
    #[arg(long)]
    out: PathBuf,
    /// Camera position, overriding the scene's (x,y,z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<Vec3>,
    /// Point the camera looks at (x,y,z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    target: Option<Vec3>,
    /// Camera up vector (x,y,z).
    #[arg(long, value_parser = parse_vec3, allow_hyphen_values = true)]
    up: Option<Vec3>,
    /// Vertical field of view in degrees.
    #[arg(long)]
    fov: Option<f32>,
    /// Seed of every random decision; the same seed gives the same image.
    #[arg(long, default_value_t = 0)]
    seed: u32,
    /// Light samples per pixel per iteration.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=64))]
    light_samples: u32,
    /// Photons traced into the photon map.
    #[arg(long, default_value_t = 1 << 20, value_parser = clap::value_parser!(u32).range(1..))]
    photons: u32,
    /// Photon grid cells along the scene's longest axis.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=1024))]
    grid: u32,
    /// Ray-view resolution of the final gather, texels per side (default: twice the image's larger side, 128 to 2048).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    bundle: Option<u32>,
    /// What the image shows.
    #[arg(long, value_enum, default_value_t = ShowArg::Full)]
    show: ShowArg,
    /// Exposure in stops for PNG output (the image is scaled by 2^exposure).
    #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
    exposure: f32,
    #[command(flatten)]
    gpu: GpuArgs,
}

fn parse_vec3(s: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!("expected three comma-separated numbers like 0,1,3.5, got '{s}'"));
    }
    let mut v = [0.0f32; 3];
    for (i, p) in parts.iter().enumerate() {
        v[i] = p.parse().map_err(|_| format!("'{p}' is not a number"))?;
        if !v[i].is_finite() {
            return Err(format!("'{p}' is not a finite number"));
        }
    }
    Ok(Vec3::from(v))
}

pub fn gpu(args: &GpuArgs) -> Result<Gpu> {
    Ok(Gpu::new(&GpuOptions { backends: args.backend })?)
}

/// The built-in scene of that name, or the scene file at that path.
pub fn load_scene(name: &str) -> Result<Scene> {
    if name == "cornell" {
        return Ok(cornell_box());
    }
    let path = Path::new(name);
    match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("obj") => Ok(load_obj(path)?),
        _ => anyhow::bail!("unknown scene '{name}': use the built-in 'cornell' or a path to a .obj file"),
    }
}

/// Refuses, before any rendering, an output path the image could never be written to.
fn check_output_path(out: &Path) -> Result<()> {
    if out.is_dir() {
        anyhow::bail!("{}: is a directory; give --out a file name ending in .exr or .png", out.display());
    }
    let dir = match out.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir,
        _ => Path::new("."),
    };
    if !dir.is_dir() {
        anyhow::bail!(
            "{}: the directory {} does not exist; create it first or choose another --out",
            out.display(),
            dir.display()
        );
    }
    Ok(())
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let format = ImageFormat::from_path(&args.out)?;
    check_output_path(&args.out)?;
    let mut scene = load_scene(&args.scene)?;
    let c = &mut scene.camera;
    c.eye = args.eye.unwrap_or(c.eye);
    c.target = args.target.unwrap_or(c.target);
    c.up = args.up.unwrap_or(c.up);
    c.fov_y_deg = args.fov.unwrap_or(c.fov_y_deg);
    scene.camera.validate()?;
    if args.iterations == 0 {
        anyhow::bail!("--iterations must be at least 1");
    }
    let gpu = gpu(&args.gpu)?;
    let settings = RenderSettings {
        width: args.width,
        height: args.height,
        seed: args.seed,
        light_samples: args.light_samples,
        photons: args.photons,
        grid_resolution: args.grid,
        show_photon_map: matches!(args.show, ShowArg::PhotonMap),
        bundle: args.bundle.unwrap_or(0),
    };
    let mut renderer = Renderer::new(&gpu, &scene, settings)?;

    let progress = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::new(args.iterations as u64);
        bar.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} iterations  {per_sec}  eta {eta}")
                .expect("valid progress template"),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        bar
    } else {
        ProgressBar::hidden()
    };
    for i in 0..args.iterations {
        renderer.iterate()?;
        // Keep the GPU queue short so the progress bar tells the truth.
        if i % 8 == 7 {
            renderer.wait()?;
            progress.set_position(i as u64 + 1);
        }
    }
    renderer.wait()?;
    progress.finish_and_clear();

    let show = match args.show {
        ShowArg::Full => Show::Full,
        ShowArg::Direct => Show::Direct,
        ShowArg::Indirect => Show::Indirect,
        ShowArg::PhotonMap => Show::PhotonMap,
    };
    match format {
        ImageFormat::Exr => write_exr(&args.out, &renderer.read_linear(show)?)?,
        ImageFormat::Png => write_png(&args.out, &renderer.read_display(show, args.exposure)?)?,
    }
    Ok(())
}
