//! Perspective shadow views: a spot along its cone, an area light from its
//! centre over its hemisphere.

use crate::gpu_types::GpuLight;
use crate::lights;
use glam::{Mat4, Vec3};
use std::f32::consts::PI;

use super::AREA_HALF_ANGLE_DEGREES;

/// An area light's record (`lights::AREA_RECT`, `AREA_DISC`,
/// `AREA_POLYGON`, laid out as `area_outline` in `area_light.glsl` reads it):
/// its centre, the unit direction it emits towards, and the side of a
/// square of its area; `None` for other records or a degenerate outline.
pub fn area_emitter(record: &GpuLight) -> Option<(Vec3, Vec3, f32)> {
    let kind = record.direction_type.w;
    let a = record.position_range.truncate();
    let b = record.direction_type.truncate();
    let c = record.attenuation_cos.truncate();
    let (centre, winding, area) = if kind == lights::AREA_POLYGON {
        let d = Vec3::new(
            record.position_range.w,
            record.attenuation_cos.w,
            record.color_exponent.w,
        );
        let winding = (c - a).cross(d - b);
        (0.25 * (a + b + c + d), winding, 0.5 * winding.length())
    } else if kind == lights::AREA_RECT {
        let winding = b.cross(c);
        (a, winding, 4.0 * winding.length())
    } else if kind == lights::AREA_DISC {
        (a, b.cross(c), PI * b.length() * c.length())
    } else {
        return None;
    };
    let facing = (-winding).try_normalize()?;
    (area.is_finite() && area > 0.0).then(|| (centre, facing, area.sqrt()))
}

/// World-to-clip for an area light's view from its `centre` along `facing`
/// (a perspective of half-angle [`AREA_HALF_ANGLE_DEGREES`] reaching `far`),
/// the world size of a texel one unit away, and the near depth.
pub fn area_clip(centre: Vec3, facing: Vec3, far: f32, tile: u32, margin: f32) -> (Mat4, f32, f32) {
    let far = far.max(1e-3);
    let (clip, texel) = spot_clip(
        centre,
        facing,
        AREA_HALF_ANGLE_DEGREES.to_radians().cos(),
        far,
        tile,
        margin,
    );
    (clip, texel, spot_near(far))
}

/// Perspective world-to-clip for a spot at `position` shining along `direction`
/// with half-angle `acos(cos_cutoff)` and reach `range` (forward Z, Y flipped),
/// widened so the cone fits inside `margin` texels from a `tile`-texel map's edge.
/// Returns the matrix and the world size of a texel one unit from the light.
pub fn spot_clip(
    position: Vec3,
    direction: Vec3,
    cos_cutoff: f32,
    range: f32,
    tile: u32,
    margin: f32,
) -> (Mat4, f32) {
    let (dir, up) = super::view_axes(direction);
    let half = cos_cutoff
        .clamp(-1.0, 1.0)
        .acos()
        .clamp(1e-3, 80f32.to_radians());
    let tile = tile.max(1) as f32;
    let tan = half.tan() * tile / (tile - 2.0 * margin).max(1.0);
    let far = range.max(1e-3);
    let near = spot_near(far);
    let view = Mat4::look_at_rh(position, position + dir, up);
    let mut proj = Mat4::perspective_rh(2.0 * tan.atan(), 1.0, near, far);
    proj.y_axis.y = -proj.y_axis.y;
    (proj * view, 2.0 * tan / tile)
}

/// The near depth of a perspective view reaching `far`.
fn spot_near(far: f32) -> f32 {
    (far * 1e-3).max(1e-3).min(far * 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Vec3Swizzles, Vec4Swizzles};

    #[test]
    fn a_spot_view_holds_its_cone_inside_the_margin() {
        let pos = Vec3::new(0.0, 5.0, 0.0);
        let dir = Vec3::new(0.2, -1.0, 0.1).normalize();
        let cos = 30f32.to_radians().cos();
        let (m, texel) = spot_clip(pos, dir, cos, 10.0, 256, 3.0);
        // A point on the cone's edge 5 units out lies 3 texels inside the tile.
        let side = dir.cross(Vec3::X).normalize();
        let q = glam::Quat::from_axis_angle(side, 30f32.to_radians());
        let edge = pos + q * dir * 5.0;
        let c = m * edge.extend(1.0);
        let ndc = c.xyz() / c.w;
        let inside = (1.0 - ndc.xy().abs().max_element()) * 128.0;
        assert!(inside > 2.9, "{inside}");
        assert!(ndc.z > 0.0 && ndc.z < 1.0);
        assert!((texel - 2.0 * 30f32.to_radians().tan() * 256.0 / 250.0 / 256.0).abs() < 1e-6);
    }

    #[test]
    fn an_area_view_looks_along_the_emission_and_holds_its_hemisphere() {
        // A 2 x 1 rectangle at height 3 facing down (its winding points up).
        let record = GpuLight {
            position_range: Vec3::new(0.0, 3.0, 0.0).extend(0.0),
            direction_type: Vec3::new(0.0, 0.0, 1.0).extend(lights::AREA_RECT),
            color_exponent: Vec3::ONE.extend(0.0),
            attenuation_cos: Vec3::new(0.5, 0.0, 0.0).extend(0.0),
        };
        let (centre, facing, size) = area_emitter(&record).expect("an area light");
        assert_eq!(centre, Vec3::new(0.0, 3.0, 0.0));
        assert!((facing - Vec3::NEG_Y).length() < 1e-6, "{facing}");
        assert!((size - 2f32.sqrt()).abs() < 1e-6, "{size}");
        let (clip, _, near) = area_clip(centre, facing, 10.0, 1024, 3.0);
        // Straight below, and 75 degrees off the axis, both inside the view.
        for angle in [0f32, 75.0] {
            let d = Vec3::new(angle.to_radians().sin(), -angle.to_radians().cos(), 0.0);
            let c = clip * (centre + d * 2.0).extend(1.0);
            let ndc = c.xyz() / c.w;
            assert!(
                ndc.xy().abs().max_element() < 1.0 && ndc.z > 0.0 && ndc.z < 1.0,
                "{angle}: {ndc}"
            );
        }
        assert!(near > 0.0 && near < 0.1);
        // Points lights and spots are not area emitters.
        let point = GpuLight {
            direction_type: Vec3::ZERO.extend(lights::POINT),
            ..record
        };
        assert_eq!(area_emitter(&point), None);
    }
}
