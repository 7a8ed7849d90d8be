//! CPU ray casting against a scene's triangles, the reference shadow maps are
//! measured against: the ray tracer's BVH (`bvh.rs`: binned SAH, up to four
//! triangles a leaf) with Möller-Trumbore triangle tests.

use glam::Vec3;
use weft_scene::Scene;

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
    tree: weft_render::Bvh,
    triangles: Vec<[Vec3; 3]>,
}

impl Bvh {
    /// Builds the hierarchy over `triangles`.
    pub fn new(triangles: Vec<[Vec3; 3]>) -> Self {
        Self {
            tree: weft_render::Bvh::build(&triangles),
            triangles,
        }
    }

    /// The world-space triangles of every placed mesh in `scene` for which
    /// `include(model, mesh)` holds.
    pub fn from_scene(scene: &Scene, include: impl Fn(usize, usize) -> bool) -> Self {
        Self::new(weft_render::scene_triangles_where(scene, include))
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
        self.tree
            .closest_hit(&self.triangles, origin, dir, t_max)
            .map(|(t, i)| {
                let [a, b, c] = self.triangles[i as usize];
                Hit {
                    t,
                    normal: (b - a).cross(c - a).normalize_or_zero(),
                }
            })
    }

    /// Whether anything lies on the ray `origin + t dir` with t in (0, t_max).
    pub fn occluded(&self, origin: Vec3, dir: Vec3, t_max: f32) -> bool {
        self.tree.any_hit(&self.triangles, origin, dir, t_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_render::intersect;

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
