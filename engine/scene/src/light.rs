//! Light types (sun, spot, point, area) and the point-light cutoff radius.

use glam::{Quat, Vec3};
use serde::{Deserialize, Serialize};

/// Distance falloff `1 / (constant + linear d + quadratic d²)`, as in fixed-function GL.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Attenuation {
    /// Constant term.
    pub constant: f32,
    /// Linear term.
    pub linear: f32,
    /// Quadratic term.
    pub quadratic: f32,
}

impl Attenuation {
    /// No falloff (the 15-462 default).
    pub const NONE: Attenuation = Attenuation {
        constant: 1.0,
        linear: 0.0,
        quadratic: 0.0,
    };
    /// Physical inverse-square falloff (glTF punctual lights).
    pub const INVERSE_SQUARE: Attenuation = Attenuation {
        constant: 0.0,
        linear: 0.0,
        quadratic: 1.0,
    };

    /// The factor at distance `d`, infinite when the denominator is 0.
    pub fn factor(&self, d: f32) -> f32 {
        1.0 / (self.constant + self.linear * d + self.quadratic * d * d)
    }
}

/// Rotation of the sun direction over time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SunMotion {
    /// The axis the direction turns around (unit).
    pub axis: Vec3,
    /// Turning speed.
    pub degrees_per_second: f32,
}

/// A directional light with an ambient term.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SunLight {
    /// Unit direction the light travels.
    pub direction: Vec3,
    /// RGB colour.
    pub color: Vec3,
    /// RGB ambient light (the 15-462 scalar times `color`, or three values).
    pub ambient: Vec3,
    /// Optional animation.
    pub motion: Option<SunMotion>,
}

/// A spotlight turning back and forth between two directions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Swivel {
    /// The first direction (unit); the light starts here.
    pub from: Vec3,
    /// The second direction (unit).
    pub to: Vec3,
    /// Seconds for a full swing there and back.
    pub period: f32,
}

/// A cone light.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SpotLight {
    /// World position.
    pub position: Vec3,
    /// Unit axis direction.
    pub direction: Vec3,
    /// RGB colour.
    pub color: Vec3,
    /// Cosine falloff exponent (GL_SPOT_EXPONENT).
    pub exponent: f32,
    /// Half-angle of the cone in degrees (GL_SPOT_CUTOFF).
    pub angle: f32,
    /// Half-angle in degrees inside which the light is at full strength (glTF inner cone), if given.
    pub inner_angle: Option<f32>,
    /// Maximum lit distance along the axis, `None` when unlimited.
    pub length: Option<f32>,
    /// Distance falloff.
    pub attenuation: Attenuation,
    /// Optional animation.
    pub swivel: Option<Swivel>,
}

/// Where a point light's cutoff radius came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum RadiusSource {
    /// The scene's `radius` property.
    Given,
    /// Derived from attenuation and luminance threshold.
    Derived,
    /// glTF KHR_lights_punctual `range`.
    Range,
}

/// A point light with a cutoff radius for tiled/clustered shading.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PointLight {
    /// World position at time 0.
    pub position: Vec3,
    /// RGB colour.
    pub color: Vec3,
    /// Angular speed of the animation in radians per second (0 = static).
    pub velocity: f32,
    /// Radius of the horizontal circle the light moves on when animated.
    pub amplitude: f32,
    /// Distance falloff.
    pub attenuation: Attenuation,
    /// Distance beyond which the light is ignored.
    pub radius: f32,
    /// Where `radius` came from.
    pub radius_source: RadiusSource,
}

/// The outline of an area light.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum AreaShape {
    /// A rectangle, centred, in the light's local XY plane.
    Rect {
        /// Size along local X.
        width: f32,
        /// Size along local Y.
        height: f32,
    },
    /// A disc, centred, in the light's local XY plane.
    Disc {
        /// Its radius.
        radius: f32,
    },
}

/// An emitting surface; it faces its local -Z axis (the way a camera looks).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AreaLight {
    /// The outline.
    pub shape: AreaShape,
    /// World position of the centre.
    pub position: Vec3,
    /// World rotation of the local frame.
    pub orientation: Quat,
    /// Emitted RGB radiance.
    pub emission: Vec3,
    /// Whether both faces emit.
    pub two_sided: bool,
}

impl AreaLight {
    /// The unit direction the light faces.
    pub fn normal(&self) -> Vec3 {
        self.orientation * Vec3::NEG_Z
    }

    /// The emitting area.
    pub fn area(&self) -> f32 {
        match self.shape {
            AreaShape::Rect { width, height } => width * height,
            AreaShape::Disc { radius } => std::f32::consts::PI * radius * radius,
        }
    }
}

/// Any light in a scene.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Light {
    /// Directional.
    Sun(SunLight),
    /// Cone.
    Spot(SpotLight),
    /// Point.
    Point(PointLight),
    /// Area.
    Area(AreaLight),
}

/// The default luminance below which a point light is cut off: one step of an 8-bit channel.
pub const DEFAULT_LUMINANCE_THRESHOLD: f32 = 1.0 / 256.0;

/// Rec. 709 luminance of an RGB colour.
pub fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// The distance at which `luminance(color) * attenuation.factor(d)` falls to `threshold`,
/// or `None` when it never does (no linear or quadratic term) or the light is black.
pub fn derive_radius(color: Vec3, attenuation: &Attenuation, threshold: f32) -> Option<f32> {
    let lum = luminance(color);
    if lum <= 0.0 || threshold <= 0.0 {
        return None;
    }
    // Solve q d² + l d + (c - lum/threshold) = 0 for the positive root.
    let (a, b, c) = (
        attenuation.quadratic,
        attenuation.linear,
        attenuation.constant - lum / threshold,
    );
    if c >= 0.0 {
        return Some(0.0);
    }
    let root = if a > 0.0 {
        (-b + (b * b - 4.0 * a * c).sqrt()) / (2.0 * a)
    } else if b > 0.0 {
        -c / b
    } else {
        return None;
    };
    root.is_finite().then_some(root)
}

/// The share of a point light's energy reaching distances up to `extent` (the scene's
/// diagonal) that a cutoff at `radius` drops: ∫ₓ^ₑ A(d) d² dd / ∫₀^ₑ A(d) d² dd,
/// with `A` the attenuation; 0 when the radius covers the extent.
pub fn energy_cut_share(attenuation: &Attenuation, radius: f32, extent: f32) -> f32 {
    if radius >= extent || extent <= 0.0 {
        return 0.0;
    }
    let total = integrate_shells(attenuation, 0.0, extent);
    if total <= 0.0 || !total.is_finite() {
        return 0.0;
    }
    (integrate_shells(attenuation, radius.max(0.0), extent) / total).clamp(0.0, 1.0) as f32
}

/// Simpson's rule over [a, b] of `A(d) d²`, in f64; the integrand is finite everywhere
/// because `d²` vanishes where a zero constant term makes `A` blow up.
fn integrate_shells(attenuation: &Attenuation, a: f32, b: f32) -> f64 {
    const STEPS: usize = 512;
    let (a, b) = (f64::from(a), f64::from(b));
    let h = (b - a) / STEPS as f64;
    let f = |d: f64| {
        let denom = f64::from(attenuation.constant)
            + f64::from(attenuation.linear) * d
            + f64::from(attenuation.quadratic) * d * d;
        if d == 0.0 {
            if attenuation.constant > 0.0 || attenuation.linear > 0.0 {
                0.0
            } else {
                1.0 / f64::from(attenuation.quadratic)
            }
        } else {
            d * d / denom
        }
    };
    let mut sum = f(a) + f(b);
    for i in 1..STEPS {
        let w = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += w * f(a + h * i as f64);
    }
    sum * h / 3.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_for_quadratic_falloff() {
        let att = Attenuation {
            constant: 0.0,
            linear: 0.0,
            quadratic: 0.3,
        };
        // 0.3 d² = 256  =>  d = sqrt(853.33) = 29.2119
        let r = derive_radius(Vec3::ONE, &att, DEFAULT_LUMINANCE_THRESHOLD).expect("finite");
        assert!((r - 29.211_869).abs() < 1e-3, "{r}");
        assert_eq!(
            derive_radius(Vec3::ONE, &Attenuation::NONE, DEFAULT_LUMINANCE_THRESHOLD),
            None
        );
        assert_eq!(
            derive_radius(Vec3::ZERO, &att, DEFAULT_LUMINANCE_THRESHOLD),
            None
        );
        let linear = Attenuation {
            constant: 1.0,
            linear: 1.0,
            quadratic: 0.0,
        };
        assert_eq!(derive_radius(Vec3::ONE, &linear, 0.5), Some(1.0));
    }

    #[test]
    fn pure_inverse_square_cuts_linearly() {
        // A(d) d² is constant, so cutting at half the extent drops half the energy.
        let share = energy_cut_share(&Attenuation::INVERSE_SQUARE, 5.0, 10.0);
        assert!((share - 0.5).abs() < 1e-6, "{share}");
        assert_eq!(
            energy_cut_share(&Attenuation::INVERSE_SQUARE, 12.0, 10.0),
            0.0
        );
    }
}
