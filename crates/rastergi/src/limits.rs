//! Device limits checked before allocation. Every GPU buffer whose size the user controls —
//! through the scene's triangle count, the image size, the gather's bundle or the photon
//! grid — is measured against the device's limits before it is created, so an oversized
//! request ends in one line that says what is too big and what to change, not in a wgpu
//! validation panic. Pure functions of [`wgpu::Limits`], so they are tested without a GPU.

use crate::error::{Error, Result};
use crate::photons::map::{GridSpec, MapLayout};

/// Largest buffer this device can create and bind whole as a storage buffer.
pub fn max_storage_buffer(limits: &wgpu::Limits) -> u64 {
    limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
}

fn mib(bytes: u64) -> String {
    let m = bytes as f64 / (1 << 20) as f64;
    if m >= 10.0 { format!("{m:.0} MiB") } else { format!("{m:.1} MiB") }
}

/// Checks that `count` items of `stride` bytes fit one storage buffer; the error names
/// `what`, the sizes, and `remedy` (what the user can change).
pub fn check_storage_buffer(limits: &wgpu::Limits, what: &str, count: u64, stride: u64, remedy: &str) -> Result<()> {
    let max = max_storage_buffer(limits);
    match count.checked_mul(stride) {
        Some(bytes) if bytes <= max => Ok(()),
        bytes => {
            let (mut need, mut have) = (bytes.map_or_else(|| "more than 2⁶⁴ bytes".to_owned(), mib), mib(max));
            if need == have {
                // Just over the limit: the rounded sizes would read the same.
                (need, have) = (format!("{} bytes", bytes.unwrap_or(u64::MAX)), format!("{max} bytes"));
            }
            Err(Error::Limits(format!(
                "{what} need {need} ({count} × {stride} bytes), more than the {have} this GPU binds as one buffer; {remedy}"
            )))
        }
    }
}

const FEWER_TRIANGLES: &str =
    "use a scene with fewer triangles (or a GPU with larger storage buffers: `rastergi info` shows the limit)";

/// The scene's buffers (`gpu_scene.rs`) that the triangle, material and emitter counts fix:
/// checked before the BVH is built, so an impossible scene fails at once.
pub fn check_scene_buffers(limits: &wgpu::Limits, triangles: usize, materials: usize, lights: usize) -> Result<()> {
    let fewer = FEWER_TRIANGLES;
    let triangle_stride = std::mem::size_of::<crate::gpu_scene::GpuTriangle>() as u64;
    let material_stride = std::mem::size_of::<crate::gpu_scene::GpuMaterial>() as u64;
    let light_stride = std::mem::size_of::<crate::lights::LightEntry>() as u64;
    let what = format!("the scene's {triangles} triangles");
    check_storage_buffer(limits, &what, triangles as u64, triangle_stride, fewer)?;
    // `3 · triangles` vertices are drawn by one non-indexed draw call.
    if triangles as u64 * 3 > u32::MAX as u64 {
        return Err(Error::Limits(format!("{what} are more than one draw call can hold (1 431 655 765); {fewer}")));
    }
    check_storage_buffer(limits, "the scene's materials", materials as u64, material_stride, "use fewer materials")?;
    check_storage_buffer(limits, "the scene's emissive triangles", lights as u64, light_stride, "use fewer emitters")
}

/// [`check_scene_buffers`] for `scene`, with its triangle count bounding its emitters'.
pub fn check_scene(limits: &wgpu::Limits, scene: &crate::scene::Scene) -> Result<()> {
    check_scene_buffers(limits, scene.triangles.len(), scene.materials.len(), scene.triangles.len())
}

/// The BVH's node buffer, once the BVH is built (about one node per triangle, at most 2·n − 1).
pub fn check_bvh_nodes(limits: &wgpu::Limits, nodes: usize) -> Result<()> {
    let stride = std::mem::size_of::<crate::bvh::BvhNode>() as u64;
    check_storage_buffer(limits, &format!("the scene's {nodes} BVH nodes"), nodes as u64, stride, FEWER_TRIANGLES)
}

/// The photon grid: its cells must have 31-bit indices (the first word of a slot's key; its
/// top bit marks caustic twins, `CAUSTIC_CELL`).
pub fn check_photon_grid(_limits: &wgpu::Limits, grid: &GridSpec) -> Result<()> {
    let d = grid.dims;
    if grid.cell_count() >= crate::consts::CAUSTIC_CELL as u64 {
        return Err(Error::Limits(format!(
            "a photon grid of {}x{}x{} cells has more than 2^31 cells; choose a smaller --grid",
            d.x, d.y, d.z
        )));
    }
    Ok(())
}

/// The photon map's slots (`photons/gpu.rs`): per table entry 64-bit counters for three
/// channels (one binding of 8 bytes per entry for each), the lookup values (16 bytes), the keys
/// (8) and the areas (4), each against the binding limit, and all of them against the largest
/// buffer.
pub fn check_photon_slots(limits: &wgpu::Limits, layout: &MapLayout) -> Result<()> {
    let d = layout.grid.dims;
    let entries = layout.table.capacity() as u64;
    let what = format!("the {} slots of a photon grid of {}x{}x{} cells", layout.table.len(), d.x, d.y, d.z);
    for (part, stride) in [("counters", 8), ("lookup values", 16), ("keys", 8)] {
        check_storage_buffer(limits, &format!("the {part} of {what}"), entries, stride, "choose a smaller --grid")?;
    }
    let total = entries * 24;
    if total > limits.max_buffer_size {
        return Err(Error::Limits(format!(
            "the counters of {what} need {} in one buffer, more than this GPU's {}; choose a smaller --grid",
            mib(total),
            mib(limits.max_buffer_size)
        )));
    }
    Ok(())
}

/// The raster gathers' ray view: its side against the texture limit, and one 4-byte counter
/// per texel (the peel's depth complexity, `gather_raster.rs`; the list heads,
/// `gather_lists.rs`) against the binding limit.
pub fn check_bundle(limits: &wgpu::Limits, bundle: u32) -> Result<()> {
    let max = limits.max_texture_dimension_2d;
    if bundle == 0 || bundle > max {
        return Err(Error::Limits(format!(
            "a ray-view bundle of {bundle}x{bundle} texels exceeds this GPU's limit of 1 to {max} per side; choose a smaller --bundle"
        )));
    }
    let what = format!("the gather's {bundle}x{bundle} per-texel counters (depth complexity or list heads)");
    check_storage_buffer(limits, &what, bundle as u64 * bundle as u64, 4, "choose a smaller --bundle")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(binding_mib: u64) -> wgpu::Limits {
        wgpu::Limits {
            max_storage_buffer_binding_size: binding_mib << 20,
            max_buffer_size: 2 * (binding_mib << 20),
            ..wgpu::Limits::default()
        }
    }

    #[test]
    fn a_scene_whose_triangles_exceed_the_binding_limit_is_refused_with_the_sizes() {
        // 48 bytes per triangle: 128 MiB hold 2 796 202 triangles.
        let l = limits(128);
        assert!(check_scene_buffers(&l, 2_796_202, 10, 2).is_ok());
        let e = check_scene_buffers(&l, 2_796_203, 10, 2).unwrap_err().to_string();
        println!("{e}");
        assert!(e.contains("2796203 triangles") && e.contains("fewer triangles"), "{e}");
        // One triangle over: the sizes in bytes, since both round to 128 MiB.
        assert!(e.contains("134217744 bytes") && e.contains("134217728 bytes"), "{e}");
        // 32 bytes per node: 128 MiB hold 4 194 304 nodes.
        assert!(check_bvh_nodes(&l, 4_194_304).is_ok());
        let e = check_bvh_nodes(&l, 4_194_305).unwrap_err().to_string();
        assert!(e.contains("4194305 BVH nodes") && e.contains("134217728 bytes"), "{e}");
    }

    #[test]
    fn the_smaller_of_binding_and_buffer_limits_applies() {
        let l =
            wgpu::Limits { max_storage_buffer_binding_size: 1 << 30, max_buffer_size: 1 << 20, ..Default::default() };
        assert_eq!(max_storage_buffer(&l), 1 << 20);
        assert!(check_storage_buffer(&l, "x", 1 << 18, 4, "").is_ok());
        assert!(check_storage_buffer(&l, "x", (1 << 18) + 1, 4, "").is_err());
        // Sizes that overflow 64 bits are refused, not wrapped.
        let e = check_storage_buffer(&l, "x", u64::MAX, 16, "less").unwrap_err().to_string();
        assert!(e.contains("2⁶⁴"), "{e}");
    }

    #[test]
    fn photon_cells_need_31_bit_indices_and_the_slots_must_fit_the_bindings() {
        let bounds = crate::scene::Aabb { min: glam::Vec3::ZERO, max: glam::Vec3::ONE };
        let l = limits(128);
        // 1280³ = 2.10·10⁹ cells fit 31 bits (the top bit marks caustic twins), 1300³ = 2.20·10⁹
        // do not.
        assert!(check_photon_grid(&l, &GridSpec::new(&bounds, 1280)).is_ok());
        let e = check_photon_grid(&l, &GridSpec::new(&bounds, 1300)).unwrap_err().to_string();
        assert!(e.contains("1300x1300x1300") && e.contains("--grid"), "{e}");
        // The largest per-entry binding is the lookup values' 16 bytes; all counters share a
        // buffer of 24 bytes per entry.
        let scene = crate::scene::cornell_box();
        let layout = MapLayout::new(&scene, &GridSpec::new(&scene.bounds(), 32));
        let entries = layout.table.capacity() as u64;
        let fits = wgpu::Limits {
            max_storage_buffer_binding_size: entries * 16,
            max_buffer_size: entries * 24,
            ..Default::default()
        };
        assert!(check_photon_slots(&fits, &layout).is_ok());
        let narrow = wgpu::Limits { max_storage_buffer_binding_size: entries * 16 - 4, ..fits.clone() };
        let e = check_photon_slots(&narrow, &layout).unwrap_err().to_string();
        assert!(e.contains("lookup values") && e.contains("32x32x32") && e.contains("--grid"), "{e}");
        let short = wgpu::Limits { max_buffer_size: entries * 24 - 1, ..fits };
        let e = check_photon_slots(&short, &layout).unwrap_err().to_string();
        assert!(e.contains("one buffer"), "{e}");
    }

    #[test]
    fn bundle_is_checked_against_texture_side_and_counter_buffer() {
        let l = limits(128);
        assert!(check_bundle(&l, 2048).is_ok());
        assert!(check_bundle(&l, 0).is_err());
        // 8192² counters of 4 bytes are 256 MiB: within the texture side, beyond the buffer.
        let l = wgpu::Limits { max_texture_dimension_2d: 16384, ..limits(128) };
        let e = check_bundle(&l, 8192).unwrap_err().to_string();
        assert!(e.contains("256 MiB") && e.contains("--bundle"), "{e}");
        assert!(check_bundle(&l, 16385).unwrap_err().to_string().contains("16384"));
    }
}
