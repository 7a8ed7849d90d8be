//! LDR-FLIP on float images (Andersson et al. 2020): both images in YCxCz,
//! filtered by the eye's contrast sensitivity per channel and compared in
//! Hunt-adjusted CIELAB (HyAB); their edges and points found with Gaussian
//! derivatives and compared; the colour error raised to one minus the
//! feature error. The steps, filters, constants and order of operations are
//! the reference implementation's (NVlabs/flip, `FLIP.h`, read for this),
//! so the error maps agree with `flip-evaluator` to float rounding.

use rayon::prelude::*;

use super::colour::{
    hyab, linear_rgb_to_hunt_lab, linear_rgb_to_xyz, xyz_to_linear_rgb, xyz_to_ycxcz, ycxcz_to_xyz,
};

/// The colour difference's exponent (q_c).
const COLOUR_EXPONENT: f32 = 0.7;
/// Where the colour difference's linear remapping bends, as a fraction of the
/// largest difference (p_c), and the error it maps there (p_t).
const COLOUR_KNEE: f32 = 0.4;
const COLOUR_KNEE_ERROR: f32 = 0.95;
/// The feature detectors' width in degrees of visual angle (w).
const FEATURE_WIDTH: f32 = 0.082;
/// The feature difference's exponent (q_f).
const FEATURE_EXPONENT: f32 = 0.5;

/// The contrast sensitivity functions, one per YCxCz channel, each a sum of
/// two Gaussians a1 √(π/b1) e^(-π² x²/b1) + a2 √(π/b2) e^(-π² x²/b2) over
/// visual angle x in degrees.
const CSF_A1: [f32; 3] = [1.0, 1.0, 34.1];
const CSF_B1: [f32; 3] = [0.0047, 0.0053, 0.04];
const CSF_A2: [f32; 3] = [0.0, 0.0, 13.5];
const CSF_B2: [f32; 3] = [1.0e-5, 1.0e-5, 0.025];

use std::f32::consts::PI;

fn gaussian(x2: f32, a: f32, b: f32) -> f32 {
    a * (PI / b).sqrt() * (-(PI * PI) * x2 / b).exp()
}

/// The square root of a Gaussian's weight: the blue-yellow filter is a sum
/// of two 2D Gaussians, applied as two separable passes whose results add.
fn gaussian_sqrt(x2: f32, a: f32, b: f32) -> f32 {
    (a * (PI / b).sqrt()).sqrt() * (-(PI * PI) * x2 / b).exp()
}

/// The separable contrast-sensitivity kernels: (Y, Cx) weights, and the
/// blue-yellow channel's two Gaussians.
struct SpatialFilter {
    y_cx: Vec<[f32; 2]>,
    cz: Vec<[f32; 2]>,
}

impl SpatialFilter {
    fn new(ppd: f32) -> Self {
        let widest = CSF_B1.into_iter().chain(CSF_B2).fold(0.0f32, f32::max);
        let radius = (3.0 * (widest / (2.0 * (PI * PI))).sqrt() * ppd).ceil() as i32;
        let delta = 1.0 / ppd;
        let (mut y_cx, mut cz) = (Vec::new(), Vec::new());
        let (mut sum_y_cx, mut sum_cz) = ([0.0f32; 2], [0.0f32; 2]);
        for i in -radius..=radius {
            let x = i as f32 * delta;
            let x2 = x * x;
            let w = [
                gaussian(x2, CSF_A1[0], CSF_B1[0]),
                gaussian(x2, CSF_A1[1], CSF_B1[1]),
            ];
            let z = [
                gaussian_sqrt(x2, CSF_A1[2], CSF_B1[2]),
                gaussian_sqrt(x2, CSF_A2[2], CSF_B2[2]),
            ];
            for k in 0..2 {
                sum_y_cx[k] += w[k];
                sum_cz[k] += z[k];
            }
            y_cx.push(w);
            cz.push(z);
        }
        let norm_y_cx = [1.0 / sum_y_cx[0], 1.0 / sum_y_cx[1]];
        let norm_cz = 1.0 / (sum_cz[0] * sum_cz[0] + sum_cz[1] * sum_cz[1]).sqrt();
        for w in &mut y_cx {
            *w = [w[0] * norm_y_cx[0], w[1] * norm_y_cx[1]];
        }
        for z in &mut cz {
            *z = z.map(|v| v * norm_cz);
        }
        Self { y_cx, cz }
    }

    fn radius(&self) -> i32 {
        self.y_cx.len() as i32 / 2
    }
}

/// The separable edge and point detectors: a Gaussian, its first derivative
/// (positive and negative weights each summing to ±1) and its second.
struct FeatureFilter {
    weights: Vec<[f32; 3]>,
}

impl FeatureFilter {
    fn new(ppd: f32) -> Self {
        let sigma = 0.5 * FEATURE_WIDTH * ppd;
        let radius = (3.0 * sigma).ceil() as i32;
        let mut weights = Vec::new();
        let mut sum = 0.0f32;
        let (mut d_positive, mut d_negative) = (0.0f32, 0.0f32);
        let (mut dd_positive, mut dd_negative) = (0.0f32, 0.0f32);
        for i in -radius..=radius {
            let x = i as f32;
            let g = (-(x * x) / (2.0 * sigma * sigma)).exp();
            sum += g;
            let dg = -x * g;
            if dg > 0.0 {
                d_positive += dg;
            } else {
                d_negative -= dg;
            }
            let ddg = (x * x / (sigma * sigma) - 1.0) * g;
            if ddg > 0.0 {
                dd_positive += ddg;
            } else {
                dd_negative -= ddg;
            }
            weights.push([g, dg, ddg]);
        }
        for [g, dg, ddg] in &mut weights {
            *g /= sum;
            *dg /= if *dg > 0.0 { d_positive } else { d_negative };
            *ddg /= if *ddg > 0.0 { dd_positive } else { dd_negative };
        }
        Self { weights }
    }

    fn radius(&self) -> i32 {
        self.weights.len() as i32 / 2
    }
}

/// One image as FLIP sees it: YCxCz per pixel, row by row.
struct Opponent<'a> {
    width: usize,
    height: usize,
    pixels: &'a [[f32; 3]],
}

impl Opponent<'_> {
    /// The pixel at (x, y), the edge pixel for x beyond the image.
    fn clamped(&self, x: i32, y: usize) -> [f32; 3] {
        let x = x.clamp(0, self.width as i32 - 1) as usize;
        self.pixels[y * self.width + x]
    }
}

/// Runs `pixel(x, y)` for every pixel, rows in parallel.
fn per_pixel<T: Send + Copy + Default>(
    width: usize,
    height: usize,
    pixel: impl Fn(usize, usize) -> T + Sync,
) -> Vec<T> {
    let mut out = vec![T::default(); width * height];
    out.par_chunks_mut(width.max(1))
        .enumerate()
        .for_each(|(y, row)| {
            for (x, value) in row.iter_mut().enumerate() {
                *value = pixel(x, y);
            }
        });
    out
}

/// The clamped row index `y + dy`.
fn row(y: usize, dy: i32, height: usize) -> usize {
    (y as i32 + dy).clamp(0, height as i32 - 1) as usize
}

/// The largest remapped colour difference FLIP expects: between pure green
/// and pure blue, raised to the colour exponent.
fn largest_colour_difference() -> f32 {
    hyab(
        linear_rgb_to_hunt_lab([0.0, 1.0, 0.0]),
        linear_rgb_to_hunt_lab([0.0, 0.0, 1.0]),
    )
    .powf(COLOUR_EXPONENT)
}

/// The per-pixel colour difference after contrast-sensitivity filtering, in
/// [0, 1].
fn colour_difference(reference: &Opponent, test: &Opponent, filter: &SpatialFilter) -> Vec<f32> {
    let (w, h, r) = (reference.width, reference.height, filter.radius());
    // Horizontal pass: (Y, Cx) and the two blue-yellow Gaussians, per image.
    let horizontal = |image: &Opponent| {
        per_pixel(w, h, |x, y| {
            let (mut y_cx, mut cz) = ([0.0f32; 2], [0.0f32; 2]);
            for i in -r..=r {
                let c = image.clamped(x as i32 + i, y);
                let (wy, wz) = (filter.y_cx[(i + r) as usize], filter.cz[(i + r) as usize]);
                y_cx[0] += wy[0] * c[0];
                y_cx[1] += wy[1] * c[1];
                cz[0] += wz[0] * c[2];
                cz[1] += wz[1] * c[2];
            }
            [y_cx[0], y_cx[1], cz[0], cz[1]]
        })
    };
    let (href, htest) = (horizontal(reference), horizontal(test));
    let cmax = largest_colour_difference();
    let knee = COLOUR_KNEE * cmax;
    per_pixel(w, h, |x, y| {
        let vertical = |rows: &[[f32; 4]]| {
            let mut sum = [0.0f32; 4];
            for i in -r..=r {
                let c = rows[row(y, i, h) * w + x];
                let (wy, wz) = (filter.y_cx[(i + r) as usize], filter.cz[(i + r) as usize]);
                sum[0] += wy[0] * c[0];
                sum[1] += wy[1] * c[1];
                sum[2] += wz[0] * c[2];
                sum[3] += wz[1] * c[3];
            }
            let ycxcz = [sum[0], sum[1], sum[2] + sum[3]];
            linear_rgb_to_hunt_lab(xyz_to_linear_rgb(ycxcz_to_xyz(ycxcz)))
        };
        let difference = hyab(vertical(&href), vertical(&htest)).powf(COLOUR_EXPONENT);
        if difference < knee {
            difference * (COLOUR_KNEE_ERROR / knee)
        } else {
            COLOUR_KNEE_ERROR + ((difference - knee) / (cmax - knee)) * (1.0 - COLOUR_KNEE_ERROR)
        }
    })
}

/// The per-pixel feature difference (edges and points of lightness), in
/// [0, 1].
fn feature_difference(reference: &Opponent, test: &Opponent, filter: &FeatureFilter) -> Vec<f32> {
    let (w, h, r) = (reference.width, reference.height, filter.radius());
    // Lightness normalised to [0, 1]; horizontal first and second derivative
    // and Gaussian.
    let horizontal = |image: &Opponent| {
        per_pixel(w, h, |x, y| {
            let mut sum = [0.0f32; 3];
            for i in -r..=r {
                let l = image.clamped(x as i32 + i, y)[0] * (1.0 / 116.0) + 16.0 / 116.0;
                let [g, dg, ddg] = filter.weights[(i + r) as usize];
                sum[0] += dg * l;
                sum[1] += ddg * l;
                sum[2] += g * l;
            }
            sum
        })
    };
    let (href, htest) = (horizontal(reference), horizontal(test));
    per_pixel(w, h, |x, y| {
        let features = |rows: &[[f32; 3]]| {
            let (mut dx, mut ddx, mut dy, mut ddy) = (0.0f32, 0.0f32, 0.0f32, 0.0f32);
            for i in -r..=r {
                let c = rows[row(y, i, h) * w + x];
                let [g, dg, ddg] = filter.weights[(i + r) as usize];
                dx += g * c[0];
                ddx += g * c[1];
                dy += dg * c[2];
                ddy += ddg * c[2];
            }
            ((dx * dx + dy * dy).sqrt(), (ddx * ddx + ddy * ddy).sqrt())
        };
        let ((edge_r, point_r), (edge_t, point_t)) = (features(&href), features(&htest));
        let largest = (edge_r - edge_t).abs().max((point_r - point_t).abs());
        ((1.0 / 2.0f32.sqrt()) * largest).powf(FEATURE_EXPONENT)
    })
}

/// LDR-FLIP's error map between two linear-RGB images of `width` × `height`
/// (values outside [0, 1] are clamped, as a display would), viewed at
/// `pixels_per_degree`.
pub fn error_map(
    reference: &[[f32; 3]],
    test: &[[f32; 3]],
    width: usize,
    height: usize,
    pixels_per_degree: f32,
) -> Vec<f32> {
    assert_eq!(reference.len(), width * height);
    assert_eq!(test.len(), width * height);
    let opponent = |image: &[[f32; 3]]| -> Vec<[f32; 3]> {
        image
            .iter()
            .map(|c| xyz_to_ycxcz(linear_rgb_to_xyz(c.map(|v| v.clamp(0.0, 1.0)))))
            .collect()
    };
    let (r, t) = (opponent(reference), opponent(test));
    let view = |pixels| Opponent {
        width,
        height,
        pixels,
    };
    let (r, t) = (view(&r), view(&t));
    let colour = colour_difference(&r, &t, &SpatialFilter::new(pixels_per_degree));
    let feature = feature_difference(&r, &t, &FeatureFilter::new(pixels_per_degree));
    colour
        .into_iter()
        .zip(feature)
        .map(|(c, f)| c.powf(1.0 - f))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// FLIP's default viewing: 0.7 m from a 0.7 m wide 3840-pixel screen.
    const PPD: f32 = 67.020_64;

    /// The kernels sum as the separable decomposition needs: the Y and Cx
    /// Gaussians to 1; the two blue-yellow halves to a unit vector (so the
    /// 2D sum of both outer products is 1); the Gaussian of the feature
    /// filter to 1 and each sign of its derivatives to ±1.
    #[test]
    fn kernels_are_normalised() {
        let spatial = SpatialFilter::new(PPD);
        assert_eq!(spatial.radius(), 10);
        for k in 0..2 {
            let sum: f32 = spatial.y_cx.iter().map(|w| w[k]).sum();
            assert!((sum - 1.0).abs() < 1e-5, "{sum}");
        }
        let cz: Vec<f32> = (0..2)
            .map(|k| spatial.cz.iter().map(|w| w[k]).sum())
            .collect();
        assert!((cz[0] * cz[0] + cz[1] * cz[1] - 1.0).abs() < 1e-5, "{cz:?}");
        let feature = FeatureFilter::new(PPD);
        assert_eq!(feature.radius(), 9);
        let sum = |k: usize, positive: bool| -> f32 {
            feature
                .weights
                .iter()
                .map(|w| w[k])
                .filter(|&v| (v > 0.0) == positive && v != 0.0)
                .sum()
        };
        assert!((sum(0, true) - 1.0).abs() < 1e-5);
        for k in 1..3 {
            assert!((sum(k, true) - 1.0).abs() < 1e-5);
            assert!((sum(k, false) + 1.0).abs() < 1e-5);
        }
    }

    /// Green against blue is the largest colour difference FLIP expects: a
    /// flat field of one against the other is error 1 everywhere, and a flat
    /// field against itself 0.
    #[test]
    fn extremes() {
        let green = vec![[0.0, 1.0, 0.0]; 24 * 16];
        let blue = vec![[0.0, 0.0, 1.0]; 24 * 16];
        for e in error_map(&green, &blue, 24, 16, PPD) {
            assert!((e - 1.0).abs() < 1e-5, "{e}");
        }
        assert!(error_map(&green, &green, 24, 16, PPD)
            .iter()
            .all(|&e| e == 0.0));
    }
}
