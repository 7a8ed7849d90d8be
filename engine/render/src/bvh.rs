//! A bounding volume hierarchy over world-space triangles, for tracing rays on
//! the GPU: a binary tree built top-down with the surface area heuristic over
//! binned centroids (16 bins per axis, as in Wald 2007), flattened into 32-byte
//! nodes (the form the BVH cache stores). Inner nodes keep their two children
//! next to each other, so a node stores one index.
//!
//! Shaders walk its 4-wide form (`bvh_wide.rs`); `Bvh::closest_hit` walks
//! the binary tree for CPU references, and the tests hold both to brute force
//! on random rays.

use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use weft_scene::Aabb;

/// Bins per axis when choosing a split.
const BINS: usize = 16;
/// Most triangles in a leaf.
pub const MAX_LEAF: usize = 4;
/// Cost of visiting a node relative to intersecting one triangle.
pub(crate) const TRAVERSAL_COST: f32 = 1.0;

/// One node of the binary tree.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct BvhNode {
    /// Lower corner of the node's box.
    pub min: [f32; 3],
    /// Inner node: index of the first child (the second follows it). Leaf:
    /// index of its first triangle in [`Bvh::triangles`].
    pub first: u32,
    /// Upper corner of the node's box.
    pub max: [f32; 3],
    /// Triangles in a leaf; 0 for an inner node.
    pub count: u32,
}

const _: () = assert!(std::mem::size_of::<BvhNode>() == 32);

/// A built hierarchy.
#[derive(Debug, Clone, PartialEq)]
pub struct Bvh {
    /// Nodes, the root first. Without triangles the root is an empty leaf
    /// and traversal must not start (check the triangle count first).
    pub nodes: Vec<BvhNode>,
    /// Triangle indices in leaf order; leaves point into this list.
    pub triangles: Vec<u32>,
}

/// The world-space triangles of every placed mesh for which
/// `include(model, mesh)` holds.
pub fn scene_triangles_where(
    scene: &weft_scene::Scene,
    include: impl Fn(usize, usize) -> bool,
) -> Vec<[Vec3; 3]> {
    let mut out = Vec::new();
    for instance in &scene.instances {
        let Some(model) = scene.models.get(instance.model) else {
            continue;
        };
        for (k, mesh) in model.meshes.iter().enumerate() {
            if !include(instance.model, k) {
                continue;
            }
            let world: Vec<Vec3> = mesh
                .positions
                .iter()
                .map(|&p| instance.transform.transform_point3(p))
                .collect();
            out.extend(mesh.indices.chunks_exact(3).filter_map(|t| {
                Some([
                    *world.get(t[0] as usize)?,
                    *world.get(t[1] as usize)?,
                    *world.get(t[2] as usize)?,
                ])
            }));
        }
    }
    out
}

/// Half a box's surface area, 0 for an empty box: the SAH's cost measure.
fn half_area(b: &Aabb) -> f32 {
    let d = (b.max - b.min).max(Vec3::ZERO);
    d.x * d.y + d.y * d.z + d.z * d.x
}

/// Half the surface area of a node's box.
pub(crate) fn node_area(node: &BvhNode) -> f32 {
    half_area(&Aabb {
        min: Vec3::from(node.min),
        max: Vec3::from(node.max),
    })
}

/// A triangle's box and centroid.
struct Primitive {
    bounds: Aabb,
    centroid: Vec3,
}

impl Bvh {
    /// Depth of the deepest leaf (the root is depth 1).
    pub fn depth(&self) -> usize {
        let mut deepest = 0;
        let mut stack = vec![(0u32, 1usize)];
        while let Some((n, d)) = stack.pop() {
            let node = &self.nodes[n as usize];
            if node.count == 0 && !self.triangles.is_empty() {
                stack.push((node.first, d + 1));
                stack.push((node.first + 1, d + 1));
            } else {
                deepest = deepest.max(d);
            }
        }
        deepest
    }

    /// Leaves in the tree.
    pub fn leaf_count(&self) -> usize {
        self.nodes.iter().filter(|n| n.count > 0).count()
    }

    /// The tree's cost by the surface area heuristic the builder minimises:
    /// for a ray that meets the root's box, the expected inner-node visits
    /// (each weighted `TRAVERSAL_COST`) plus triangle tests, a node being met
    /// with the ratio of its box's area to the root's.
    pub fn sah_cost(&self) -> f32 {
        let root = node_area(&self.nodes[0]).max(f32::MIN_POSITIVE);
        self.nodes
            .iter()
            .map(|n| {
                let weight = if n.count == 0 {
                    TRAVERSAL_COST
                } else {
                    n.count as f32
                };
                weight * node_area(n) / root
            })
            .sum()
    }

    /// Builds the hierarchy over `triangles` (three corners each). Degenerate
    /// triangles are kept (a ray never hits them).
    pub fn build(triangles: &[[Vec3; 3]]) -> Bvh {
        let prims: Vec<Primitive> = triangles
            .iter()
            .map(|t| Primitive {
                bounds: Aabb::from_points(t),
                centroid: (t[0] + t[1] + t[2]) / 3.0,
            })
            .collect();
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut nodes = vec![BvhNode::zeroed()];
        // (node index, first, count) still to split.
        let mut pending = vec![(0usize, 0usize, order.len())];
        while let Some((node, first, count)) = pending.pop() {
            let slice = &mut order[first..first + count];
            let bounds = slice
                .iter()
                .fold(Aabb::EMPTY, |b, &i| b.union(&prims[i as usize].bounds));
            let centroids = Aabb::from_points(slice.iter().map(|&i| &prims[i as usize].centroid));
            nodes[node] = BvhNode {
                min: bounds.min.to_array(),
                first: first as u32,
                max: bounds.max.to_array(),
                count: count as u32,
            };
            let Some(left) = split(&prims, slice, &bounds, &centroids) else {
                continue;
            };
            let children = nodes.len();
            nodes.push(BvhNode::zeroed());
            nodes.push(BvhNode::zeroed());
            nodes[node].first = children as u32;
            nodes[node].count = 0;
            pending.push((children, first, left));
            pending.push((children + 1, first + left, count - left));
        }
        Bvh {
            nodes,
            triangles: order,
        }
    }

    /// The nearest hit of the ray `origin + t * dir` with `t` in `(0, t_max)`:
    /// `(t, triangle index)`. Walks the nodes as the shader does.
    pub fn closest_hit(
        &self,
        triangles: &[[Vec3; 3]],
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
    ) -> Option<(f32, u32)> {
        let mut best = None;
        self.walk(triangles, origin, dir, t_max, |t, tri| {
            best = Some((t, tri));
            false
        });
        best
    }

    /// Whether anything lies on the ray with `t` in `(0, t_max)`; stops at the
    /// first hit found (shadow rays).
    pub fn any_hit(&self, triangles: &[[Vec3; 3]], origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let mut hit = false;
        self.walk(triangles, origin, dir, t_max, |_, _| {
            hit = true;
            true
        });
        hit
    }

    /// Visits hits nearer than every hit before them, nearer child boxes
    /// first (the order `trace_walk` in `trace.glsl` uses), until `visit`
    /// returns true.
    fn walk(
        &self,
        triangles: &[[Vec3; 3]],
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        mut visit: impl FnMut(f32, u32) -> bool,
    ) {
        if self.triangles.is_empty() {
            return;
        }
        let inv = dir.recip();
        let mut limit = t_max;
        let mut stack: Vec<(u32, f32)> = slab(&self.nodes[0], origin, inv)
            .map(|t| (0, t))
            .into_iter()
            .collect();
        while let Some((n, entry)) = stack.pop() {
            if entry >= limit {
                continue;
            }
            let node = &self.nodes[n as usize];
            if node.count == 0 {
                // Nearer child on top of the stack, ties to the first.
                let mut children = [node.first, node.first + 1]
                    .map(|c| (c, slab(&self.nodes[c as usize], origin, inv)));
                if children[0].1.unwrap_or(-1.0) > children[1].1.unwrap_or(-1.0) {
                    children.swap(0, 1);
                }
                for (child, t) in children.into_iter().rev() {
                    if let Some(t) = t.filter(|&t| t < limit) {
                        stack.push((child, t));
                    }
                }
                continue;
            }
            let leaf = &self.triangles[node.first as usize..(node.first + node.count) as usize];
            for &tri in leaf {
                if let Some(t) = intersect(&triangles[tri as usize], origin, dir) {
                    if t < limit {
                        limit = t;
                        if visit(t, tri) {
                            return;
                        }
                    }
                }
            }
        }
    }
}

/// Where to split `slice` (reordered in place) by the surface area heuristic:
/// the size of the left part, or `None` to make a leaf.
fn split(prims: &[Primitive], slice: &mut [u32], bounds: &Aabb, centroids: &Aabb) -> Option<usize> {
    let count = slice.len();
    if count <= 1 {
        return None;
    }
    let extent = centroids.max - centroids.min;
    let leaf_cost = count as f32;
    let mut best: Option<(f32, usize, f32)> = None; // (cost, axis, position)
    for axis in 0..3 {
        if extent[axis] <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let bin_of = |c: Vec3| (((c[axis] - centroids.min[axis]) * scale) as usize).min(BINS - 1);
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        let mut bin_counts = [0usize; BINS];
        for &i in slice.iter() {
            let b = bin_of(prims[i as usize].centroid);
            bin_bounds[b] = bin_bounds[b].union(&prims[i as usize].bounds);
            bin_counts[b] += 1;
        }
        // Left sweeps: areas and counts of bins 0..=k; right: k+1..BINS.
        let mut left_area = [0.0f32; BINS - 1];
        let mut left_count = [0usize; BINS - 1];
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for k in 0..BINS - 1 {
            acc = acc.union(&bin_bounds[k]);
            n += bin_counts[k];
            left_area[k] = half_area(&acc);
            left_count[k] = n;
        }
        let (mut acc, mut n) = (Aabb::EMPTY, 0);
        for k in (1..BINS).rev() {
            acc = acc.union(&bin_bounds[k]);
            n += bin_counts[k];
            let (l, r) = (left_count[k - 1], n);
            if l == 0 || r == 0 {
                continue;
            }
            let cost = TRAVERSAL_COST
                + (left_area[k - 1] * l as f32 + half_area(&acc) * r as f32)
                    / half_area(bounds).max(f32::MIN_POSITIVE);
            if best.is_none_or(|b| cost < b.0) {
                let position = centroids.min[axis] + k as f32 / scale;
                best = Some((cost, axis, position));
            }
        }
    }
    let left = match best {
        Some((cost, axis, position)) if cost < leaf_cost || count > MAX_LEAF => {
            partition(slice, |i| prims[i as usize].centroid[axis] < position)
        }
        // All centroids coincide: halve a leaf that is too big.
        None if count > MAX_LEAF => count / 2,
        _ => return None,
    };
    (left > 0 && left < count)
        .then_some(left)
        .or((count > MAX_LEAF).then_some(count / 2))
}

/// Moves the elements for which `left` holds to the front; returns how many.
fn partition(slice: &mut [u32], left: impl Fn(u32) -> bool) -> usize {
    let mut next = 0;
    for i in 0..slice.len() {
        if left(slice[i]) {
            slice.swap(i, next);
            next += 1;
        }
    }
    next
}

/// Entry distance of a ray into a node's box, if it meets it in front of the origin.
fn slab(node: &BvhNode, origin: Vec3, inv: Vec3) -> Option<f32> {
    let t0 = (Vec3::from(node.min) - origin) * inv;
    let t1 = (Vec3::from(node.max) - origin) * inv;
    let near = t0.min(t1).max_element().max(0.0);
    let far = t0.max(t1).min_element();
    (near <= far).then_some(near)
}

/// How far outside a triangle, in barycentric units, a hit still counts.
/// Two triangles that share an edge compute their barycentrics with different
/// rounding, so a ray through the edge could miss both; accepting this little
/// overlap closes such cracks (`EDGE_TOLERANCE` in `trace.glsl`).
pub const EDGE_TOLERANCE: f32 = 1e-5;

/// Möller–Trumbore: the ray parameter of the hit, if in front of the origin.
pub fn intersect(tri: &[Vec3; 3], origin: Vec3, dir: Vec3) -> Option<f32> {
    intersect_edges(tri[0], tri[1] - tri[0], tri[2] - tri[0], origin, dir)
}

/// [`intersect`] for the triangle with corner `a` and edges `e1`, `e2` from
/// it (the wide BVH stores leaf triangles so).
pub fn intersect_edges(a: Vec3, e1: Vec3, e2: Vec3, origin: Vec3, dir: Vec3) -> Option<f32> {
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv_det = 1.0 / det;
    let s = origin - a;
    let u = s.dot(p) * inv_det;
    if !(-EDGE_TOLERANCE..=1.0 + EDGE_TOLERANCE).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv_det;
    if v < -EDGE_TOLERANCE || u + v > 1.0 + EDGE_TOLERANCE {
        return None;
    }
    let t = e2.dot(q) * inv_det;
    (t > 0.0).then_some(t)
}

#[cfg(test)]
/// Random triangle soups and brute-force hits, for the tests of both BVH forms.
#[cfg(test)]
pub(crate) mod test_scenes {
    use super::intersect;
    use glam::Vec3;
    use weft_scene::rng::Rng;

    /// A point in the cube [0, scale)³.
    pub(crate) fn point(rng: &mut Rng, scale: f32) -> Vec3 {
        Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * scale
    }

    /// `n` small random triangles in a 10-unit cube.
    pub(crate) fn soup(n: usize, seed: u64) -> Vec<[Vec3; 3]> {
        let mut rng = Rng::new(seed);
        (0..n)
            .map(|_| {
                let c = point(&mut rng, 10.0);
                [c, c + point(&mut rng, 0.8), c + point(&mut rng, 0.8)]
            })
            .collect()
    }

    /// The nearest hit over every triangle: (t, triangle index).
    pub(crate) fn brute_force(tris: &[[Vec3; 3]], origin: Vec3, dir: Vec3) -> Option<(f32, u32)> {
        tris.iter()
            .enumerate()
            .filter_map(|(i, t)| intersect(t, origin, dir).map(|d| (d, i as u32)))
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }
}

#[cfg(test)]
mod tests {
    use super::test_scenes::{brute_force, point, soup};
    use super::*;
    use weft_scene::rng::Rng;

    #[test]
    fn every_triangle_is_in_exactly_one_leaf_and_boxes_nest() {
        let tris = soup(3000, 1);
        let bvh = Bvh::build(&tris);
        let mut seen = vec![0u32; tris.len()];
        for node in &bvh.nodes {
            if node.count > 0 {
                assert!(node.count as usize <= MAX_LEAF);
                for &t in &bvh.triangles[node.first as usize..(node.first + node.count) as usize] {
                    seen[t as usize] += 1;
                    for p in tris[t as usize] {
                        assert!(
                            p.cmpge(Vec3::from(node.min)).all()
                                && p.cmple(Vec3::from(node.max)).all()
                        );
                    }
                }
            } else {
                for child in [node.first, node.first + 1] {
                    let c = &bvh.nodes[child as usize];
                    assert!(Vec3::from(c.min).cmpge(Vec3::from(node.min)).all());
                    assert!(Vec3::from(c.max).cmple(Vec3::from(node.max)).all());
                }
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
        assert!(bvh.nodes.len() < 2 * tris.len());
    }

    #[test]
    fn closest_hits_equal_brute_force_on_random_rays() {
        let tris = soup(2000, 2);
        let bvh = Bvh::build(&tris);
        let mut rng = Rng::new(3);
        let mut hits = 0;
        for _ in 0..2000 {
            let origin = point(&mut rng, 14.0) - Vec3::splat(2.0);
            let dir = (point(&mut rng, 2.0) - Vec3::ONE).normalize_or(Vec3::X);
            let expected = brute_force(&tris, origin, dir);
            let got = bvh.closest_hit(&tris, origin, dir, f32::INFINITY);
            match (expected, got) {
                (None, None) => {}
                (Some(e), Some(g)) => {
                    hits += 1;
                    assert!((e.0 - g.0).abs() <= 1e-5 * e.0.max(1.0), "{e:?} vs {g:?}");
                }
                other => panic!("brute force and BVH disagree: {other:?}"),
            }
        }
        assert!(
            hits > 500,
            "the test rays must hit often enough to mean something: {hits}"
        );
    }

    #[test]
    fn the_root_separates_two_far_apart_clusters() {
        // Two far-apart clusters: the root must separate them.
        let mut tris = soup(200, 4);
        tris.extend(
            soup(200, 5)
                .into_iter()
                .map(|t| t.map(|p| p + Vec3::splat(100.0))),
        );
        let bvh = Bvh::build(&tris);
        let root = &bvh.nodes[0];
        assert_eq!(root.count, 0);
        let (a, b) = (
            &bvh.nodes[root.first as usize],
            &bvh.nodes[root.first as usize + 1],
        );
        let gap = Vec3::from(a.max).max_element() < Vec3::from(b.min).min_element()
            || Vec3::from(b.max).max_element() < Vec3::from(a.min).min_element();
        assert!(gap, "children overlap: {a:?} {b:?}");
    }

    #[test]
    fn empty_and_single_triangle_scenes() {
        let empty = Bvh::build(&[]);
        assert_eq!(empty.nodes.len(), 1);
        assert!(empty.triangles.is_empty());
        assert_eq!(
            empty.closest_hit(&[], Vec3::ZERO, Vec3::X, f32::INFINITY),
            None
        );
        let one = [[
            Vec3::new(1.0, -1.0, -1.0),
            Vec3::new(1.0, 1.0, -1.0),
            Vec3::new(1.0, 0.0, 1.0),
        ]];
        let bvh = Bvh::build(&one);
        assert_eq!(
            bvh.closest_hit(&one, Vec3::ZERO, Vec3::X, f32::INFINITY),
            Some((1.0, 0))
        );
        assert_eq!(bvh.closest_hit(&one, Vec3::ZERO, Vec3::X, 0.5), None);
    }
}
