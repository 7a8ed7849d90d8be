//! The path tracer's glass and coatings on the CPU: the exact unpolarised
//! Fresnel reflectance of a smooth dielectric interface, its hemispherical
//! (diffuse) average, and the parameters of a Fresnel coat over a Lambert base
//! (`shaders/pathtrace/dielectric.glsl` and `bsdf.glsl` use them; docs/pathtrace.md
//! says where the energy goes).

use glam::Vec3;

/// Fresnel reflectance of unpolarised light meeting a smooth interface at
/// `cos_i` (0..1) to the normal, going from index n_i to n_t with
/// `eta` = n_i / n_t; 1 past the critical angle.
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// The cosine-weighted hemispherical average of Fresnel reflectance,
/// ∫ F(cos θ) 2 cos θ dcos θ, for light arriving from the outside (index 1)
/// of a medium of index `ior`: the fraction of diffuse light outside that an
/// interface reflects. Simpson's rule on 2,048 intervals; the integrand is
/// smooth from this side (no total internal reflection).
pub fn diffuse_reflectance_outside(ior: f64) -> f64 {
    const N: usize = 2048;
    let f = |c: f64| fresnel_dielectric(c, 1.0 / ior) * 2.0 * c;
    let h = 1.0 / N as f64;
    let sum: f64 = (0..=N)
        .map(|i| {
            let w = if i == 0 || i == N {
                1.0
            } else if i % 2 == 1 {
                4.0
            } else {
                2.0
            };
            w * f(i as f64 * h)
        })
        .sum();
    sum * h / 3.0
}

/// The same average for diffuse light inside a medium of index `ior` meeting
/// its boundary with air: 1 − (1 − F̄_outside) / ior², since a surface passes
/// the same power both ways and radiance squeezes by ior² on the way in. For
/// glass (1.5) about 0.596: most light scattered inside reflects back.
pub fn diffuse_reflectance_inside(ior: f64) -> f64 {
    1.0 - (1.0 - diffuse_reflectance_outside(ior)) / (ior * ior)
}

/// A Lambert base under a smooth dielectric coat (MTL `illum 5`: "Fresnel
/// on"): `Ks` is the coat's reflectance at normal incidence.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coat {
    /// The coat's index, the one whose normal-incidence reflectance
    /// ((n − 1) / (n + 1))² is the largest channel of `Ks`.
    pub ior: f32,
    /// `Ks` over that reflectance: the colour of the coat's reflection (1 for
    /// a grey `Ks`; below 1 the coat absorbs the rest).
    pub tint: Vec3,
    /// [`diffuse_reflectance_inside`] the coat: the share of light scattered
    /// by the base that the coat sends back down.
    pub internal_reflectance: f32,
}

impl Coat {
    /// The coat whose normal-incidence reflectance is `ks`. A black `ks` is no
    /// coat (index 1): the base shows as plain Lambert.
    pub fn from_specular(ks: Vec3) -> Self {
        let f0 = f64::from(ks.max_element()).clamp(0.0, 0.999);
        if f0 <= 0.0 || ks.is_nan() {
            return Self {
                ior: 1.0,
                tint: Vec3::ZERO,
                internal_reflectance: 0.0,
            };
        }
        let r = f0.sqrt();
        let ior = (1.0 + r) / (1.0 - r);
        Self {
            ior: ior as f32,
            tint: (ks / f0 as f32).clamp(Vec3::ZERO, Vec3::ONE),
            internal_reflectance: diffuse_reflectance_inside(ior) as f32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_and_total_internal_reflection() {
        for n in [1.0001, 1.33, 1.5, 2.4, 3.0] {
            let r0: f64 = ((n - 1.0) / (n + 1.0)) * ((n - 1.0) / (n + 1.0));
            assert!((fresnel_dielectric(1.0, 1.0 / n) - r0).abs() < 1e-12);
            assert!((fresnel_dielectric(1.0, n) - r0).abs() < 1e-12);
            let critical = (1.0 / n).asin();
            assert_eq!(fresnel_dielectric(critical.cos() - 1e-9, n), 1.0);
            assert!(fresnel_dielectric((critical - 1e-6).cos(), n) < 1.0);
        }
    }

    /// Against a midpoint sum on a million intervals, the limit at index 1,
    /// and the values usually quoted for glass (about 0.092 outside, 0.596
    /// inside) and water (about 0.066 outside).
    #[test]
    fn diffuse_reflectance_matches_brute_force_and_quoted_values() {
        assert!(diffuse_reflectance_outside(1.0).abs() < 1e-12);
        for (n, quoted_outside) in [(1.5, 0.092), (1.33, 0.066)] {
            let steps = 1_000_000;
            let brute: f64 = (0..steps)
                .map(|i| {
                    let c = (i as f64 + 0.5) / steps as f64;
                    fresnel_dielectric(c, 1.0 / n) * 2.0 * c / steps as f64
                })
                .sum();
            let outside = diffuse_reflectance_outside(n);
            assert!((outside - brute).abs() < 1e-9, "{outside} vs {brute}");
            assert!((outside - quoted_outside).abs() < 1e-3, "{outside}");
        }
        let inside = diffuse_reflectance_inside(1.5);
        assert!((inside - 0.596).abs() < 1e-3, "{inside}");
    }

    /// Integrating the inside directly (with its total internal reflection)
    /// agrees with the reciprocity form to 1e-5.
    #[test]
    fn inside_reflectance_by_reciprocity_matches_direct_integration() {
        for n in [1.2, 1.5, 2.0] {
            let steps = 400_000;
            let direct: f64 = (0..steps)
                .map(|i| {
                    let c = (i as f64 + 0.5) / steps as f64;
                    fresnel_dielectric(c, n) * 2.0 * c / steps as f64
                })
                .sum();
            let diff = (direct - diffuse_reflectance_inside(n)).abs();
            assert!(diff < 1e-5, "n {n}: {diff}");
        }
    }

    #[test]
    fn coat_index_reproduces_ks_at_normal_incidence() {
        let coat = Coat::from_specular(Vec3::new(0.04, 0.02, 0.01));
        assert!((coat.ior - 1.5).abs() < 1e-5, "{}", coat.ior);
        assert!((coat.tint - Vec3::new(1.0, 0.5, 0.25)).abs().max_element() < 1e-5);
        let mirror = Coat::from_specular(Vec3::splat(0.95));
        let r0 = fresnel_dielectric(1.0, 1.0 / f64::from(mirror.ior));
        assert!((r0 - 0.95).abs() < 1e-5, "{r0}");
        assert_eq!(Coat::from_specular(Vec3::ZERO).ior, 1.0);
    }
}
