//! `rastergi bench rays`: rays per second of each kind the renderer casts (camera, shadow,
//! diffuse bounce, the gather's shared directions, photons), traced by the GPU kernel as the
//! passes trace them and by the CPU twin on every core, hit for hit; and the BVH they walk
//! (build time, nodes, SAH cost, memory).

use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rastergi::gpu_scene::{GpuScene, PreparedScene};
use rastergi::rays::{RayCaster, RayKind, disagreements, make_rays, trace_cpu};

use super::{load_valid_scene, median};
use crate::args::{GpuArgs, gpu};

#[derive(Args, Debug)]
pub struct RaysArgs {
    /// The scene: built in (`cornell`, `atrium`, `spheres:N`, `rooms`, `glossy-room`, `sunroom`) or a file.
    #[arg(default_value = "cornell")]
    scene: String,
    /// The camera's image is SIZE × SIZE pixels: one ray of each kind per pixel.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=16384))]
    size: u32,
    /// Timed GPU runs per kind (the median is reported), after one warm-up run.
    #[arg(long, default_value_t = 3)]
    repeats: u32,
    /// Print one JSON object instead of the table.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    gpu: GpuArgs,
}

/// One kind's figures.
struct KindFigures {
    kind: RayKind,
    rays: usize,
    gpu_s: f64,
    cpu_s: f64,
    disagree: usize,
}

pub fn run(a: &RaysArgs) -> Result<()> {
    let scene = load_valid_scene(&a.scene)?;
    let gpu = gpu(&a.gpu)?;
    let t = Instant::now();
    let prepared = PreparedScene::new(&scene);
    let prepare_s = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let bvh = rastergi::bvh::Bvh::build(&scene.triangles);
    let build_s = t.elapsed().as_secs_f64();
    // Before any ray is made: a batch the GPU cannot bind is refused in one line.
    let ray_bytes = std::mem::size_of::<rastergi::rays::GpuRay>() as u64;
    let count = a.size as u64 * a.size as u64;
    rastergi::limits::check_storage_buffer(
        &gpu.device.limits(),
        "the rays",
        count,
        ray_bytes,
        "choose a smaller --size",
    )?;
    let gs = GpuScene::new(&gpu, &prepared)?;
    let caster = RayCaster::new(&gpu, &gs);
    let mut figures = Vec::new();
    for kind in RayKind::ALL {
        let rays = make_rays(&prepared, &scene.camera, (a.size, a.size), kind, 7);
        if rays.is_empty() {
            continue;
        }
        let (hits, times) = caster.trace(&gpu, &gs, &rays, a.repeats.max(1))?;
        let t = Instant::now();
        let cpu_hits = trace_cpu(&prepared, &rays);
        let cpu_s = t.elapsed().as_secs_f64();
        let disagree = disagreements(&rays, &hits, &cpu_hits);
        figures.push(KindFigures { kind, rays: rays.len(), gpu_s: median(times).as_secs_f64(), cpu_s, disagree });
    }
    let node_bytes = std::mem::size_of_val(bvh.nodes.as_slice());
    let wide = bvh.wide();
    let wide_bytes = std::mem::size_of_val(wide.as_slice());
    let triangle_bytes = scene.triangles.len() * std::mem::size_of::<rastergi::gpu_scene::GpuTriangle>();
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if a.json {
        let kinds: Vec<String> = figures
            .iter()
            .map(|f| {
                format!(
                    "{{\"kind\":\"{}\",\"rays\":{},\"gpu_mrays_per_s\":{:.4},\"cpu_mrays_per_s\":{:.4},\"disagreements\":{}}}",
                    f.kind.name(),
                    f.rays,
                    f.rays as f64 / f.gpu_s / 1e6,
                    f.rays as f64 / f.cpu_s / 1e6,
                    f.disagree
                )
            })
            .collect();
        println!(
            "{{\"scene\":{:?},\"triangles\":{},\"gpu\":{:?},\"cpu_threads\":{threads},\"bvh\":{{\"build_s\":{build_s:.4},\"prepare_s\":{prepare_s:.4},\"nodes\":{},\"depth\":{},\"sah_cost\":{:.3},\"node_bytes\":{node_bytes},\"wide_nodes\":{},\"wide_node_bytes\":{wide_bytes},\"triangle_bytes\":{triangle_bytes}}},\"kinds\":[{}]}}",
            a.scene,
            scene.triangles.len(),
            format!("{} ({:?})", gpu.info.name, gpu.info.backend),
            bvh.nodes.len(),
            bvh.depth(),
            bvh.sah_cost(),
            wide.len(),
            kinds.join(",")
        );
        return Ok(());
    }
    println!("rays: {} ({} triangles), {}² rays per kind", a.scene, scene.triangles.len(), a.size);
    println!(
        "  BVH: built in {build_s:.3} s (scene prepared in {prepare_s:.3} s), {} binary nodes ({:.1} MiB; the CPU's), depth {}, SAH cost {:.2}; {} 4-wide nodes ({:.1} MiB; the GPU's), {:.1} MiB of triangles",
        bvh.nodes.len(),
        node_bytes as f64 / (1 << 20) as f64,
        bvh.depth(),
        bvh.sah_cost(),
        wide.len(),
        wide_bytes as f64 / (1 << 20) as f64,
        triangle_bytes as f64 / (1 << 20) as f64
    );
    println!("  GPU: {} ({:?}); CPU twin: {threads} threads (rayon)", gpu.info.name, gpu.info.backend);
    for f in &figures {
        println!(
            "  {:<7} {:<35} {:>8} rays: GPU {:>8.3} M rays/s, CPU {:>8.3} M rays/s (GPU/CPU {:.2}x), {} disagree",
            f.kind.name(),
            format!("({})", f.kind.description()),
            f.rays,
            f.rays as f64 / f.gpu_s / 1e6,
            f.rays as f64 / f.cpu_s / 1e6,
            f.cpu_s / f.gpu_s,
            f.disagree
        );
    }
    Ok(())
}
