//! The grid: orientation bins and every triangle's plane key, the cell size and its refinement
//! by the progressive passes, and the lattice of cells over the scene.

use glam::{DVec3, UVec3, Vec3};

use crate::gpu::structs::gpu_struct;
use crate::photons::table::EMPTY;
use crate::scene::Aabb;

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

gpu_struct! {
    /// A triangle's plane as the map keys it (read by `table.wgsl`'s `plane_key`).
    #[derive(PartialEq)]
    pub struct TrianglePlane as "TrianglePlane" {
        /// The front side's unit normal.
        pub normal: [f32; 3],
        /// n·v₀: the plane is {x : n·x = offset}.
        pub offset: f32,
        /// The orientation bins of the front and back sides.
        pub bins: [u32; 2],
        pub _pad: [u32; 2],
    }
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
