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

pub use crate::consts::MAX_SEPARATORS;
/// A separator splits a slot only where each side holds at least this fraction of its area.
pub const MIN_REGION: f64 = 0.02;

/// The separators of every base slot that has any, in a table keyed like the slots
/// (`slot_keys` from the slots' capacity on, `separator_planes` in WGSL).
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

/// Up to [`MAX_SEPARATORS`] planes of other surfaces in the cell, the ones with the most
/// surface in the cell first, leaving out planes the slot's own fragments lie in (all their
/// vertices within `eps`) and planes that cut off less than [`MIN_REGION`] of their area. A
/// plane that cuts the fragments splits the slot into regions: a
/// wall standing on a floor splits the floor's slot into its two rooms and the strip under
/// the wall, which no photon reaches; a box standing on it, the floor under it from the floor
/// around it. A plane that bounds them (a wall the floor ends at) splits nothing, but the
/// lookup reads no neighbouring cell beyond it.
pub(crate) fn separators_of(own: &[&Fragment], all: &[Fragment], key: u32, eps: f64) -> Vec<(DVec3, f64)> {
    // (key, plane, area in the cell, splits the slot's fragments)
    let mut candidates: Vec<(u32, (DVec3, f64), f64, bool)> = Vec::new();
    for f in all.iter().filter(|f| f.key != key) {
        match candidates.iter_mut().find(|c| c.0 == f.key) {
            Some(c) => c.2 += f.area,
            None => candidates.push((f.key, f.plane, f.area, false)),
        }
    }
    let vertices = || own.iter().flat_map(|f| f.poly.iter());
    let total: f64 = own.iter().map(|f| f.area).sum();
    let negative =
        |(n, d): (DVec3, f64)| own.iter().map(|f| polygon_area(&clip_to_half_space(&f.poly, n, d, true))).sum::<f64>();
    candidates.retain_mut(|c| {
        let (n, d) = c.1;
        if !vertices().any(|v| (n.dot(*v) - d).abs() > eps) {
            return false; // the slot's own plane
        }
        let below = negative(c.1);
        let least = below.min(total - below);
        // A plane that cuts off a sliver would make a slot of almost no area, whose few
        // photons read as a spike: it neither splits nor fences.
        c.3 = least > MIN_REGION * total;
        c.3 || least <= 1e-9 * total
    });
    // Planes that split first, then by their surface in the cell.
    candidates.sort_by(|a, b| b.3.cmp(&a.3).then(b.2.total_cmp(&a.2)).then(a.0.cmp(&b.0)));
    candidates.into_iter().take(MAX_SEPARATORS).map(|c| c.1).collect()
}
