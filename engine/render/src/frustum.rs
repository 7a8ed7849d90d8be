//! View-frustum culling of draws: the six planes of a Vulkan clip-space
//! volume (-w <= x, y <= w, 0 <= z <= w) taken from a world-to-clip matrix,
//! and a conservative box test, so a camera or shadow view skips meshes it
//! cannot see.

use glam::{Mat4, Vec3, Vec4};
use weft_scene::Aabb;

/// The planes of a view volume, normals pointing in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frustum {
    planes: [Vec4; 6],
}

impl Frustum {
    /// The volume `clip` maps into Vulkan's clip box (Gribb-Hartmann: each
    /// plane is a sum or difference of the matrix's rows). Reverse-Z and
    /// orthographic matrices work the same way.
    pub fn from_clip(clip: Mat4) -> Self {
        let [x, y, z, w] = [clip.row(0), clip.row(1), clip.row(2), clip.row(3)];
        Self {
            planes: [w + x, w - x, w + y, w - y, z, w - z],
        }
    }

    /// Whether any part of `aabb` may lie inside: false only when the whole
    /// box is behind one plane (boxes that straddle two planes outside a
    /// corner are kept, which costs a draw, never a missing mesh).
    pub fn may_contain(&self, aabb: &Aabb) -> bool {
        if aabb.is_empty() {
            return false;
        }
        self.planes.iter().all(|p| {
            let n = p.truncate();
            // The box corner farthest along the plane's normal.
            let corner = Vec3::select(n.cmpge(Vec3::ZERO), aabb.max, aabb.min);
            n.dot(corner) + p.w >= 0.0
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_scene::reverse_z_projection;

    fn unit_box_at(centre: Vec3) -> Aabb {
        Aabb {
            min: centre - Vec3::splat(0.5),
            max: centre + Vec3::splat(0.5),
        }
    }

    #[test]
    fn a_perspective_view_keeps_what_it_sees_and_drops_the_rest() {
        // Looking down -Z from the origin, 90 degrees, square, near 0.1, far 100.
        let view = Mat4::look_at_rh(Vec3::ZERO, Vec3::NEG_Z, Vec3::Y);
        let f = Frustum::from_clip(
            reverse_z_projection(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 100.0) * view,
        );
        assert!(f.may_contain(&unit_box_at(Vec3::new(0.0, 0.0, -10.0))));
        // Straddling the left plane (x = z): kept.
        assert!(f.may_contain(&unit_box_at(Vec3::new(-10.4, 0.0, -10.0))));
        // Wholly left of it, above it, behind the eye, beyond far: dropped.
        assert!(!f.may_contain(&unit_box_at(Vec3::new(-11.2, 0.0, -10.0))));
        assert!(!f.may_contain(&unit_box_at(Vec3::new(0.0, 11.2, -10.0))));
        assert!(!f.may_contain(&unit_box_at(Vec3::new(0.0, 0.0, 5.0))));
        assert!(!f.may_contain(&unit_box_at(Vec3::new(0.0, 0.0, -101.0))));
        assert!(f.may_contain(&unit_box_at(Vec3::new(0.0, 0.0, -100.4))));
        // A box around the eye is kept although no corner is in view.
        assert!(f.may_contain(&Aabb {
            min: Vec3::splat(-50.0),
            max: Vec3::splat(50.0),
        }));
        assert!(!f.may_contain(&Aabb::EMPTY));
    }

    #[test]
    fn an_orthographic_shadow_view_culls_along_all_three_axes() {
        let f = Frustum::from_clip(Mat4::orthographic_rh(-1.0, 1.0, -1.0, 1.0, 0.0, 10.0));
        assert!(f.may_contain(&unit_box_at(Vec3::new(0.0, 0.0, -5.0))));
        assert!(!f.may_contain(&unit_box_at(Vec3::new(2.0, 0.0, -5.0))));
        assert!(!f.may_contain(&unit_box_at(Vec3::new(0.0, 0.0, 1.0))));
        assert!(!f.may_contain(&unit_box_at(Vec3::new(0.0, 0.0, -11.0))));
    }
}
