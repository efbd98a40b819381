//! The map's layout: what depends on the geometry alone (the grid, the planes, the slots with
//! their areas and separators), built once and shared by the GPU tracer and its CPU twin.

use std::collections::HashMap;

use glam::{DVec3, IVec3, UVec3, Vec3};

use crate::par::prelude::*;

use super::*;
use crate::gpu::consts::{CAUSTIC_CELL, NEAR_FACE, REGION_SHIFT};
use crate::photons::clip::{clip_to_box, clip_to_half_space, polygon_area};
use crate::photons::separators::{
    CellPlanes, Fragment, MAX_SEPARATORS, Separator, Separators, region_of, separators_of,
};
use crate::photons::table::{EMPTY, SlotTable};
use crate::scene::{Aabb, Scene, triangle_normal};

/// Everything about a map that depends on the geometry alone: the grid, every triangle's
/// plane, the slots and their areas. Shared by the GPU tracer and its CPU twin.
#[derive(Clone, Debug)]
pub struct MapLayout {
    pub grid: GridSpec,
    /// Per triangle (in the scene's order): its plane.
    pub planes: Vec<TrianglePlane>,
    pub table: SlotTable,
    /// Surface area per table entry (zero where there is no slot).
    pub area: Vec<f64>,
    /// The planes that split base slots into regions.
    pub separators: Separators,
}

/// The mean coverage ([`Scene::coverage_at`]) of triangle `tri` over the convex polygon
/// `piece` of its plane: 16 stratified points in each triangle of the polygon's fan, weighted
/// by area.
pub fn mean_coverage(scene: &Scene, tri: usize, piece: &[DVec3]) -> f64 {
    let t = scene.triangles[tri].map(|p| p.as_dvec3());
    let (e1, e2) = (t[1] - t[0], t[2] - t[0]);
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let det = d11 * d22 - d12 * d12;
    if det <= 0.0 || piece.len() < 3 {
        return 1.0;
    }
    let (mut sum, mut total) = (0.0, 0.0);
    for k in 1..piece.len() - 1 {
        let (a, b, c) = (piece[0], piece[k], piece[k + 1]);
        let w = (b - a).cross(c - a).length();
        if w <= 0.0 {
            continue;
        }
        let mut mean = 0.0;
        for i in 0..4 {
            for j in 0..4 {
                // Uniform on the sub-triangle: (√u1, u2) warped, stratified 4 × 4.
                let su = ((i as f64 + 0.5) / 4.0).sqrt();
                let v = (j as f64 + 0.5) / 4.0;
                let p = a * (1.0 - su) + b * (su * (1.0 - v)) + c * (su * v);
                let d = p - t[0];
                let (p1, p2) = (d.dot(e1), d.dot(e2));
                let b1 = (d22 * p1 - d12 * p2) / det;
                let b2 = (d11 * p2 - d12 * p1) / det;
                mean += scene.coverage_at(tri, b1 as f32, b2 as f32) as f64 / 16.0;
            }
        }
        sum += w * mean;
        total += w;
    }
    if total > 0.0 { sum / total } else { 1.0 }
}

impl MapLayout {
    /// The layout of `scene` over `grid`: every triangle clipped to every cell its bounding
    /// box overlaps, its area added to the slot of each side that reflects light (the front
    /// face, and the back of two-sided materials).
    pub fn new(scene: &Scene, grid: &GridSpec) -> MapLayout {
        let planes: Vec<TrianglePlane> =
            scene.triangles.iter().map(|t| TrianglePlane::new(triangle_normal(t), t[0])).collect();
        // Every side's fragment in every cell, per triangle (on all cores), then grouped by
        // cell in the triangles' order.
        let levels: Vec<(Lattice, CellBoxes)> =
            std::iter::once(grid.coarse()).chain(grid.fine()).map(|l| (l, grid.cell_boxes(&l))).collect();
        let fragments_of = |i: usize| -> Vec<(u32, Fragment)> {
            let mut out = Vec::new();
            let t = &scene.triangles[i];
            if planes[i].bins[0] == EMPTY {
                return out;
            }
            let sides: &[bool] = if scene.material_of(i).two_sided { &[false, true] } else { &[false] };
            let holed = scene.material_of(i).has_holes();
            let poly: Vec<DVec3> = t.iter().map(|p| p.as_dvec3()).collect();
            let n = Vec3::from(planes[i].normal).as_dvec3();
            let (tmin, tmax) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
            // The coarse cells outside the refinement, then the fine cells, that the
            // triangle's box overlaps.
            for (lattice, boxes) in &levels {
                let refined_level = lattice.base > 0;
                let (lo, hi) = (lattice.cell_of(tmin), lattice.cell_of(tmax));
                if refined_level
                    && (grid.coarse().cell_of(tmax).cmplt(grid.refine.lo).any()
                        || grid.coarse().cell_of(tmin).cmpge(grid.refine.hi).any())
                {
                    continue;
                }
                for z in lo.z..=hi.z {
                    for y in lo.y..=hi.y {
                        for x in lo.x..=hi.x {
                            let c = UVec3::new(x, y, z);
                            if !refined_level && grid.is_refined(c) {
                                continue;
                            }
                            let (min, max) = boxes.cell_box(c);
                            let piece = clip_to_box(&poly, min, max);
                            let coverage = if holed { mean_coverage(scene, i, &piece) } else { 1.0 };
                            let area = polygon_area(&piece) * coverage;
                            if area > 0.0 {
                                for &back in sides {
                                    let side = if back { -n } else { n };
                                    out.push((
                                        lattice.index(c),
                                        Fragment {
                                            key: planes[i].key(lattice, c, back),
                                            plane: (side, side.dot(poly[0])),
                                            poly: piece.clone(),
                                            area,
                                            coverage,
                                        },
                                    ));
                                }
                            }
                        }
                    }
                }
            }
            out
        };
        let per_triangle: Vec<Vec<(u32, Fragment)>> =
            (0..scene.triangles.len()).into_par_iter().with_min_len(64).map(fragments_of).collect();
        let mut cells: HashMap<u32, Vec<Fragment>> = HashMap::new();
        for (cell, f) in per_triangle.into_iter().flatten() {
            cells.entry(cell).or_default().push(f);
        }
        // Per cell (on all cores): its slots' areas and its separators.
        let eps = 1e-4 * grid.finest_cell() as f64;
        type CellSlots = (Vec<([u32; 2], f64)>, Vec<([u32; 2], [Separator; MAX_SEPARATORS])>);
        let slots_of = |(&cell, fragments): (&u32, &Vec<Fragment>)| -> CellSlots {
            let (mut areas, mut separated) = (Vec::new(), Vec::new());
            // The cell's fragments grouped by key (in the cell's order within each key) and its
            // candidate planes, once.
            let mut by_key: Vec<&Fragment> = fragments.iter().collect();
            by_key.sort_by_key(|f| f.key);
            let cell_planes = CellPlanes::new(fragments);
            for own in by_key.chunk_by(|a, b| a.key == b.key) {
                let key = own[0].key;
                let separators = separators_of(own, &cell_planes, key, eps);
                if separators.is_empty() {
                    areas.push(([cell, key], own.iter().map(|f| f.area).sum::<f64>()));
                    continue;
                }
                let mut record = [[0.0f32; 4]; MAX_SEPARATORS];
                for (r, &(n, d)) in record.iter_mut().zip(&separators) {
                    *r = [n.x as f32, n.y as f32, n.z as f32, d as f32];
                }
                separated.push(([cell, key], record));
                for region in 0..1u32 << separators.len() {
                    let mut area = 0.0;
                    for f in own {
                        let mut piece = f.poly.clone();
                        for (k, &(n, d)) in separators.iter().enumerate() {
                            piece = clip_to_half_space(&piece, n, d, region >> k & 1 == 1);
                        }
                        area += polygon_area(&piece) * f.coverage;
                    }
                    // Regions that only rounding creates (where two cuts nearly meet) get no slot.
                    if area > 1e-9 * own.iter().map(|f| f.area).sum::<f64>() {
                        areas.push(([cell, key | region << REGION_SHIFT], area));
                    }
                }
            }
            (areas, separated)
        };
        let cell_list: Vec<(&u32, &Vec<Fragment>)> = cells.iter().collect();
        let per_cell: Vec<CellSlots> = cell_list.into_par_iter().with_min_len(64).map(slots_of).collect();
        let mut areas: HashMap<[u32; 2], f64> = HashMap::new();
        let mut separated: Vec<([u32; 2], [Separator; MAX_SEPARATORS])> = Vec::new();
        for (cell_areas, cell_separated) in per_cell {
            for (k, a) in cell_areas {
                *areas.entry(k).or_default() += a;
            }
            separated.extend(cell_separated);
        }
        // A scene with perfect mirrors or smooth glass gets a caustic twin of every slot (its
        // cell index with CAUSTIC_CELL set, the same area): the flux of photons that reached
        // it through specular surfaces alone, which visible points read directly.
        if scene.materials.iter().any(crate::scene::Material::passes_rays) {
            let twins: Vec<([u32; 2], f64)> = areas.iter().map(|(k, &a)| ([k[0] | CAUSTIC_CELL, k[1]], a)).collect();
            areas.extend(twins);
        }
        let mut keys: Vec<[u32; 2]> = areas.keys().copied().collect();
        keys.sort_unstable();
        let table = SlotTable::new(&keys);
        let mut area = vec![0.0; table.capacity()];
        for (k, a) in &areas {
            area[table.find(k[0], k[1]).expect("every slot is in the table")] = *a;
        }
        separated.sort_unstable_by_key(|s| s.0);
        let sep_keys: Vec<[u32; 2]> = separated.iter().map(|s| s.0).collect();
        let sep_table = SlotTable::new(&sep_keys);
        let mut sep_planes = vec![[[0.0f32; 4]; MAX_SEPARATORS]; sep_table.capacity()];
        for (k, record) in &separated {
            sep_planes[sep_table.find(k[0], k[1]).expect("every record is in the table")] = *record;
        }
        let separators = Separators { table: sep_table, planes: sep_planes };
        MapLayout { grid: *grid, planes, table, area, separators }
    }

    /// The region bits of p among the separators of base slot (cell, key): 0 where it has
    /// none.
    pub fn region(&self, cell: u32, key: u32, p: Vec3) -> u32 {
        self.separators.table.find(cell, key).map_or(0, |e| region_of(&self.separators.planes[e], p))
    }

    /// The layout over a grid of `resolution` cells along the longest axis of `bounds`, or of
    /// the finest coarser grid (halving the resolution) whose slots fit `limits`, with a
    /// warning saying so. The slot count is first estimated from the triangles (a planar
    /// triangle of area A and perimeter P meets at most about √3·A/h² + 3·P/h + 1 cells of side
    /// h), so an impossible grid costs no clipping; the estimate is then checked against the
    /// clipped table. Errors only where the grid's cells have no 32-bit index.
    pub fn within(
        scene: &Scene,
        bounds: &Aabb,
        resolution: u32,
        region: Option<&PhotonRegion>,
        limits: &wgpu::Limits,
    ) -> crate::Result<MapLayout> {
        // Per triangle: area, perimeter, and whether its centroid lies in the refined region.
        let sizes: Vec<(f64, f64, bool)> = (scene.triangles.iter())
            .map(|t| {
                let e = [t[1] - t[0], t[2] - t[1], t[0] - t[2]];
                let c = (t[0] + t[1] + t[2]) / 3.0;
                let inside = region.is_some_and(|r| c.cmpge(r.bounds.min).all() && c.cmple(r.bounds.max).all());
                (0.5 * e[0].cross(-e[2]).length() as f64, e.iter().map(|e| e.length() as f64).sum::<f64>(), inside)
            })
            .collect();
        let mut resolution = resolution.max(1);
        loop {
            let mut grid = GridSpec::new(bounds, resolution);
            if let Some(r) = region {
                grid = grid.refined(&r.bounds, r.factor);
            }
            check_photon_grid(limits, &grid)?;
            let (coarse, fine) = (grid.cell as f64, grid.finest_cell() as f64);
            let cells_met: f64 = (sizes.iter())
                .map(|&(a, p, inside)| {
                    let h = if inside { fine } else { coarse };
                    3f64.sqrt() * a / (h * h) + 3.0 * p / h + 1.0
                })
                .sum();
            // Both sides of every triangle, at most; twice that with caustic twins.
            let twins = if scene.materials.iter().any(crate::scene::Material::passes_rays) { 2.0 } else { 1.0 };
            let estimate = twins * 2.0 * cells_met;
            let fits = |slots: f64| {
                let entries = (2.0 * slots).max(16.0).log2().ceil().exp2() as u64;
                entries.saturating_mul(16) <= crate::gpu::limits::max_storage_buffer(limits)
                    && entries.saturating_mul(24) <= limits.max_buffer_size
            };
            let outcome = if fits(estimate) || resolution == 1 {
                let start = web_time::Instant::now();
                let layout = MapLayout::new(scene, &grid);
                log::info!(
                    "photon map layout: grid {}x{}x{}{}, {} slots, {} with separators, {:.2} s",
                    grid.dims.x,
                    grid.dims.y,
                    grid.dims.z,
                    grid.fine().map_or(String::new(), |f| format!(
                        " refined {}x{}x{} in {}x{}x{} cells of {:.3}",
                        grid.refine.factor,
                        grid.refine.factor,
                        grid.refine.factor,
                        f.dims.x,
                        f.dims.y,
                        f.dims.z,
                        f.cell
                    )),
                    layout.table.len(),
                    layout.separators.table.len(),
                    start.elapsed().as_secs_f64()
                );
                check_photon_slots(limits, &layout).map(|()| layout)
            } else {
                Err(crate::Error::Limits(format!(
                    "the photon map of a grid of {resolution} cells would need about {:.0} slots, more than this GPU binds",
                    estimate
                )))
            };
            match outcome {
                Ok(layout) => return Ok(layout),
                // Cells twice as wide hold about a quarter as many slots.
                Err(e) if resolution > 1 => {
                    log::warn!("{e}; using a photon grid of {} cells instead of {resolution}", resolution / 2);
                    resolution /= 2;
                }
                Err(e) => return Err(e),
            }
        }
    }

    /// (Deposits in slots of the fine level, all deposits), from per-entry `deposits`: the
    /// share of photon hits in the photon region.
    pub fn region_share(&self, deposits: &[u32]) -> (u64, u64) {
        let base = self.grid.fine().map_or(u32::MAX, |f| f.base);
        (self.table.keys.iter().zip(deposits)).fold((0, 0), |(inside, all), (k, &d)| {
            let fine = k[0] != EMPTY && (k[0] & !CAUSTIC_CELL) >= base;
            (inside + if fine { d as u64 } else { 0 }, all + d as u64)
        })
    }

    /// The caustic twin of table entry `slot` ([`CAUSTIC_CELL`]), where the scene has them.
    pub fn caustic_twin(&self, slot: usize) -> Option<usize> {
        let [cell, key] = *self.table.keys.get(slot)?;
        if cell == u32::MAX || cell & CAUSTIC_CELL != 0 {
            return None;
        }
        self.table.find(cell | CAUSTIC_CELL, key)
    }

    /// The table entry where a photon landing at p on side `back` of triangle `tri` deposits
    /// (`None` where the cell holds no area of that plane: a hit point that rounding moved into
    /// a neighbouring cell).
    ///
    /// A point on a face of its cell (within [`NEAR_FACE`] of a cell side) whose cell holds no
    /// area of its plane deposits in the neighbour across that face where that one does: a
    /// surface lying on a cell boundary has its area in the cell above it (exact arithmetic,
    /// `clip_to_box`) while `cell_of`'s f32 rounding may put its points in the cell below.
    /// Axis-aligned floors and walls meet boundaries exactly at some resolutions; without this
    /// their photons were lost there (7–8 % of a sunlit room's indirect deposits at four of
    /// the progressive passes' resolutions, a few per cent of the image).
    pub fn deposit_slot(&self, tri: usize, back: bool, p: Vec3) -> Option<usize> {
        let lattice = self.grid.lattice_at(p);
        let c = lattice.cell_of(p);
        let find = |c: UVec3| {
            let (cell, key) = (lattice.index(c), self.planes[tri].key(&lattice, c, back));
            self.table.find(cell, key | self.region(cell, key, p) << REGION_SHIFT)
        };
        if let Some(s) = find(c) {
            return Some(s);
        }
        let f = (p - lattice.origin) / lattice.cell - c.as_vec3();
        let (lo, hi) = (lattice.lo.as_ivec3(), (lattice.lo + lattice.dims).as_ivec3() - 1);
        for axis in 0..3 {
            let step = if f[axis] < NEAR_FACE {
                -1
            } else if f[axis] > 1.0 - NEAR_FACE {
                1
            } else {
                continue;
            };
            let n = c.as_ivec3() + IVec3::AXES[axis] * step;
            if n.cmpge(lo).all()
                && n.cmple(hi).all()
                && let Some(s) = find(n.as_uvec3())
            {
                return Some(s);
            }
        }
        None
    }
}
