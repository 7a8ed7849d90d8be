//! The viewer's fly camera, kept apart from windowing so it is tested without
//! a display: it starts at a scene camera's pose, moves relative to where it
//! looks (scaled by frame time), turns about world up and its own right axis,
//! and never tips over the vertical.

use glam::{Quat, Vec2, Vec3};

/// How much faster Shift moves.
pub const FAST: f32 = 4.0;
/// Speed factor per scroll-wheel notch.
pub const SCROLL_STEP: f32 = 1.25;
/// Radians per second of look with the arrow keys.
pub const KEY_LOOK: f32 = 1.5;
/// Radians per pixel of mouse drag.
pub const DRAG_LOOK: f32 = 0.004;
/// Furthest the view may tilt up or down, as the sine of the angle (about 89 degrees).
const MAX_TILT: f32 = 0.9998;

/// Movement asked for in one frame: each axis in -1..=1 (keys held), plus look.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FlyInput {
    /// W minus S.
    pub forward: f32,
    /// D minus A.
    pub right: f32,
    /// E minus Q (world up).
    pub up: f32,
    /// Shift held.
    pub fast: bool,
    /// Turn in radians: x to the right, y upwards.
    pub look: Vec2,
}

/// A camera flown by keyboard and mouse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlyCamera {
    /// World position.
    pub position: Vec3,
    /// World rotation; looks down local -Z with local +Y up (the scene convention).
    pub orientation: Quat,
    /// Units per second without Shift.
    pub speed: f32,
}

impl FlyCamera {
    /// Where it looks.
    pub fn forward(&self) -> Vec3 {
        self.orientation * Vec3::NEG_Z
    }

    /// Its right-hand direction.
    pub fn right(&self) -> Vec3 {
        self.orientation * Vec3::X
    }

    /// Applies one frame of input lasting `dt` seconds.
    pub fn update(&mut self, input: &FlyInput, dt: f32) {
        self.turn(input.look);
        let speed = self.speed * if input.fast { FAST } else { 1.0 };
        let step = self.forward() * input.forward + self.right() * input.right + Vec3::Y * input.up;
        self.position += step * speed * dt;
    }

    /// Turns right by `look.x` radians about world up and up by `look.y` radians
    /// about its right axis; a tilt that would reach or pass the vertical (turning
    /// the view upside down) is left out.
    pub fn turn(&mut self, look: Vec2) {
        if look == Vec2::ZERO {
            return;
        }
        let yawed = Quat::from_rotation_y(-look.x) * self.orientation;
        let tilted = (yawed * Quat::from_rotation_x(look.y)).normalize();
        let upright = (tilted * Vec3::Y).y > 0.0 && (tilted * Vec3::NEG_Z).y.abs() <= MAX_TILT;
        self.orientation = if upright { tilted } else { yawed.normalize() };
    }

    /// Changes speed by [`SCROLL_STEP`] per notch (negative slows down), within
    /// a millionth to a million times the starting speed `base`.
    pub fn scroll(&mut self, notches: f32, base: f32) {
        self.speed = (self.speed * SCROLL_STEP.powf(notches)).clamp(base * 1e-6, base * 1e6);
    }
}

/// A starting speed for a scene of bounding-box diagonal `diagonal`: crossing
/// it takes about eight seconds.
pub fn speed_for(diagonal: f32) -> f32 {
    if diagonal.is_finite() && diagonal > 0.0 {
        diagonal / 8.0
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera() -> FlyCamera {
        FlyCamera {
            position: Vec3::ZERO,
            orientation: Quat::IDENTITY,
            speed: 2.0,
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    #[test]
    fn moves_along_its_axes_scaled_by_frame_time_and_shift() {
        let mut c = camera();
        let input = FlyInput {
            forward: 1.0,
            ..FlyInput::default()
        };
        c.update(&input, 0.5);
        assert!(
            close(c.position, Vec3::new(0.0, 0.0, -1.0)),
            "{}",
            c.position
        );
        c.update(
            &FlyInput {
                right: 1.0,
                up: -1.0,
                fast: true,
                ..FlyInput::default()
            },
            0.25,
        );
        assert!(
            close(c.position, Vec3::new(2.0, -2.0, -1.0)),
            "{}",
            c.position
        );
    }

    #[test]
    fn up_and_down_follow_world_up_even_when_looking_down() {
        let mut c = camera();
        c.turn(Vec2::new(0.0, -1.0));
        assert!(c.forward().y < -0.8);
        c.update(
            &FlyInput {
                up: 1.0,
                ..FlyInput::default()
            },
            1.0,
        );
        assert!(
            close(c.position, Vec3::new(0.0, 2.0, 0.0)),
            "{}",
            c.position
        );
    }

    #[test]
    fn turning_right_and_up_and_never_past_vertical() {
        let mut c = camera();
        c.turn(Vec2::new(std::f32::consts::FRAC_PI_2, 0.0));
        assert!(close(c.forward(), Vec3::X), "{}", c.forward());
        c.turn(Vec2::new(0.0, 0.5));
        assert!((c.forward().y - 0.5f32.sin()).abs() < 1e-5);
        assert!(close(c.right(), Vec3::Z), "{}", c.right());
        c.turn(Vec2::new(0.0, 2.0));
        assert!(
            (c.forward().y - 0.5f32.sin()).abs() < 1e-5,
            "a tilt past vertical is refused"
        );
        assert!(c.right().y.abs() < 1e-5, "no roll creeps in");
    }

    #[test]
    fn no_input_keeps_the_starting_pose_exactly() {
        let start = FlyCamera {
            position: Vec3::new(1.0, 2.0, 3.0),
            orientation: Quat::from_euler(glam::EulerRot::YXZ, 0.3, -0.2, 0.1),
            speed: 1.0,
        };
        let mut c = start;
        c.update(&FlyInput::default(), 0.016);
        assert_eq!(c, start);
    }

    #[test]
    fn scroll_scales_speed_within_bounds() {
        let mut c = camera();
        c.scroll(2.0, 2.0);
        assert!((c.speed - 2.0 * 1.5625).abs() < 1e-6);
        c.scroll(-200.0, 2.0);
        assert!((c.speed - 2e-6).abs() < 1e-9);
        assert_eq!(speed_for(16.0), 2.0);
        assert_eq!(speed_for(f32::NAN), 1.0);
    }
}
