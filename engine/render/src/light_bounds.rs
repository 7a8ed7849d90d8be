//! What a light-tree node knows of its lights (engine/render/src/light_tree.rs):
//! the box around their positions, their power, the cone their normals
//! lie in and how far past it they emit, their range and attenuation; for
//! one light record, and for two nodes together. [`power`], the estimate
//! of what a light emits, also weighs the lights `light_choice` picks by
//! power.

use crate::emitters::luminance;
use crate::gpu_types::GpuLight;
use crate::lights::{AREA_DISC, AREA_RECT, POINT, SPOT_CONE, SPOT_SPHERE, SUN};
use glam::{Quat, Vec3};
use std::f32::consts::PI;

/// An estimate of the luminous power a light record emits, in the path
/// tracer's units (docs/pathtrace.md, "Lights and units"): a point light of
/// colour C gives irradiance π C at unit attenuation, so intensity π C and
/// power 4π² C; a spot, its cone's share of that; a sun, irradiance π C over
/// the scene's cross-section π r²; an area light, π L A per emitting face.
/// Attenuation and cutoff ranges are left out.
pub fn power(light: &GpuLight, scene_radius: f32) -> f32 {
    let colour = luminance(light.color_exponent.truncate()).max(0.0);
    let kind = light.direction_type.w;
    if kind == SUN {
        PI * colour * PI * scene_radius * scene_radius
    } else if kind == POINT {
        4.0 * PI * PI * colour
    } else if kind == SPOT_CONE || kind == SPOT_SPHERE {
        let cos_cutoff = light.attenuation_cos.w.clamp(-1.0, 1.0);
        2.0 * PI * (1.0 - cos_cutoff) * PI * colour
    } else if kind == AREA_RECT || kind == AREA_DISC {
        let (x, y) = (
            light.direction_type.truncate().length(),
            light.attenuation_cos.truncate().length(),
        );
        let area = if kind == AREA_DISC { PI } else { 4.0 } * x * y;
        let faces = if light.color_exponent.w != 0.0 {
            2.0
        } else {
            1.0
        };
        PI * colour * area * faces
    } else {
        0.0
    }
}

/// Radians a spot's bounds reach past its cone.
const SPOT_EDGE_SLACK: f32 = 1e-3;

/// What a node knows of its lights.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightBounds {
    pub lo: Vec3,
    pub hi: Vec3,
    /// Their power ([`power`]).
    pub phi: f32,
    /// A cone around `axis` of half-angle θo holds every light's normal...
    pub axis: Vec3,
    pub cos_theta_o: f32,
    /// ...and each emits up to θe beyond its normal.
    pub cos_theta_e: f32,
    pub two_sided: bool,
    /// No light reaches a point farther than this from the box.
    pub range: f32,
    /// Constant, linear and quadratic attenuation for its lights together
    /// (a punctual light's intensity falls as 1 / (c + l d + q d²); an area
    /// light's as the inverse square, (0, 0, 1)): see [`blend_falloff`].
    pub falloff: Vec3,
}

/// The bounds of one light record, when it belongs in the tree.
pub fn bounds_of(light: &GpuLight) -> Option<LightBounds> {
    let kind = light.direction_type.w;
    let centre = light.position_range.truncate();
    let spot = kind == SPOT_CONE || kind == SPOT_SPHERE;
    if kind == AREA_RECT || kind == AREA_DISC {
        let (x, y) = (
            light.direction_type.truncate(),
            light.attenuation_cos.truncate(),
        );
        // It emits towards -(x × y) (include/area_light.glsl's winding).
        let reach = x.abs() + y.abs();
        return Some(LightBounds {
            lo: centre - reach,
            hi: centre + reach,
            phi: power(light, 1.0),
            axis: -x.cross(y).normalize_or(Vec3::Z),
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided: light.color_exponent.w > 0.5,
            range: f32::INFINITY,
            falloff: Vec3::Z,
        });
    }
    if kind != POINT && !spot {
        return None;
    }
    // A point light shines all round. A spot counts as a point light of its
    // intensity, as in pbrt-v4: its cone, not a smaller power, says where it
    // shines (a narrow spot is as bright inside its cone as a point light of
    // its colour); its cutoff is along the axis, and inside the cone a point
    // at distance d lies at least d cos(half-angle) along it.
    let cos_half = light.attenuation_cos.w.clamp(-1.0, 1.0);
    let (axis, cos_theta_o, cos_theta_e, range) = if spot {
        let range = if cos_half > 0.0 {
            light.position_range.w / cos_half
        } else {
            f32::INFINITY
        };
        // Nothing past the cone; a milliradian of slack so rounding at its
        // edge never rules out a point the shader's test lights.
        let axis = light.direction_type.truncate().normalize_or(Vec3::Z);
        (axis, cos_half, SPOT_EDGE_SLACK.cos(), range)
    } else {
        (Vec3::Z, -1.0, 0.0, light.position_range.w)
    };
    let as_point = GpuLight {
        direction_type: light.direction_type.truncate().extend(POINT),
        ..*light
    };
    Some(LightBounds {
        lo: centre,
        hi: centre,
        phi: power(&as_point, 1.0),
        axis,
        cos_theta_o,
        cos_theta_e,
        two_sided: false,
        range: if range.is_nan() { f32::INFINITY } else { range },
        falloff: light.attenuation_cos.truncate().max(Vec3::ZERO),
    })
}

impl LightBounds {
    /// The bounds of two nodes together.
    pub fn union(&self, other: &LightBounds) -> LightBounds {
        let (axis, cos_theta_o) = cone_union(
            (self.axis, self.cos_theta_o),
            (other.axis, other.cos_theta_o),
        );
        LightBounds {
            lo: self.lo.min(other.lo),
            hi: self.hi.max(other.hi),
            phi: self.phi + other.phi,
            axis,
            cos_theta_o,
            cos_theta_e: self.cos_theta_e.min(other.cos_theta_e),
            two_sided: self.two_sided || other.two_sided,
            range: self.range.max(other.range),
            falloff: blend_falloff(self, other),
        }
    }

    /// How much light the node's lights can send to `p`, up to a constant
    /// (pbrt-v4's `LightBounds::Importance` without the receiver's normal,
    /// so the BSDF-sampled side of MIS can evaluate it too, and with the
    /// lights' own attenuation in place of the inverse square, so a light
    /// of constant attenuation is not undersampled far away nor one of
    /// 1 / (1 + d²) oversampled close by), and zero beyond their range.
    /// `light_tree.glsl` computes the same, in the same order.
    #[cfg(test)]
    pub fn importance(&self, p: Vec3) -> f32 {
        let nearest = p.clamp(self.lo, self.hi);
        if (p - nearest).length_squared() > self.range * self.range {
            return 0.0;
        }
        let centre = 0.5 * (self.lo + self.hi);
        let half_diagonal = 0.5 * (self.hi - self.lo).length();
        let d2 = (p - centre).length_squared().max(half_diagonal);
        let to_p = (p - centre).normalize_or_zero();
        let mut cos_w = self.axis.dot(to_p);
        if self.two_sided {
            cos_w = cos_w.abs();
        }
        let sin_w = (1.0 - cos_w * cos_w).max(0.0).sqrt();
        // The directions from the box to p lie within θb of to_p.
        let r2 = half_diagonal * half_diagonal;
        let dist2 = (p - centre).length_squared();
        let cos_b = if dist2 < r2 {
            -1.0
        } else {
            (1.0 - r2 / dist2).max(0.0).sqrt()
        };
        let sin_b = (1.0 - cos_b * cos_b).max(0.0).sqrt();
        let sin_o = (1.0 - self.cos_theta_o * self.cos_theta_o).max(0.0).sqrt();
        // θx = max(0, θw - θo), then θ' = max(0, θx - θb).
        let (cos_x, sin_x) = sub_clamped((sin_w, cos_w), (sin_o, self.cos_theta_o));
        let (cos_p, _) = sub_clamped((sin_x, cos_x), (sin_b, cos_b));
        if cos_p <= self.cos_theta_e {
            return 0.0;
        }
        let f = self.falloff;
        self.phi * cos_p / (f.x + f.y * d2.sqrt() + f.z * d2).max(f32::MIN_POSITIVE)
    }
}

/// cos and sin of max(0, a - b) from the sines and cosines of a and b.
#[cfg(test)]
fn sub_clamped((sin_a, cos_a): (f32, f32), (sin_b, cos_b): (f32, f32)) -> (f32, f32) {
    if cos_a > cos_b {
        (1.0, 0.0)
    } else {
        (cos_a * cos_b + sin_a * sin_b, sin_a * cos_b - cos_a * sin_b)
    }
}

/// Two nodes' attenuation as one: each coefficient their power-weighted
/// mean. An estimate, not a bound (importance only steers samples; the
/// range and cone tests are what rule lights out), and a bound would go
/// badly wrong: the least coefficients of a spot with 1 / (1 + 0.05 d +
/// 0.01 d²) and an area light with 1 / d² are 1 / (0.05 d + 0.01 d²),
/// sixteen times either at d = 1, and such a node starves its siblings.
fn blend_falloff(a: &LightBounds, b: &LightBounds) -> Vec3 {
    let total = a.phi + b.phi;
    if total > 0.0 && total.is_finite() {
        (a.falloff * a.phi + b.falloff * b.phi) / total
    } else {
        0.5 * (a.falloff + b.falloff)
    }
}

/// The narrowest cone (axis, cos of its half-angle) holding two cones.
fn cone_union(a: (Vec3, f32), b: (Vec3, f32)) -> (Vec3, f32) {
    let theta_a = a.1.clamp(-1.0, 1.0).acos();
    let theta_b = b.1.clamp(-1.0, 1.0).acos();
    let theta_d = a.0.dot(b.0).clamp(-1.0, 1.0).acos();
    let pi = std::f32::consts::PI;
    if (theta_d + theta_b).min(pi) <= theta_a {
        return a;
    }
    if (theta_d + theta_a).min(pi) <= theta_b {
        return b;
    }
    let theta_o = 0.5 * (theta_a + theta_d + theta_b);
    if theta_o >= pi {
        return (a.0, -1.0);
    }
    let turn = a.0.cross(b.0);
    if turn.length_squared() == 0.0 {
        return (a.0, -1.0);
    }
    let axis = Quat::from_axis_angle(turn.normalize(), theta_o - theta_a) * a.0;
    (axis.normalize(), theta_o.cos())
}

/// A light record of type `kind` and grey colour `colour`, facing +y, with
/// a 60-degree spot cutoff: what the light-choice tests build tables of.
#[cfg(test)]
pub(crate) fn test_light(kind: f32, colour: f32) -> GpuLight {
    GpuLight {
        position_range: glam::Vec4::ZERO,
        direction_type: Vec3::Y.extend(kind),
        color_exponent: glam::Vec4::new(colour, colour, colour, 0.0),
        attenuation_cos: glam::Vec4::new(0.0, 0.0, 1.0, 0.5),
    }
}

#[cfg(test)]
mod tests {
    use super::test_light as light;
    use super::*;
    use glam::Vec4;

    #[test]
    fn powers_follow_the_path_tracers_units() {
        // A point light of colour 1: intensity π, power 4π².
        assert!((power(&light(POINT, 1.0), 1.0) - 4.0 * PI * PI).abs() < 1e-4);
        // A spot of half-angle 60° (cos 0.5) emits a quarter of that.
        assert!((power(&light(SPOT_CONE, 1.0), 1.0) - PI * PI).abs() < 1e-4);
        // A one-sided 2 x 1 rectangle of radiance 1 (half axes 1 and 0.5): π A.
        let rect = GpuLight {
            position_range: Vec4::ZERO,
            direction_type: Vec3::X.extend(AREA_RECT),
            color_exponent: Vec4::new(1.0, 1.0, 1.0, 0.0),
            attenuation_cos: (Vec3::Y * 0.5).extend(0.0),
        };
        assert!((power(&rect, 1.0) - 2.0 * PI).abs() < 1e-5);
        let two_sided = GpuLight {
            color_exponent: Vec4::new(1.0, 1.0, 1.0, 1.0),
            ..rect
        };
        assert!((power(&two_sided, 1.0) - 4.0 * PI).abs() < 1e-5);
        // A sun of colour 1 over a scene of radius 2: π · π 2².
        assert!((power(&light(SUN, 1.0), 2.0) - 4.0 * PI * PI).abs() < 1e-4);
    }
}
