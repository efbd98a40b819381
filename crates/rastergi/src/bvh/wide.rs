//! The 4-wide BVH the GPU traverses (`trace` in `bvh.wgsl`): the binary SAH tree collapsed so
//! that every node holds the boxes of up to four children side by side, by axis. One node read
//! tests four boxes with vector arithmetic, and a ray visits about half as many nodes as in
//! the binary tree (each of which also read both children's boxes from two more nodes).
//!
//! Collapse: a binary interior node's children replace it; while fewer than four, the interior
//! child of largest surface area is replaced by its two children. Leaves stay the binary
//! tree's (the same triangle ranges, in BVH order), so the triangles need no second order.
//!
//! Compression (Ylitie et al. 2017, "Efficient incoherent ray traversal on GPUs through
//! compressed wide BVHs"): a node stores its box's low corner p and, per axis, a power-of-two
//! step s = 2^e; child i's box is p + q·s with 8-bit grid coordinates q, rounded outwards so
//! that the decoded box contains the child's exact one. As q ≤ 255 has 8 significant bits, q·s
//! is exact in f32 and the decoded corner p + q·s is rounded once: the GPU and its CPU twin
//! decode the same box bit for bit, fused multiply-add or not. A node is 64 bytes (15 words
//! read) instead of 128. It was chosen on Mesa 22.3's lavapipe, whose storage-buffer loads run
//! lane by lane (the words read were what a traversal step cost), and measured again on Mesa 25,
//! whose loads are vector gathers, against the same boxes decoded into 128-byte nodes: the
//! compressed nodes still trace 1.07–1.23× more rays per second (`bench rays`, Cornell at 1024²,
//! atrium and spheres:1000000 at 512², every kind; docs/performance.md).

use bytemuck::Zeroable;
use glam::{UVec4, Vec3, Vec4};

use super::{Bvh, BvhNode, Hit, intersect_triangle};
use crate::gpu::structs::gpu_struct;

/// Marks an unused child slot (its count byte in [`WideNode::counts`] is `NO_CHILD & 0xff`).
pub use crate::gpu::consts::NO_CHILD;
/// The count byte of an unused slot.
const NO_CHILD_BYTE: u32 = NO_CHILD & 0xff;

gpu_struct! {
    /// A compressed node of the 4-wide tree (`WideNode` in WGSL; module docs).
    /// Axis a's step is s_a = f32::from_bits(byte a of `exponents` << 23), and child i's box is
    /// origin[a] + byte i of lo[a] · s_a – origin[a] + byte i of hi[a] · s_a. Byte i of `counts` is
    /// 0 for an interior child (`child[i]` indexes the wide nodes), the triangle count of a leaf
    /// (triangles `child[i] ..`, BVH order), or `NO_CHILD & 0xff` for an unused slot (which the
    /// traversal skips by its count).
    #[derive(PartialEq)]
    pub struct WideNode as "WideNode" {
        pub origin: [f32; 3],
        pub exponents: u32,
        pub lo: [u32; 3],
        pub counts: u32,
        pub hi: [u32; 3],
        pub _pad: u32,
        pub child: [u32; 4],
    }
}

/// The four bytes of `w`, lowest first.
fn bytes(w: u32) -> UVec4 {
    (UVec4::splat(w) >> UVec4::new(0, 8, 16, 24)) & UVec4::splat(0xff)
}

impl WideNode {
    /// Per child, 0 (interior), a leaf's triangle count, or [`NO_CHILD`].
    pub fn count(&self) -> [u32; 4] {
        bytes(self.counts).to_array().map(|c| if c == NO_CHILD_BYTE { NO_CHILD } else { c })
    }

    /// The grid step of each axis.
    pub fn steps(&self) -> Vec3 {
        let e = bytes(self.exponents);
        Vec3::new(f32::from_bits(e.x << 23), f32::from_bits(e.y << 23), f32::from_bits(e.z << 23))
    }

    /// The children's decoded boxes, by axis: (lo, hi) of x, y and z.
    pub fn boxes(&self) -> [(Vec4, Vec4); 3] {
        let s = self.steps();
        let decode = |a: usize, q: u32| Vec4::splat(self.origin[a]) + bytes(q).as_vec4() * s[a];
        [0, 1, 2].map(|a| (decode(a, self.lo[a]), decode(a, self.hi[a])))
    }

    /// The node of `slots` (child box, child index, count): boxes rounded outwards onto the
    /// grid of step 2^e per axis from the children's common low corner, with e the smallest
    /// that spans the children on 255 steps.
    fn new(slots: &[(BvhNode, u32, u32)]) -> WideNode {
        assert!(slots.len() <= 4);
        let mut n = WideNode { counts: NO_CHILD, ..WideNode::zeroed() };
        if slots.is_empty() {
            return n;
        }
        let lo = slots.iter().fold(Vec3::INFINITY, |m, (b, ..)| m.min(b.min.into()));
        let hi = slots.iter().fold(Vec3::NEG_INFINITY, |m, (b, ..)| m.max(b.max.into()));
        n.origin = lo.into();
        for a in 0..3 {
            let (biased, q) = quantize_axis(lo[a], hi[a], slots.iter().map(|(b, ..)| (b.min[a], b.max[a])));
            n.exponents |= biased << (8 * a);
            for (i, (q_lo, q_hi)) in q.into_iter().enumerate() {
                n.lo[a] |= q_lo << (8 * i);
                n.hi[a] |= q_hi << (8 * i);
            }
        }
        for (i, &(_, child, count)) in slots.iter().enumerate() {
            assert!(count < NO_CHILD_BYTE, "a leaf of {count} triangles does not fit a count byte");
            n.child[i] = child;
            n.counts = n.counts & !(0xff << (8 * i)) | count << (8 * i);
        }
        n
    }
}

/// One axis of a node: the biased exponent of its step and each child's grid interval
/// [q_lo, q_hi], with p + q_lo·s ≤ lo and p + q_hi·s ≥ hi in f32 (p = `origin`).
fn quantize_axis(origin: f32, top: f32, children: impl Iterator<Item = (f32, f32)> + Clone) -> (u32, Vec<(u32, u32)>) {
    let extent = (top - origin).max(0.0);
    // The smallest normal power of two with 255 steps spanning the extent (1 if it is 0),
    // then larger where outward rounding of the high corners needs it.
    let mut e = if extent > 0.0 { ((extent / 255.0).log2().ceil() as i32).clamp(-126, 127) } else { -126 };
    loop {
        let s = 2f32.powi(e);
        let decode = |q: u32| origin + q as f32 * s;
        let q: Vec<(u32, u32)> = children
            .clone()
            .map(|(lo, hi)| {
                let mut q_lo = (((lo - origin) / s).floor().max(0.0) as u32).min(255);
                while q_lo > 0 && decode(q_lo) > lo {
                    q_lo -= 1;
                }
                let mut q_hi = ((hi - origin) / s).ceil().max(0.0) as u32;
                while q_hi <= 255 && decode(q_hi) < hi {
                    q_hi += 1;
                }
                (q_lo, q_hi)
            })
            .collect();
        if q.iter().all(|&(_, q_hi)| q_hi <= 255) || e == 127 {
            return ((e + 127) as u32, q.into_iter().map(|(l, h)| (l, h.min(255))).collect());
        }
        e += 1;
    }
}

fn area(n: &BvhNode) -> f32 {
    let e = (Vec3::from(n.max) - Vec3::from(n.min)).max(Vec3::ZERO);
    e.x * e.y + e.y * e.z + e.z * e.x
}

impl Bvh {
    /// The tree collapsed to four children per node (module docs); node 0 is the root.
    pub fn wide(&self) -> Vec<WideNode> {
        let root = &self.nodes[0];
        if root.count > 0 || self.nodes.len() == 1 {
            // One leaf (or the empty scene's single empty node).
            let slots = if root.count > 0 { vec![(*root, root.offset, root.count)] } else { Vec::new() };
            return vec![WideNode::new(&slots)];
        }
        let mut out = vec![WideNode::zeroed()];
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
        let mut entries = Vec::with_capacity(4);
        for &s in &slots {
            let b = self.nodes[s];
            if b.count > 0 {
                entries.push((b, b.offset, b.count));
            } else {
                let index = out.len();
                out.push(WideNode::zeroed());
                entries.push((b, index as u32, 0));
                self.collapse(s, index, out);
            }
        }
        out[at] = WideNode::new(&entries);
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
        let [(lo_x, hi_x), (lo_y, hi_y), (lo_z, hi_z)] = n.boxes();
        let (t0x, t1x) = ((lo_x - o.x) * inv.x, (hi_x - o.x) * inv.x);
        let (t0y, t1y) = ((lo_y - o.y) * inv.y, (hi_y - o.y) * inv.y);
        let (t0z, t1z) = ((lo_z - o.z) * inv.z, (hi_z - o.z) * inv.z);
        let counts = n.count();
        let near = t0x.min(t1x).max(t0y.min(t1y)).max(t0z.min(t1z)).max(Vec4::splat(t_min));
        let far = t0x.max(t1x).min(t0y.max(t1y)).min(t0z.max(t1z));
        // Leaves first: their hits shorten the ray before the interior children are ordered.
        for i in 0..4 {
            let count = counts[i];
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
            .filter(|&i| counts[i] == 0 && near[i] <= far[i].min(t_far))
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
                let count = w.count();
                for i in 0..4 {
                    if count[i] != 0 && count[i] != NO_CHILD {
                        (w.child[i]..w.child[i] + count[i]).for_each(|t| covered[t as usize] += 1);
                    }
                }
            }
            assert!(covered.iter().all(|&c| c == 1), "{n} triangles: leaves cover {covered:?}");
            // Every node but the root is some node's child, once.
            let mut parents = vec![0u32; wide.len()];
            for w in &wide {
                let count = w.count();
                (0..4).filter(|&i| count[i] == 0).for_each(|i| parents[w.child[i] as usize] += 1);
            }
            assert_eq!(parents[0], 0);
            assert!(parents[1..].iter().all(|&p| p == 1), "{n} triangles");
            let binary_interior = bvh.nodes.iter().filter(|b| b.count == 0).count();
            assert!(wide.len() <= binary_interior.max(1), "{} wide nodes for {binary_interior} binary", wide.len());
        }
    }

    /// The triangles under child `i` of wide node `w`.
    fn under(wide: &[WideNode], w: usize, i: usize) -> Vec<u32> {
        let (count, child) = (wide[w].count()[i], wide[w].child[i]);
        match count {
            0 => (0..4).flat_map(|j| under(wide, child as usize, j)).collect(),
            NO_CHILD => Vec::new(),
            n => (child..child + n).collect(),
        }
    }

    #[test]
    fn decoded_child_boxes_contain_their_triangles_and_are_tight_to_a_grid_step() {
        // A soup far from the origin (large exponents, coarse f32 spacing), one at small
        // scale, and flat boxes (walls on axis planes: zero extent on one axis).
        let far: Vec<[Vec3; 3]> = soup(2000, 3).iter().map(|t| t.map(|v| v * 40.0 + Vec3::splat(9000.0))).collect();
        let small: Vec<[Vec3; 3]> = soup(500, 4).iter().map(|t| t.map(|v| v * 1e-3)).collect();
        let flat: Vec<[Vec3; 3]> = soup(300, 6).iter().map(|t| t.map(|v| Vec3::new(v.x, 0.25, v.z))).collect();
        for tris in [far, small, flat] {
            let bvh = Bvh::build(&tris);
            let tris = bvh.permute(&tris);
            let wide = bvh.wide();
            for (w, node) in wide.iter().enumerate() {
                let boxes = node.boxes();
                let step = node.steps();
                for i in 0..4 {
                    let inside = under(&wide, w, i);
                    if inside.is_empty() {
                        continue;
                    }
                    let points = inside.iter().flat_map(|&t| tris[t as usize]);
                    let (lo, hi) = points.fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), p| (l.min(p), h.max(p)));
                    for a in 0..3 {
                        let (q_lo, q_hi) = (boxes[a].0[i], boxes[a].1[i]);
                        assert!(
                            q_lo <= lo[a] && q_hi >= hi[a],
                            "node {w} child {i} axis {a}: [{q_lo}, {q_hi}] misses [{}, {}]",
                            lo[a],
                            hi[a]
                        );
                        // Rounded outwards by less than a step (plus the f32 rounding of p + q·s).
                        let slack = step[a] as f64 + 2.0 * (f32::EPSILON * hi[a].abs().max(lo[a].abs())) as f64;
                        assert!(
                            lo[a] as f64 - q_lo as f64 <= slack && q_hi as f64 - hi[a] as f64 <= slack,
                            "node {w} child {i} axis {a}: loose"
                        );
                    }
                }
                // The step is the smallest power of two spanning the node on 255 steps, or the next.
                let (lo, hi) = (0..4).filter(|&i| !under(&wide, w, i).is_empty()).fold(
                    (Vec3::INFINITY, Vec3::NEG_INFINITY),
                    |(l, h), i| {
                        let b = node.boxes();
                        (
                            l.min(Vec3::new(b[0].0[i], b[1].0[i], b[2].0[i])),
                            h.max(Vec3::new(b[0].1[i], b[1].1[i], b[2].1[i])),
                        )
                    },
                );
                for a in 0..3 {
                    let extent = hi[a] - lo[a];
                    assert!(
                        step[a] <= (4.0 * extent / 255.0).max(f32::MIN_POSITIVE),
                        "node {w} axis {a}: step {} for extent {extent}",
                        step[a]
                    );
                }
            }
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
