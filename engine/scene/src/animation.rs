//! Light animation evaluated at a time: point lights circling, spotlights swivelling, the sun
//! turning. Pure functions of (light, index, time, seed), so every frame is reproducible.
//! Time is f64 seconds, and phases are reduced to one period in f64 before
//! any f32 trigonometry, so a time of 1e9 seconds (or a negative one) gives
//! the same pose as the same point in the first period, not f32 noise, and
//! frames 1/60 s apart at 1e9 s still differ (docs/stability.md).

use crate::light::{Light, PointLight, SpotLight, SunLight};
use crate::rng::Rng;
use glam::{Quat, Vec3};

/// `rate × time` reduced to [0, `period`), computed in f64; 0 where the
/// product overflows f64 (no phase is left to keep there).
fn wrapped(rate: f32, time: f64, period: f64) -> f32 {
    let phase = f64::from(rate) * time;
    if phase.is_finite() {
        phase.rem_euclid(period) as f32
    } else {
        0.0
    }
}

/// Where point light number `index` is at `time` seconds: on a horizontal circle of radius
/// `amplitude` around its position, at `velocity` radians per second, with a start phase and
/// a turning sense drawn from `seed` and `index`.
pub fn point_position_at(light: &PointLight, index: usize, time: f64, seed: u64) -> Vec3 {
    if light.velocity == 0.0 || light.amplitude == 0.0 {
        return light.position;
    }
    let mut rng = Rng::new(seed ^ (index as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let phase = rng.range(0.0, std::f32::consts::TAU);
    let sense = if rng.next_u64() & 1 == 0 { 1.0 } else { -1.0 };
    let angle = phase + sense * wrapped(light.velocity, time, std::f64::consts::TAU);
    // Start on the circle at the phase, so the offset at t=0 is zero.
    let start = Vec3::new(phase.cos(), 0.0, phase.sin());
    let now = Vec3::new(angle.cos(), 0.0, angle.sin());
    light.position + (now - start) * light.amplitude
}

/// The spotlight's direction at `time`: eased back and forth between the swivel directions.
pub fn spot_direction_at(light: &SpotLight, time: f64) -> Vec3 {
    let Some(sw) = light.swivel else {
        return light.direction;
    };
    let s = if sw.period > 0.0 {
        0.5 - 0.5 * (std::f32::consts::TAU * wrapped(1.0 / sw.period, time, 1.0)).cos()
    } else {
        0.0
    };
    if s == 0.0 {
        return sw.from;
    }
    let turn = Quat::from_rotation_arc(sw.from, sw.to);
    (Quat::IDENTITY.slerp(turn, s) * sw.from).normalize()
}

/// The sun's direction at `time`, turned about its motion axis.
pub fn sun_direction_at(light: &SunLight, time: f64) -> Vec3 {
    match light.motion {
        Some(m) => {
            Quat::from_axis_angle(
                m.axis,
                wrapped(m.degrees_per_second, time, 360.0).to_radians(),
            ) * light.direction
        }
        None => light.direction,
    }
}

/// Every light as it is at `time` for animation seed `seed`; point lights are numbered in
/// list order among point lights.
pub fn lights_at(lights: &[Light], time: f64, seed: u64) -> Vec<Light> {
    lights_at_with(lights, time, seed, |_| None)
}

/// [`lights_at`], with `fixed(i)` standing in for light `i` where it gives
/// one (a light a scene script has changed): that light is taken as it is,
/// not animated. Point lights are still numbered over every point light.
pub fn lights_at_with<'f>(
    lights: &[Light],
    time: f64,
    seed: u64,
    fixed: impl Fn(usize) -> Option<&'f Light>,
) -> Vec<Light> {
    let mut point_index = 0;
    lights
        .iter()
        .enumerate()
        .map(|(i, light)| {
            let index = point_index;
            if matches!(light, Light::Point(_)) {
                point_index += 1;
            }
            if let Some(kept) = fixed(i) {
                return kept.clone();
            }
            match light {
                Light::Point(p) => {
                    let mut moved = p.clone();
                    moved.position = point_position_at(p, index, time, seed);
                    Light::Point(moved)
                }
                Light::Spot(s) => {
                    let mut turned = s.clone();
                    turned.direction = spot_direction_at(s, time);
                    Light::Spot(turned)
                }
                Light::Sun(s) => {
                    let mut turned = s.clone();
                    turned.direction = sun_direction_at(s, time);
                    Light::Sun(turned)
                }
                Light::Area(a) => Light::Area(a.clone()),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::{Attenuation, RadiusSource, SunMotion, Swivel};

    fn point(velocity: f32) -> PointLight {
        PointLight {
            position: Vec3::new(1.0, 2.0, 3.0),
            color: Vec3::ONE,
            velocity,
            amplitude: 2.0,
            attenuation: Attenuation::INVERSE_SQUARE,
            radius: 10.0,
            radius_source: RadiusSource::Given,
        }
    }

    #[test]
    fn point_motion_is_deterministic_and_stays_on_its_circle() {
        let p = point(1.0);
        assert_eq!(point_position_at(&p, 3, 0.0, 9), p.position);
        let a = point_position_at(&p, 3, 1.5, 9);
        assert_eq!(a, point_position_at(&p, 3, 1.5, 9));
        assert_ne!(a, point_position_at(&p, 3, 1.5, 10));
        assert_eq!(a.y, 2.0);
        // Full turn after 2π seconds at 1 rad/s.
        let back = point_position_at(&p, 3, std::f64::consts::TAU, 9);
        assert!(back.distance(p.position) < 1e-4);
        assert_eq!(point_position_at(&point(0.0), 0, 5.0, 1), p.position);
    }

    /// A spot at the origin swivelling from straight down to +X and back every 4 s.
    fn swivelling_spot() -> SpotLight {
        SpotLight {
            position: Vec3::ZERO,
            direction: Vec3::NEG_Y,
            color: Vec3::ONE,
            exponent: 1.0,
            angle: 30.0,
            inner_angle: None,
            length: None,
            attenuation: Attenuation::NONE,
            swivel: Some(Swivel {
                from: Vec3::NEG_Y,
                to: Vec3::X,
                period: 4.0,
            }),
        }
    }

    /// A sun along +X turning about +Y at 90 degrees a second.
    fn turning_sun() -> SunLight {
        SunLight {
            direction: Vec3::X,
            color: Vec3::ONE,
            ambient: Vec3::ZERO,
            motion: Some(SunMotion {
                axis: Vec3::Y,
                degrees_per_second: 90.0,
            }),
        }
    }

    #[test]
    fn swivel_and_sun_motion() {
        let spot = swivelling_spot();
        assert!(spot_direction_at(&spot, 0.0).distance(Vec3::NEG_Y) < 1e-6);
        assert!(spot_direction_at(&spot, 2.0).distance(Vec3::X) < 1e-6);
        assert!(spot_direction_at(&spot, 4.0).distance(Vec3::NEG_Y) < 1e-6);
        let sun = turning_sun();
        assert!(sun_direction_at(&sun, 1.0).distance(Vec3::NEG_Z) < 1e-6);
    }

    #[test]
    fn poses_at_huge_and_negative_times_are_finite_and_periodic() {
        // At 1 rad/s the point light's pose at any time is its pose at that
        // time reduced modulo 2π (reduced here in f64, as the code does); a
        // spot swivelling every 4 s and a sun turning 90 degrees a second are
        // back where they started at 1e9 s and at -8 s (whole periods, exact
        // in f64).
        let p = point(1.0);
        for t in [1e9, -8.0, 12345.678] {
            let reduced = f64::rem_euclid(t, std::f64::consts::TAU);
            let at = point_position_at(&p, 3, t, 9);
            assert!(at.is_finite(), "{t}");
            let expected = point_position_at(&p, 3, reduced, 9);
            assert!(
                at.distance(expected) < 1e-4,
                "point at {t}: {at}, expected {expected}"
            );
        }
        let spot = swivelling_spot();
        let sun = turning_sun();
        for t in [1e9, -8.0] {
            assert!(
                spot_direction_at(&spot, t).distance(Vec3::NEG_Y) < 1e-5,
                "spot at {t}"
            );
            assert!(
                sun_direction_at(&sun, t).distance(Vec3::X) < 1e-5,
                "sun at {t}"
            );
        }
        assert!(spot_direction_at(&spot, 1e9 + 128.0 + 2.0).is_finite());
        assert!(spot_direction_at(&spot, -6.0).distance(Vec3::X) < 1e-5);
        // Every pose is finite at any time, the extremes of f64 included.
        for t in [f64::MAX, f64::MIN, 1e-300, 0.0] {
            assert!(point_position_at(&p, 1, t, 2).is_finite(), "{t}");
            assert!(spot_direction_at(&spot, t).is_finite(), "{t}");
            assert!(sun_direction_at(&sun, t).is_finite(), "{t}");
        }
    }

    #[test]
    fn frames_a_sixtieth_of_a_second_apart_differ_at_a_billion_seconds() {
        // In f32, 1e9 and 1e9 + 1/60 are the same number; the clock is f64.
        assert_eq!(1e9f32, 1e9f32 + 1.0 / 60.0);
        let sun = turning_sun();
        let frame = 1.0 / 60.0;
        for start in [0.0, 1e9] {
            let turned = sun_direction_at(&sun, start + frame);
            // 90 degrees a second: 1.5 degrees from +X towards -Z.
            let expected = Quat::from_rotation_y(1.5f32.to_radians()) * Vec3::X;
            assert!(
                turned.distance(expected) < 1e-5,
                "sun at {start} + 1/60 s: {turned}, expected {expected}"
            );
        }
        let spot = swivelling_spot();
        assert_ne!(
            spot_direction_at(&spot, 1e9 + 1.0),
            spot_direction_at(&spot, 1e9 + 1.0 + frame)
        );
        let p = point(1.0);
        let a = point_position_at(&p, 0, 1e9, 4);
        let b = point_position_at(&p, 0, 1e9 + frame, 4);
        // 1/60 rad along a circle of radius 2.
        assert!(
            (a.distance(b) - 2.0 / 60.0).abs() < 1e-4,
            "{}",
            a.distance(b)
        );
    }
}
