//! The grid photon map, stored sparsely: only the slots that hold surface, in a hash table.
//!
//! * A **slot** is a (cell, plane) pair: a cubic cell of the grid and a surface plane key, the
//!   side's orientation bin and its plane's offset. Photons deposit their flux Φ in the slot of
//!   the cell they land in and the plane of the side they land on; the slot's area A is the
//!   part of the scene's surfaces with that plane key inside the cell (triangles clipped to
//!   the cell). Irradiance of a slot: E = Φ / A. Where the surface has holes (cut-outs,
//!   stochastic opacity), photons stop only with the probability c(x) that it is there
//!   ([`Scene::coverage_at`]), so A = ∫ c dA over the piece ([`mean_coverage`]): the holes
//!   would otherwise dilute the irradiance of what is solid.
//! * **Orientation bins** ([`orientation_bin`]): the cube face of the dominant axis and sign
//!   of the side's normal, each face divided 3 × 3 by the other two coordinates over the
//!   dominant one, 54 bins in all; axis-aligned normals lie at the centre of a bin, and normals
//!   sharing a bin are at most 2·atan(√2/3) ≈ 50.5° apart (across the central bin's diagonal;
//!   a plain grid's 6 axis bins mix normals up to 109.5° apart).
//! * **Plane offsets**: the signed distance d = n·(v₀ − c) from the cell's centre c to the
//!   side's plane, rounded to [`OFFSET_STEP`] cells. Parallel surfaces farther apart than that
//!   never share a slot (the light's underside and the ceiling above it, 1 cm apart in the
//!   Cornell box, with 3.1 cm cells), while the facets of a smooth curved surface, whose planes
//!   pass within a fraction of a step of each other inside a cell, mostly do. Every triangle's
//!   plane (unit normal, n·v₀, the bins of both sides) is computed once
//!   ([`MapLayout::planes`]), so a deposit, the area and a lookup on the same triangle compute
//!   the same key from the same numbers.
//! * **Separators** ([`Separators`]): up to [`MAX_SEPARATORS`] planes of other surfaces in the
//!   cell split a slot into regions, a point's region being the signs of its distances to
//!   them. A wall standing on a floor splits the floor's slot into each room's floor and the
//!   strip under the wall (which no photon reaches, and which no longer dilutes the
//!   irradiance beside it); planes that only bound the slot (the wall the floor ends at) split
//!   nothing but fence the lookup.
//! * **Lookup** at p on a triangle's side: trilinear weights w_i over the 8 cells around p,
//!   each cell's slot of the same plane and of p's region there, E(p) = Σ w_i Φ_i / Σ w_i A_i
//!   (cells without such a slot count nothing, nor cells whose centre lies beyond a separator
//!   of p's own cell). Outgoing radiance of a Lambertian surface of albedo ρ: L = ρ/π · E.
//! * **Hash table** ([`SlotTable`]): open addressing with linear probing over a power-of-two
//!   capacity at most half full, keyed by (cell index, plane key); built once on the CPU from
//!   the geometry, read by the GPU tracer's deposits and every lookup. The longest probe of any
//!   slot bounds every search. Memory is per surface slot, not per cell: 24 bytes per table
//!   entry while rendering.
//!
//! Known bias: the estimate averages over up to 2×2×2 cells, so irradiance gradients blur over
//! a cell, and surfaces of one plane and region sharing a cell mix. Progressive passes
//! ([`super::passes`]) shrink the cells as the render goes on.

use std::collections::HashMap;

use glam::{DVec3, IVec3, UVec3, Vec3};

use crate::par::prelude::*;

use super::clip::{clip_to_box, clip_to_half_space, polygon_area};
use super::separators::{CellPlanes, Fragment, separators_of};
pub use super::separators::{MAX_SEPARATORS, MIN_REGION, Separator, Separators, region_of};
pub use super::table::{EMPTY, SlotTable};
use crate::gpu::consts::CAUSTIC_CELL;
pub use crate::gpu::consts::{MIN_LOOKUP_AREA, NEAR_FACE};
use crate::gpu::limits::{check_storage_buffer, mib};
use crate::scene::{Aabb, Scene, triangle_normal};

/// The slot table's search in WGSL (`find_slot`, the twin of [`SlotTable::find`]). The GPU
/// needs no bins: it reads every triangle's plane keys.
pub const TABLE_WGSL: &str = include_str!("table.wgsl");
/// The map's lookup in WGSL (`photon_irradiance`, bind group 3), with the table's search.
pub const LOOKUP_WGSL: &str = concat!(include_str!("table.wgsl"), "\n", include_str!("map.wgsl"));

/// Divisions of each cube face along each of its two axes.
pub const FACE_DIVISIONS: usize = 3;
/// Orientation bins: 6 cube faces × FACE_DIVISIONS².
pub const BINS: usize = 6 * FACE_DIVISIONS * FACE_DIVISIONS;
pub use crate::gpu::consts::{OFFSET_SHIFT, OFFSET_STEP, REGION_SHIFT};

/// The bin of a surface side with normal n: face 2·axis + sign of
/// the dominant axis, then the 3 × 3 cell of the other two coordinates (in axis order after
/// it) divided by the dominant one's magnitude, each in [−1, 1].
pub fn orientation_bin(n: Vec3) -> usize {
    let a = n.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let face = 2 * axis + usize::from(n[axis] < 0.0);
    let major = a[axis].max(f32::MIN_POSITIVE);
    let sub = |c: f32| (((c / major + 1.0) * 0.5 * FACE_DIVISIONS as f32) as usize).min(FACE_DIVISIONS - 1);
    let (u, v) = (sub(n[(axis + 1) % 3]), sub(n[(axis + 2) % 3]));
    (face * FACE_DIVISIONS + u) * FACE_DIVISIONS + v
}

/// A triangle's plane as the map keys it (`TrianglePlane` in `map.wgsl` and `trace.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct TrianglePlane {
    /// The front side's unit normal.
    pub normal: [f32; 3],
    /// n·v₀: the plane is {x : n·x = offset}.
    pub offset: f32,
    /// The orientation bins of the front and back sides.
    pub bins: [u32; 2],
    pub _pad: [u32; 2],
}

impl TrianglePlane {
    /// The plane with front normal n through `point` (n zero: a degenerate triangle, which no
    /// photon lands on).
    pub fn new(n: Vec3, point: Vec3) -> TrianglePlane {
        let bins = if n == Vec3::ZERO { [EMPTY; 2] } else { [orientation_bin(n) as u32, orientation_bin(-n) as u32] };
        TrianglePlane { normal: n.into(), offset: n.dot(point), bins, _pad: [0; 2] }
    }

    /// The plane key of side `back` in cell c of `lattice` (`plane_key` in WGSL): the orientation
    /// bin in the low 6 bits, the region's bits free above it (zero here), and from
    /// [`OFFSET_SHIFT`] up the signed distance from the cell's centre to the plane along the
    /// side's normal in steps of [`OFFSET_STEP`] cells, rounded (two's complement).
    pub fn key(&self, lattice: &Lattice, c: UVec3, back: bool) -> u32 {
        let centre = lattice.centre(c);
        let d = (self.offset - Vec3::from(self.normal).dot(centre)) / (OFFSET_STEP * lattice.cell);
        // floor(d + ½) as in WGSL (whose round() breaks ties to even).
        let steps = (d + 0.5).floor() as i32;
        let steps = if back { -steps } else { steps };
        self.bins[usize::from(back)] | ((steps as u32) << OFFSET_SHIFT)
    }
}

/// The refined part of a grid: the coarse cells `lo ..< hi` (per axis), each split into
/// `factor`³ cells; `factor` 1 refines nothing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Refinement {
    pub lo: UVec3,
    pub hi: UVec3,
    pub factor: u32,
}

impl Refinement {
    pub const NONE: Refinement = Refinement { lo: UVec3::ZERO, hi: UVec3::ZERO, factor: 1 };
}

/// Placement of the grid: cubic cells of side `cell` from `origin`, `dims` cells per axis,
/// some of them refined ([`Refinement`]): a two-level grid whose fine cells lie where the
/// camera reads the map ([`crate::fit::photon_region`]), however far the scene reaches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridSpec {
    pub origin: Vec3,
    pub cell: f32,
    pub dims: UVec3,
    pub refine: Refinement,
}

/// Where the camera reads the photon map: the box whose grid cells are refined, `factor`
/// times finer than the rest's per axis ([`GridSpec::refined`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PhotonRegion {
    pub bounds: Aabb,
    pub factor: u32,
}

impl std::fmt::Display for PhotonRegion {
    /// "(x, y, z) to (x, y, z), cells kx finer", for logs and benchmarks.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (a, b) = (self.bounds.min, self.bounds.max);
        write!(
            f,
            "({:.2}, {:.2}, {:.2}) to ({:.2}, {:.2}, {:.2}), cells {}x finer",
            a.x, a.y, a.z, b.x, b.y, b.z, self.factor
        )
    }
}

/// One level of a [`GridSpec`]: cubic cells of side `cell` from `origin`, integer coordinates
/// `lo ..< lo + dims` per axis (the fine level's count from the grid's origin in fine cells),
/// linear indices from `base`. Every point is in exactly one level's cells; a slot's cell index
/// names its level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lattice {
    pub origin: Vec3,
    pub cell: f32,
    pub lo: UVec3,
    pub dims: UVec3,
    pub base: u32,
}

impl Lattice {
    /// The cell holding p (clamped to the lattice).
    pub fn cell_of(&self, p: Vec3) -> UVec3 {
        let hi = (self.lo + self.dims).as_ivec3() - 1;
        ((p - self.origin) / self.cell).floor().as_ivec3().clamp(self.lo.as_ivec3(), hi).as_uvec3()
    }

    /// The linear index of cell c (x fastest), the first word of a slot's key.
    pub fn index(&self, c: UVec3) -> u32 {
        let r = c - self.lo;
        self.base + (r.z * self.dims.y + r.y) * self.dims.x + r.x
    }

    /// The centre of cell c (`cell_centre` in WGSL).
    pub fn centre(&self, c: UVec3) -> Vec3 {
        self.origin + (c.as_vec3() + 0.5) * self.cell
    }

    /// The cell coordinate of x along `axis` before clamping: floor((x − origin)/cell) in f32,
    /// as [`Self::cell_of`] computes it.
    fn class(&self, axis: usize, x: f32) -> i64 {
        ((x - self.origin[axis]) / self.cell).floor() as i64
    }

    /// Where cells i − 1 and i meet along `axis` as [`Self::cell_of`] sees points: the least
    /// f32 coordinate of class i or more (within a few f32 steps of origin + i·cell; the class
    /// only grows with x, so the points of cell i are exactly those from face(i) to before
    /// face(i + 1)).
    pub fn face(&self, axis: usize, i: i64) -> f64 {
        let mut x = self.origin[axis] + i as f32 * self.cell;
        for _ in 0..256 {
            if self.class(axis, x) < i {
                x = x.next_up();
            } else if self.class(axis, x.next_down()) >= i {
                x = x.next_down();
            } else {
                break;
            }
        }
        x as f64
    }

    pub fn cell_count(&self) -> u64 {
        self.dims.x as u64 * self.dims.y as u64 * self.dims.z as u64
    }
}

/// The cells' boxes of one level of a grid ([`GridSpec::cell_boxes`]): per axis, the faces
/// between its cells, its first cell's lower face first.
pub struct CellBoxes {
    lo: UVec3,
    faces: [Vec<f64>; 3],
}

impl CellBoxes {
    /// The half-open box [min, max) of cell c.
    pub fn cell_box(&self, c: UVec3) -> (DVec3, DVec3) {
        let i = (c - self.lo).as_usizevec3();
        let min = DVec3::new(self.faces[0][i.x], self.faces[1][i.y], self.faces[2][i.z]);
        let max = DVec3::new(self.faces[0][i.x + 1], self.faces[1][i.y + 1], self.faces[2][i.z + 1]);
        (min, max)
    }
}

impl GridSpec {
    /// A grid over `bounds` with `resolution` cells along its longest axis, unrefined. The
    /// bounds are padded by a thousandth so that surfaces on the bounding box lie strictly
    /// inside.
    pub fn new(bounds: &Aabb, resolution: u32) -> GridSpec {
        let resolution = resolution.max(1);
        let extent = bounds.extent().max(Vec3::splat(1e-6));
        let pad = 1e-3 * extent.max_element();
        let cell = (extent.max_element() + 2.0 * pad) / resolution as f32;
        let dims = ((extent + 2.0 * pad) / cell).ceil().as_uvec3().max(UVec3::ONE).min(UVec3::splat(resolution));
        let origin = bounds.center() - 0.5 * dims.as_vec3() * cell;
        GridSpec { origin, cell, dims, refine: Refinement::NONE }
    }

    /// A grid of cells `cell` wide from `origin`, unrefined.
    pub fn uniform(origin: Vec3, cell: f32, dims: UVec3) -> GridSpec {
        GridSpec { origin, cell, dims, refine: Refinement::NONE }
    }

    /// This grid with the coarse cells that `region` overlaps split into `factor`³ cells
    /// (`factor` ≤ 1, or a region outside the grid: unchanged).
    pub fn refined(self, region: &Aabb, factor: u32) -> GridSpec {
        let coarse = self.coarse();
        let (lo, hi) = (coarse.cell_of(region.min), coarse.cell_of(region.max) + 1);
        if factor <= 1 || region.min.cmpgt(region.max).any() {
            return self;
        }
        GridSpec { refine: Refinement { lo, hi, factor }, ..self }
    }

    /// The coarse level: every cell of the grid (those refined hold no slots).
    pub fn coarse(&self) -> Lattice {
        Lattice { origin: self.origin, cell: self.cell, lo: UVec3::ZERO, dims: self.dims, base: 0 }
    }

    /// The fine level, where the grid is refined. Its cell side is a division done once, here
    /// (the shaders read it, never recompute it).
    pub fn fine(&self) -> Option<Lattice> {
        let r = &self.refine;
        (r.factor > 1).then(|| Lattice {
            origin: self.origin,
            cell: self.cell / r.factor as f32,
            lo: r.lo * r.factor,
            dims: (r.hi - r.lo) * r.factor,
            base: self.coarse().cell_count() as u32,
        })
    }

    /// Whether coarse cell c is refined.
    pub fn is_refined(&self, c: UVec3) -> bool {
        let r = &self.refine;
        r.factor > 1 && c.cmpge(r.lo).all() && c.cmplt(r.hi).all()
    }

    /// The level whose cells hold p: the fine one inside the refined cells, else the coarse
    /// one (`lattice_at` in WGSL).
    pub fn lattice_at(&self, p: Vec3) -> Lattice {
        let coarse = self.coarse();
        match self.fine() {
            Some(fine) if self.is_refined(coarse.cell_of(p)) => fine,
            _ => coarse,
        }
    }

    /// Cells of both levels (the coarse ones refined included: they keep their indices).
    pub fn cell_count(&self) -> u64 {
        self.coarse().cell_count() + self.fine().map_or(0, |f| f.cell_count())
    }

    /// The half-open boxes of the cells of `lattice` (one of this grid's levels), with faces
    /// where `cell_of`'s f32 arithmetic divides points ([`Lattice::face`]), so that a surface
    /// lying on a cell boundary has its area in the cell its photons land in (in exact
    /// arithmetic f32 rounding put them in the other one where the surface met a boundary, as
    /// axis-aligned walls through the origin of a grid centred there do: 7–18 % of a sunlit
    /// room's deposits were lost at some resolutions). A level's outermost cells reach to its
    /// edge: the fine level's to the refined coarse cells' faces, the coarse level's without
    /// end (points beyond are clamped into them).
    pub fn cell_boxes(&self, lattice: &Lattice) -> CellBoxes {
        let coarse = self.coarse();
        let fine = lattice.base > 0;
        let faces = std::array::from_fn(|axis| {
            let n = lattice.dims[axis] as usize;
            (0..=n)
                .map(|k| match (k, fine) {
                    (0, true) => coarse.face(axis, self.refine.lo[axis] as i64),
                    (0, false) => f64::NEG_INFINITY,
                    (k, true) if k == n => coarse.face(axis, self.refine.hi[axis] as i64),
                    (k, false) if k == n => f64::INFINITY,
                    (k, _) => lattice.face(axis, (lattice.lo[axis] as usize + k) as i64),
                })
                .collect()
        });
        CellBoxes { lo: lattice.lo, faces }
    }

    /// The finest cell side.
    pub fn finest_cell(&self) -> f32 {
        self.fine().map_or(self.cell, |f| f.cell)
    }
}

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

/// A photon map on the CPU: flux (RGB) and area per table entry. Built by the CPU tracer, or
/// read back from the GPU; its lookup is the twin of `photon_irradiance` in WGSL.
#[derive(Clone, Debug)]
pub struct PhotonMap {
    pub layout: MapLayout,
    /// Φ per table entry (watts, RGB).
    pub flux: Vec<[f64; 3]>,
    /// Sum of squared deposits per entry (green channel), for noise estimates (CPU maps only).
    pub flux_sq: Vec<f64>,
    /// Number of deposits per entry (CPU maps only).
    pub deposits: Vec<u32>,
    /// Deposits that found no slot (CPU maps only; see [`MapLayout::deposit_slot`]).
    pub dropped: u64,
}

impl PhotonMap {
    pub fn grid(&self) -> &GridSpec {
        &self.layout.grid
    }

    /// Surface area per table entry.
    pub fn area(&self) -> &[f64] {
        &self.layout.area
    }

    /// Irradiance of one entry, Φ/A (zero where there is no surface).
    pub fn cell_irradiance(&self, slot: usize) -> [f64; 3] {
        let a = self.layout.area[slot];
        if a > 0.0 { self.flux[slot].map(|f| f / a) } else { [0.0; 3] }
    }

    /// E(p) for the surface side with unit normal n through p: the lookup on the plane
    /// through p with normal n (see [`PhotonMap::irradiance_on_plane`]).
    pub fn irradiance(&self, p: Vec3, n: Vec3) -> [f64; 3] {
        self.irradiance_on_plane(p, &TrianglePlane::new(n, p), false)
    }

    /// E(p) on side `back` of triangle `tri` (its plane, as the passes look it up).
    pub fn irradiance_on(&self, tri: usize, back: bool, p: Vec3) -> [f64; 3] {
        self.irradiance_on_plane(p, &self.layout.planes[tri], back)
    }

    /// The caustic map's E(p) on side `back` of triangle `tri`: the lookup over the caustic
    /// twins of the slots ([`CAUSTIC_CELL`]; zero where the scene has none).
    pub fn caustic_irradiance_on(&self, tri: usize, back: bool, p: Vec3) -> [f64; 3] {
        self.lookup(p, &self.layout.planes[tri], back, CAUSTIC_CELL)
    }

    /// Σ w_i Φ_i / Σ w_i A_i over the slots of side `back` of `plane` in the 8 cells around p
    /// (trilinear weights on cell centres, clamped at the grid's border), each cell's slot of
    /// p's region among that cell's separators; a cell whose centre lies on the other side of a
    /// separator of p's own cell is left out, and so is a slot of less than
    /// [`MIN_LOOKUP_AREA`]·h²: what photons rounding put there (a sliver of a plane that only
    /// touches the cell, a region that a separator only grazes) would read as Φ/A with A ≈ 0,
    /// spikes of 10⁸ times the irradiance around them (measured on a 120-triangle sphere).
    pub fn irradiance_on_plane(&self, p: Vec3, plane: &TrianglePlane, back: bool) -> [f64; 3] {
        self.lookup(p, plane, back, 0)
    }

    /// [`Self::irradiance_on_plane`] over the slots whose cell index has the bits `twin` set.
    fn lookup(&self, p: Vec3, plane: &TrianglePlane, back: bool, twin: u32) -> [f64; 3] {
        let layout = &self.layout;
        // The level holding p: its 8 cells around p (those of the other level hold no slots
        // of this one, and count nothing).
        let grid = layout.grid.lattice_at(p);
        // The separators of p's own slot: cells beyond them (across a wall) do not count.
        let home = grid.cell_of(p);
        let own = layout.separators.table.find(grid.index(home), plane.key(&grid, home, back));
        let own = own.map(|e| &layout.separators.planes[e]);
        let g = (p - grid.origin) / grid.cell - 0.5;
        let base = g.floor();
        let f = g - base;
        let (min, max) = (grid.lo.as_ivec3(), (grid.lo + grid.dims).as_ivec3() - 1);
        let min_area = MIN_LOOKUP_AREA as f64 * (grid.cell as f64).powi(2);
        let (mut flux, mut area) = ([0.0f64; 3], 0.0f64);
        for k in 0..8 {
            let o = IVec3::new(k & 1, (k >> 1) & 1, (k >> 2) & 1);
            let w = o.as_vec3() * f + (Vec3::ONE - o.as_vec3()) * (Vec3::ONE - f);
            let w = (w.x * w.y * w.z) as f64;
            let c = (base.as_ivec3() + o).clamp(min, max).as_uvec3();
            if let Some(own) = own
                && c != home
                && region_of(own, p) != region_of(own, grid.centre(c))
            {
                continue;
            }
            let (cell, key) = (grid.index(c), plane.key(&grid, c, back));
            if let Some(s) = layout.table.find(cell | twin, key | layout.region(cell, key, p) << REGION_SHIFT)
                && self.layout.area[s] >= min_area
            {
                for (acc, f) in flux.iter_mut().zip(self.flux[s]) {
                    *acc += w * f;
                }
                area += w * self.layout.area[s];
            }
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

/// The photon grid: its cells must have 31-bit indices (the first word of a slot's key; its
/// top bit marks caustic twins, `CAUSTIC_CELL`).
pub fn check_photon_grid(_limits: &wgpu::Limits, grid: &GridSpec) -> crate::error::Result<()> {
    let d = grid.dims;
    if grid.cell_count() >= crate::gpu::consts::CAUSTIC_CELL as u64 {
        return Err(crate::error::Error::Limits(format!(
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
pub fn check_photon_slots(limits: &wgpu::Limits, layout: &MapLayout) -> crate::error::Result<()> {
    let d = layout.grid.dims;
    let entries = layout.table.capacity() as u64;
    let what = format!("the {} slots of a photon grid of {}x{}x{} cells", layout.table.len(), d.x, d.y, d.z);
    for (part, stride) in [("counters", 8), ("lookup values", 16), ("keys", 8)] {
        check_storage_buffer(limits, &format!("the {part} of {what}"), entries, stride, "choose a smaller --grid")?;
    }
    let total = entries * 24;
    if total > limits.max_buffer_size {
        return Err(crate::error::Error::Limits(format!(
            "the counters of {what} need {} in one buffer, more than this GPU's {}; choose a smaller --grid",
            mib(total),
            mib(limits.max_buffer_size)
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::gpu::limits::test_limits as limits;

    use super::*;
    use crate::sampling::{Rng, uniform_sphere};
    use crate::scene::{Camera, Material, cornell_box, triangle_area};

    fn scene_of_quads(quads: &[[Vec3; 4]]) -> Scene {
        let cam = Camera { eye: Vec3::Z, target: Vec3::ZERO, up: Vec3::Y, fov_y_deg: 40.0 };
        let mut s = Scene::new(cam);
        let m = s.add_material(Material::diffuse("m", Vec3::ONE));
        for q in quads {
            s.add_quad(*q, m);
        }
        s
    }

    /// The angle between two unit vectors, in degrees.
    fn angle(a: Vec3, b: Vec3) -> f32 {
        a.dot(b).clamp(-1.0, 1.0).acos().to_degrees()
    }

    #[test]
    fn axis_normals_lie_in_the_central_bin_of_their_face_and_every_bin_is_used() {
        for (face, n) in [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z].into_iter().enumerate() {
            assert_eq!(orientation_bin(n), (face * FACE_DIVISIONS + 1) * FACE_DIVISIONS + 1, "{n}");
        }
        // Random directions: all 54 bins occur, and within a bin no two are farther apart than
        // the central bin's diagonal, 2·atan(√2/3) = 50.48°.
        let mut rng = Rng::new(3, 0, 0);
        let mut members: Vec<Vec<Vec3>> = vec![Vec::new(); BINS];
        for _ in 0..20_000 {
            let n = uniform_sphere(rng.next_f32(), rng.next_f32());
            members[orientation_bin(n)].push(n);
        }
        let widest = 2.0 * (2f32.sqrt() / 3.0).atan().to_degrees();
        for (b, m) in members.iter().enumerate() {
            assert!(!m.is_empty(), "bin {b} never used");
            for x in m.iter().step_by(7) {
                for y in m.iter().step_by(11) {
                    assert!(angle(*x, *y) <= widest + 0.01, "bin {b}: {x} and {y} {}° apart", angle(*x, *y));
                }
            }
        }
    }

    #[test]
    fn parallel_planes_farther_apart_than_the_offset_step_never_share_a_key() {
        let grid = GridSpec::uniform(Vec3::ZERO, 0.25, UVec3::splat(8));
        let step = OFFSET_STEP * grid.cell;
        let mut rng = Rng::new(5, 0, 0);
        for _ in 0..2000 {
            let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0;
            let gap = step * (1.0 + 2.0 * rng.next_f32());
            let c = grid.coarse().cell_of(p);
            let (a, b) = (TrianglePlane::new(-Vec3::Y, p), TrianglePlane::new(-Vec3::Y, p + Vec3::Y * gap));
            for back in [false, true] {
                assert_ne!(a.key(&grid.coarse(), c, back), b.key(&grid.coarse(), c, back), "{p} {gap}");
            }
        }
        // The same plane through any of its points: one key per cell.
        let c = UVec3::new(2, 1, 3);
        let k = TrianglePlane::new(Vec3::Y, Vec3::new(0.1, 0.37, 0.2)).key(&grid.coarse(), c, false);
        assert_eq!(TrianglePlane::new(Vec3::Y, Vec3::new(1.9, 0.37, 1.3)).key(&grid.coarse(), c, false), k);
    }

    #[test]
    fn clipped_areas_sum_to_the_scene_area_per_plane_key() {
        let scene = cornell_box();
        for resolution in [1, 7, 32] {
            let grid = GridSpec::new(&scene.bounds(), resolution);
            let layout = MapLayout::new(&scene, &grid);
            let mut expected: HashMap<u32, f64> = HashMap::new();
            // Per orientation bin: the bin is the key's low bits, below the region.
            for (i, t) in scene.triangles.iter().enumerate() {
                *expected.entry(layout.planes[i].bins[0]).or_default() += triangle_area(t) as f64;
                if scene.material_of(i).two_sided {
                    *expected.entry(layout.planes[i].bins[1]).or_default() += triangle_area(t) as f64;
                }
            }
            let mut got: HashMap<u32, f64> = HashMap::new();
            for (k, a) in layout.table.keys.iter().zip(&layout.area) {
                if k[0] != EMPTY {
                    *got.entry(k[1] & ((1 << REGION_SHIFT) - 1)).or_default() += a;
                }
            }
            assert_eq!(got.len(), expected.len(), "bins at {resolution}");
            for (bin, e) in &expected {
                let g = got.get(bin).copied().unwrap_or(0.0);
                assert!((g - e).abs() < 1e-5 * e.max(1.0), "bin {bin} at {resolution}: {g} vs {e}");
            }
        }
    }

    #[test]
    fn a_refined_grid_keeps_every_area_once_and_puts_fine_cells_in_its_region_only() {
        // Cornell's box with its middle refined 4×: per orientation bin, the areas of both
        // levels sum to the scene's; every slot inside the region is a fine one (of a quarter
        // the side), every one outside a coarse one; each deposit point finds the slot of its
        // own level.
        let scene = cornell_box();
        let region = Aabb { min: Vec3::new(-0.5, -0.3, -0.4), max: Vec3::new(0.2, 0.6, 0.5) };
        let grid = GridSpec::new(&scene.bounds(), 16).refined(&region, 4);
        let fine = grid.fine().expect("a fine level");
        assert_eq!(fine.cell, grid.cell / 4.0);
        let layout = MapLayout::new(&scene, &grid);
        let mut expected: HashMap<u32, f64> = HashMap::new();
        for (i, t) in scene.triangles.iter().enumerate() {
            *expected.entry(layout.planes[i].bins[0]).or_default() += triangle_area(t) as f64;
            if scene.material_of(i).two_sided {
                *expected.entry(layout.planes[i].bins[1]).or_default() += triangle_area(t) as f64;
            }
        }
        let mut got: HashMap<u32, f64> = HashMap::new();
        let (mut coarse_slots, mut fine_slots) = (0, 0);
        for (k, a) in layout.table.keys.iter().zip(&layout.area) {
            if k[0] != EMPTY {
                *got.entry(k[1] & ((1 << REGION_SHIFT) - 1)).or_default() += a;
                if k[0] >= fine.base { fine_slots += 1 } else { coarse_slots += 1 }
            }
        }
        assert!(coarse_slots > 0 && fine_slots > 0);
        for (bin, e) in &expected {
            let g = got.get(bin).copied().unwrap_or(0.0);
            assert!((g - e).abs() < 1e-5 * e.max(1.0), "bin {bin}: {g} vs {e}");
        }
        let mut rng = Rng::new(4, 0, 0);
        for _ in 0..4000 {
            let tri = (rng.next_u32() as usize) % scene.triangles.len();
            let t = &scene.triangles[tri];
            let p = crate::sampling::uniform_triangle(t, rng.next_f32(), rng.next_f32());
            let level = grid.lattice_at(p);
            let inside = grid.is_refined(grid.coarse().cell_of(p));
            assert_eq!(level.base > 0, inside, "{p}");
            if let Some(s) = layout.deposit_slot(tri, false, p) {
                assert_eq!(layout.table.keys[s][0] >= fine.base, inside, "{p}");
            }
        }
    }

    #[test]
    fn points_on_walls_that_lie_on_cell_boundaries_find_their_slot() {
        // The sunroom's walls at z = 0 and x = 0 lie on cell boundaries of its grids (centred
        // on the origin) at some resolutions; cell_of's f32 rounding put their points in the
        // cell below, their area (clipped exactly) in the cell above, and every photon landing
        // there was lost: all of some walls at 274, 287, 329 and 379 cells, the progressive
        // passes' resolutions from 228. Now every point of every triangle finds its slot, in
        // both levels of the refined grid and in the plain one.
        let scene = crate::scene::generate::sunroom();
        let region = Aabb { min: Vec3::new(-0.4, 0.0, -3.45), max: Vec3::new(6.4, 3.2, 5.4) };
        let mut rng = Rng::new(8, 0, 0);
        for r in [228, 274, 287, 329, 379] {
            for refine in [10, 1] {
                let grid = GridSpec::new(&scene.bounds(), r).refined(&region, refine);
                let layout = MapLayout::new(&scene, &grid);
                for (i, t) in scene.triangles.iter().enumerate() {
                    for _ in 0..200 {
                        let p = crate::sampling::uniform_triangle(t, rng.next_f32(), rng.next_f32());
                        assert!(layout.deposit_slot(i, false, p).is_some(), "{r} cells, refined {refine}: {p} on {i}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_uniform_map_reads_uniform_across_the_two_levels() {
        // Φ = 2·A in every slot of both levels: E = 2 at any point, beside the region's border
        // too (a lookup counts only cells of its own level).
        let scene = cornell_box();
        let region = Aabb { min: Vec3::new(-0.2, -0.2, -0.2), max: Vec3::new(0.3, 0.3, 0.3) };
        let grid = GridSpec::new(&scene.bounds(), 8).refined(&region, 3);
        let layout = MapLayout::new(&scene, &grid);
        let flux = layout.area.iter().map(|&a| [2.0 * a; 3]).collect();
        let n = layout.table.capacity();
        let map = PhotonMap { layout, flux, flux_sq: vec![0.0; n], deposits: vec![0; n], dropped: 0 };
        let mut rng = Rng::new(6, 0, 0);
        for _ in 0..2000 {
            let tri = (rng.next_u32() as usize) % scene.triangles.len();
            let p = crate::sampling::uniform_triangle(&scene.triangles[tri], rng.next_f32(), rng.next_f32());
            let e = map.irradiance_on(tri, false, p);
            assert!((e[0] - 2.0).abs() < 1e-9, "{tri} {p}: {e:?}");
        }
    }

    #[test]
    fn the_cornell_light_and_the_ceiling_above_it_never_share_a_slot() {
        let scene = cornell_box();
        let grid = GridSpec::new(&scene.bounds(), 64);
        let layout = MapLayout::new(&scene, &grid);
        // The ceiling at y = 1 and the light at y = 0.99 (3.1 cm cells), both facing down:
        // in every cell holding light, the light's slot holds the light's area alone.
        let lights = scene.emissive_triangles();
        let light_area: f64 = lights.iter().map(|&i| triangle_area(&scene.triangles[i as usize]) as f64).sum();
        let mut slots = std::collections::HashSet::new();
        let mut ceiling_cells = 0;
        let mut rng = Rng::new(9, 0, 0);
        for _ in 0..4000 {
            let p = Vec3::new(rng.next_f32() * 0.46 - 0.23, 0.99, rng.next_f32() * 0.38 - 0.18);
            let i = lights[0] as usize;
            slots.insert(layout.deposit_slot(i, false, p).expect("the light's slot"));
            let q = Vec3::new(p.x, 1.0, p.z);
            let c = grid.coarse().cell_of(q);
            let (cell, key) = (grid.coarse().index(c), TrianglePlane::new(-Vec3::Y, q).key(&grid.coarse(), c, false));
            if layout.table.find(cell, key | layout.region(cell, key, q) << REGION_SHIFT).is_some() {
                ceiling_cells += 1;
            }
        }
        let total: f64 = slots.iter().map(|&s| layout.area[s]).sum();
        assert!((total - light_area).abs() < 1e-6, "light slots hold {total}, the light {light_area}");
        assert!(ceiling_cells > 0, "the ceiling shares the light's cells");
    }

    #[test]
    fn a_unit_square_on_a_cell_boundary_plane_splits_its_area_exactly() {
        // A square in the plane z = 0.3, from (0,0) to (1,1), in a grid of cells 0.25 wide:
        // every cell it crosses gets exactly 0.0625.
        let s = scene_of_quads(&[[
            Vec3::new(0.0, 0.0, 0.3),
            Vec3::new(1.0, 0.0, 0.3),
            Vec3::new(1.0, 1.0, 0.3),
            Vec3::new(0.0, 1.0, 0.3),
        ]]);
        let grid = GridSpec::uniform(Vec3::ZERO, 0.25, UVec3::new(4, 4, 4));
        let layout = MapLayout::new(&s, &grid);
        for y in 0..4 {
            for x in 0..4 {
                let c = UVec3::new(x, y, 1);
                let e = layout
                    .table
                    .find(grid.coarse().index(c), layout.planes[0].key(&grid.coarse(), c, false))
                    .expect("a slot");
                assert!((layout.area[e] - 0.0625).abs() < 1e-9, "cell ({x},{y}): {}", layout.area[e]);
            }
        }
        assert_eq!(layout.table.len(), 16);
    }

    #[test]
    fn a_square_exactly_on_a_cell_boundary_counts_once_in_the_cell_its_photons_land_in() {
        let s = scene_of_quads(&[[
            Vec3::new(0.0, 0.0, 0.5),
            Vec3::new(1.0, 0.0, 0.5),
            Vec3::new(1.0, 1.0, 0.5),
            Vec3::new(0.0, 1.0, 0.5),
        ]]);
        let grid = GridSpec::uniform(Vec3::ZERO, 0.25, UVec3::new(4, 4, 4));
        let layout = MapLayout::new(&s, &grid);
        let total: f64 = layout.area.iter().sum();
        assert!((total - 1.0).abs() < 1e-9, "area counted {total} times");
        assert_eq!(grid.coarse().cell_of(Vec3::new(0.3, 0.3, 0.5)).z, 2);
        let e = layout.deposit_slot(0, false, Vec3::new(0.3, 0.3, 0.5)).expect("the slot photons land in");
        assert!((layout.area[e] - 0.0625).abs() < 1e-9);
    }

    #[test]
    fn a_grid_whose_slots_exceed_the_binding_limit_degrades_to_coarser_cells() {
        let scene = cornell_box();
        let roomy =
            wgpu::Limits { max_storage_buffer_binding_size: 1 << 30, max_buffer_size: 1 << 32, ..Default::default() };
        let asked = MapLayout::within(&scene, &scene.bounds(), 32, None, &roomy).unwrap();
        assert_eq!(asked.grid, GridSpec::new(&scene.bounds(), 32));
        // 1 MiB binds 65 536 lookup values; 256³ cells would need millions.
        let tight =
            wgpu::Limits { max_storage_buffer_binding_size: 1 << 20, max_buffer_size: 1 << 32, ..Default::default() };
        let coarse = MapLayout::within(&scene, &scene.bounds(), 256, None, &tight).unwrap();
        let used = coarse.grid.dims.max_element();
        assert!(used < 256 && 256 % used == 0, "{used}");
        assert!(check_photon_slots(&tight, &coarse).is_ok());
        assert!(coarse.table.capacity() as u64 * 16 <= 1 << 20);
        // The coarser map is a whole map: every triangle's area is in it.
        let total: f64 = coarse.area.iter().sum();
        let expected: f64 = scene.triangles.iter().map(|t| triangle_area(t) as f64).sum();
        assert!((total - expected).abs() < 1e-4 * expected, "{total} vs {expected}");
    }

    #[test]
    fn lookup_of_a_uniform_map_returns_the_uniform_irradiance_anywhere() {
        // Φ = 3·A in every slot: E = 3 wherever interpolated, even at borders and next to
        // cells without that plane. Three quads of different planes, areas varied by their
        // cuts through the cells.
        let s = scene_of_quads(&[
            [Vec3::new(0.0, 0.0, 0.1), Vec3::new(2.9, 0.0, 0.1), Vec3::new(2.9, 1.7, 0.1), Vec3::new(0.0, 1.7, 0.1)],
            [Vec3::new(0.2, 0.3, 0.0), Vec3::new(0.2, 2.9, 0.0), Vec3::new(0.2, 2.9, 2.1), Vec3::new(0.2, 0.3, 2.1)],
            [Vec3::new(0.0, 2.3, 0.0), Vec3::new(0.0, 2.3, 2.9), Vec3::new(1.1, 2.3, 2.9), Vec3::new(1.1, 2.3, 0.0)],
        ]);
        let grid = GridSpec::uniform(Vec3::ZERO, 1.0, UVec3::new(3, 3, 3));
        let layout = MapLayout::new(&s, &grid);
        let flux = layout.area.iter().map(|&a| [3.0 * a; 3]).collect();
        let n = layout.table.capacity();
        let map = PhotonMap { layout, flux, flux_sq: vec![0.0; n], deposits: vec![0; n], dropped: 0 };
        for (tri, p) in [(0, Vec3::new(0.01, 0.01, 0.1)), (0, Vec3::new(2.8, 1.6, 0.1)), (2, Vec3::new(0.3, 0.5, 1.5))]
        {
            let e = map.irradiance_on(tri, false, p);
            assert!((e[0] - 3.0).abs() < 1e-9, "{tri} {p}: {e:?}");
        }
        let e = map.irradiance(Vec3::new(0.5, 2.3, 2.5), triangle_normal(&s.triangles[4]));
        assert!((e[0] - 3.0).abs() < 1e-9, "{e:?}");
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
}
