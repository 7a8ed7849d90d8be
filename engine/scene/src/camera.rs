//! Cameras: named viewpoints with optional keyframed paths, and the default framing camera.

use crate::bounds::Aabb;
use glam::{Mat4, Quat, Vec3};
use serde::{Deserialize, Serialize};

/// One key of a camera path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CameraKey {
    /// Seconds from the start.
    pub time: f32,
    /// World position.
    pub position: Vec3,
    /// World rotation (the camera looks down its local -Z with +Y up).
    pub orientation: Quat,
}

/// Where a camera came from, for reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum CameraOrigin {
    /// A `camera` block.
    Scene,
    /// A glTF camera node.
    Gltf,
    /// Made by [`default_camera`].
    Default,
}

/// A perspective camera.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Camera {
    /// Name used to select it (`"default"` for the framing camera).
    pub name: String,
    /// World position at time 0.
    pub position: Vec3,
    /// World rotation at time 0; the camera looks down local -Z, +Y up.
    pub orientation: Quat,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Near clip distance.
    pub near: f32,
    /// Far clip distance.
    pub far: f32,
    /// Keys sorted by time, empty for a still camera.
    pub path: Vec<CameraKey>,
    /// Where it came from.
    pub origin: CameraOrigin,
}

/// The direction, from the centre of the bounds, where the default camera sits:
/// in front (+Z), a little to the right (+X) and above (+Y).
pub const DEFAULT_VIEW_DIRECTION: Vec3 = Vec3::new(0.3, 0.4, 1.0);
/// The default vertical field of view: 45 degrees.
pub const DEFAULT_FOV_Y: f32 = std::f32::consts::FRAC_PI_4;

impl Camera {
    /// The unit direction it looks at time 0.
    pub fn forward(&self) -> Vec3 {
        self.orientation * Vec3::NEG_Z
    }

    /// Position and orientation at `time` seconds: the path interpolated (linear position,
    /// slerped rotation), clamped to its ends; the still pose when there is no path.
    pub fn pose_at(&self, time: f64) -> (Vec3, Quat) {
        let (Some(first), Some(last)) = (self.path.first(), self.path.last()) else {
            return (self.position, self.orientation);
        };
        if time <= f64::from(first.time) {
            return (first.position, first.orientation);
        }
        if time >= f64::from(last.time) {
            return (last.position, last.orientation);
        }
        let next = self.path.partition_point(|k| f64::from(k.time) <= time);
        let (a, b) = (&self.path[next - 1], &self.path[next]);
        let span = f64::from(b.time) - f64::from(a.time);
        let s = if span > 0.0 {
            ((time - f64::from(a.time)) / span) as f32
        } else {
            1.0
        };
        (
            a.position.lerp(b.position, s),
            a.orientation.slerp(b.orientation, s),
        )
    }

    /// The projection for a viewport of `aspect` = width / height:
    /// [`reverse_z_projection`] with the camera's field of view and planes.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        reverse_z_projection(self.fov_y, aspect, self.near, self.far)
    }

    /// World-to-clip at `time` seen through a viewport of `aspect` = width / height.
    pub fn view_projection(&self, time: f64, aspect: f32) -> Mat4 {
        self.projection(aspect) * self.view_at(time)
    }

    /// The world-to-view matrix at `time`.
    pub fn view_at(&self, time: f64) -> Mat4 {
        let (p, q) = self.pose_at(time);
        Mat4::from_rotation_translation(q, p).inverse()
    }
}

/// Reverse-Z perspective with Y flipped for Vulkan's viewport: near maps to
/// depth 1, far to 0 (so float depth keeps precision far away), world up to
/// clip-space down.
pub fn reverse_z_projection(fov_y: f32, aspect: f32, near: f32, far: f32) -> Mat4 {
    let mut m = Mat4::perspective_rh(fov_y, aspect, far, near);
    m.y_axis.y = -m.y_axis.y;
    m
}

/// The rotation that makes a camera at `from` look at `target` with +Y up (or +Z when looking
/// straight up or down).
pub fn look_at_rotation(from: Vec3, target: Vec3) -> Quat {
    let forward = (target - from).try_normalize().unwrap_or(Vec3::NEG_Z);
    let up = if forward.cross(Vec3::Y).length_squared() < 1e-8 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    let right = forward.cross(up).normalize();
    let true_up = right.cross(forward);
    Quat::from_mat3(&glam::Mat3::from_cols(right, true_up, -forward)).normalize()
}

/// A camera that frames `bounds`: it looks at the centre from [`DEFAULT_VIEW_DIRECTION`],
/// far enough that the bounding sphere fits the vertical field of view [`DEFAULT_FOV_Y`].
pub fn default_camera(bounds: &Aabb) -> Camera {
    let (center, radius) = if bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (bounds.center(), (bounds.diagonal() * 0.5).max(1e-3))
    };
    let distance = radius / (DEFAULT_FOV_Y * 0.5).sin();
    let position = center + DEFAULT_VIEW_DIRECTION.normalize() * distance;
    Camera {
        name: "default".to_string(),
        position,
        orientation: look_at_rotation(position, center),
        fov_y: DEFAULT_FOV_Y,
        near: (distance - radius).max(distance * 1e-3),
        far: distance + radius * 2.0,
        path: Vec::new(),
        origin: CameraOrigin::Default,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_camera_looks_at_the_centre() {
        let b = Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        };
        let c = default_camera(&b);
        let to_center = (b.center() - c.position).normalize();
        assert!(c.forward().distance(to_center) < 1e-5);
        let distance = c.position.length();
        assert!((distance - 3.0f32.sqrt() / (std::f32::consts::FRAC_PI_8).sin()).abs() < 1e-4);
        assert!(c.near > 0.0 && c.far > distance + 1.7);
    }

    #[test]
    fn projection_maps_near_to_one_and_far_to_zero() {
        let c = Camera {
            near: 0.5,
            far: 10.0,
            ..default_camera(&Aabb::EMPTY)
        };
        let p = c.projection(16.0 / 9.0);
        let near = p.project_point3(Vec3::new(0.0, 0.0, -0.5));
        let far = p.project_point3(Vec3::new(0.0, 0.0, -10.0));
        assert!(
            (near.z - 1.0).abs() < 1e-6 && far.z.abs() < 1e-6,
            "reverse Z: {near} {far}"
        );
        let up = p * Vec3::new(0.0, 1.0, -1.0).extend(1.0);
        assert!(up.y < 0.0, "world up is clip-space down in Vulkan");
        let view = c.view_at(0.0);
        assert!(view.transform_point3(c.position).length() < 1e-4);
    }

    #[test]
    fn path_interpolates_and_clamps() {
        let key = |time, x| CameraKey {
            time,
            position: Vec3::new(x, 0.0, 0.0),
            orientation: Quat::IDENTITY,
        };
        let mut c = default_camera(&Aabb::EMPTY);
        c.path = vec![key(0.0, 0.0), key(2.0, 4.0)];
        assert_eq!(c.pose_at(1.0).0, Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(c.pose_at(-1.0).0, Vec3::ZERO);
        assert_eq!(c.pose_at(9.0).0, Vec3::new(4.0, 0.0, 0.0));
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
