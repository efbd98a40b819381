//! Separators: planes of other surfaces in a cell that split a photon-map slot into regions
//! (a wall standing on a floor: each room's floor, and the strip under the wall) and fence the
//! lookup (no neighbouring cell beyond them is read). See [`super::map`].

use glam::{DVec3, Vec3};

use super::clip::{clip_to_half_space, polygon_area};
use super::table::SlotTable;

/// A surface side's part inside one cell.
pub(crate) struct Fragment {
    /// Its base plane key in the cell.
    pub(crate) key: u32,
    /// Its plane, (n, d) with n·x = d on it, n the side's normal.
    pub(crate) plane: (DVec3, f64),
    pub(crate) poly: Vec<DVec3>,
    /// Its area, weighted by its surface's mean coverage (see `MapLayout::new`).
    pub(crate) area: f64,
    /// The mean coverage of its surface over it (1 where the material has no holes).
    pub(crate) coverage: f64,
}

/// A separator plane (n, d), n unit: a point x lies on its negative side where n·x − d < 0.
pub type Separator = [f32; 4];

pub use crate::gpu::consts::MAX_SEPARATORS;
/// A separator splits a slot only where each side holds at least this fraction of its area.
pub const MIN_REGION: f64 = 0.02;

/// The separators of every base slot that has any, in a table keyed like the slots
/// (`slot_keys` from the slots' capacity on, the records after them: `photons::gpu::table_entries`).
#[derive(Clone, Debug, PartialEq)]
pub struct Separators {
    pub table: SlotTable,
    /// Per table entry; unused separators are all zero (every point on their positive side).
    pub planes: Vec<[Separator; MAX_SEPARATORS]>,
}

/// Bit k set where p lies on the negative side of separator k (`region_of` in WGSL).
pub fn region_of(planes: &[Separator; MAX_SEPARATORS], p: Vec3) -> u32 {
    let mut region = 0;
    for (k, s) in planes.iter().enumerate() {
        // Unused separators are zero: every point on their non-negative side.
        if Vec3::new(s[0], s[1], s[2]).dot(p) - s[3] < 0.0 {
            region |= 1 << k;
        }
    }
    region
}

/// The base plane keys of a cell's fragments, each with the plane of its first fragment (in
/// the cell's order) and the summed area of its fragments: the candidate separators of every
/// slot in the cell, gathered once per cell.
pub(crate) struct CellPlanes {
    /// (key, plane, area in the cell), in the order of each key's first fragment.
    pub(crate) planes: Vec<(u32, (DVec3, f64), f64)>,
}

impl CellPlanes {
    pub(crate) fn new(all: &[Fragment]) -> CellPlanes {
        let mut planes: Vec<(u32, (DVec3, f64), f64)> = Vec::new();
        let mut index: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
        for f in all {
            match index.get(&f.key) {
                Some(&i) => planes[i].2 += f.area,
                None => {
                    index.insert(f.key, planes.len());
                    planes.push((f.key, f.plane, f.area));
                }
            }
        }
        CellPlanes { planes }
    }
}

/// Up to [`MAX_SEPARATORS`] planes of other surfaces in the cell (`cell`, gathered from all
/// its fragments), the ones with the most surface in the cell first, leaving out planes the
/// slot's own fragments lie in (all their vertices within `eps`) and planes that cut off less
/// than [`MIN_REGION`] of their area. A plane that cuts the fragments splits the slot into
/// regions: a wall standing on a floor splits the floor's slot into its two rooms and the
/// strip under the wall, which no photon reaches; a box standing on it, the floor under it
/// from the floor around it. A plane that bounds them (a wall the floor ends at) splits
/// nothing, but the lookup reads no neighbouring cell beyond it.
///
/// A fragment with every vertex on one side of a plane needs no clipping: the part of it below
/// is all of it or nothing, exactly as clipping finds (every vertex kept, or none).
pub(crate) fn separators_of(own: &[&Fragment], cell: &CellPlanes, key: u32, eps: f64) -> Vec<(DVec3, f64)> {
    // (key, plane, area in the cell, splits the slot's fragments)
    let mut candidates: Vec<(u32, (DVec3, f64), f64, bool)> = Vec::new();
    let total: f64 = own.iter().map(|f| f.area).sum();
    for &(k, (n, d), area) in cell.planes.iter().filter(|c| c.0 != key) {
        // The area below the plane, fragment by fragment: all of one whose vertices are all
        // below, none of one whose vertices are all on or above, the clipped part of one the
        // plane cuts.
        let (mut off, mut below) = (false, 0.0f64);
        for f in own {
            let (mut lo, mut hi) = (false, false);
            for v in &f.poly {
                let s = n.dot(*v) - d;
                off |= s.abs() > eps;
                if s < 0.0 { lo = true } else { hi = true }
            }
            below += match (lo, hi) {
                (false, _) => 0.0,
                (true, false) => polygon_area(&f.poly),
                (true, true) => polygon_area(&clip_to_half_space(&f.poly, n, d, true)),
            };
        }
        if !off {
            continue; // the slot's own plane
        }
        let least = below.min(total - below);
        // A plane that cuts off a sliver would make a slot of almost no area, whose few
        // photons read as a spike: it neither splits nor fences.
        let splits = least > MIN_REGION * total;
        if splits || least <= 1e-9 * total {
            candidates.push((k, (n, d), area, splits));
        }
    }
    // Planes that split first, then by their surface in the cell.
    candidates.sort_by(|a, b| b.3.cmp(&a.3).then(b.2.total_cmp(&a.2)).then(a.0.cmp(&b.0)));
    candidates.into_iter().take(MAX_SEPARATORS).map(|c| c.1).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// The separators as first written: candidates gathered anew for every slot, every
    /// fragment clipped against every candidate (the obvious twin of [`separators_of`]).
    fn separators_by_clipping(own: &[&Fragment], all: &[Fragment], key: u32, eps: f64) -> Vec<(DVec3, f64)> {
        let mut candidates: Vec<(u32, (DVec3, f64), f64, bool)> = Vec::new();
        for f in all.iter().filter(|f| f.key != key) {
            match candidates.iter_mut().find(|c| c.0 == f.key) {
                Some(c) => c.2 += f.area,
                None => candidates.push((f.key, f.plane, f.area, false)),
            }
        }
        let vertices = || own.iter().flat_map(|f| f.poly.iter());
        let total: f64 = own.iter().map(|f| f.area).sum();
        let negative = |(n, d): (DVec3, f64)| {
            own.iter().map(|f| polygon_area(&clip_to_half_space(&f.poly, n, d, true))).sum::<f64>()
        };
        candidates.retain_mut(|c| {
            let (n, d) = c.1;
            if !vertices().any(|v| (n.dot(*v) - d).abs() > eps) {
                return false;
            }
            let below = negative(c.1);
            let least = below.min(total - below);
            c.3 = least > MIN_REGION * total;
            c.3 || least <= 1e-9 * total
        });
        candidates.sort_by(|a, b| b.3.cmp(&a.3).then(b.2.total_cmp(&a.2)).then(a.0.cmp(&b.0)));
        candidates.into_iter().take(MAX_SEPARATORS).map(|c| c.1).collect()
    }

    /// Cells of random triangles on a few shared planes (floors, walls, slanted boards, and
    /// some on their own): the separators of every slot are the twin's, bit for bit.
    #[test]
    fn separators_are_those_of_clipping_every_fragment() {
        let mut rng = Rng::new(3, 1, 4);
        let mut u = || rng.next_f32() as f64;
        let (mut slots, mut separated) = (0, 0);
        for _cell in 0..200 {
            let planes: Vec<(DVec3, f64)> = (0..1 + (u() * 8.0) as usize)
                .map(|_| {
                    let n = DVec3::new(u() - 0.5, u() - 0.5, u() - 0.5).normalize();
                    (n, u() - 0.5)
                })
                .collect();
            let mut all = Vec::new();
            for _ in 0..(u() * 40.0) as usize {
                let k = (u() * planes.len() as f64) as usize % planes.len();
                let (n, d) = planes[k];
                // Three points in the plane n·x = d around a random centre.
                let c = DVec3::new(u() - 0.5, u() - 0.5, u() - 0.5);
                let c = c - n * (n.dot(c) - d);
                let (t, b) = (n.any_orthonormal_pair().0, n.any_orthonormal_pair().1);
                let poly: Vec<DVec3> = (0..3).map(|_| c + t * (u() - 0.5) * 0.6 + b * (u() - 0.5) * 0.6).collect();
                let area = polygon_area(&poly);
                all.push(Fragment { key: k as u32, plane: (n, d), poly, area, coverage: 1.0 });
            }
            let cell = CellPlanes::new(&all);
            for key in 0..planes.len() as u32 {
                let own: Vec<&Fragment> = all.iter().filter(|f| f.key == key).collect();
                if own.is_empty() {
                    continue;
                }
                let fast = separators_of(&own, &cell, key, 1e-4);
                let slow = separators_by_clipping(&own, &all, key, 1e-4);
                assert_eq!(fast, slow, "key {key} of a cell of {} fragments", all.len());
                slots += 1;
                separated += (!fast.is_empty()) as usize;
            }
        }
        println!("{separated} of {slots} slots have separators");
        assert!(separated > slots / 4 && separated < slots, "{separated} of {slots} slots have separators");
    }
}
