//! View and projection matrices: reverse-Z perspective for scene cameras (near
//! maps to depth 1, far to 0, so float depth keeps precision far away) with
//! Vulkan's downward clip-space Y. Shadow views are in `shadows.rs`.

use glam::{Mat4, Vec3};
use weft_scene::Camera;

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

#[cfg(test)]
mod tests {
    use super::*;

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
}
