//! Fitting a table of LTCs to a lobe family, as in Heitz et al.'s reference
//! fit: for each roughness (roughest first) and view angle (normal incidence
//! first), the lobe's integral, Fresnel moment and mean direction by
//! importance sampling, then the matrix's free entries by Nelder-Mead,
//! minimising the cubed difference between the LTC and the lobe sampled from
//! both (multiple importance sampling). Each fit starts from its neighbour's.

use crate::lobe::Lobe;
use crate::ltc::Ltc;
use crate::nelder_mead::minimise;
use crate::{column_cos, row_roughness, TABLE_SIZE};
use glam::{Mat3, Vec3};

/// Samples per axis for fit errors (the reference fit's 32).
pub const SAMPLES: usize = 32;
/// Samples per axis for a lobe's moments: its integral is the directional
/// albedo energy compensation divides by (`energy`), so it must hold to
/// 1e-4, which the fit's 32 x 32 samples do not near grazing.
pub const MOMENT_SAMPLES: usize = 256;

/// One table entry: the inverse matrix normalised to a middle entry of 1,
/// as `(a, b, c, d)` of `[[a, 0, b], [0, 1, 0], [c, 0, d]]` (rows), the
/// lobe's integral, and its Fresnel moment `integral of lobe * (1 - v.h)^5`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Entry {
    /// Entries of the normalised inverse.
    pub inverse: [f32; 4],
    /// Integral of the lobe over the sphere.
    pub magnitude: f32,
    /// Integral of the lobe times `(1 - v.h)^5`.
    pub fresnel: f32,
}

impl Entry {
    /// The entry's distribution as an [`Ltc`] scaled by its magnitude.
    pub fn ltc(&self) -> Ltc {
        let [a, b, c, d] = self.inverse;
        let inverse = Mat3::from_cols(Vec3::new(a, 0.0, c), Vec3::Y, Vec3::new(b, 0.0, d));
        Ltc::new(inverse.inverse(), self.magnitude)
    }
}

/// The lobe's integral, Fresnel moment and mean direction seen from `v`.
pub fn moments<L: Lobe>(lobe: &L, v: Vec3) -> (f32, f32, Vec3) {
    let (mut magnitude, mut fresnel, mut direction) = (0.0f64, 0.0f64, Vec3::ZERO);
    for j in 0..MOMENT_SAMPLES {
        for i in 0..MOMENT_SAMPLES {
            let u1 = (i as f32 + 0.5) / MOMENT_SAMPLES as f32;
            let u2 = (j as f32 + 0.5) / MOMENT_SAMPLES as f32;
            let l = lobe.sample(v, u1, u2);
            let (value, pdf) = lobe.eval(v, l);
            if pdf <= 0.0 {
                continue;
            }
            let weight = value / pdf;
            let h = (v + l).normalize();
            magnitude += weight as f64;
            fresnel += (weight * (1.0 - v.dot(h).max(0.0)).powi(5)) as f64;
            direction += l * weight;
        }
    }
    let count = (MOMENT_SAMPLES * MOMENT_SAMPLES) as f64;
    let direction = Vec3::new(direction.x, 0.0, direction.z).normalize_or(Vec3::Z);
    (
        (magnitude / count) as f32,
        (fresnel / count) as f32,
        direction,
    )
}

/// The mean cubed difference between `ltc` (of magnitude 1) and the lobe
/// divided by its `magnitude`, each sampled from both. Comparing the
/// normalised lobe keeps the error's scale, and so the minimiser's stopping
/// tolerance, the same for dim lobes (sharp Blinn-Phong highlights integrate
/// to a few percent) and bright ones.
fn error<L: Lobe>(ltc: &Ltc, lobe: &L, magnitude: f32, v: Vec3) -> f32 {
    let mut sum = 0.0f64;
    for j in 0..SAMPLES {
        for i in 0..SAMPLES {
            let u1 = (i as f32 + 0.5) / SAMPLES as f32;
            let u2 = (j as f32 + 0.5) / SAMPLES as f32;
            for l in [ltc.sample(u1, u2), lobe.sample(v, u1, u2)] {
                let (value, pdf_lobe) = lobe.eval(v, l);
                let fitted = ltc.eval(l);
                let pdf_ltc = fitted;
                let difference = (value / magnitude - fitted).abs() as f64;
                let pdf = (pdf_ltc + pdf_lobe) as f64;
                if pdf > 0.0 {
                    sum += difference.powi(3) / pdf;
                }
            }
        }
    }
    (sum / (SAMPLES * SAMPLES) as f64) as f32
}

/// The matrix `[x y z] * [[m11, 0, m13], [0, m22, 0], [0, 0, 1]]`.
fn matrix(basis: Mat3, m11: f32, m22: f32, m13: f32) -> Mat3 {
    basis
        * Mat3::from_cols(
            Vec3::new(m11, 0.0, 0.0),
            Vec3::new(0.0, m22, 0.0),
            Vec3::new(m13, 0.0, 1.0),
        )
}

/// Fits the table for `lobe_at(roughness)`: entry `row * TABLE_SIZE + column`
/// holds roughness [`row_roughness`]`(row)` seen at [`column_cos`]`(column)`.
pub fn fit_table<L: Lobe>(lobe_at: impl Fn(f32) -> L) -> Vec<Entry> {
    let n = TABLE_SIZE;
    let mut table = vec![
        Entry {
            inverse: [1.0, 0.0, 0.0, 1.0],
            magnitude: 0.0,
            fresnel: 0.0,
        };
        n * n
    ];
    // (m11, m22) of the previous roughness at normal incidence.
    let mut previous_normal = (1.0f32, 1.0f32);
    for row in (0..n).rev() {
        let lobe = lobe_at(row_roughness(row));
        // The previous column's (m11, m22, m13): each fit starts from its neighbour's.
        let mut last = [1.0f32, 1.0, 0.0];
        for column in 0..n {
            let cos_v = column_cos(column);
            let v = Vec3::new((1.0 - cos_v * cos_v).sqrt(), 0.0, cos_v);
            let (magnitude, fresnel, mean) = moments(&lobe, v);
            let isotropic = column == 0;
            let (basis, start) = if isotropic {
                (Mat3::IDENTITY, [previous_normal.0, previous_normal.1, 0.0])
            } else {
                let x = Vec3::new(mean.z, 0.0, -mean.x);
                (Mat3::from_cols(x, Vec3::Y, mean), last)
            };
            let params = |p: &[f32; 3]| -> (f32, f32, f32) {
                let m11 = p[0].max(1e-7);
                if isotropic {
                    (m11, m11, 0.0)
                } else {
                    (m11, p[1].max(1e-7), p[2])
                }
            };
            let best = minimise(
                |p| {
                    let (m11, m22, m13) = params(p);
                    error(
                        &Ltc::new(matrix(basis, m11, m22, m13), 1.0),
                        &lobe,
                        magnitude,
                        v,
                    )
                },
                start,
                0.05,
                1e-5,
                100,
            );
            let (m11, m22, m13) = params(&best);
            if isotropic {
                previous_normal = (m11, m22);
            }
            last = [m11, m22, m13];
            let inverse = matrix(basis, m11, m22, m13).inverse();
            let scale = inverse.y_axis.y;
            table[row * n + column] = Entry {
                inverse: [
                    inverse.x_axis.x / scale,
                    inverse.z_axis.x / scale,
                    inverse.x_axis.z / scale,
                    inverse.z_axis.z / scale,
                ],
                magnitude,
                fresnel,
            };
        }
    }
    table
}
