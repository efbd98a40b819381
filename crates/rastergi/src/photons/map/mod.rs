//! The grid photon map, stored sparsely: only the slots that hold surface, in a hash table.
//!
//! * A **slot** is a (cell, plane) pair: a cubic cell of the grid and a surface plane key, the
//!   side's orientation bin and its plane's offset. Photons deposit their flux Φ in the slot of
//!   the cell they land in and the plane of the side they land on; the slot's area A is the
//!   part of the scene's surfaces with that plane key inside the cell (triangles clipped to
//!   the cell). Irradiance of a slot: E = Φ / A. Where the surface has holes (cut-outs,
//!   stochastic opacity), photons stop only with the probability c(x) that it is there
//!   ([`Scene::coverage_at`](crate::scene::Scene::coverage_at)), so A = ∫ c dA over the piece ([`mean_coverage`]): the holes
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

mod grid;
mod layout;
#[cfg(test)]
mod tests;

use glam::{IVec3, Vec3};

pub use super::separators::{MAX_SEPARATORS, MIN_REGION, Separator, Separators, region_of};
pub use super::table::{EMPTY, SlotTable};
use crate::gpu::consts::CAUSTIC_CELL;
pub use crate::gpu::consts::{MIN_LOOKUP_AREA, NEAR_FACE};
use crate::gpu::limits::{check_storage_buffer, mib};
pub use grid::*;
pub use layout::*;

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
