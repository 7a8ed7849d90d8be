//! View and projection matrices: reverse-Z perspective for scene cameras (near
//! maps to depth 1, far to 0, so float depth keeps precision far away) with
//! Vulkan's downward clip-space Y, and the sun's orthographic shadow matrix.

use glam::{Mat4, Vec3};
use weft_scene::{Aabb, Camera};

/// Reverse-Z perspective with Y flipped for Vulkan's viewport: near -> 1, far -> 0.
pub fn reverse_z_projection(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let mut m = Mat4::perspective_rh(fov_y, aspect, far, near);
    m.y_axis.y = -m.y_axis.y;
    m
}

/// World-to-clip for `camera` at `time` seen through a viewport of `aspect` = width / height.
pub fn view_projection(camera: &Camera, time: f32, aspect: f32) -> Mat4 {
    reverse_z_projection(camera.fov_y, aspect, camera.near, camera.far) * camera.view_at(time)
}

/// World position of the camera at `time`.
pub fn camera_position(camera: &Camera, time: f32) -> Vec3 {
    camera.pose_at(time).0
}

/// World-to-clip for a sun shadow map: an orthographic box around `bounds` seen along
/// `direction` (the way the light travels), forward Z (the shadow map clears to 1) and
/// Y flipped like the camera, so a lookup uses the same convention as rendering.
pub fn sun_shadow_matrix(direction: Vec3, bounds: &Aabb) -> Mat4 {
    let (center, radius) = if bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (bounds.center(), (bounds.diagonal() * 0.5).max(1e-3))
    };
    let dir = direction.try_normalize().unwrap_or(Vec3::NEG_Y);
    let up = if dir.cross(Vec3::Y).length_squared() < 1e-6 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let eye = center - dir * (radius * 2.0);
    let view = Mat4::look_at_rh(eye, center, up);
    let mut proj = Mat4::orthographic_rh(-radius, radius, -radius, radius, radius, radius * 3.0);
    proj.y_axis.y = -proj.y_axis.y;
    proj * view
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4Swizzles;

    #[test]
    fn reverse_z_maps_near_to_one_and_far_to_zero() {
        let p = reverse_z_projection(1.0, 2.0, 0.5, 100.0);
        let near = p * Vec3::new(0.0, 0.0, -0.5).extend(1.0);
        let far = p * Vec3::new(0.0, 0.0, -100.0).extend(1.0);
        assert!((near.z / near.w - 1.0).abs() < 1e-6);
        assert!((far.z / far.w).abs() < 1e-6);
        let up = p * Vec3::new(0.0, 1.0, -1.0).extend(1.0);
        assert!(up.y < 0.0, "world up is clip-space down in Vulkan");
    }

    #[test]
    fn shadow_matrix_keeps_the_bounds_inside_the_unit_box() {
        let b = Aabb {
            min: Vec3::splat(-2.0),
            max: Vec3::splat(2.0),
        };
        let m = sun_shadow_matrix(Vec3::new(-0.3, -1.0, -0.2), &b);
        for corner in 0..8 {
            let p = Vec3::new(
                if corner & 1 == 0 { -2.0 } else { 2.0 },
                if corner & 2 == 0 { -2.0 } else { 2.0 },
                if corner & 4 == 0 { -2.0 } else { 2.0 },
            );
            let c = m * p.extend(1.0);
            assert!(c.xy().abs().max_element() <= 1.0 + 1e-5, "{c}");
            assert!(c.z >= -1e-5 && c.z <= 1.0 + 1e-5, "{c}");
        }
    }
}
