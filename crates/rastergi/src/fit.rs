//! Settings that fit the scene, for front ends whose user gave none: the photon grid's
//! resolution, the photon count and the exposure of a display image. Each rule is calibrated
//! so the built-in Cornell box keeps the defaults its documented figures were measured with
//! (grid 64, 2²⁰ photons, exposure 0), and each reduces to a statement a user can check:
//!
//! - **Grid**: as many cubic cells as the Cornell box's 64³, whatever the scene's shape. A
//!   cube gets 64 cells per side; a corridor ten times longer than wide gets about 300 along
//!   its length and 30 across, where "64 along the longest axis" would give it only 6 across.
//!   Memory stays that of the 64³ grid (about 70 MB).
//! - **Photons**: about [`PHOTONS_PER_CELL_AREA`] photons per cell-sized patch of surface
//!   (total surface area A over the cell's face h²), so a cell's irradiance estimate has
//!   about the same noise as in the Cornell box; rounded to a power of two, from 2¹⁸ to 2²⁴;
//!   for progressive passes at the fitted cadence, at most what keeps a pass within about 64
//!   iterations of the image ([`photons_for_image`]): a small image of a large scene gets
//!   several smaller maps in a render rather than one large one it never leaves.
//! - **Bundle** (the gather's ray-view resolution): at least [`TEXELS_PER_EDGE`] texels
//!   across the median triangle's shortest edge, over the scene's bounding sphere (the ray
//!   view's width), and never less than twice the image's larger side
//!   ([`default_bundle`]); 128 to 2048. A ray-view texel samples one
//!   surface: a gather ray from a point on a curved, tessellated surface (a column, a vault)
//!   can meet the plane of a neighbouring facet that covers the same texel. The raster
//!   gathers trace such rays where they cross the plane off the facet; before they did, it
//!   darkened such surfaces by about 10 % × texel / facet (measured on `atrium`: −5.4 %,
//!   −3.2 %, −1.6 %, −0.9 % at 192, 384, 768, 1536 texels for its 10 cm facets), and eight
//!   texels per edge kept that near 1 %. Fewer such rays need tracing at that resolution, and
//!   silhouettes are sampled finer. Flat scenes such as the Cornell box get the image-size
//!   rule unchanged.
//! - **Exposure** (PNG): 0 unless the image's median luminance (over pixels that see
//!   anything) is more than two stops away from middle grey 0.18; then the whole number of
//!   stops that brings it to 0.18. A guard rail for scenes whose emitters are far too
//!   strong or weak, not a tone mapper: a reasonably lit image is left as rendered.

use glam::Vec3;

use crate::image_io::LinearImage;
use crate::photons::map::{GridSpec, PhotonRegion};
use crate::sampling::{Rng, cosine_hemisphere};
use crate::scene::{Aabb, Camera, Scene, triangle_area, triangle_normal};
use crate::surface::PreparedScene;

/// The default ray-view resolution: twice the image's larger side, within [128, 2048], so a
/// ray-view texel is about as wide as an eye pixel's footprint on a scene seen whole.
pub fn default_bundle(width: u32, height: u32) -> u32 {
    (2 * width.max(height)).clamp(128, 2048)
}

/// Grid cells of the Cornell box's default grid, the budget every scene gets.
pub const GRID_CELL_BUDGET: u64 = 64 * 64 * 64;
/// Largest fitted resolution (a flat scene gets about 500 × 1 × 500 cells).
pub const MAX_GRID: u32 = 512;
/// Photons per h² of surface: the Cornell box's 2²⁰ photons over its ≈ 25 m² of surface in
/// cells of h = 3.1 cm (≈ 25 000 patches) are ≈ 41 per patch; 40 puts it in the middle of the
/// band that rounds to 2²⁰.
pub const PHOTONS_PER_CELL_AREA: f64 = 40.0;
/// Range of fitted photon counts.
pub const MIN_PHOTONS: u32 = 1 << 18;
pub const MAX_PHOTONS: u32 = 1 << 24;
/// Ray-view texels across the median triangle's shortest edge (see the module's notes).
pub const TEXELS_PER_EDGE: f64 = 8.0;
/// Range of the fitted bundle (the larger bound keeps a ray-view layer at 16 MiB).
pub const MIN_BUNDLE: u32 = 128;
pub const MAX_BUNDLE: u32 = 2048;
/// Middle grey, and how far (in stops) an image's median may stray from it unadjusted.
pub const MIDDLE_GREY: f64 = 0.18;
pub const EXPOSURE_DEAD_BAND: f64 = 2.0;

/// The largest grid resolution (cells along the longest axis) whose grid over `bounds` has
/// at most [`GRID_CELL_BUDGET`] cells, within 1 ..= [`MAX_GRID`].
pub fn grid_resolution(bounds: &Aabb) -> u32 {
    // The cell count grows with the resolution: bisect for the last one within budget.
    let cells = |r: u32| GridSpec::new(bounds, r).cell_count();
    let (mut lo, mut hi) = (1u32, MAX_GRID);
    if cells(hi) <= GRID_CELL_BUDGET {
        return hi;
    }
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if cells(mid) <= GRID_CELL_BUDGET { lo = mid } else { hi = mid }
    }
    lo
}

/// Photons for `scene` in a grid of `resolution` over its bounds: [`PHOTONS_PER_CELL_AREA`]
/// per cell-sized patch of its surface, rounded to the nearest power of two and clamped to
/// [`MIN_PHOTONS`] ..= [`MAX_PHOTONS`].
pub fn photon_count(scene: &Scene, resolution: u32) -> u32 {
    let grid = GridSpec::new(&scene.bounds(), resolution);
    let area: f64 = scene.triangles.iter().map(|t| triangle_area(t) as f64).sum();
    let patches = area / (grid.cell as f64).powi(2);
    let wanted = (PHOTONS_PER_CELL_AREA * patches).max(1.0);
    let exponent = wanted.log2().round().clamp(MIN_PHOTONS.ilog2() as f64, MAX_PHOTONS.ilog2() as f64);
    1 << exponent as u32
}

/// Longest photon pass of the fitted settings, in iterations ([`photons_for_image`]).
pub const MAX_FITTED_PASS_ITERATIONS: u64 = 64;

/// The fitted photon count `photons` of a render of `pixels` pixels with progressive passes at
/// the fitted cadence (4·photons/pixels iterations per pass, at least 16:
/// [`crate::photons::passes::fitted_pass_iterations`]), capped at pixels ·
/// [`MAX_FITTED_PASS_ITERATIONS`] / 4 rounded to the nearest power of two, so that a pass lasts
/// at most about 64 iterations. A pass's map is one estimate whose error the image keeps until
/// the next pass; the error falls with the number of passes (`photons::passes`), so a render
/// of 1024 iterations at 96 × 72 of a scene fitted 2²¹ photons, whose pass would last 1214
/// iterations, stayed on its first map: the sunlit room came out 4 % bright in its means and
/// 3.9 % in its blocks against Mitsuba; with 2¹⁷ photons a pass (76 iterations) it is within
/// 0.8 % in both, in less time. Images of 256 × 256 and larger keep the scene's count up to 2²⁰
/// (the Cornell box's unchanged there); none gets fewer than [`MIN_PASS_PHOTONS`].
pub fn photons_for_image(photons: u32, pixels: u64) -> u32 {
    let wanted = (pixels.max(1) * MAX_FITTED_PASS_ITERATIONS / 4) as f64;
    let cap = (1u64 << (wanted.log2().round() as u32).min(31)).max(MIN_PASS_PHOTONS as u64);
    photons.min(cap.min(u32::MAX as u64) as u32)
}

/// The fitted photon count `photons` of a pass of a balanced render of `pixels` pixels
/// ([`crate::photons::budget`]): the budget chooses how long a pass lasts, but at most
/// [`crate::photons::budget::MAX_ITERATIONS`], so a thumbnail of a large scene is capped at 256
/// photons per pixel (16 times [`photons_for_image`]'s cap): a pass of 2²⁴ photons for a
/// 48 × 27 image took seconds for a few milliseconds of iterations.
pub fn photons_for_balanced_image(photons: u32, pixels: u64) -> u32 {
    photons_for_image(photons, pixels.saturating_mul(16))
}

/// The fewest photons [`photons_for_image`] leaves a pass (a thumbnail keeps a usable map).
pub const MIN_PASS_PHOTONS: u32 = 1 << 16;

/// The ray-view resolution the scene's detail asks for: [`TEXELS_PER_EDGE`] texels across
/// the median (over triangles of non-zero size) of the triangles' shortest edges, over the
/// diameter of the scene's bounding sphere; within [`MIN_BUNDLE`] ..= [`MAX_BUNDLE`].
pub fn detail_bundle(scene: &Scene) -> u32 {
    let mut edges: Vec<f32> = scene
        .triangles
        .iter()
        .map(|t| (t[1] - t[0]).length().min((t[2] - t[1]).length()).min((t[0] - t[2]).length()))
        .filter(|&e| e > 0.0 && e.is_finite())
        .collect();
    if edges.is_empty() {
        return MIN_BUNDLE;
    }
    let mid = edges.len() / 2;
    let edge = *edges.select_nth_unstable_by(mid, f32::total_cmp).1 as f64;
    // The ray view spans the bounding sphere's diameter (`gather::ray_view_projection`).
    let diameter = scene.bounds().extent().length() as f64 * 1.001;
    (TEXELS_PER_EDGE * diameter / edge).ceil().clamp(MIN_BUNDLE as f64, MAX_BUNDLE as f64) as u32
}

/// The bundle for a `width × height` image of a scene whose [`detail_bundle`] is `detail`:
/// the larger of that and [`default_bundle`].
pub fn bundle(detail: u32, width: u32, height: u32) -> u32 {
    default_bundle(width, height).max(detail).clamp(MIN_BUNDLE, MAX_BUNDLE)
}

/// Camera rays across the image (columns × rows, at the image's aspect) that probe where the
/// camera reads the photon map, and gather rays from each point they hit.
pub const REGION_PROBE: (u32, u32) = (64, 48);
pub const REGION_GATHER_RAYS: u32 = 4;
/// The fraction of probe points left out at each end of each axis: the region is where most
/// reads are, not every far patch a ray through a window reaches.
pub const REGION_TRIM: f64 = 0.01;
/// The region's margin on each side, as a fraction of its extent.
pub const REGION_MARGIN: f32 = 0.05;

/// Where the camera reads the photon map, and how much finer its cells are there
/// ([`PhotonRegion`]): `None` where that is the whole scene anyway.
///
/// The probe: [`REGION_PROBE`] camera rays through the image (aspect `aspect` = width /
/// height), and from each surface point they reach [`REGION_GATHER_RAYS`] cosine-distributed
/// rays, the directions the final gather samples; the points these rays hit are what the
/// passes look up in the map. The region is the box of those points, trimmed by
/// [`REGION_TRIM`] at each end of each axis and padded by [`REGION_MARGIN`]. Its cells get
/// the same cell budget as a whole scene ([`grid_resolution`]), scaled as `resolution` is
/// against the scene's fitted resolution (a user's `--grid` twice the fit refines twice as
/// finely); `factor` is the coarse cell over the region's cell, rounded. An interior
/// standing on a ground plane two hundred metres wide gets cells sized to the room, not to
/// the ground.
pub fn photon_region(prepared: &PreparedScene, camera: &Camera, aspect: f32, resolution: u32) -> Option<PhotonRegion> {
    let scene = &prepared.scene;
    let triangles = &scene.triangles;
    let (right, up, forward) = camera.frame();
    let tan = (camera.fov_y_deg.to_radians() * 0.5).tan();
    let (cols, rows) = REGION_PROBE;
    let mut rng = Rng::new(0x5e61, 0, 0);
    let mut points: Vec<Vec3> = Vec::new();
    let hit_point = |o: Vec3, d: Vec3, skip: u32| {
        (prepared.bvh.intersect(triangles, o, d, 0.0, f32::INFINITY, skip, |_| true)).map(|h| (o + d * h.t, h.triangle))
    };
    let eps = prepared.ray_epsilon();
    for j in 0..rows {
        for i in 0..cols {
            let x = (2.0 * (i as f32 + rng.next_f32()) / cols as f32 - 1.0) * tan * aspect;
            let y = (1.0 - 2.0 * (j as f32 + rng.next_f32()) / rows as f32) * tan;
            let d = (forward + right * x + up * y).normalize();
            let Some((p, tri)) = hit_point(camera.eye, d, u32::MAX) else { continue };
            points.push(p);
            let n = triangle_normal(&triangles[tri as usize]);
            let n = if n.dot(d) > 0.0 { -n } else { n };
            for _ in 0..REGION_GATHER_RAYS {
                let w = cosine_hemisphere(n, rng.next_f32(), rng.next_f32());
                if let Some((q, _)) = hit_point(p + n * eps, w, tri) {
                    points.push(q);
                }
            }
        }
    }
    if points.len() < 16 {
        return None;
    }
    let mut region = Aabb::EMPTY;
    for axis in 0..3 {
        let mut v: Vec<f32> = points.iter().map(|p| p[axis]).collect();
        v.sort_unstable_by(f32::total_cmp);
        let k = ((REGION_TRIM * v.len() as f64) as usize).min(v.len() / 2);
        region.min[axis] = v[k];
        region.max[axis] = v[v.len() - 1 - k];
    }
    let margin = REGION_MARGIN * region.extent().max_element();
    region.min -= Vec3::splat(margin);
    region.max += Vec3::splat(margin);
    let bounds = scene.bounds();
    region.min = region.min.max(bounds.min);
    region.max = region.max.min(bounds.max);
    let coarse = GridSpec::new(&bounds, resolution).cell;
    let scale = resolution as f32 / grid_resolution(&bounds) as f32;
    let fine_resolution = ((grid_resolution(&region) as f32 * scale).round() as u32).max(1);
    let fine = GridSpec::new(&region, fine_resolution).cell;
    let factor = (coarse / fine).round() as u32;
    (factor >= 2).then_some(PhotonRegion { bounds: region, factor: factor.min(MAX_REGION_FACTOR) })
}

/// The finest refinement: fine cells at most this many times smaller than the coarse ones.
pub const MAX_REGION_FACTOR: u32 = 64;

/// Rec. 709 luminance of a linear RGB pixel.
fn luminance(p: &[f32; 3]) -> f64 {
    0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64
}

/// The exposure (stops) for displaying `image`: 0 when the median luminance of its non-black
/// pixels lies within [`EXPOSURE_DEAD_BAND`] stops of [`MIDDLE_GREY`], else the whole number
/// of stops that brings the median to middle grey. A black image gets 0.
pub fn exposure(image: &LinearImage) -> f32 {
    let mut lit: Vec<f64> = image.pixels.iter().map(luminance).filter(|l| l.is_finite() && *l > 0.0).collect();
    if lit.is_empty() {
        return 0.0;
    }
    let mid = lit.len() / 2;
    let median = *lit.select_nth_unstable_by(mid, f64::total_cmp).1;
    let stops = (MIDDLE_GREY / median).log2();
    if stops.abs() <= EXPOSURE_DEAD_BAND { 0.0 } else { stops.round().clamp(-64.0, 64.0) as f32 }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::scene::{Camera, Material, cornell_box, generate};

    #[test]
    fn cornell_box_keeps_the_documented_defaults() {
        let s = cornell_box();
        let grid = grid_resolution(&s.bounds());
        assert_eq!(grid, 64);
        assert_eq!(photon_count(&s, grid), 1 << 20);
        // Cornell's photon count is not at the edge of its rounding band: ±25 % keeps it.
        let area: f64 = s.triangles.iter().map(|t| triangle_area(t) as f64).sum();
        let h = GridSpec::new(&s.bounds(), 64).cell as f64;
        let exponent = (PHOTONS_PER_CELL_AREA * area / (h * h)).log2();
        assert!((exponent - 20.0).abs() < 0.5 - 0.32, "log2 of Cornell's photons {exponent}");
    }

    fn slab(extent: Vec3) -> Scene {
        let camera = Camera { eye: Vec3::Z * 10.0, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 45.0 };
        let mut s = Scene::new(camera);
        let m = s.add_material(Material::diffuse("m", Vec3::splat(0.5)));
        let e = extent;
        s.add_triangle([Vec3::ZERO, Vec3::new(e.x, 0.0, 0.0), Vec3::new(0.0, e.y, 0.0)], m);
        s.add_triangle([Vec3::ZERO, Vec3::new(0.0, 0.0, e.z), Vec3::new(e.x, e.y, e.z)], m);
        s
    }

    #[test]
    fn grid_keeps_the_cell_budget_whatever_the_shape() {
        for extent in [Vec3::splat(2.0), Vec3::new(20.0, 2.0, 2.0), Vec3::new(8.0, 4.5, 9.0), Vec3::new(5.0, 1.0, 0.1)]
        {
            let bounds = slab(extent).bounds();
            let r = grid_resolution(&bounds);
            let cells = |r| GridSpec::new(&bounds, r).cell_count();
            println!("extent {extent}: resolution {r}, {} cells", cells(r));
            assert!(cells(r) <= GRID_CELL_BUDGET && (r == MAX_GRID || cells(r + 1) > GRID_CELL_BUDGET));
            // Within a factor two of the budget, unless the shape is flatter than the cap allows.
            assert!(r == MAX_GRID || cells(r) * 2 > GRID_CELL_BUDGET);
        }
        // A corridor ten times longer than wide: cells along its width, not just its length.
        let corridor = slab(Vec3::new(20.0, 2.0, 2.0)).bounds();
        let corridor = GridSpec::new(&corridor, grid_resolution(&corridor));
        assert!(corridor.dims.y >= 25, "{:?}", corridor.dims);
        // A flat square: one cell thick (the grid's padding makes it two from 501 on).
        let flat = slab(Vec3::new(4.0, 0.0, 4.0)).bounds();
        assert_eq!(GridSpec::new(&flat, grid_resolution(&flat)).dims.y, 1);
        assert!(grid_resolution(&flat) >= 500);
    }

    #[test]
    fn photons_grow_with_surface_per_cell_and_stay_powers_of_two_in_range() {
        let atrium = generate::atrium();
        let r = grid_resolution(&atrium.bounds());
        let n = photon_count(&atrium, r);
        println!("atrium: grid {r}, {n} photons");
        assert!(n.is_power_of_two() && (MIN_PHOTONS..=MAX_PHOTONS).contains(&n));
        // Doubling the resolution quarters the cell face: four times the photons.
        let s = cornell_box();
        assert_eq!(photon_count(&s, 128), 4 << 20);
        // The cap of progressive passes: 256² keeps 2²⁰, 96 × 72 (110 592 · 4/…) gets 2¹⁷,
        // whose pass at the fitted cadence lasts 76 iterations instead of 1214 for 2²¹.
        assert_eq!(photons_for_image(1 << 20, 256 * 256), 1 << 20);
        assert_eq!(photons_for_image(1 << 21, 96 * 72), 1 << 17);
        assert_eq!(crate::photons::passes::fitted_pass_iterations(1 << 17, 96 * 72), 76);
        assert_eq!(photons_for_image(1 << 18, 1920 * 1080), 1 << 18);
        assert_eq!(photons_for_image(1 << 20, 16 * 16), MIN_PASS_PHOTONS);
        assert_eq!(photon_count(&s, 4), MIN_PHOTONS);
        assert_eq!(photon_count(&s, 1024), MAX_PHOTONS);
    }

    #[test]
    fn bundle_follows_the_scene_detail_but_leaves_flat_scenes_to_the_image_size() {
        // Cornell: 60 cm edges over a 3.5 m sphere ask for 47 texels: the image decides.
        let cornell = detail_bundle(&cornell_box());
        assert_eq!(cornell, MIN_BUNDLE);
        assert_eq!(bundle(cornell, 256, 256), 512);
        assert_eq!(bundle(cornell, 128, 128), default_bundle(128, 128));
        // Atrium: 10 cm facets over a 12.9 m sphere: 8 · 128.7 ≈ 1030 texels.
        let atrium = detail_bundle(&generate::atrium());
        assert!((1000..1060).contains(&atrium), "{atrium}");
        assert_eq!(bundle(atrium, 64, 48), atrium);
        assert_eq!(bundle(atrium, 1024, 768), 2048);
        // A million triangles of 3 cm facets: the cap.
        assert_eq!(detail_bundle(&generate::spheres(100_000)), MAX_BUNDLE);
    }

    fn image(values: &[f32]) -> LinearImage {
        LinearImage { width: values.len() as u32, height: 1, pixels: values.iter().map(|&v| [v; 3]).collect() }
    }

    #[test]
    fn exposure_leaves_reasonable_images_alone_and_fixes_far_off_ones() {
        // Median 0.05 (1.85 stops under grey, as the Cornell box's 0.06) and 0.6: unchanged.
        assert_eq!(exposure(&image(&[0.0, 0.0, 0.01, 0.05, 100.0])), 0.0);
        assert_eq!(exposure(&image(&[0.3, 0.6, 0.9])), 0.0);
        // 100× too bright: 0.18/18 → −6.6 stops → −7; 1000× too dark: +10.
        assert_eq!(exposure(&image(&[18.0, 18.0, 1e4])), -7.0);
        assert_eq!(exposure(&image(&[0.00018, 0.0, 0.00018])), 10.0);
        // Black and non-finite pixels do not count; an all-black image is left alone.
        assert_eq!(exposure(&image(&[0.0, f32::NAN, 0.0])), 0.0);
    }
}
