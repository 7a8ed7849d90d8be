//! The CPU mirror of the shader's walk of a [`WideBvh`] (`trace_walk` in
//! `trace.glsl`), step for step: what the tests hold the GPU to, and what
//! the CPU ray casts of the tests use.

use super::{GpuWideNode, WideBvh, GROUP_BITS, MAX_NODES, NO_CHILD, WIDTH};
use crate::bvh::intersect_edges;
use glam::Vec3;

impl WideBvh {
    /// The nearest hit of the ray `origin + t * dir` with `t` in `(0, t_max)`:
    /// `(t, triangle index)`, found as the shader finds it.
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<(f32, u32)> {
        self.walk(origin, dir, t_max, false)
    }

    /// Whether anything lies on the ray with `t` in `(0, t_max)`; stops at the
    /// first hit found, as the shader's shadow rays do.
    pub fn any_hit(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        self.walk(origin, dir, t_max, true).is_some()
    }

    /// `trace_walk`: takes the next node of the current group, measures the
    /// ray's entry into its four boxes, orders them nearest first, tests the
    /// triangles of the leaves the ray enters before the nearest hit so far,
    /// in that order, and makes the inner children it enters the current
    /// group, putting the one they replace on the stack when it has nodes left.
    fn walk(&self, origin: Vec3, dir: Vec3, t_max: f32, first_hit: bool) -> Option<(f32, u32)> {
        if self.triangles.is_empty() {
            return None;
        }
        let inv = dir.recip();
        let mut best: Option<(f32, u32)> = None;
        let mut limit = t_max;
        let mut group = Group::ROOT;
        let mut stack: Vec<(u32, f32)> = Vec::new();
        loop {
            if group.count == 0 {
                match stack.pop() {
                    Some((packed, entry)) => group = Group::unpack(packed, entry),
                    None => break,
                }
            }
            let (n, entry) = group.take();
            if entry >= limit {
                continue;
            }
            let node = &self.nodes[n as usize];
            let mut near = entries(node, origin, inv, limit);
            let mut slot = [0, 1, 2, 3];
            for (i, j) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
                if near[j] < near[i] {
                    near.swap(i, j);
                    slot.swap(i, j);
                }
            }
            // Which leaves to test is settled before any of them is: the
            // shader tests them in one loop.
            let tests = std::array::from_fn::<_, WIDTH, _>(|k| {
                let count = node.count(slot[k]);
                if near[k] < limit && count != NO_CHILD {
                    count as usize
                } else {
                    0
                }
            });
            for k in (0..WIDTH).filter(|&k| tests[k] > 0) {
                let first = node.child(slot[k]) as usize;
                for tri in &self.triangles[first..first + tests[k]] {
                    let hit = intersect_edges(
                        Vec3::from(tri.a),
                        Vec3::from_slice(&tri.e1[..3]),
                        Vec3::from_slice(&tri.e2[..3]),
                        origin,
                        dir,
                    );
                    if let Some(t) = hit.filter(|&t| t < limit) {
                        limit = t;
                        best = Some((t, tri.triangle));
                    }
                }
            }
            if first_hit && best.is_some() {
                return best;
            }
            let children = Group::of_children(node, &near, &slot, limit);
            if children.count > 0 {
                if group.count > 0 {
                    stack.push(group.pack());
                }
                group = children;
            }
        }
        best
    }
}

/// Nodes the walk visits next (`trace_walk`'s current group): some inner
/// children of one node, nearest first. A node's inner children are
/// consecutive ([`WideBvh::collapse`] numbers them in turn), so a group is
/// the first of them and each node's offset from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Group {
    /// The node the offsets count from.
    pub(super) base: u32,
    /// The nodes' offsets from `base`, two bits each, the next lowest.
    pub(super) order: u32,
    /// How many nodes are left.
    pub(super) count: u32,
    /// Where the ray enters each node, the next first (lower bounds once
    /// the group has been on the stack).
    pub(super) entries: [f32; WIDTH],
}

impl Group {
    /// The walk's first group: the root alone.
    pub(super) const ROOT: Group = Group {
        base: 0,
        order: 0,
        count: 1,
        entries: [0.0, f32::INFINITY, f32::INFINITY, f32::INFINITY],
    };

    /// The inner children of `node` the ray enters before `limit`, given
    /// their entries `near` in order with their `slot`s.
    pub(super) fn of_children(
        node: &GpuWideNode,
        near: &[f32; WIDTH],
        slot: &[usize; WIDTH],
        limit: f32,
    ) -> Group {
        let base = (0..WIDTH)
            .filter(|&s| node.count(s) == 0)
            .map(|s| node.child(s))
            .min()
            .unwrap_or(0);
        let mut group = Group {
            base,
            order: 0,
            count: 0,
            entries: [f32::INFINITY; WIDTH],
        };
        for k in (0..WIDTH).rev() {
            if near[k] < limit && node.count(slot[k]) == 0 {
                group.order = group.order << 2 | (node.child(slot[k]) - base);
                group.entries = [
                    near[k],
                    group.entries[0],
                    group.entries[1],
                    group.entries[2],
                ];
                group.count += 1;
            }
        }
        group
    }

    /// Takes the next node: its index and where the ray enters it.
    pub(super) fn take(&mut self) -> (u32, f32) {
        let next = (self.base + (self.order & 3), self.entries[0]);
        self.order >>= 2;
        self.count -= 1;
        self.entries = [
            self.entries[1],
            self.entries[2],
            self.entries[3],
            f32::INFINITY,
        ];
        next
    }

    /// The stack entry: the group packed in one word (`stack_group` in
    /// `trace_walk`, with at most three nodes left) and its next node's
    /// entry.
    pub(super) fn pack(&self) -> (u32, f32) {
        debug_assert!(self.count < WIDTH as u32 && (self.base as usize) < MAX_NODES);
        (
            self.base | self.order << GROUP_BITS | self.count << (GROUP_BITS + 6),
            self.entries[0],
        )
    }

    /// The group of a stack entry; every node's entry is bounded by the
    /// next's.
    pub(super) fn unpack(packed: u32, entry: f32) -> Group {
        Group {
            base: packed & (MAX_NODES as u32 - 1),
            order: packed >> GROUP_BITS & 63,
            count: packed >> (GROUP_BITS + 6),
            entries: [entry; WIDTH],
        }
    }
}

/// Where the ray enters each child's box, or infinity for a child it misses,
/// meets only at or beyond `limit`, or an empty slot.
fn entries(node: &GpuWideNode, origin: Vec3, inv: Vec3, limit: f32) -> [f32; WIDTH] {
    std::array::from_fn(|slot| {
        let lo = Vec3::new(node.lo[0][slot], node.lo[1][slot], node.lo[2][slot]);
        let hi = Vec3::new(node.hi[0][slot], node.hi[1][slot], node.hi[2][slot]);
        let t0 = (lo - origin) * inv;
        let t1 = (hi - origin) * inv;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element();
        let meets = near <= far && near < limit && node.count(slot) != NO_CHILD;
        if meets {
            near
        } else {
            f32::INFINITY
        }
    })
}
