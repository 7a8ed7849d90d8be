//! The 4-wide form of a [`Bvh`] that shaders walk (`trace_walk` in
//! `trace.glsl`): each node holds its up to four children's boxes, so one
//! step of the walk tests four boxes at once and reads one node, and leaves
//! are children that point straight at their triangles, stored in leaf order
//! with their edges precomputed. The binary tree is collapsed into it by
//! pulling up, while a node has fewer than four children, the grandchildren
//! of its largest inner child (the collapse of Wald et al. 2008 and Ylitie et
//! al. 2017's compressed wide BVH, without the compression).
//!
//! On lavapipe a step of a divergent walk costs the same for every lane of a
//! SIMD group, whatever node each lane is at; fewer, wider steps are what
//! makes the wide tree faster (docs/pathtrace.md measures it).
//!
//! [`WideBvh::closest_hit`] (walk.rs) is the CPU mirror of the shader's
//! walk, step for step, so a test can hold the GPU to it exactly.

mod walk;

use crate::bvh::{node_area, Bvh, TRAVERSAL_COST};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;

/// Children per node.
pub const WIDTH: usize = 4;

/// [`GpuWideNode::count`] of a child slot that holds no child: the count
/// bits of [`EMPTY_LINK`] (`NO_CHILD` in `trace.glsl`).
pub const NO_CHILD: u32 = EMPTY_LINK >> LINK_BITS;

/// Groups the GPU walk's stack holds (`TRACE_STACK` in
/// `shaders/include/trace.glsl`; a test holds the two equal). A deeper tree
/// than it allows would lose nodes there, so the renderer warns of one.
pub const GPU_STACK: usize = 72;

/// Most nodes a tree may have: the walk's stack entries and a node's links
/// hold a node index in 24 bits (`TRACE_GROUP_BITS` in `trace.glsl`).
pub const MAX_NODES: usize = 1 << GROUP_BITS;

/// Most leaf triangles a tree may have: a node's links hold a leaf's first
/// slot in 24 bits.
pub const MAX_LEAF_TRIANGLES: usize = 1 << LINK_BITS;

/// Bits of a stack entry that hold its group's first node.
const GROUP_BITS: u32 = 24;

/// Bits of a link that hold its child's index (node or leaf slot); the
/// count is in the 8 above.
const LINK_BITS: u32 = 24;

/// The link of a slot that holds no child (count [`NO_CHILD`]).
const EMPTY_LINK: u32 = u32::MAX;

/// One node as the shader reads it (`struct WideNode`): seven texels, so a
/// node costs lavapipe seven texel-fetch calls (docs/pathtrace.md).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuWideNode {
    /// Lower corners of the children's boxes, per axis then per child.
    pub lo: [[f32; WIDTH]; 3],
    /// Upper corners of the children's boxes, per axis then per child.
    pub hi: [[f32; WIDTH]; 3],
    /// Per child slot, its [`child`](Self::child) in the low 24 bits and
    /// its [`count`](Self::count) in the 8 above; all ones for no child.
    pub link: [u32; WIDTH],
}

const _: () = assert!(std::mem::size_of::<GpuWideNode>() == 112);

impl GpuWideNode {
    /// A node whose slots are all empty.
    const EMPTY: GpuWideNode = GpuWideNode {
        lo: [[0.0; WIDTH]; 3],
        hi: [[0.0; WIDTH]; 3],
        link: [EMPTY_LINK; WIDTH],
    };

    /// Slot `slot`'s inner node index, or its leaf's first slot in
    /// [`WideBvh::triangles`].
    pub fn child(&self, slot: usize) -> u32 {
        self.link[slot] & ((1 << LINK_BITS) - 1)
    }

    /// 0 for an inner child, the triangle count of a leaf, or [`NO_CHILD`].
    pub fn count(&self, slot: usize) -> u32 {
        self.link[slot] >> LINK_BITS
    }

    /// Links slot `slot` to `child` with `count` (0 for an inner node).
    fn link(&mut self, slot: usize, child: u32, count: u32) {
        debug_assert!(child < 1 << LINK_BITS && (count as usize) <= crate::bvh::MAX_LEAF);
        self.link[slot] = child | count << LINK_BITS;
    }
}

/// A leaf triangle as the shader reads it (`struct LeafTriangle`): its first
/// corner with the triangle's index in the scene's triangle list (as bits),
/// and its two edges from that corner.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct GpuLeafTriangle {
    pub a: [f32; 3],
    pub triangle: u32,
    pub e1: [f32; 4],
    pub e2: [f32; 4],
}

/// A hierarchy in the form the shaders walk.
#[derive(Debug, Clone, PartialEq)]
pub struct WideBvh {
    /// Nodes, the root first; without triangles, one node with no children.
    pub nodes: Vec<GpuWideNode>,
    /// The triangles in leaf order.
    pub triangles: Vec<GpuLeafTriangle>,
}

impl WideBvh {
    /// The wide form of `bvh`, built over `triangles`.
    pub fn collapse(bvh: &Bvh, triangles: &[[Vec3; 3]]) -> WideBvh {
        let leaf_triangles = bvh
            .triangles
            .iter()
            .map(|&t| {
                let [a, b, c] = triangles[t as usize];
                GpuLeafTriangle {
                    a: a.to_array(),
                    triangle: t,
                    e1: (b - a).extend(0.0).to_array(),
                    e2: (c - a).extend(0.0).to_array(),
                }
            })
            .collect();
        let mut nodes = vec![GpuWideNode::EMPTY];
        if bvh.triangles.is_empty() {
            return WideBvh {
                nodes,
                triangles: leaf_triangles,
            };
        }
        // (wide node, binary node whose children it takes).
        let mut pending = vec![(0usize, 0u32)];
        while let Some((wide, binary)) = pending.pop() {
            for (slot, c) in wide_children(bvh, binary).into_iter().enumerate() {
                let child = &bvh.nodes[c as usize];
                for axis in 0..3 {
                    nodes[wide].lo[axis][slot] = child.min[axis];
                    nodes[wide].hi[axis][slot] = child.max[axis];
                }
                if child.count > 0 {
                    nodes[wide].link(slot, child.first, child.count);
                } else {
                    let index = nodes.len();
                    nodes.push(GpuWideNode::EMPTY);
                    nodes[wide].link(slot, index as u32, 0);
                    pending.push((index, c));
                }
            }
        }
        WideBvh {
            nodes,
            triangles: leaf_triangles,
        }
    }

    /// Depth of the deepest leaf (the root's children are depth 1).
    pub fn depth(&self) -> usize {
        if self.triangles.is_empty() {
            return 0;
        }
        let mut deepest = 0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((n, d)) = stack.pop() {
            let node = &self.nodes[n];
            for slot in 0..WIDTH {
                match node.count(slot) {
                    0 => stack.push((node.child(slot) as usize, d + 1)),
                    NO_CHILD => {}
                    _ => deepest = deepest.max(d),
                }
            }
        }
        deepest
    }

    /// At most how many groups the walk's stack holds at once on this tree:
    /// a group goes on it when the walk steps down from its level, so it
    /// holds at most one per level between the root's and the deepest inner
    /// node's.
    pub fn stack_need(&self) -> usize {
        self.depth().saturating_sub(1)
    }

    /// [`Bvh::sah_cost`] for the wide tree: a visit, which tests four boxes,
    /// costs `TRAVERSAL_COST`, the root's box being the union of its
    /// children's.
    pub fn sah_cost(&self) -> f32 {
        if self.triangles.is_empty() {
            return 0.0;
        }
        let root = &self.nodes[0];
        let slots = || (0..WIDTH).filter(|&s| root.count(s) != NO_CHILD);
        let lo = slots().fold(Vec3::INFINITY, |m, s| {
            m.min(Vec3::new(root.lo[0][s], root.lo[1][s], root.lo[2][s]))
        });
        let hi = slots().fold(Vec3::NEG_INFINITY, |m, s| {
            m.max(Vec3::new(root.hi[0][s], root.hi[1][s], root.hi[2][s]))
        });
        let d = (hi - lo).max(Vec3::ZERO);
        let area = (d.x * d.y + d.y * d.z + d.z * d.x).max(f32::MIN_POSITIVE);
        let children: f32 = self
            .nodes
            .iter()
            .flat_map(|n| (0..WIDTH).map(move |s| (n, s)))
            .map(|(n, s)| match n.count(s) {
                NO_CHILD => 0.0,
                0 => TRAVERSAL_COST * slot_area(n, s) / area,
                count => count as f32 * slot_area(n, s) / area,
            })
            .sum();
        TRAVERSAL_COST + children
    }
}

/// The binary nodes that become the wide children of binary inner node
/// `node` (or the root itself when it is a leaf): its two children, then,
/// while fewer than four, the largest inner one among them replaced by its
/// own two.
fn wide_children(bvh: &Bvh, node: u32) -> Vec<u32> {
    let root = &bvh.nodes[node as usize];
    if root.count > 0 {
        return vec![node];
    }
    let mut children = vec![root.first, root.first + 1];
    while children.len() < WIDTH {
        let largest = children
            .iter()
            .enumerate()
            .filter(|(_, &c)| bvh.nodes[c as usize].count == 0)
            .max_by(|a, b| half_area(bvh, *a.1).total_cmp(&half_area(bvh, *b.1)))
            .map(|(i, _)| i);
        let Some(i) = largest else {
            break;
        };
        let first = bvh.nodes[children[i] as usize].first;
        children[i] = first;
        children.insert(i + 1, first + 1);
    }
    children
}

/// Half the surface area of a binary node's box.
fn half_area(bvh: &Bvh, node: u32) -> f32 {
    node_area(&bvh.nodes[node as usize])
}

/// Half the surface area of the box a node holds for its child in `slot`.
fn slot_area(node: &GpuWideNode, slot: usize) -> f32 {
    let d = Vec3::new(
        node.hi[0][slot] - node.lo[0][slot],
        node.hi[1][slot] - node.lo[1][slot],
        node.hi[2][slot] - node.lo[2][slot],
    )
    .max(Vec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

#[cfg(test)]
mod tests {
    use super::walk::Group;
    use super::*;
    use crate::bvh::test_scenes::{brute_force, point, soup};
    use weft_scene::rng::Rng;

    fn slot_box(node: &GpuWideNode, slot: usize) -> (Vec3, Vec3) {
        (
            Vec3::new(node.lo[0][slot], node.lo[1][slot], node.lo[2][slot]),
            Vec3::new(node.hi[0][slot], node.hi[1][slot], node.hi[2][slot]),
        )
    }

    #[test]
    fn every_triangle_is_in_one_leaf_inside_its_box_and_boxes_nest() {
        let tris = soup(3000, 1);
        let bvh = Bvh::build(&tris);
        let wide = WideBvh::collapse(&bvh, &tris);
        let mut seen = vec![0u32; tris.len()];
        // (node, the box its parent holds for it)
        let mut stack = vec![(0usize, None::<(Vec3, Vec3)>)];
        let mut visited = 0;
        while let Some((n, outer)) = stack.pop() {
            visited += 1;
            let node = &wide.nodes[n];
            let children = (0..WIDTH).filter(|&s| node.count(s) != NO_CHILD).count();
            assert!(children >= 2, "node {n} has {children} children");
            for slot in 0..WIDTH {
                if node.count(slot) == NO_CHILD {
                    continue;
                }
                let (lo, hi) = slot_box(node, slot);
                if let Some((olo, ohi)) = outer {
                    assert!(lo.cmpge(olo).all() && hi.cmple(ohi).all());
                }
                if node.count(slot) == 0 {
                    stack.push((node.child(slot) as usize, Some((lo, hi))));
                    continue;
                }
                assert!(node.count(slot) as usize <= crate::bvh::MAX_LEAF);
                let first = node.child(slot) as usize;
                for leaf in &wide.triangles[first..first + node.count(slot) as usize] {
                    seen[leaf.triangle as usize] += 1;
                    for p in tris[leaf.triangle as usize] {
                        assert!(p.cmpge(lo).all() && p.cmple(hi).all());
                    }
                    let [a, b, c] = tris[leaf.triangle as usize];
                    assert_eq!(leaf.a, a.to_array());
                    assert_eq!(leaf.e1, (b - a).extend(0.0).to_array());
                    assert_eq!(leaf.e2, (c - a).extend(0.0).to_array());
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
        assert_eq!(visited, wide.nodes.len(), "every node is reachable once");
        // Same leaves, a third of the visits: the wide tree costs less.
        assert!(
            wide.sah_cost() < bvh.sah_cost(),
            "{} vs {}",
            wide.sah_cost(),
            bvh.sah_cost()
        );
        // Four children per node but where the binary tree ran out: about a
        // third of the binary tree's inner nodes, and half its depth.
        let binary_inner = bvh.nodes.len() - bvh.leaf_count();
        assert!(
            wide.nodes.len() * 2 < binary_inner,
            "{} vs {binary_inner}",
            wide.nodes.len()
        );
        assert!(
            wide.depth() * 3 <= bvh.depth() * 2,
            "{} vs {}",
            wide.depth(),
            bvh.depth()
        );
    }

    #[test]
    fn closest_and_any_hits_equal_brute_force_on_random_rays() {
        let tris = soup(2000, 2);
        let wide = WideBvh::collapse(&Bvh::build(&tris), &tris);
        let mut rng = Rng::new(3);
        let mut hits = 0;
        for _ in 0..2000 {
            let origin = point(&mut rng, 14.0) - Vec3::splat(2.0);
            let dir = (point(&mut rng, 2.0) - Vec3::ONE).normalize_or(Vec3::X);
            let expected = brute_force(&tris, origin, dir);
            let got = wide.closest_hit(origin, dir, f32::INFINITY);
            assert_eq!(got.is_some(), wide.any_hit(origin, dir, f32::INFINITY));
            match (expected, got) {
                (None, None) => {}
                (Some(e), Some(g)) => {
                    hits += 1;
                    assert_eq!(e.0, g.0, "{e:?} vs {g:?}");
                    let shorter = wide.closest_hit(origin, dir, e.0);
                    assert_eq!(shorter, None, "t_max is exclusive");
                }
                other => panic!("brute force and the wide BVH disagree: {other:?}"),
            }
        }
        assert!(
            hits > 500,
            "the test rays must hit often enough to mean something: {hits}"
        );
    }

    /// The most groups on the stack when every box is entered (the walk's
    /// worst case): the walk's groups and stack, simulated.
    fn pushed_when_every_box_is_entered(wide: &WideBvh) -> usize {
        let entered = [0.0; WIDTH];
        let mut group = Group::ROOT;
        let mut stack = Vec::new();
        let mut most = 0;
        loop {
            if group.count == 0 {
                match stack.pop() {
                    Some((packed, entry)) => group = Group::unpack(packed, entry),
                    None => return most,
                }
            }
            let node = &wide.nodes[group.take().0 as usize];
            let children = Group::of_children(node, &entered, &[0, 1, 2, 3], f32::INFINITY);
            if children.count > 0 {
                if group.count > 0 {
                    stack.push(group.pack());
                    most = most.max(stack.len());
                }
                group = children;
            }
        }
    }

    /// The shader the walk's constants must agree with.
    fn trace_glsl() -> String {
        std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../shaders/include/trace.glsl"),
        )
        .expect("trace.glsl")
    }

    #[test]
    fn a_link_holds_its_child_and_count_and_an_empty_slot_reads_as_none() {
        let mut node = GpuWideNode::EMPTY;
        node.link(
            0,
            (MAX_LEAF_TRIANGLES - 1) as u32,
            crate::bvh::MAX_LEAF as u32,
        );
        node.link(1, (MAX_NODES - 1) as u32, 0);
        node.link(2, 0, 1);
        assert_eq!(node.child(0), (MAX_LEAF_TRIANGLES - 1) as u32);
        assert_eq!(node.count(0), crate::bvh::MAX_LEAF as u32);
        assert_eq!((node.child(1), node.count(1)), ((MAX_NODES - 1) as u32, 0));
        assert_eq!((node.child(2), node.count(2)), (0, 1));
        assert_eq!(node.count(3), NO_CHILD);
        // The shader reads the same words: count 255 is no child there.
        assert_eq!(NO_CHILD, 0xff);
        let shader = trace_glsl();
        for define in [
            format!("#define TRACE_LINK_BITS {LINK_BITS}u\n"),
            format!("#define NO_CHILD {NO_CHILD:#x}u\n"),
        ] {
            assert!(shader.contains(&define), "trace.glsl lacks {define:?}");
        }
        assert_eq!(node.link[0], 0x04ff_ffff);
    }

    #[test]
    fn a_group_packs_into_one_word_and_back() {
        let group = Group {
            base: MAX_NODES as u32 - 1,
            order: 0b10_01_11,
            count: 3,
            entries: [1.5, 2.0, 3.0, f32::INFINITY],
        };
        let (packed, entry) = group.pack();
        assert_eq!(entry, 1.5);
        assert_eq!(
            Group::unpack(packed, entry),
            Group {
                entries: [1.5; WIDTH],
                ..group
            }
        );
        let mut back = Group::unpack(packed, entry);
        assert_eq!(back.take().0, MAX_NODES as u32 - 1 + 3);
        assert_eq!(back.take().0, MAX_NODES as u32 - 1 + 1);
        assert_eq!(back.take().0, MAX_NODES as u32 - 1 + 2);
        assert_eq!(back.count, 0);
    }

    #[test]
    fn a_nodes_inner_children_are_consecutive() {
        let tris = soup(3000, 5);
        let wide = WideBvh::collapse(&Bvh::build(&tris), &tris);
        for node in &wide.nodes {
            let inner: Vec<u32> = (0..WIDTH)
                .filter(|&s| node.count(s) == 0)
                .map(|s| node.child(s))
                .collect();
            for pair in inner.windows(2) {
                assert_eq!(pair[1], pair[0] + 1, "{inner:?}");
            }
        }
    }

    #[test]
    fn the_stack_need_bounds_the_walk_and_the_shader_holds_it() {
        for (count, seed) in [(1, 1), (40, 2), (3000, 3), (20000, 4)] {
            let tris = soup(count, seed);
            let wide = WideBvh::collapse(&Bvh::build(&tris), &tris);
            let pushed = pushed_when_every_box_is_entered(&wide);
            assert!(
                pushed <= wide.stack_need(),
                "{count}: {pushed} > {}",
                wide.stack_need()
            );
            assert!(
                wide.stack_need() <= GPU_STACK,
                "{count}: {}",
                wide.stack_need()
            );
        }
        let shader = trace_glsl();
        assert!(
            shader.contains(&format!("#define TRACE_STACK {GPU_STACK}\n")),
            "trace.glsl's TRACE_STACK is not GPU_STACK ({GPU_STACK})"
        );
    }

    #[test]
    fn empty_single_and_four_triangle_scenes() {
        let empty = WideBvh::collapse(&Bvh::build(&[]), &[]);
        assert_eq!(empty.nodes, vec![GpuWideNode::EMPTY]);
        assert_eq!(empty.closest_hit(Vec3::ZERO, Vec3::X, f32::INFINITY), None);
        assert_eq!(empty.depth(), 0);
        // A root that is one leaf becomes the root's only child.
        let wall = |x: f32| {
            [
                Vec3::new(x, -1.0, -1.0),
                Vec3::new(x, 1.0, -1.0),
                Vec3::new(x, 0.0, 1.0),
            ]
        };
        let one = [wall(1.0)];
        let wide = WideBvh::collapse(&Bvh::build(&one), &one);
        // A leaf root: one test; wide, a visit to the root and the test.
        assert_eq!(Bvh::build(&one).sah_cost(), 1.0);
        assert_eq!(wide.sah_cost(), 2.0);
        assert_eq!(wide.nodes.len(), 1);
        let counts: Vec<u32> = (0..WIDTH).map(|s| wide.nodes[0].count(s)).collect();
        assert_eq!(counts, [1, NO_CHILD, NO_CHILD, NO_CHILD]);
        assert_eq!(
            wide.closest_hit(Vec3::ZERO, Vec3::X, f32::INFINITY),
            Some((1.0, 0))
        );
        assert_eq!(wide.closest_hit(Vec3::ZERO, Vec3::X, 0.5), None);
        assert_eq!(wide.closest_hit(Vec3::ZERO, -Vec3::X, f32::INFINITY), None);
        let four = [wall(3.0), wall(1.0), wall(4.0), wall(2.0)];
        let wide = WideBvh::collapse(&Bvh::build(&four), &four);
        assert_eq!(
            wide.closest_hit(Vec3::ZERO, Vec3::X, f32::INFINITY),
            Some((1.0, 1))
        );
        assert!(wide.any_hit(Vec3::ZERO, Vec3::X, 1.5));
        assert!(!wide.any_hit(Vec3::ZERO, Vec3::X, 1.0));
    }
}
