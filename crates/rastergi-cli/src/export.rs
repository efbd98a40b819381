//! `rastergi export`: writes a scene (a built-in one, or a loaded file) as Wavefront OBJ + MTL.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use rastergi::scene::export::write_obj;

use crate::args::load_scene;

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// The scene: built in (`cornell`, `atrium`, `spheres:N`, `rooms`, `glossy-room`, `sunroom`) or a file rastergi reads.
    scene: String,
    /// The .obj file to write; its materials go to the .mtl file of the same name beside it.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(args: &ExportArgs) -> Result<()> {
    if !args.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj")) {
        anyhow::bail!("{}: give --out a file name ending in .obj", args.out.display());
    }
    let scene = load_scene(&args.scene)?;
    let start = Instant::now();
    let comment = format!("rastergi export {} (rastergi {})", args.scene, env!("CARGO_PKG_VERSION"));
    write_obj(&scene, &args.out, &comment)?;
    log::info!("{} triangles written in {:.2} s", scene.triangles.len(), start.elapsed().as_secs_f64());
    Ok(())
}
