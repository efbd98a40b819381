//! Device limits checked before allocation. Every GPU buffer whose size the user controls —
//! through the scene's triangle count, the image size, the gather's bundle or the photon
//! grid — is measured against the device's limits before it is created, so an oversized
//! request ends in one line that says what is too big and what to change, not in a wgpu
//! validation panic. Pure functions of [`wgpu::Limits`], so they are tested without a GPU.

use crate::error::{Error, Result};
use crate::photons::map::{BINS, GridSpec};

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

/// The photon map of `grid` (`photons/gpu.rs`): a 3D texture of (nx, ny, 6·nz) texels and
/// 64-bit counters for three channels per slot (24 bytes, one binding of 8 bytes per slot for
/// each channel).
pub fn check_photon_grid(limits: &wgpu::Limits, grid: &GridSpec) -> Result<()> {
    let d = grid.dims;
    let max = limits.max_texture_dimension_3d;
    if d.max_element() > max || BINS as u64 * d.z as u64 > max as u64 {
        return Err(Error::Limits(format!(
            "a photon grid of {}x{}x{} cells needs a 3D texture of {}x{}x{} texels, more than this GPU's {max} per side; choose a smaller --grid",
            d.x,
            d.y,
            d.z,
            d.x,
            d.y,
            BINS as u64 * d.z as u64
        )));
    }
    let what = format!("a photon grid of {}x{}x{} cells", d.x, d.y, d.z);
    check_storage_buffer(
        limits,
        &format!("the counters of {what}"),
        grid.slot_count() as u64,
        8,
        "choose a smaller --grid",
    )?;
    let total = grid.slot_count() as u64 * 24;
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
    fn photon_grid_is_checked_against_texture_depth_and_counter_buffer() {
        let bounds = crate::scene::Aabb { min: glam::Vec3::ZERO, max: glam::Vec3::ONE };
        let l = wgpu::Limits { max_texture_dimension_3d: 2048, max_buffer_size: 1 << 30, ..limits(128) };
        // 128³ cells: 6·128 = 768 texels deep, 128³·6·8 bytes = 96 MiB of counters per channel.
        assert!(check_photon_grid(&l, &GridSpec::new(&bounds, 128)).is_ok());
        // 160³: 160³·6·8 bytes = 187.5 MiB per channel.
        let e = check_photon_grid(&l, &GridSpec::new(&bounds, 160)).unwrap_err().to_string();
        assert!(e.contains("160x160x160") && e.contains("188 MiB") && e.contains("--grid"), "{e}");
        // All three channels live in one buffer: 288 MiB for 128³.
        let small = wgpu::Limits { max_buffer_size: 256 << 20, ..l.clone() };
        let e = check_photon_grid(&small, &GridSpec::new(&bounds, 128)).unwrap_err().to_string();
        assert!(e.contains("288 MiB") && e.contains("one buffer"), "{e}");
        // 400 cells deep need 2400 texels: deeper than 2048.
        let e = check_photon_grid(&l, &GridSpec::new(&bounds, 400)).unwrap_err().to_string();
        assert!(e.contains("2400") && e.contains("2048"), "{e}");
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
