//! The 4-wide BVH the GPU traverses (`trace` in `bvh.wgsl`): the binary SAH tree collapsed so
//! that every node holds the boxes of up to four children side by side, by axis. One node read
//! tests four boxes with vector arithmetic, and a ray visits about half as many nodes as in
//! the binary tree (each of which also read both children's boxes from two more nodes).
//!
//! Collapse: a binary interior node's children replace it; while fewer than four, the interior
//! child of largest surface area is replaced by its two children. Leaves stay the binary
//! tree's (the same triangle ranges, in BVH order), so the triangles need no second order.

use bytemuck::{Pod, Zeroable};
use glam::{Vec3, Vec4};

use super::{Bvh, BvhNode, Hit, intersect_triangle};

/// Marks an unused child slot in [`WideNode::count`].
pub const NO_CHILD: u32 = u32::MAX;

/// A node of the 4-wide tree (`WideNode` in `gpu_scene.wgsl`). Child `i`'s box is
/// (lo_x[i], lo_y[i], lo_z[i]) – (hi_x[i], hi_y[i], hi_z[i]); `count[i]` is 0 for an interior
/// child (`child[i]` indexes the wide nodes), the triangle count of a leaf (triangles
/// `child[i] ..`, BVH order), or [`NO_CHILD`] for an unused slot (which the traversal skips by
/// its count; its box is the point at +∞).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable, PartialEq)]
pub struct WideNode {
    pub lo_x: [f32; 4],
    pub hi_x: [f32; 4],
    pub lo_y: [f32; 4],
    pub hi_y: [f32; 4],
    pub lo_z: [f32; 4],
    pub hi_z: [f32; 4],
    pub child: [u32; 4],
    pub count: [u32; 4],
}

impl WideNode {
    const EMPTY: WideNode = WideNode {
        lo_x: [f32::INFINITY; 4],
        hi_x: [f32::INFINITY; 4],
        lo_y: [f32::INFINITY; 4],
        hi_y: [f32::INFINITY; 4],
        lo_z: [f32::INFINITY; 4],
        hi_z: [f32::INFINITY; 4],
        child: [0; 4],
        count: [NO_CHILD; 4],
    };

    fn set(&mut self, i: usize, b: &BvhNode, child: u32, count: u32) {
        (self.lo_x[i], self.lo_y[i], self.lo_z[i]) = (b.min[0], b.min[1], b.min[2]);
        (self.hi_x[i], self.hi_y[i], self.hi_z[i]) = (b.max[0], b.max[1], b.max[2]);
        (self.child[i], self.count[i]) = (child, count);
    }
}

fn area(n: &BvhNode) -> f32 {
    let e = (Vec3::from(n.max) - Vec3::from(n.min)).max(Vec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

impl Bvh {
    /// The tree collapsed to four children per node (module docs); node 0 is the root.
    pub fn wide(&self) -> Vec<WideNode> {
        let mut out = vec![WideNode::EMPTY];
        let root = &self.nodes[0];
        if root.count > 0 || self.nodes.len() == 1 {
            // One leaf (or the empty scene's single empty node).
            if root.count > 0 {
                out[0].set(0, root, root.offset, root.count);
            }
            return out;
        }
        self.collapse(0, 0, &mut out);
        out
    }

    /// Fills wide node `at` with the collapsed children of binary interior node `node`.
    fn collapse(&self, node: usize, at: usize, out: &mut Vec<WideNode>) {
        let children = |i: usize| [i + 1, self.nodes[i].offset as usize];
        let mut slots: Vec<usize> = children(node).to_vec();
        while slots.len() < 4 {
            let widest = slots
                .iter()
                .enumerate()
                .filter(|(_, s)| self.nodes[**s].count == 0)
                .max_by(|a, b| area(&self.nodes[*a.1]).total_cmp(&area(&self.nodes[*b.1])));
            let Some((k, &s)) = widest else { break };
            slots.swap_remove(k);
            slots.extend(children(s));
        }
        for (i, &s) in slots.iter().enumerate() {
            let b = self.nodes[s];
            if b.count > 0 {
                out[at].set(i, &b, b.offset, b.count);
            } else {
                let index = out.len();
                out.push(WideNode::EMPTY);
                out[at].set(i, &b, index as u32, 0);
                self.collapse(s, index, out);
            }
        }
    }
}

/// The CPU twin of the GPU's traversal of `nodes` (`traverse` in `bvh.wgsl`, step for step):
/// the closest hit with t in (t_min, t_max) of a triangle other than those in `skip`.
pub fn intersect_wide(
    nodes: &[WideNode],
    triangles: &[[Vec3; 3]],
    (o, d): (Vec3, Vec3),
    (t_min, t_max): (f32, f32),
    skip: [u32; 3],
) -> Option<Hit> {
    let inv = d.recip();
    let mut best: Option<Hit> = None;
    let mut t_far = t_max;
    let mut stack = Vec::with_capacity(64);
    let mut node = 0usize;
    loop {
        let n = &nodes[node];
        let (t0x, t1x) = ((Vec4::from(n.lo_x) - o.x) * inv.x, (Vec4::from(n.hi_x) - o.x) * inv.x);
        let (t0y, t1y) = ((Vec4::from(n.lo_y) - o.y) * inv.y, (Vec4::from(n.hi_y) - o.y) * inv.y);
        let (t0z, t1z) = ((Vec4::from(n.lo_z) - o.z) * inv.z, (Vec4::from(n.hi_z) - o.z) * inv.z);
        let near = t0x.min(t1x).max(t0y.min(t1y)).max(t0z.min(t1z)).max(Vec4::splat(t_min));
        let far = t0x.max(t1x).min(t0y.max(t1y)).min(t0z.max(t1z));
        // Leaves first: their hits shorten the ray before the interior children are ordered.
        for i in 0..4 {
            let count = n.count[i];
            if count == 0 || count == NO_CHILD || near[i] > far[i].min(t_far) {
                continue;
            }
            for tri in n.child[i]..n.child[i] + count {
                if skip.contains(&tri) {
                    continue;
                }
                if let Some((t, b1, b2)) = intersect_triangle(&triangles[tri as usize], o, d)
                    && t > t_min
                    && t < t_far
                {
                    t_far = t;
                    best = Some(Hit { t, triangle: tri, b1, b2 });
                }
            }
        }
        let mut inner: Vec<(f32, usize)> = (0..4)
            .filter(|&i| n.count[i] == 0 && near[i] <= far[i].min(t_far))
            .map(|i| (near[i], n.child[i] as usize))
            .collect();
        // Farthest pushed first: the nearest is popped next.
        inner.sort_by(|a, b| b.0.total_cmp(&a.0));
        stack.extend(inner.iter().map(|&(_, c)| c));
        match stack.pop() {
            Some(next) => node = next,
            None => return best,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{Rng, uniform_sphere};

    /// Random triangles in the unit cube, some tiny and some large, like a real scene's mix.
    fn soup(n: u32, seed: u32) -> Vec<[Vec3; 3]> {
        (0..n)
            .map(|i| {
                let mut r = Rng::new(seed, i, 0);
                let c = Vec3::new(r.next_f32(), r.next_f32(), r.next_f32());
                let s = if i % 7 == 0 { 0.3 } else { 0.03 };
                [0, 1, 2].map(|_| c + (Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) - 0.5) * s)
            })
            .collect()
    }

    #[test]
    fn every_leaf_of_the_binary_tree_is_a_child_of_the_wide_tree_once() {
        for n in [1, 2, 3, 9, 17, 100, 5000] {
            let bvh = Bvh::build(&soup(n, n));
            let wide = bvh.wide();
            let mut covered = vec![0u32; n as usize];
            for w in &wide {
                for i in 0..4 {
                    if w.count[i] != 0 && w.count[i] != NO_CHILD {
                        (w.child[i]..w.child[i] + w.count[i]).for_each(|t| covered[t as usize] += 1);
                    }
                }
            }
            assert!(covered.iter().all(|&c| c == 1), "{n} triangles: leaves cover {covered:?}");
            // Every node but the root is some node's child, once.
            let mut parents = vec![0u32; wide.len()];
            for w in &wide {
                (0..4).filter(|&i| w.count[i] == 0).for_each(|i| parents[w.child[i] as usize] += 1);
            }
            assert_eq!(parents[0], 0);
            assert!(parents[1..].iter().all(|&p| p == 1), "{n} triangles");
            let binary_interior = bvh.nodes.iter().filter(|b| b.count == 0).count();
            assert!(wide.len() <= binary_interior.max(1), "{} wide nodes for {binary_interior} binary", wide.len());
        }
    }

    #[test]
    fn the_wide_traversal_finds_the_binary_trees_closest_hits() {
        let tris = soup(3000, 5);
        let bvh = Bvh::build(&tris);
        let tris = bvh.permute(&tris);
        let wide = bvh.wide();
        let mut hits = 0;
        for i in 0..20000u32 {
            let mut r = Rng::new(9, i, 0);
            let o = Vec3::new(r.next_f32(), r.next_f32(), r.next_f32()) * 1.4 - 0.2;
            let d = uniform_sphere(r.next_f32(), r.next_f32());
            // Axis-aligned rays too: 1/d is infinite in two components.
            let d = if i % 50 == 0 { Vec3::X * d.x.signum() } else { d };
            let skip = if i % 3 == 0 { (i * 7) % 3000 } else { u32::MAX };
            let t_max = if i % 5 == 0 { 0.3 } else { f32::INFINITY };
            let a = bvh.intersect(&tris, o, d, 1e-4, t_max, skip, |_| true);
            let b = intersect_wide(&wide, &tris, (o, d), (1e-4, t_max), [skip, u32::MAX, u32::MAX]);
            assert_eq!(a.map(|h| (h.triangle, h.t)), b.map(|h| (h.triangle, h.t)), "ray {i}");
            hits += a.is_some() as u32;
        }
        assert!(hits > 5000, "only {hits} hits");
    }
}
