//! The lobes the raster passes shade area lights with, each as "BRDF times
//! cosine" with the normal along +Z: GGX as `cook_torrance` in
//! `shaders/include/brdf.glsl` evaluates it (Fresnel left out: the table
//! carries it separately), and the unnormalised Blinn-Phong highlight
//! `(N.H)^n (N.L)` of `blinn_phong` there.

use glam::Vec3;
use std::f32::consts::PI;

/// A lobe that can be evaluated and importance-sampled.
pub trait Lobe {
    /// The lobe's value (BRDF times cos) towards `l` seen from `v`, and the
    /// density with which [`Lobe::sample`] picks `l`.
    fn eval(&self, v: Vec3, l: Vec3) -> (f32, f32);
    /// A direction drawn from uniform numbers `u1`, `u2`.
    fn sample(&self, v: Vec3, u1: f32, u2: f32) -> Vec3;
}

/// GGX with height-correlated Smith visibility and no Fresnel, times cos.
#[derive(Debug, Clone, Copy)]
pub struct Ggx {
    /// alpha = roughness².
    pub alpha: f32,
}

/// Blinn-Phong `(N.H)^n (N.L)`, unnormalised as the raster passes shade it.
#[derive(Debug, Clone, Copy)]
pub struct BlinnPhong {
    /// The exponent (MTL `Ns`).
    pub exponent: f32,
}

/// `l` mirrored about the half vector `h` from `v`.
fn reflect(v: Vec3, h: Vec3) -> Vec3 {
    2.0 * v.dot(h) * h - v
}

/// A unit vector at polar cosine `cos_theta` and azimuth `phi` about +Z.
fn spherical(cos_theta: f32, phi: f32) -> Vec3 {
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin_theta * phi.cos(), sin_theta * phi.sin(), cos_theta)
}

impl Lobe for Ggx {
    fn eval(&self, v: Vec3, l: Vec3) -> (f32, f32) {
        if l.z <= 0.0 || v.z <= 0.0 {
            return (0.0, 0.0);
        }
        let h = (v + l).normalize();
        let a2 = self.alpha * self.alpha;
        let q = h.z * h.z * (a2 - 1.0) + 1.0;
        let d = a2 / (PI * q * q);
        let (ndl, ndv) = (l.z, v.z.max(1e-4));
        let vis = 0.5
            / (ndl * (ndv * ndv * (1.0 - a2) + a2).sqrt()
                + ndv * (ndl * ndl * (1.0 - a2) + a2).sqrt());
        // Visible normals: G1(v) D(h) / (4 N.V), so value / pdf = G2 / G1(v) <= 1.
        let masking = 2.0 * ndv / (ndv + (a2 + (1.0 - a2) * ndv * ndv).sqrt());
        let pdf = masking * d / (4.0 * ndv);
        (d * vis * ndl, pdf)
    }

    /// A normal visible from `v` (Heitz, "Sampling the GGX Distribution of
    /// Visible Normals", 2018) and `v` reflected about it. Sampling `D cos`
    /// instead gives weights that grow as `1 / N.H` at grazing views, with
    /// unbounded variance: the table's integrals were 4% low there.
    fn sample(&self, v: Vec3, u1: f32, u2: f32) -> Vec3 {
        let a = self.alpha;
        let stretched = Vec3::new(a * v.x, a * v.y, v.z.max(1e-4)).normalize();
        let len2 = stretched.x * stretched.x + stretched.y * stretched.y;
        let t1 = if len2 > 0.0 {
            Vec3::new(-stretched.y, stretched.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = stretched.cross(t1);
        let r = u1.sqrt();
        let phi = 2.0 * PI * u2;
        let p1 = r * phi.cos();
        let s = 0.5 * (1.0 + stretched.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * phi.sin();
        let normal = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * stretched;
        let h = Vec3::new(a * normal.x, a * normal.y, normal.z.max(1e-6)).normalize();
        reflect(v, h)
    }
}

impl Lobe for BlinnPhong {
    fn eval(&self, v: Vec3, l: Vec3) -> (f32, f32) {
        if l.z <= 0.0 || v.z <= 0.0 {
            return (0.0, 0.0);
        }
        let h = (v + l).normalize();
        let n = self.exponent;
        let ndh = h.z.max(0.0);
        let value = ndh.powf(n) * l.z;
        let pdf = (n + 1.0) / (2.0 * PI) * ndh.powf(n) / (4.0 * v.dot(h).max(1e-7));
        (value, pdf)
    }

    fn sample(&self, v: Vec3, u1: f32, u2: f32) -> Vec3 {
        let cos_theta = u1.powf(1.0 / (self.exponent + 1.0));
        reflect(v, spherical(cos_theta, 2.0 * PI * u2))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Sampling and the reported density agree: the density integrates to
    /// the share of samples above the horizon (estimated by uniform
    /// hemisphere quadrature), and E[value / pdf] equals the value's
    /// integral by quadrature.
    fn check<L: Lobe>(lobe: &L, v: Vec3) {
        let n = 400;
        let (mut density, mut integral) = (0.0f64, 0.0f64);
        for j in 0..n {
            for i in 0..n {
                let cos_theta = (j as f32 + 0.5) / n as f32;
                let l = spherical(cos_theta, 2.0 * PI * (i as f32 + 0.5) / n as f32);
                let (value, pdf) = lobe.eval(v, l);
                let weight = 2.0 * PI as f64 / (n * n) as f64;
                density += pdf as f64 * weight;
                integral += value as f64 * weight;
            }
        }
        let m = 256;
        let (mut estimate, mut above) = (0.0f64, 0usize);
        for j in 0..m {
            for i in 0..m {
                let l = lobe.sample(v, (i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                let (value, pdf) = lobe.eval(v, l);
                if l.z > 0.0 && pdf > 0.0 {
                    estimate += (value / pdf) as f64;
                    above += 1;
                }
            }
        }
        let estimate = estimate / (m * m) as f64;
        let share = above as f64 / (m * m) as f64;
        assert!(
            (density - share).abs() < 0.02,
            "density {density} vs share {share}"
        );
        assert!(
            (estimate - integral).abs() <= 0.02 * integral,
            "estimate {estimate} vs integral {integral}"
        );
    }

    #[test]
    fn ggx_samples_match_its_density() {
        for (alpha, cos_v) in [(0.5f32, 0.9f32), (0.2, 0.5), (0.9, 0.2)] {
            let v = spherical(cos_v, 0.0);
            check(&Ggx { alpha }, v);
        }
    }

    #[test]
    fn blinn_phong_samples_match_its_density() {
        for (exponent, cos_v) in [(1.0f32, 0.9f32), (10.0, 0.5), (32.0, 0.8)] {
            let v = spherical(cos_v, 0.0);
            check(&BlinnPhong { exponent }, v);
        }
    }
}
