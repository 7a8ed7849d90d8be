//! CPU ray casting against a scene's triangles, the reference shadow maps are
//! measured against: a bounding-volume hierarchy (median split on the longest
//! axis, up to four triangles a leaf) with Möller-Trumbore triangle tests.

use glam::{Mat4, Vec3};
use weft_scene::Scene;

/// Triangles a leaf holds at most.
const LEAF: usize = 4;

#[derive(Debug, Clone, Copy)]
struct Node {
    min: Vec3,
    max: Vec3,
    /// Leaf: first triangle; interior: index of the left child (right is next).
    first: u32,
    /// Leaf: triangle count; interior: 0.
    count: u32,
}

/// The closest hit along a ray.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) direction.
    pub t: f32,
    /// Unit geometric normal of the triangle hit (either side).
    pub normal: Vec3,
}

/// World-space triangles in a hierarchy of boxes.
#[derive(Debug, Clone)]
pub struct Bvh {
    nodes: Vec<Node>,
    triangles: Vec<[Vec3; 3]>,
}

impl Bvh {
    /// Builds the hierarchy over `triangles`.
    pub fn new(mut triangles: Vec<[Vec3; 3]>) -> Self {
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF + 1);
        nodes.push(Node {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
            first: 0,
            count: 0,
        });
        let mut stack = vec![(0usize, 0usize, triangles.len())];
        while let Some((index, start, end)) = stack.pop() {
            let (min, max) = bounds(&triangles[start..end]);
            if end - start <= LEAF {
                nodes[index] = Node {
                    min,
                    max,
                    first: start as u32,
                    count: (end - start) as u32,
                };
                continue;
            }
            let extent = max - min;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let mid = (start + end) / 2;
            triangles[start..end].select_nth_unstable_by(mid - start, |a, b| {
                centroid(a)[axis].total_cmp(&centroid(b)[axis])
            });
            let left = nodes.len();
            nodes.push(nodes[index]);
            nodes.push(nodes[index]);
            nodes[index] = Node {
                min,
                max,
                first: left as u32,
                count: 0,
            };
            stack.push((left, start, mid));
            stack.push((left + 1, mid, end));
        }
        Self { nodes, triangles }
    }

    /// The world-space triangles of every placed mesh in `scene` for which
    /// `include(model, mesh)` holds.
    pub fn from_scene(scene: &Scene, include: impl Fn(usize, usize) -> bool) -> Self {
        let mut triangles = Vec::new();
        for instance in &scene.instances {
            let Some(model) = scene.models.get(instance.model) else {
                continue;
            };
            let m: Mat4 = instance.transform;
            for (k, mesh) in model.meshes.iter().enumerate() {
                if !include(instance.model, k) {
                    continue;
                }
                let world: Vec<Vec3> = mesh
                    .positions
                    .iter()
                    .map(|p| m.transform_point3(*p))
                    .collect();
                for t in mesh.indices.chunks_exact(3) {
                    let corner = |i: u32| world.get(i as usize).copied();
                    if let (Some(a), Some(b), Some(c)) = (corner(t[0]), corner(t[1]), corner(t[2]))
                    {
                        triangles.push([a, b, c]);
                    }
                }
            }
        }
        Self::new(triangles)
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.triangles.len()
    }

    /// Whether there is no triangle.
    pub fn is_empty(&self) -> bool {
        self.triangles.is_empty()
    }

    /// The closest hit of the ray `origin + t dir` (unit `dir`) with t in (0, t_max).
    pub fn closest(&self, origin: Vec3, dir: Vec3, t_max: f32) -> Option<Hit> {
        let mut best: Option<(f32, usize)> = None;
        self.walk(origin, dir, t_max, |i, t| {
            if best.is_none_or(|(b, _)| t < b) {
                best = Some((t, i));
            }
            false
        });
        best.map(|(t, i)| {
            let [a, b, c] = self.triangles[i];
            Hit {
                t,
                normal: (b - a).cross(c - a).normalize_or_zero(),
            }
        })
    }

    /// Whether anything lies on the ray `origin + t dir` with t in (0, t_max).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        let mut hit = false;
        self.walk(origin, dir, t_max, |_, _| {
            hit = true;
            true
        });
        hit
    }

    /// Visits triangle hits (index, t) until `visit` returns true; boxes beyond
    /// the closest hit so far are still visited (simple, and exact for `occluded`).
    fn walk(&self, origin: Vec3, dir: Vec3, t_max: f32, mut visit: impl FnMut(usize, f32) -> bool) {
        if self.triangles.is_empty() {
            return;
        }
        let inv = dir.recip();
        let mut limit = t_max;
        let mut stack = vec![0usize];
        while let Some(n) = stack.pop() {
            let node = self.nodes[n];
            if !slab(origin, inv, node.min, node.max, limit) {
                continue;
            }
            if node.count == 0 {
                stack.push(node.first as usize);
                stack.push(node.first as usize + 1);
                continue;
            }
            let first = node.first as usize;
            for i in first..first + node.count as usize {
                if let Some(t) = intersect(&self.triangles[i], origin, dir) {
                    if t < limit {
                        if visit(i, t) {
                            return;
                        }
                        limit = t;
                    }
                }
            }
        }
    }
}

fn centroid(t: &[Vec3; 3]) -> Vec3 {
    (t[0] + t[1] + t[2]) / 3.0
}

fn bounds(triangles: &[[Vec3; 3]]) -> (Vec3, Vec3) {
    triangles.iter().flatten().fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    )
}

/// Whether the ray meets the box before `limit`.
fn slab(origin: Vec3, inv: Vec3, min: Vec3, max: Vec3, limit: f32) -> bool {
    let a = (min - origin) * inv;
    let b = (max - origin) * inv;
    let near = a.min(b).max_element().max(0.0);
    let far = a.max(b).min_element().min(limit);
    near <= far
}

/// Möller-Trumbore: the distance to the triangle, if the ray meets it at t > 0.
fn intersect(tri: &[Vec3; 3], origin: Vec3, dir: Vec3) -> Option<f32> {
    let e1 = tri[1] - tri[0];
    let e2 = tri[2] - tri[0];
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let inv = 1.0 / det;
    let s = origin - tri[0];
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(e1);
    let v = dir.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = e2.dot(q) * inv;
    (t > 0.0).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad(y: f32, half: f32) -> Vec<[Vec3; 3]> {
        let c = |x, z| Vec3::new(x, y, z);
        vec![
            [c(-half, -half), c(half, -half), c(half, half)],
            [c(-half, -half), c(half, half), c(-half, half)],
        ]
    }

    #[test]
    fn finds_the_closest_of_stacked_quads() {
        let mut tris = Vec::new();
        for k in 0..50 {
            tris.extend(quad(k as f32, 1.0));
        }
        let bvh = Bvh::new(tris);
        assert_eq!(bvh.len(), 100);
        let hit = bvh
            .closest(Vec3::new(0.3, 10.5, 0.2), Vec3::NEG_Y, f32::MAX)
            .expect("hit");
        assert!((hit.t - 0.5).abs() < 1e-5, "{hit:?}");
        assert!((hit.normal.y.abs() - 1.0).abs() < 1e-6);
        let up = bvh
            .closest(Vec3::new(0.3, 10.5, 0.2), Vec3::Y, f32::MAX)
            .expect("hit");
        assert!((up.t - 0.5).abs() < 1e-5);
        assert!(bvh
            .closest(Vec3::new(1.5, 10.5, 0.0), Vec3::NEG_Y, f32::MAX)
            .is_none());
    }

    #[test]
    fn occlusion_respects_the_ray_length_and_agrees_with_brute_force() {
        let mut tris = Vec::new();
        let mut seed = 7u32;
        let mut rand = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        };
        for _ in 0..400 {
            let c = Vec3::new(rand(), rand(), rand()) * 10.0;
            let e = |r: &mut dyn FnMut() -> f32| Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5);
            tris.push([c, c + e(&mut rand), c + e(&mut rand)]);
        }
        let bvh = Bvh::new(tris.clone());
        for _ in 0..500 {
            let o = Vec3::new(rand(), rand(), rand()) * 10.0;
            let d = Vec3::new(rand() - 0.5, rand() - 0.5, rand() - 0.5).normalize();
            let brute = tris
                .iter()
                .filter_map(|t| intersect(t, o, d))
                .fold(f32::MAX, f32::min);
            let closest = bvh.closest(o, d, f32::MAX).map_or(f32::MAX, |h| h.t);
            assert_eq!(closest, brute);
            assert_eq!(bvh.occluded(o, d, 3.0), brute < 3.0);
        }
        assert!(!bvh.occluded(Vec3::new(0.0, 5.0, 0.0), Vec3::Y, 0.0));
    }
}
