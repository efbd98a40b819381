//! Writes the microfacet albedo tables that `bsdf/albedo.rs` includes: the GGX lobe's
//! (`crates/rastergi/src/bsdf/ggx_albedo.bin`, every cell integrated by
//! [`rastergi::bsdf::albedo::ggx_cell`]) and the rough glass's single-scattering albedo
//! (`glass_albedo.bin`, by [`rastergi::bsdf::albedo::glass_cell`]).
//!
//! `cargo run --release -p rastergi --example albedo_tables`

fn main() -> std::io::Result<()> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/bsdf");
    let ggx = rastergi::bsdf::albedo::GgxAlbedo::compute();
    let bytes: Vec<u8> = ggx.e.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join("ggx_albedo.bin"), bytes)?;
    println!("{} GGX cells written to {}", ggx.e.len(), dir.join("ggx_albedo.bin").display());
    let glass = rastergi::bsdf::albedo::GlassAlbedo::compute();
    let bytes: Vec<u8> = glass.e.iter().flat_map(|v| v.to_le_bytes()).collect();
    std::fs::write(dir.join("glass_albedo.bin"), bytes)?;
    println!("{} glass cells written to {}", glass.e.len(), dir.join("glass_albedo.bin").display());
    Ok(())
}
