//! Where scene values enter the GPU, they are made finite and bounded, so a
//! NaN or infinity in one input (a light's colour, a material, a vertex)
//! cannot reach the shaders and spread: docs/stability.md lists each rule.

use glam::{Vec3, Vec4};

/// The largest radiance, light colour or emission accepted per channel
/// (larger values and +inf are clamped to it): shader arithmetic on it stays
/// finite in f32, and every pass clamps its output to [`HDR_PASS_MAX`].
pub const RADIANCE_MAX: f32 = 1e30;

/// The most one pass writes to an RGBA16F HDR channel (`HDR_PASS_MAX` in
/// `shaders/include/hdr.glsl`): seven additive passes stay below the
/// format's 65504.
pub const HDR_PASS_MAX: f32 = 8192.0;

// Seven passes at the per-pass maximum stay inside RGBA16F.
const _: () = assert!(7.0 * HDR_PASS_MAX < 65504.0);

/// A non-negative quantity: NaN and negatives become 0, +inf and values above
/// `max` become `max`.
pub fn bounded(x: f32, max: f32) -> f32 {
    if x.is_nan() {
        0.0
    } else {
        x.clamp(0.0, max)
    }
}

/// A colour or radiance: NaN and negative channels become 0, +inf becomes
/// [`RADIANCE_MAX`], and a colour whose brightest channel exceeds it is scaled
/// down as a whole, so it keeps its hue (`finite_clamped` in `hdr.glsl`).
pub fn radiance(c: Vec3) -> Vec3 {
    let c = Vec3::new(
        bounded(c.x, f32::INFINITY),
        bounded(c.y, f32::INFINITY),
        bounded(c.z, f32::INFINITY),
    );
    let c = Vec3::select(c.cmpeq(Vec3::INFINITY), Vec3::splat(RADIANCE_MAX), c);
    let peak = c.max_element();
    if peak > RADIANCE_MAX {
        c * (RADIANCE_MAX / peak)
    } else {
        c
    }
}

/// An RGBA reflectance or base colour: RGB as [`radiance`], alpha in [0, 1].
pub fn colour_alpha(c: Vec4) -> Vec4 {
    radiance(c.truncate()).extend(bounded(c.w, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn non_finite_and_out_of_range_values_are_bounded() {
        assert_eq!(bounded(f32::NAN, 5.0), 0.0);
        assert_eq!(bounded(f32::INFINITY, 5.0), 5.0);
        assert_eq!(bounded(f32::NEG_INFINITY, 5.0), 0.0);
        assert_eq!(bounded(-1.0, 5.0), 0.0);
        assert_eq!(bounded(1e-30, 5.0), 1e-30);
        // Too bright: scaled as a whole, so the hue stays (2 : 1e38 keeps its ratio).
        let scaled = radiance(Vec3::new(f32::NAN, 1e38, 2e30));
        assert_eq!(scaled.x, 0.0);
        assert!((scaled.y / RADIANCE_MAX - 1.0).abs() < 1e-6, "{scaled}");
        assert!(
            (scaled.z / (2e-8 * RADIANCE_MAX) - 1.0).abs() < 1e-6,
            "{scaled}"
        );
        assert_eq!(
            radiance(Vec3::new(-1.0, 3.0, 2.0)),
            Vec3::new(0.0, 3.0, 2.0)
        );
        assert_eq!(
            colour_alpha(Vec4::new(0.5, f32::INFINITY, -2.0, 7.0)),
            Vec4::new(0.5, RADIANCE_MAX, 0.0, 1.0)
        );
    }
}
