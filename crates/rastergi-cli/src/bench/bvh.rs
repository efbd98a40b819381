//! `rastergi bench bvh`: scene loading and BVH build times, and the tree's shape.

use std::time::Instant;

use anyhow::Result;
use clap::Args;

use super::median;
use crate::args::load_scene;

#[derive(Args, Debug)]
pub struct BvhArgs {
    /// The scene: built in (`cornell`, `atrium`, `spheres:N`, `rooms`, `glossy-room`, `sunroom`) or a file.
    #[arg(default_value = "spheres:1000000")]
    scene: String,
    /// Timed builds (the median is reported).
    #[arg(long, default_value_t = 3)]
    repeats: u32,
}

/// Load time, then the median BVH build time over the repeats (single-threaded binned SAH)
/// and the tree's size, depth and leaf occupancy.
pub fn run(a: &BvhArgs) -> Result<()> {
    let t = Instant::now();
    let scene = load_scene(&a.scene)?;
    let load = t.elapsed().as_secs_f64();
    scene.validate()?;
    let mut times = Vec::new();
    let mut built = None;
    for _ in 0..a.repeats.max(1) {
        let t = Instant::now();
        let b = rastergi::bvh::Bvh::build(&scene.triangles);
        times.push(t.elapsed());
        built = Some(b);
    }
    let b = built.expect("at least one build");
    let leaves: Vec<u32> = b.nodes.iter().filter(|n| n.count > 0).map(|n| n.count).collect();
    let n = scene.triangles.len() as f64;
    let build = median(times).as_secs_f64();
    println!("BVH: {} ({} triangles)", a.scene, scene.triangles.len());
    println!("  load   {load:>8.3} s");
    println!("  build  {build:>8.3} s  ({:.2} M triangles/s, median of {})", n / build / 1e6, a.repeats.max(1));
    println!(
        "  {} nodes, depth {}, {} leaves of {:.2} triangles on average (at most {})",
        b.nodes.len(),
        b.depth(),
        leaves.len(),
        n / leaves.len() as f64,
        leaves.iter().max().unwrap_or(&0)
    );
    Ok(())
}
