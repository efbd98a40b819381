//! The grid photon map: a uniform 3D grid over the scene holding, per cell and per surface
//! orientation bin, the photon flux Φ deposited there and the surface area A inside the cell.
//!
//! * Irradiance of a cell is E = Φ / A with A the area of the scene's surfaces *inside the
//!   cell* (triangles clipped to the cell), so a flat, evenly lit surface is estimated without
//!   bias however it cuts the cell.
//! * Bins: the dominant axis and sign of the normal of the side a photon lands on (±x, ±y, ±z).
//!   The floor and the wall meeting in a corner cell, or the two sides of a thin wall, fall in
//!   different bins and never mix.
//! * Lookup at (p, n): trilinear weights w_i over the 8 cells around p, in n's bin, combined as
//!   E(p) = Σ w_i Φ_i / Σ w_i A_i — the neighbours' irradiances weighted by w_i A_i, so cells
//!   with little surface count little and empty cells not at all.
//! * Outgoing radiance of a Lambertian surface of albedo ρ there: L = ρ/π · E.
//!
//! Known bias: the estimate is an average over up to 2×2×2 cells. Surfaces of the same bin
//! sharing a cell mix (e.g. the floor on both sides of a wall thinner than a cell: the leak
//! reaches at most 1.5 cell widths from the wall), and irradiance gradients blur over a cell.

use glam::{DVec3, IVec3, UVec3, Vec3};

use crate::scene::{Aabb, Scene, triangle_normal};

/// The orientation bin in WGSL (`orientation_bin`, the twin of [`orientation_bin`]).
pub const BIN_WGSL: &str = include_str!("bin.wgsl");
/// The map's lookup in WGSL (`photon_irradiance`, bind group 3), with the orientation bin.
pub const LOOKUP_WGSL: &str = concat!(include_str!("bin.wgsl"), "\n", include_str!("map.wgsl"));

/// Orientation bins: 0 +x, 1 −x, 2 +y, 3 −y, 4 +z, 5 −z.
pub const BINS: usize = 6;

/// The bin of a surface side with normal n: its dominant axis and sign (`orientation_bin` in WGSL).
pub fn orientation_bin(n: Vec3) -> usize {
    let a = n.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + usize::from(n[axis] < 0.0)
}

/// Placement of the grid: cubic cells of side `cell` from `origin`, `dims` cells per axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    pub origin: Vec3,
    pub cell: f32,
    pub dims: UVec3,
}

impl GridSpec {
    /// A grid over `bounds` with `resolution` cells along its longest axis. The bounds are
    /// padded by a thousandth so that surfaces on the bounding box lie strictly inside.
    pub fn new(bounds: &Aabb, resolution: u32) -> GridSpec {
        let resolution = resolution.max(1);
        let extent = bounds.extent().max(Vec3::splat(1e-6));
        let pad = 1e-3 * extent.max_element();
        let cell = (extent.max_element() + 2.0 * pad) / resolution as f32;
        let dims = ((extent + 2.0 * pad) / cell).ceil().as_uvec3().max(UVec3::ONE).min(UVec3::splat(resolution));
        let origin = bounds.center() - 0.5 * dims.as_vec3() * cell;
        GridSpec { origin, cell, dims }
    }

    pub fn cell_count(&self) -> usize {
        (self.dims.x * self.dims.y * self.dims.z) as usize
    }

    /// The cell holding p (clamped to the grid).
    pub fn cell_of(&self, p: Vec3) -> UVec3 {
        ((p - self.origin) / self.cell).floor().as_ivec3().clamp(IVec3::ZERO, self.dims.as_ivec3() - 1).as_uvec3()
    }

    /// Linear index of (cell, bin): bins are slabs of the z axis, as in the 3D texture whose
    /// depth is `BINS · dims.z` (`slot` in WGSL).
    pub fn slot(&self, c: UVec3, bin: usize) -> usize {
        let z = bin as u32 * self.dims.z + c.z;
        ((z * self.dims.y + c.y) * self.dims.x + c.x) as usize
    }

    pub fn slot_count(&self) -> usize {
        BINS * self.cell_count()
    }
}

/// Area of the part of each surface side inside each (cell, bin) slot, by clipping every
/// triangle to every cell its bounding box overlaps. A side is counted where it can reflect
/// light: the front face, and the back face of two-sided materials.
pub fn surface_areas(scene: &Scene, grid: &GridSpec) -> Vec<f64> {
    let mut area = vec![0.0f64; grid.slot_count()];
    for (i, t) in scene.triangles.iter().enumerate() {
        let n = triangle_normal(t);
        if n == Vec3::ZERO {
            continue;
        }
        let mut bins = vec![orientation_bin(n)];
        if scene.material_of(i).two_sided {
            bins.push(orientation_bin(-n));
        }
        let poly: Vec<DVec3> = t.iter().map(|p| p.as_dvec3()).collect();
        let lo = grid.cell_of(t[0].min(t[1]).min(t[2]));
        let hi = grid.cell_of(t[0].max(t[1]).max(t[2]));
        for z in lo.z..=hi.z {
            for y in lo.y..=hi.y {
                for x in lo.x..=hi.x {
                    let c = UVec3::new(x, y, z);
                    let min = grid.origin.as_dvec3() + c.as_dvec3() * grid.cell as f64;
                    let a = polygon_area(&clip_to_box(&poly, min, min + DVec3::splat(grid.cell as f64)));
                    if a > 0.0 {
                        for &b in &bins {
                            area[grid.slot(c, b)] += a;
                        }
                    }
                }
            }
        }
    }
    area
}

/// Sutherland–Hodgman clipping of a convex polygon to the half-open box [min, max), the
/// same cells `GridSpec::cell_of` assigns points to: a polygon lying exactly on a cell
/// boundary counts in the cell above it only, where its photons land.
fn clip_to_box(poly: &[DVec3], min: DVec3, max: DVec3) -> Vec<DVec3> {
    let mut out = poly.to_vec();
    for axis in 0..3 {
        for (bound, keep_below) in [(min[axis], false), (max[axis], true)] {
            let inside = |p: &DVec3| if keep_below { p[axis] < bound } else { p[axis] >= bound };
            let input = std::mem::take(&mut out);
            for (k, p) in input.iter().enumerate() {
                let q = &input[(k + 1) % input.len()];
                if inside(p) {
                    out.push(*p);
                }
                if inside(p) != inside(q) {
                    let t = (bound - p[axis]) / (q[axis] - p[axis]);
                    out.push(*p + (*q - *p) * t);
                }
            }
            if out.len() < 3 {
                return Vec::new();
            }
        }
    }
    out
}

fn polygon_area(poly: &[DVec3]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let mut s = DVec3::ZERO;
    for k in 1..poly.len() - 1 {
        s += (poly[k] - poly[0]).cross(poly[k + 1] - poly[0]);
    }
    0.5 * s.length()
}

/// A photon map on the CPU: flux (RGB) and area per slot. Built by the CPU tracer, or read
/// back from the GPU; its lookup is the twin of `photon_irradiance` in WGSL.
#[derive(Clone, Debug)]
pub struct PhotonMap {
    pub grid: GridSpec,
    /// Φ per slot (watts, RGB).
    pub flux: Vec<[f64; 3]>,
    /// Surface area per slot.
    pub area: Vec<f64>,
    /// Sum of squared deposits per slot (green channel), for noise estimates (CPU maps only).
    pub flux_sq: Vec<f64>,
    /// Number of deposits per slot (CPU maps only).
    pub deposits: Vec<u32>,
}

impl PhotonMap {
    /// Irradiance of one slot, Φ/A (zero where there is no surface).
    pub fn cell_irradiance(&self, slot: usize) -> [f64; 3] {
        let a = self.area[slot];
        if a > 0.0 { self.flux[slot].map(|f| f / a) } else { [0.0; 3] }
    }

    /// E(p) for the surface side with normal n: Σ w_i Φ_i / Σ w_i A_i over the 8 cells
    /// around p in n's bin (trilinear weights on cell centres, clamped at the grid's border).
    pub fn irradiance(&self, p: Vec3, n: Vec3) -> [f64; 3] {
        let bin = orientation_bin(n);
        let g = (p - self.grid.origin) / self.grid.cell - 0.5;
        let base = g.floor();
        let f = g - base;
        let max = self.grid.dims.as_ivec3() - 1;
        let (mut flux, mut area) = ([0.0f64; 3], 0.0f64);
        for k in 0..8 {
            let o = IVec3::new(k & 1, (k >> 1) & 1, (k >> 2) & 1);
            let w = o.as_vec3() * f + (Vec3::ONE - o.as_vec3()) * (Vec3::ONE - f);
            let w = (w.x * w.y * w.z) as f64;
            let c = (base.as_ivec3() + o).clamp(IVec3::ZERO, max).as_uvec3();
            let s = self.grid.slot(c, bin);
            for (acc, f) in flux.iter_mut().zip(self.flux[s]) {
                *acc += w * f;
            }
            area += w * self.area[s];
        }
        if area > 0.0 { flux.map(|v| v / area) } else { [0.0; 3] }
    }

    /// Total deposited flux.
    pub fn total_flux(&self) -> [f64; 3] {
        let mut t = [0.0; 3];
        for f in &self.flux {
            for c in 0..3 {
                t[c] += f[c];
            }
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Camera, Material, cornell_box, triangle_area};

    #[test]
    fn bins_follow_the_dominant_axis_and_sign() {
        assert_eq!(orientation_bin(Vec3::X), 0);
        assert_eq!(orientation_bin(-Vec3::X), 1);
        assert_eq!(orientation_bin(Vec3::new(0.1, 0.9, -0.3)), 2);
        assert_eq!(orientation_bin(Vec3::new(0.1, -0.9, -0.3)), 3);
        assert_eq!(orientation_bin(Vec3::new(0.1, 0.2, 0.9)), 4);
        assert_eq!(orientation_bin(Vec3::new(0.1, 0.2, -0.9)), 5);
    }

    #[test]
    fn clipped_areas_sum_to_the_scene_area_per_bin() {
        let scene = cornell_box();
        for resolution in [1, 7, 32] {
            let grid = GridSpec::new(&scene.bounds(), resolution);
            let areas = surface_areas(&scene, &grid);
            let mut expected = [0.0f64; BINS];
            for t in &scene.triangles {
                expected[orientation_bin(triangle_normal(t))] += triangle_area(t) as f64;
            }
            let mut got = [0.0f64; BINS];
            for b in 0..BINS {
                for z in 0..grid.dims.z {
                    for y in 0..grid.dims.y {
                        for x in 0..grid.dims.x {
                            got[b] += areas[grid.slot(UVec3::new(x, y, z), b)];
                        }
                    }
                }
            }
            for b in 0..BINS {
                assert!(
                    (got[b] - expected[b]).abs() < 1e-5 * expected[b].max(1.0),
                    "bin {b} at {resolution}: {} vs {}",
                    got[b],
                    expected[b]
                );
            }
        }
    }

    #[test]
    fn a_unit_square_on_a_cell_boundary_plane_splits_its_area_exactly() {
        // A square in the plane z = 0.3, from (0,0) to (1,1), in a grid of cells 0.25 wide:
        // every cell it crosses gets exactly 0.0625 (or the clipped fraction at the border).
        let cam = Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        let mut s = Scene::new(cam);
        let m = s.add_material(Material::diffuse("m", Vec3::ONE));
        s.add_quad(
            [Vec3::new(0.0, 0.0, 0.3), Vec3::new(1.0, 0.0, 0.3), Vec3::new(1.0, 1.0, 0.3), Vec3::new(0.0, 1.0, 0.3)],
            m,
        );
        let grid = GridSpec { origin: Vec3::ZERO, cell: 0.25, dims: UVec3::new(4, 4, 4) };
        let areas = surface_areas(&s, &grid);
        for y in 0..4 {
            for x in 0..4 {
                let a = areas[grid.slot(UVec3::new(x, y, 1), 4)];
                assert!((a - 0.0625).abs() < 1e-9, "cell ({x},{y}): {a}");
            }
        }
    }

    #[test]
    fn a_square_exactly_on_a_cell_boundary_counts_once_in_the_cell_its_photons_land_in() {
        let cam = Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        let mut s = Scene::new(cam);
        let m = s.add_material(Material::diffuse("m", Vec3::ONE));
        s.add_quad(
            [Vec3::new(0.0, 0.0, 0.5), Vec3::new(1.0, 0.0, 0.5), Vec3::new(1.0, 1.0, 0.5), Vec3::new(0.0, 1.0, 0.5)],
            m,
        );
        let grid = GridSpec { origin: Vec3::ZERO, cell: 0.25, dims: UVec3::new(4, 4, 4) };
        let areas = surface_areas(&s, &grid);
        let total: f64 = areas.iter().sum();
        assert!((total - 1.0).abs() < 1e-9, "area counted {total} times");
        assert_eq!(grid.cell_of(Vec3::new(0.3, 0.3, 0.5)).z, 2);
        assert!((areas[grid.slot(UVec3::new(1, 1, 2), 4)] - 0.0625).abs() < 1e-9);
    }

    #[test]
    fn lookup_of_a_uniform_map_returns_the_uniform_irradiance_anywhere() {
        // Φ = 3·A in every slot with surface: E = 3 wherever interpolated, even at borders
        // and next to empty cells.
        let grid = GridSpec { origin: Vec3::ZERO, cell: 1.0, dims: UVec3::new(3, 3, 3) };
        let n = grid.slot_count();
        // Varied areas, and the whole slab of cells x = 2 without surface.
        let area: Vec<f64> = (0..n).map(|i| if i % 3 == 2 { 0.0 } else { 0.1 + (i % 7) as f64 }).collect();
        let flux = area.iter().map(|&a| [3.0 * a; 3]).collect();
        let map = PhotonMap { grid, flux, area, flux_sq: vec![0.0; n], deposits: vec![0; n] };
        for p in [Vec3::splat(0.01), Vec3::new(1.3, 2.9, 0.5), Vec3::splat(1.5)] {
            for normal in [Vec3::X, -Vec3::Y, Vec3::Z] {
                let e = map.irradiance(p, normal);
                assert!((e[0] - 3.0).abs() < 1e-9, "{p} {normal}: {e:?}");
            }
        }
    }
}
