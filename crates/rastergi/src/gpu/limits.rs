//! Device limits checked before allocation. Every GPU buffer whose size the user controls —
//! through the scene's triangle count, the image size, the gather's bundle or the photon
//! grid — is measured against the device's limits before it is created, so an oversized
//! request ends in one line that says what is too big and what to change, not in a wgpu
//! validation panic. Pure functions of [`wgpu::Limits`], so they are tested without a GPU. The
//! checks of one pass's buffers live with the pass (`gpu_scene::check_scene`,
//! `photons::map::check_photon_slots`, …) and use [`check_storage_buffer`].

use crate::error::{Error, Result};

/// Largest buffer this device can create and bind whole as a storage buffer.
pub fn max_storage_buffer(limits: &wgpu::Limits) -> u64 {
    limits.max_storage_buffer_binding_size.min(limits.max_buffer_size)
}

/// A size for messages: `12 MiB`, `1.5 MiB`.
pub fn mib(bytes: u64) -> String {
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

/// Limits of `binding_mib` MiB per storage binding and twice that per buffer, for tests.
#[cfg(test)]
pub(crate) fn test_limits(binding_mib: u64) -> wgpu::Limits {
    wgpu::Limits {
        max_storage_buffer_binding_size: binding_mib << 20,
        max_buffer_size: 2 * (binding_mib << 20),
        ..wgpu::Limits::default()
    }
}

#[cfg(test)]
mod tests {
    use super::test_limits as limits;
    use super::*;

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
