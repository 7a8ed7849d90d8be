//! One linearly transformed cosine: the clamped cosine about +Z warped by a
//! matrix `m` (directions `normalize(m * l_o)`), scaled by the lobe's integral.

use glam::{Mat3, Vec3};
use std::f32::consts::PI;

/// A warped cosine distribution with its scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ltc {
    /// Cosine space to lobe space.
    pub m: Mat3,
    /// Lobe space to cosine space.
    pub inverse: Mat3,
    /// `|det(inverse)|`.
    det_inverse: f32,
    /// The lobe's integral over the sphere (its directional albedo).
    pub magnitude: f32,
}

impl Ltc {
    /// The distribution of `m`, scaled by `magnitude`.
    pub fn new(m: Mat3, magnitude: f32) -> Self {
        let inverse = m.inverse();
        Self {
            m,
            inverse,
            det_inverse: inverse.determinant().abs(),
            magnitude,
        }
    }

    /// The density towards unit `l`, times the magnitude: the clamped cosine
    /// `max(z, 0) / pi` at `normalize(inverse * l)` times the Jacobian
    /// `|det(inverse)| / |inverse * l|³`.
    pub fn eval(&self, l: Vec3) -> f32 {
        let warped = self.inverse * l;
        let length = warped.length();
        let lo = warped / length;
        let cosine = lo.z.max(0.0) / PI;
        self.magnitude * cosine * self.det_inverse / (length * length * length)
    }

    /// A direction drawn from the distribution (cosine-weighted, then warped).
    pub fn sample(&self, u1: f32, u2: f32) -> Vec3 {
        let r = u1.sqrt();
        let phi = 2.0 * PI * u2;
        let lo = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt());
        (self.m * lo).normalize()
    }

    /// The distribution's integral over the polygon `vertices` (lobe space,
    /// the shading point at the origin), without the magnitude: the cosine's
    /// integral over the polygon transformed into cosine space, signed by the
    /// winding of the transformed polygon about +Z.
    pub fn polygon_integral(&self, vertices: &[Vec3]) -> f32 {
        let warped: Vec<Vec3> = vertices.iter().map(|&p| self.inverse * p).collect();
        crate::polygon::cosine_integral(&warped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The integral of `f` over the sphere by an n x n quadrature in (z, phi).
    fn over_sphere<T: std::ops::Add<Output = T> + std::ops::Mul<f32, Output = T>>(
        n: usize,
        zero: T,
        f: impl Fn(Vec3) -> T,
    ) -> T {
        let cell = 4.0 * PI / (n * n) as f32;
        let mut sum = zero;
        for j in 0..n {
            for i in 0..n {
                let z = -1.0 + 2.0 * (j as f32 + 0.5) / n as f32;
                let phi = 2.0 * PI * (i as f32 + 0.5) / n as f32;
                let s = (1.0 - z * z).sqrt();
                sum = sum + f(Vec3::new(s * phi.cos(), s * phi.sin(), z)) * cell;
            }
        }
        sum
    }

    #[test]
    fn a_warped_cosine_integrates_to_its_magnitude_and_samples_as_it_evaluates() {
        let m = Mat3::from_cols(
            Vec3::new(0.4, 0.0, 0.1),
            Vec3::new(0.0, 0.5, 0.0),
            Vec3::new(0.3, 0.0, 1.0),
        );
        let ltc = Ltc::new(m, 0.7);
        let total = over_sphere(600, 0.0f32, |l| ltc.eval(l));
        assert!((total - 0.7).abs() < 0.005, "{total}");
        // The mean of samples equals the density-weighted mean direction.
        let k = 300;
        let mut mean = Vec3::ZERO;
        for j in 0..k {
            for i in 0..k {
                mean += ltc.sample((i as f32 + 0.5) / k as f32, (j as f32 + 0.5) / k as f32);
            }
        }
        mean /= (k * k) as f32;
        let expected = over_sphere(600, Vec3::ZERO, |l| l * (ltc.eval(l) / 0.7));
        assert!((mean - expected).length() < 0.01, "{mean} vs {expected}");
    }
}
