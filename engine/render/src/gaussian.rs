//! Gaussian blur taps derived from the `Gaussian` provider's `sigma` and `radius`.
//!
//! A separable Gaussian of radius R needs 2R + 1 fetches per direction. Pairing
//! neighbouring taps k and k + 1 into one bilinear fetch placed between them,
//! at offset (k w_k + (k+1) w_{k+1}) / (w_k + w_{k+1}) with weight w_k + w_{k+1},
//! gives exactly the same sum (the hardware's linear filter does the weighting),
//! so R = 21 (a 43-tap footprint) needs 1 + 2 * 11 = 23 fetches. Computing the
//! weights here, in f64 and normalised once, rather than per pixel in the shader
//! keeps `exp` out of the inner loop and makes the weights sum to 1 to within
//! f32 rounding, which the shader cannot guarantee.

/// The most taps either side a pass may ask for; larger radii are an error.
pub const MAX_RADIUS: u32 = 128;

/// One side of a symmetric kernel: tap 0 is the centre, taps 1.. are applied
/// at `+offset` and `-offset` texels.
#[derive(Debug, Clone, PartialEq)]
pub struct GaussianTaps {
    /// Weight of each tap (the centre once, every other tap twice).
    pub weights: Vec<f64>,
    /// Offset of each tap in texels (0 for the centre).
    pub offsets: Vec<f64>,
}

impl GaussianTaps {
    /// The discrete kernel exp(-k^2 / (2 sigma^2)) for k in -radius..=radius,
    /// normalised to sum to 1: one tap per texel.
    pub fn discrete(sigma: f64, radius: u32) -> Result<Self, String> {
        check(sigma, radius)?;
        let raw: Vec<f64> = (0..=radius)
            .map(|k| {
                let k = f64::from(k);
                (-k * k / (2.0 * sigma * sigma)).exp()
            })
            .collect();
        let total = raw[0] + 2.0 * raw[1..].iter().sum::<f64>();
        Ok(Self {
            weights: raw.iter().map(|w| w / total).collect(),
            offsets: (0..=radius).map(f64::from).collect(),
        })
    }

    /// The same kernel with neighbouring taps paired into linear-filtered
    /// fetches: `ceil(radius / 2)` taps either side plus the centre.
    pub fn linear(sigma: f64, radius: u32) -> Result<Self, String> {
        let discrete = Self::discrete(sigma, radius)?;
        let w = &discrete.weights;
        let mut taps = Self {
            weights: vec![w[0]],
            offsets: vec![0.0],
        };
        for k in (1..w.len()).step_by(2) {
            let w1 = w[k];
            let w2 = w.get(k + 1).copied().unwrap_or(0.0);
            let x1 = k as f64;
            taps.weights.push(w1 + w2);
            taps.offsets.push((x1 * w1 + (x1 + 1.0) * w2) / (w1 + w2));
        }
        Ok(taps)
    }

    /// Number of taps including the centre.
    pub fn len(&self) -> usize {
        self.weights.len()
    }

    /// Whether there are no taps (never true for a built kernel).
    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// Sum of the weights as the shader applies them (centre once, others
    /// twice), accumulated in f32 from the f32 weights the shader receives.
    pub fn applied_sum_f32(&self) -> f32 {
        let w: Vec<f32> = self.weights.iter().map(|&w| w as f32).collect();
        w[0] + w[1..].iter().map(|x| 2.0 * x).sum::<f32>()
    }
}

fn check(sigma: f64, radius: u32) -> Result<(), String> {
    if !(sigma.is_finite() && sigma > 0.0) {
        return Err(format!("`sigma` must be a positive number, got {sigma}"));
    }
    if radius == 0 || radius > MAX_RADIUS {
        return Err(format!(
            "`radius` must be between 1 and {MAX_RADIUS}, got {radius}"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Convolves `signal` at `x` with the taps, reading between texels by
    /// linear interpolation and clamping at the edges (as the sampler does).
    fn apply(taps: &GaussianTaps, signal: &[f64], x: usize) -> f64 {
        let at = |p: f64| {
            let last = (signal.len() - 1) as f64;
            let p = p.clamp(0.0, last);
            let i = p.floor() as usize;
            let f = p - i as f64;
            let j = (i + 1).min(signal.len() - 1);
            signal[i] * (1.0 - f) + signal[j] * f
        };
        let centre = x as f64;
        let mut sum = taps.weights[0] * at(centre);
        for (w, o) in taps.weights.iter().zip(&taps.offsets).skip(1) {
            sum += w * (at(centre + o) + at(centre - o));
        }
        sum
    }

    #[test]
    fn weights_sum_to_one_in_f32_as_applied() {
        for (sigma, radius) in [(9.0, 21), (1.0, 1), (2.5, 7), (40.0, 128), (0.3, 5)] {
            for taps in [
                GaussianTaps::discrete(sigma, radius).unwrap(),
                GaussianTaps::linear(sigma, radius).unwrap(),
            ] {
                let sum = taps.applied_sum_f32();
                assert!(
                    (sum - 1.0).abs() <= 1e-6,
                    "sigma {sigma} radius {radius}: sum {sum}"
                );
            }
        }
    }

    #[test]
    fn the_default_bloom_kernel_is_23_fetches_for_43_taps() {
        let discrete = GaussianTaps::discrete(9.0, 21).unwrap();
        let linear = GaussianTaps::linear(9.0, 21).unwrap();
        assert_eq!(discrete.len(), 22);
        assert_eq!(linear.len(), 12);
        assert_eq!(linear.offsets[0], 0.0);
        // The lone last tap (21 has no partner inside the footprint) stays on its texel.
        assert_eq!(linear.offsets[11], 21.0);
        assert!(
            (linear.offsets[1]
                - (1.0 * discrete.weights[1] + 2.0 * discrete.weights[2])
                    / (discrete.weights[1] + discrete.weights[2]))
                .abs()
                < 1e-15
        );
    }

    #[test]
    fn linear_taps_reproduce_the_discrete_convolution() {
        // A pseudo-random signal: the paired fetches must give the same result
        // as one tap per texel everywhere, edges included.
        let mut state = 0x2545_f491_u64;
        let signal: Vec<f64> = (0..97)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state % 1000) as f64 / 100.0
            })
            .collect();
        for (sigma, radius) in [(9.0, 21), (3.0, 8), (1.5, 3)] {
            let discrete = GaussianTaps::discrete(sigma, radius).unwrap();
            let linear = GaussianTaps::linear(sigma, radius).unwrap();
            for x in 0..signal.len() {
                let a = apply(&discrete, &signal, x);
                let b = apply(&linear, &signal, x);
                assert!((a - b).abs() < 1e-12, "x {x}: {a} vs {b}");
            }
        }
    }

    #[test]
    fn rejects_bad_parameters() {
        assert_eq!(
            GaussianTaps::linear(0.0, 21).unwrap_err(),
            "`sigma` must be a positive number, got 0"
        );
        assert_eq!(
            GaussianTaps::linear(9.0, 0).unwrap_err(),
            "`radius` must be between 1 and 128, got 0"
        );
    }
}
