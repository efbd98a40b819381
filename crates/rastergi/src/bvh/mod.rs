//! Bounding volume hierarchy over the scene's triangles: built on the CPU with a binned
//! surface-area heuristic, flattened depth-first into [`BvhNode`]s that every ray-tracing
//! pass shares (shadow rays, photons, the CPU twins). `bvh.wgsl` is the GPU traversal.
//!
//! SAH cost of a split: C = C_trav + (A_L/A)·N_L·C_tri + (A_R/A)·N_R·C_tri, evaluated at the
//! boundaries of 16 centroid bins per axis; a node becomes a leaf when no split is cheaper
//! than N·C_tri (and is always split above [`MAX_LEAF`] triangles).
//!
//! The tree is at most [`MAX_DEPTH`] levels deep, what the traversals' fixed stacks hold: below
//! depth 64 − ⌈log2 N⌉ − 1 (N the triangles; 45 for the staircase's 262 k, whose SAH tree is
//! 27 deep) every split is at the median, which adds at most ⌈log2 N⌉ levels. SAH splits of
//! coordinates spread over many orders of magnitude (a hostile file's 1e15 beside 1e37) peel
//! one triangle off per level and would otherwise nest as deep as there are triangles.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;

use bounds::Aabb;

pub mod bounds;
pub mod wide;

const BINS: usize = 16;
const MAX_LEAF: usize = 8;
const COST_TRAVERSAL: f32 = 1.0;
const COST_TRIANGLE: f32 = 1.0;
/// Most levels of the tree (a leaf alone is one): the traversals' stacks hold 64 nodes.
pub const MAX_DEPTH: usize = 64;

/// A flattened node (`BvhNode` in `gpu_scene.wgsl`). Interior nodes (`count == 0`) have their
/// left child right after them and their right child at `offset`; leaves hold the triangles
/// `offset .. offset + count` (in the BVH's triangle order).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct BvhNode {
    pub min: [f32; 3],
    pub offset: u32,
    pub max: [f32; 3],
    pub count: u32,
}

#[derive(Clone, Debug)]
pub struct Bvh {
    pub nodes: Vec<BvhNode>,
    /// `order[i]` is the input index of the i-th triangle in BVH order.
    pub order: Vec<u32>,
}

/// A ray hit: distance, triangle index (BVH order) and barycentrics of v1 and v2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub triangle: u32,
    pub b1: f32,
    pub b2: f32,
}

struct Build<'a> {
    bounds: Vec<Aabb>,
    centroids: Vec<Vec3>,
    order: &'a mut [u32],
    /// The depth from which every split is at the median (module docs).
    median_from: usize,
}

impl Bvh {
    /// Builds the hierarchy over `triangles`. The result's leaves index the triangles in
    /// `order`; renderers permute their triangle arrays by it once (see [`Bvh::permute`]).
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let bounds: Vec<Aabb> = triangles
            .iter()
            .map(|t| {
                let mut b = Aabb::EMPTY;
                t.iter().for_each(|&p| b.grow(p));
                b
            })
            .collect();
        let centroids = bounds.iter().map(|b| b.center()).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len().max(1));
        let levels = (triangles.len().max(1) as u64).next_power_of_two().trailing_zeros() as usize;
        let median_from = MAX_DEPTH.saturating_sub(levels + 1).max(1);
        let mut build = Build { bounds, centroids, order: &mut order, median_from };
        if triangles.is_empty() {
            nodes.push(BvhNode { min: [0.0; 3], offset: 0, max: [0.0; 3], count: 0 });
        } else {
            build.node(&mut nodes, 0, triangles.len(), 1);
        }
        Bvh { nodes, order }
    }

    /// Reorders per-triangle data into BVH order.
    pub fn permute<T: Clone>(&self, items: &[T]) -> Vec<T> {
        self.order.iter().map(|&i| items[i as usize].clone()).collect()
    }

    /// Closest hit with t in (t_min, t_max), skipping triangle `skip` (BVH order; `u32::MAX`
    /// skips none), counting only the hits that `solid` accepts (the others, holes of a
    /// cut-out or of a stochastic surface, are passed through; `|_| true` for none), as `trace`
    /// in `bvh.wgsl`. `triangles` must be in BVH order.
    #[allow(clippy::too_many_arguments)]
    pub fn intersect(
        &self,
        triangles: &[[Vec3; 3]],
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
        skip: u32,
        solid: impl Fn(&Hit) -> bool,
    ) -> Option<Hit> {
        let mut best: Option<Hit> = None;
        let mut t_far = t_max;
        self.traverse(o, d, t_min, &mut t_far, |i, t_far| {
            if i == skip {
                return false;
            }
            if let Some((t, b1, b2)) = intersect_triangle(&triangles[i as usize], o, d)
                && t > t_min
                && t < *t_far
            {
                let hit = Hit { t, triangle: i, b1, b2 };
                if solid(&hit) {
                    *t_far = t;
                    best = Some(hit);
                }
            }
            false
        });
        best
    }

    /// Whether any triangle other than `skip_a` and `skip_b` is hit with t in (t_min, t_max).
    pub fn occluded(&self, triangles: &[[Vec3; 3]], o: Vec3, d: Vec3, t_min: f32, t_max: f32, skip: [u32; 2]) -> bool {
        let mut t_far = t_max;
        let mut hit = false;
        self.traverse(o, d, t_min, &mut t_far, |i, t_far| {
            if skip.contains(&i) {
                return false;
            }
            if let Some((t, _, _)) = intersect_triangle(&triangles[i as usize], o, d)
                && t > t_min
                && t < *t_far
            {
                hit = true;
                return true;
            }
            false
        });
        hit
    }

    /// Stack traversal, nearer child first. `visit(triangle, t_far)` returns true to stop.
    fn traverse(&self, o: Vec3, d: Vec3, t_min: f32, t_far: &mut f32, mut visit: impl FnMut(u32, &mut f32) -> bool) {
        let inv = d.recip();
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut node = 0u32;
        loop {
            let n = &self.nodes[node as usize];
            if n.count > 0 {
                for i in n.offset..n.offset + n.count {
                    if visit(i, t_far) {
                        return;
                    }
                }
            } else {
                let (l, r) = (node + 1, n.offset);
                let tl = slab(&self.nodes[l as usize], o, inv, t_min, *t_far);
                let tr = slab(&self.nodes[r as usize], o, inv, t_min, *t_far);
                match (tl, tr) {
                    (Some(a), Some(b)) => {
                        let (near, far) = if a <= b { (l, r) } else { (r, l) };
                        stack[sp] = far;
                        sp += 1;
                        node = near;
                        continue;
                    }
                    (Some(_), None) => {
                        node = l;
                        continue;
                    }
                    (None, Some(_)) => {
                        node = r;
                        continue;
                    }
                    (None, None) => {}
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            node = stack[sp];
        }
    }

    /// The tree's surface-area-heuristic cost, the expected work of a ray that crosses the root's
    /// box in units of one triangle test: Σ over interior nodes of (A(n)/A(root))·C_trav plus Σ
    /// over leaves of (A(l)/A(root))·N_l·C_tri, with the build's C_trav = C_tri = 1.
    pub fn sah_cost(&self) -> f64 {
        let area = |n: &BvhNode| {
            let e = (Vec3::from(n.max) - Vec3::from(n.min)).max(Vec3::ZERO).as_dvec3();
            2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
        };
        let root = area(&self.nodes[0]);
        if root <= 0.0 {
            return 0.0;
        }
        let cost: f64 = self
            .nodes
            .iter()
            .map(|n| {
                let c = if n.count > 0 { n.count as f64 * COST_TRIANGLE as f64 } else { COST_TRAVERSAL as f64 };
                area(n) * c
            })
            .sum();
        cost / root
    }

    /// Depth of the tree (a leaf alone has depth 1).
    pub fn depth(&self) -> usize {
        fn rec(nodes: &[BvhNode], i: usize) -> usize {
            if nodes[i].count > 0 { 1 } else { 1 + rec(nodes, i + 1).max(rec(nodes, nodes[i].offset as usize)) }
        }
        rec(&self.nodes, 0)
    }
}

/// Entry distance of the ray into a node's box, if it overlaps [t_min, t_max].
fn slab(n: &BvhNode, o: Vec3, inv: Vec3, t_min: f32, t_max: f32) -> Option<f32> {
    let t0 = (Vec3::from(n.min) - o) * inv;
    let t1 = (Vec3::from(n.max) - o) * inv;
    let near = t0.min(t1).max_element().max(t_min);
    let far = t0.max(t1).min_element().min(t_max);
    (near <= far).then_some(near)
}

/// Möller–Trumbore: (t, b1, b2) of the hit with the triangle's plane inside it, either face.
pub fn intersect_triangle(t: &[Vec3; 3], o: Vec3, d: Vec3) -> Option<(f32, f32, f32)> {
    let e1 = t[1] - t[0];
    let e2 = t[2] - t[0];
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-20 {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = o - t[0];
    let b1 = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&b1) {
        return None;
    }
    let q = s.cross(e1);
    let b2 = d.dot(q) * inv_det;
    if b2 < 0.0 || b1 + b2 > 1.0 {
        return None;
    }
    Some((e2.dot(q) * inv_det, b1, b2))
}

impl Build<'_> {
    fn range_bounds(&self, first: usize, count: usize) -> (Aabb, Aabb) {
        let mut b = Aabb::EMPTY;
        let mut c = Aabb::EMPTY;
        for &i in &self.order[first..first + count] {
            b = b.union(self.bounds[i as usize]);
            c.grow(self.centroids[i as usize]);
        }
        (b, c)
    }

    /// Emits the node for order[first .. first+count] at `depth` (the root's is 1) and its
    /// subtree; returns its index.
    fn node(&mut self, nodes: &mut Vec<BvhNode>, first: usize, count: usize, depth: usize) -> usize {
        let (b, cb) = self.range_bounds(first, count);
        let index = nodes.len();
        nodes.push(BvhNode { min: b.min.into(), offset: first as u32, max: b.max.into(), count: count as u32 });
        if count <= 1 {
            return index;
        }
        let split = if depth < self.median_from { self.find_split(first, count, &b, &cb) } else { None };
        let mid = match split {
            Some((axis, pos)) => {
                let slice = &mut self.order[first..first + count];
                let centroids = &self.centroids;
                let mut l = 0;
                for j in 0..slice.len() {
                    if centroids[slice[j] as usize][axis] < pos {
                        slice.swap(l, j);
                        l += 1;
                    }
                }
                first + l
            }
            None if count > MAX_LEAF => {
                // No useful SAH split (e.g. identical centroids): split at the median.
                let axis = cb.extent().max_position();
                let centroids = &self.centroids;
                self.order[first..first + count]
                    .sort_by(|&a, &b| centroids[a as usize][axis].total_cmp(&centroids[b as usize][axis]));
                first + count / 2
            }
            None => return index,
        };
        if mid == first || mid == first + count {
            if count <= MAX_LEAF {
                return index;
            }
            let mid = first + count / 2;
            return self.children(nodes, index, first, count, mid, depth);
        }
        self.children(nodes, index, first, count, mid, depth)
    }

    fn children(
        &mut self,
        nodes: &mut Vec<BvhNode>,
        index: usize,
        first: usize,
        count: usize,
        mid: usize,
        depth: usize,
    ) -> usize {
        nodes[index].count = 0;
        self.node(nodes, first, mid - first, depth + 1);
        let right = self.node(nodes, mid, first + count - mid, depth + 1);
        nodes[index].offset = right as u32;
        index
    }

    /// The cheapest binned SAH split (axis, centroid plane), if cheaper than a leaf.
    fn find_split(&self, first: usize, count: usize, b: &Aabb, cb: &Aabb) -> Option<(usize, f32)> {
        let leaf_cost = count as f32 * COST_TRIANGLE;
        let mut best: Option<(f32, usize, f32)> = None;
        for axis in 0..3 {
            let (lo, hi) = (cb.min[axis], cb.max[axis]);
            if hi - lo <= 0.0 {
                continue;
            }
            let scale = BINS as f32 / (hi - lo);
            let mut bin_bounds = [Aabb::EMPTY; BINS];
            let mut bin_count = [0usize; BINS];
            for &i in &self.order[first..first + count] {
                let k = (((self.centroids[i as usize][axis] - lo) * scale) as usize).min(BINS - 1);
                bin_bounds[k] = bin_bounds[k].union(self.bounds[i as usize]);
                bin_count[k] += 1;
            }
            // Sweep: area·count of everything left of each boundary, then right of it.
            let mut left = [0.0f32; BINS];
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in 0..BINS - 1 {
                acc = acc.union(bin_bounds[k]);
                n += bin_count[k];
                left[k] = if n > 0 { acc.area() * n as f32 } else { 0.0 };
            }
            let (mut acc, mut n) = (Aabb::EMPTY, 0);
            for k in (1..BINS).rev() {
                acc = acc.union(bin_bounds[k]);
                n += bin_count[k];
                let right = if n > 0 { acc.area() * n as f32 } else { 0.0 };
                let cost = COST_TRAVERSAL + COST_TRIANGLE * (left[k - 1] + right) / b.area().max(f32::MIN_POSITIVE);
                if best.is_none_or(|(c, _, _)| cost < c) {
                    best = Some((cost, axis, lo + k as f32 / scale));
                }
            }
        }
        match best {
            Some((cost, axis, pos)) if cost < leaf_cost || count > MAX_LEAF => Some((axis, pos)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, uniform_sphere};

    fn random_soup(n: usize, rng: &mut Rng) -> Vec<[Vec3; 3]> {
        let mut p = || Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
        (0..n)
            .map(|_| {
                let c = p() * 10.0;
                let e = 0.6;
                [c, c + (p() - 0.5) * e * 2.0, c + (p() - 0.5) * e * 2.0]
            })
            .collect()
    }

    fn brute_force(tris: &[[Vec3; 3]], o: Vec3, d: Vec3, t_max: f32) -> Option<(f32, u32)> {
        let mut best = None;
        for (i, t) in tris.iter().enumerate() {
            if let Some((t, _, _)) = intersect_triangle(t, o, d)
                && t > 0.0
                && t < t_max
                && best.is_none_or(|(bt, _)| t < bt)
            {
                best = Some((t, i as u32));
            }
        }
        best
    }

    #[test]
    fn closest_hit_matches_brute_force_on_random_rays() {
        let mut rng = Rng::new(1, 2, 3);
        let soup = random_soup(3000, &mut rng);
        let bvh = Bvh::build(&soup);
        let tris = bvh.permute(&soup);
        let mut hits = 0;
        for _ in 0..4000 {
            let o = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 12.0 - 1.0;
            let d = uniform_sphere(rng.next_f32(), rng.next_f32());
            let t_max = if rng.next_f32() < 0.3 { 3.0 } else { f32::INFINITY };
            let expected = brute_force(&tris, o, d, t_max);
            let got = bvh.intersect(&tris, o, d, 0.0, t_max, u32::MAX, |_| true);
            match (expected, got) {
                (None, None) => {}
                (Some((t, i)), Some(h)) => {
                    hits += 1;
                    assert!(h.triangle == i || (h.t - t).abs() < 1e-5, "different closest triangle");
                    assert_eq!(h.t, t);
                }
                (e, g) => panic!("brute force {e:?} but BVH {g:?}"),
            }
            assert_eq!(bvh.occluded(&tris, o, d, 0.0, t_max, [u32::MAX; 2]), expected.is_some());
        }
        assert!(hits > 1000, "too few rays hit ({hits}) for the test to mean anything");
    }

    #[test]
    fn every_triangle_is_in_exactly_one_leaf_and_boxes_nest() {
        let mut rng = Rng::new(4, 5, 6);
        let soup = random_soup(1000, &mut rng);
        let bvh = Bvh::build(&soup);
        let mut sorted = bvh.order.clone();
        sorted.sort();
        assert_eq!(sorted, (0..1000).collect::<Vec<_>>());
        let tris = bvh.permute(&soup);
        let mut covered = vec![0; tris.len()];
        for n in &bvh.nodes {
            if n.count > 0 {
                for i in n.offset..n.offset + n.count {
                    covered[i as usize] += 1;
                    for p in tris[i as usize] {
                        assert!(p.cmpge(Vec3::from(n.min)).all() && p.cmple(Vec3::from(n.max)).all());
                    }
                }
            }
        }
        assert!(covered.iter().all(|&c| c == 1));
        assert!(bvh.depth() < 40);
    }

    /// Triangles at x = 2^k for k from −120 to 127, as a hostile file's coordinates over many
    /// orders of magnitude: the binned SAH peels a few off per level (all but the largest fall
    /// in the first bin), 125 levels without the median splits; the tree stays within
    /// [`MAX_DEPTH`], and rays find what a brute-force test of every triangle finds.
    #[test]
    fn coordinates_over_many_magnitudes_keep_the_tree_within_the_stack() {
        let tris: Vec<[Vec3; 3]> = (-120..=127)
            .map(|k| {
                let x = 2f32.powi(k);
                [Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0)]
            })
            .collect();
        let bvh = Bvh::build(&tris);
        println!("depth {}", bvh.depth());
        assert!(bvh.depth() <= MAX_DEPTH, "depth {}", bvh.depth());
        let ordered = bvh.permute(&tris);
        for k in [-120, -3, 0, 60, 126, 127] {
            let o = Vec3::new(2f32.powi(k) * 0.75, 0.25, 0.25);
            for d in [Vec3::X, -Vec3::X] {
                let expected = ordered
                    .iter()
                    .filter_map(|t| intersect_triangle(t, o, d).map(|h| h.0).filter(|&t| t > 0.0))
                    .fold(f32::INFINITY, f32::min);
                let hit = bvh.intersect(&ordered, o, d, 0.0, f32::INFINITY, u32::MAX, |_| true);
                assert_eq!(hit.map_or(f32::INFINITY, |h| h.t), expected, "ray from 0.75 · 2^{k} along {d}");
            }
        }
    }

    #[test]
    fn degenerate_inputs_build() {
        let same = vec![[Vec3::ZERO, Vec3::X, Vec3::Y]; 100];
        let bvh = Bvh::build(&same);
        assert!(bvh.intersect(&same, Vec3::new(0.2, 0.2, 1.0), -Vec3::Z, 0.0, 10.0, u32::MAX, |_| true).is_some());
        let one = vec![[Vec3::ZERO, Vec3::X, Vec3::Y]];
        assert_eq!(Bvh::build(&one).nodes.len(), 1);
    }
}
