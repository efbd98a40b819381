//! Writes the rough glass's single-scattering albedo table that `bsdf/albedo.rs` includes
//! (`crates/rastergi/src/bsdf/glass_albedo.bin`): every cell integrated by
//! [`rastergi::bsdf::albedo::glass_cell`].
//!
//! `cargo run --release -p rastergi --example glass_albedo_table`

fn main() -> std::io::Result<()> {
    let table = rastergi::bsdf::albedo::GlassAlbedo::compute();
    let bytes: Vec<u8> = table.e.iter().flat_map(|v| v.to_le_bytes()).collect();
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/bsdf/glass_albedo.bin");
    std::fs::write(&path, bytes)?;
    println!("{} cells written to {}", table.e.len(), path.display());
    Ok(())
}
