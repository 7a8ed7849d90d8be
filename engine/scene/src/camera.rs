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

    /// The projection for a viewport of `aspect` = width / height: right-handed, depth 0..1
    /// (Vulkan's range), +Y up in clip space (flip Y with a negative viewport height).
    pub fn projection(&self, aspect: f32) -> Mat4 {
        Mat4::perspective_rh(self.fov_y, aspect, self.near, self.far)
    }

    /// The world-to-view matrix at `time`.
    pub fn view_at(&self, time: f64) -> Mat4 {
        let (p, q) = self.pose_at(time);
        Mat4::from_rotation_translation(q, p).inverse()
    }
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
    fn projection_maps_near_and_far_to_vulkan_depth() {
        let c = Camera {
            near: 0.5,
            far: 10.0,
            ..default_camera(&Aabb::EMPTY)
        };
        let p = c.projection(16.0 / 9.0);
        let near = p.project_point3(Vec3::new(0.0, 0.0, -0.5));
        let far = p.project_point3(Vec3::new(0.0, 0.0, -10.0));
        assert!(
            near.z.abs() < 1e-6 && (far.z - 1.0).abs() < 1e-6,
            "{near} {far}"
        );
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
}
