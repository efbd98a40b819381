//! `rastergi bench rays`: rays per second of each kind the renderer casts (camera, shadow,
//! diffuse bounce, the gather's shared directions, photons), traced by the GPU kernel as the
//! passes trace them and by the CPU twin on every core, hit for hit; and the BVH they walk
//! (build time, nodes, SAH cost, memory). Where the device has hardware ray queries (and
//! `--rays` is not `compute`), each kind is traced on both paths, the compute BVH and the ray
//! query, side by side, with the acceleration structures' build time and memory.

use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rastergi::gpu::accel::{RayPath, Rays};
use rastergi::gpu_scene::GpuScene;
use rastergi::rays::{RayCaster, RayKind, disagreements, make_rays, trace_cpu};
use rastergi::surface::PreparedScene;

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
    /// Per ray path traced: the path, the median seconds, the rays that disagree with the CPU.
    paths: Vec<(RayPath, f64, usize)>,
    cpu_s: f64,
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
    rastergi::gpu::limits::check_storage_buffer(
        &gpu.device.limits(),
        "the rays",
        count,
        ray_bytes,
        "choose a smaller --size",
    )?;
    let gs = GpuScene::new(&gpu, &prepared)?;
    let paths: Vec<RayPath> = match (&gs.accel, gpu.rays) {
        (Some(_), Rays::Hardware) => vec![RayPath::Hardware],
        (Some(_), _) => vec![RayPath::Compute, RayPath::Hardware],
        (None, _) => vec![RayPath::Compute],
    };
    let casters: Vec<(RayPath, RayCaster)> = paths.iter().map(|&p| (p, RayCaster::on(&gpu, &gs, p))).collect();
    let mut figures = Vec::new();
    for kind in RayKind::ALL {
        let rays = make_rays(&prepared, &scene.camera, (a.size, a.size), kind, 7);
        if rays.is_empty() {
            continue;
        }
        let t = Instant::now();
        let cpu_hits = trace_cpu(&prepared, &rays);
        let cpu_s = t.elapsed().as_secs_f64();
        let mut per_path = Vec::new();
        for (path, caster) in &casters {
            let (hits, times) = caster.trace(&gpu, &gs, &rays, a.repeats.max(1))?;
            per_path.push((*path, median(times).as_secs_f64(), disagreements(&rays, &hits, &cpu_hits)));
        }
        figures.push(KindFigures { kind, rays: rays.len(), paths: per_path, cpu_s });
    }
    let accel_json = gs.accel.as_ref().map_or("null".to_owned(), |x| {
        format!(
            "{{\"build_s\":{:.4},\"bytes\":{}}}",
            x.build_seconds,
            x.memory.map_or("null".to_owned(), |m| m.to_string())
        )
    });
    let node_bytes = std::mem::size_of_val(bvh.nodes.as_slice());
    let wide = bvh.wide();
    let wide_bytes = std::mem::size_of_val(wide.as_slice());
    let triangle_bytes = scene.triangles.len() * std::mem::size_of::<rastergi::gpu_scene::GpuTriangle>();
    let threads = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    if a.json {
        let kinds: Vec<String> = figures
            .iter()
            .map(|f| {
                // gpu_mrays_per_s and disagreements: the first path's (compute where traced).
                let (_, gpu_s, disagree) = f.paths[0];
                let paths: Vec<String> = f
                    .paths
                    .iter()
                    .map(|(p, s, d)| {
                        format!("\"{}\":{{\"mrays_per_s\":{:.4},\"disagreements\":{d}}}", p.name(), f.rays as f64 / s / 1e6)
                    })
                    .collect();
                format!(
                    "{{\"kind\":\"{}\",\"rays\":{},\"gpu_mrays_per_s\":{:.4},\"cpu_mrays_per_s\":{:.4},\"disagreements\":{disagree},\"paths\":{{{}}}}}",
                    f.kind.name(),
                    f.rays,
                    f.rays as f64 / gpu_s / 1e6,
                    f.rays as f64 / f.cpu_s / 1e6,
                    paths.join(",")
                )
            })
            .collect();
        println!(
            "{{\"scene\":{:?},\"triangles\":{},\"gpu\":{:?},\"cpu_threads\":{threads},\"bvh\":{{\"build_s\":{build_s:.4},\"prepare_s\":{prepare_s:.4},\"nodes\":{},\"depth\":{},\"sah_cost\":{:.3},\"node_bytes\":{node_bytes},\"wide_nodes\":{},\"wide_node_bytes\":{wide_bytes},\"triangle_bytes\":{triangle_bytes}}},\"accel\":{accel_json},\"kinds\":[{}]}}",
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
    match &gs.accel {
        Some(x) => println!(
            "  acceleration structures (hardware path): built in {:.3} s, {}",
            x.build_seconds,
            x.memory.map_or("memory not reported by this backend".to_owned(), |m| format!(
                "{:.1} KiB (BLAS + TLAS; {:.0} bytes a triangle)",
                m as f64 / 1024.0,
                m as f64 / scene.triangles.len().max(1) as f64
            ))
        ),
        None => println!("  hardware path: not traced ({})", gs.rays_why),
    }
    println!("  GPU: {} ({:?}); CPU twin: {threads} threads (rayon)", gpu.info.name, gpu.info.backend);
    for f in &figures {
        let gpu_columns: Vec<String> = f
            .paths
            .iter()
            .map(|(p, s, d)| format!("{} {:>8.3} M rays/s ({d} disagree)", p.name(), f.rays as f64 / s / 1e6))
            .collect();
        println!(
            "  {:<7} {:<35} {:>8} rays: {}, CPU {:>8.3} M rays/s",
            f.kind.name(),
            format!("({})", f.kind.description()),
            f.rays,
            gpu_columns.join(", "),
            f.rays as f64 / f.cpu_s / 1e6,
        );
    }
    Ok(())
}
