//! Convex polygon clipping (Sutherland–Hodgman) for the photon map's slot areas: to a cell's
//! half-open box and to a plane's half-space.

use glam::DVec3;

/// Sutherland–Hodgman clipping of a convex polygon to the half-open box [min, max), the
/// same cells `GridSpec::cell_of` assigns points to: a polygon lying exactly on a cell
/// boundary counts in the cell above it only, where its photons land.
pub(crate) fn clip_to_box(poly: &[DVec3], min: DVec3, max: DVec3) -> Vec<DVec3> {
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

pub(crate) fn polygon_area(poly: &[DVec3]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let mut s = DVec3::ZERO;
    for k in 1..poly.len() - 1 {
        s += (poly[k] - poly[0]).cross(poly[k + 1] - poly[0]);
    }
    0.5 * s.length()
}

/// The part of the convex polygon on the negative side of plane (n, d) (`negative`), or on
/// its non-negative side.
pub(crate) fn clip_to_half_space(poly: &[DVec3], n: DVec3, d: f64, negative: bool) -> Vec<DVec3> {
    let inside = |p: &DVec3| (n.dot(*p) - d < 0.0) == negative;
    let mut out = Vec::new();
    for (k, p) in poly.iter().enumerate() {
        let q = &poly[(k + 1) % poly.len()];
        if inside(p) {
            out.push(*p);
        }
        if inside(p) != inside(q) {
            let (sp, sq) = (n.dot(*p) - d, n.dot(*q) - d);
            out.push(*p + (*q - *p) * (sp / (sp - sq)));
        }
    }
    if out.len() < 3 { Vec::new() } else { out }
}
