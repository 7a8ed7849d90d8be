//! View and projection matrices: reverse-Z perspective for scene cameras (near
//! maps to depth 1, far to 0, so float depth keeps precision far away) with
//! Vulkan's downward clip-space Y. Shadow views are in `shadows/`.

use glam::{Mat4, Vec3};
use weft_scene::Camera;

/// Reverse-Z perspective with Y flipped for Vulkan's viewport: near -> 1, far -> 0.
pub fn reverse_z_projection(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let mut m = Mat4::perspective_rh(fov_y, aspect, far, near);
    m.y_axis.y = -m.y_axis.y;
    m
}

/// World-to-clip for `camera` at `time` seen through a viewport of `aspect` = width / height.
pub fn view_projection(camera: &Camera, time: f64, aspect: f32) -> Mat4 {
    reverse_z_projection(camera.fov_y, aspect, camera.near, camera.far) * camera.view_at(time)
}

/// World position of the camera at `time`.
pub fn camera_position(camera: &Camera, time: f64) -> Vec3 {
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

    use glam::DVec3;

    /// How a depth buffer maps view distance, for the precision table.
    #[derive(Debug, Clone, Copy)]
    enum Depth {
        /// near -> 0, far -> 1 (OpenGL-style, moved to Vulkan's [0, 1]).
        Conventional,
        /// near -> 1, far -> 0: the engine's projection.
        Reverse,
        /// near -> 1, infinity -> 0.
        ReverseInfinite,
    }

    /// The relative error (to the distance from the camera) of world
    /// positions reconstructed from a D32 depth as the lighting passes do it
    /// (`position_from_depth` in gbuffer.glsl: clip = view-projection *
    /// position in f32, depth stored as f32, position = inverse
    /// view-projection * (ndc, depth, 1) in f32), over 20,000 points spread
    /// log-uniformly in distance from `near` to `far` and uniformly over the
    /// view, against the analytic position (f64). Returns (mean, max).
    fn reconstruction_error(depth: Depth, near: f64, far: f64, eye: DVec3) -> (f64, f64) {
        use glam::{DMat4, Vec4};
        let (fov, aspect) = (1.0f64, 16.0 / 9.0);
        let view = DMat4::look_at_rh(eye, eye + DVec3::new(-5.0, -1.0, -10.0), DVec3::Y);
        let projection = match depth {
            Depth::Conventional => {
                Mat4::perspective_rh(fov as f32, aspect as f32, near as f32, far as f32)
            }
            Depth::Reverse => {
                Mat4::perspective_rh(fov as f32, aspect as f32, far as f32, near as f32)
            }
            Depth::ReverseInfinite => {
                Mat4::perspective_infinite_reverse_rh(fov as f32, aspect as f32, near as f32)
            }
        };
        let view_projection = projection * view.as_mat4();
        let inverse = view_projection.inverse();
        let to_world = view.inverse();
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut sum, mut max) = (0.0f64, 0.0f64);
        const POINTS: usize = 20_000;
        for _ in 0..POINTS {
            let distance = near * (far / near).powf(uniform()) * (1.0 - 1e-6);
            let tan = (fov / 2.0).tan();
            let (x, y) = (uniform() * 2.0 - 1.0, uniform() * 2.0 - 1.0);
            let in_view = DVec3::new(x * tan * aspect, y * tan, -1.0) * distance;
            let world = to_world.transform_point3(in_view);
            let world32 = world.as_vec3();
            let clip = view_projection * world32.extend(1.0);
            let ndc = clip / clip.w;
            let rebuilt = inverse * Vec4::new(ndc.x, ndc.y, ndc.z, 1.0);
            let rebuilt = (rebuilt / rebuilt.w).truncate().as_dvec3();
            let error = (rebuilt - world32.as_dvec3()).length() / (world - eye).length();
            sum += error;
            max = max.max(error);
        }
        (sum / POINTS as f64, max)
    }

    /// The engine's reverse-Z depth (D32, finite far plane) reconstructs
    /// positions to float precision at every near/far ratio from 1e2 to 1e7
    /// when positions are small next to their distance from the camera:
    /// measured mean 6.4e-8 to 9.6e-8, max 2.3e-7 to 3.2e-7 of the distance
    /// (an infinite far plane: 6.6e-8 and 2.4e-7 to 2.7e-7). Held to mean
    /// 1.2e-7 and max 4e-7. The other columns printed are the comparison
    /// docs/stability.md tabulates: conventional depth (max 0.27 at 1e6, inf
    /// at 1e7) and the same reverse-Z with the camera 3.7 units from the
    /// origin (max 7.5e-6: the world positions' own rounding, which
    /// camera-relative positions remove).
    #[test]
    fn reverse_z_reconstructs_positions_within_float_precision() {
        for eye in [DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0)] {
            println!("eye {eye}: near/far  conventional (mean, max)  reverse (mean, max)  reverse infinite (mean, max)");
            for exponent in 2..=7 {
                let (near, far) = (0.1, 0.1 * 10f64.powi(exponent));
                let c = reconstruction_error(Depth::Conventional, near, far, eye);
                let r = reconstruction_error(Depth::Reverse, near, far, eye);
                let i = reconstruction_error(Depth::ReverseInfinite, near, far, eye);
                println!(
                    "1e{exponent}  {:.1e} {:.1e}  {:.1e} {:.1e}  {:.1e} {:.1e}",
                    c.0, c.1, r.0, r.1, i.0, i.1
                );
                if eye == DVec3::ZERO {
                    for (mean, max) in [r, i] {
                        assert!(mean <= 1.2e-7 && max <= 4e-7, "1e{exponent}: {mean} {max}");
                    }
                }
            }
        }
    }
}
