//! Pixel-wise error measures: RMSE and relative MSE on linear HDR (what a
//! renderer's estimate is judged by), PSNR on the 8-bit tonemapped output
//! (what a viewer sees).

use crate::image_io::SrgbImage;

/// Root mean square difference over every pixel and channel of linear RGB.
pub fn rmse(image: &[[f32; 3]], reference: &[[f32; 3]]) -> f64 {
    let sum: f64 = pairs(image, reference)
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    (sum / channels(reference)).sqrt()
}

/// Mean of (a − b)² / (b² + 0.01) over every pixel and channel: squared error
/// relative to the reference's brightness, 0.01 keeping black pixels finite
/// (the measure Mitsuba and most rendering papers report; Rousselle et al.).
pub fn rel_mse(image: &[[f32; 3]], reference: &[[f32; 3]]) -> f64 {
    let sum: f64 = pairs(image, reference)
        .map(|(a, b)| (a - b) * (a - b) / (b * b + 0.01))
        .sum();
    sum / channels(reference)
}

/// Mean Rec. 709 luminance of `image` over that of `reference`: 1 when the
/// two carry the same light overall, whatever its arrangement (a unit or
/// energy mismatch shows here first); infinite against a black reference
/// unless the image is black too (then 1).
pub fn luminance_ratio(image: &[[f32; 3]], reference: &[[f32; 3]]) -> f64 {
    let mean = |pixels: &[[f32; 3]]| -> f64 {
        pixels
            .iter()
            .map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
            .sum::<f64>()
    };
    let (a, b) = (mean(image), mean(reference));
    if a == b {
        1.0
    } else {
        a / b
    }
}

/// Peak signal-to-noise ratio of 8-bit images in dB: 10 log10(255² / MSE);
/// infinite for identical images.
pub fn psnr(image: &SrgbImage, reference: &SrgbImage) -> f64 {
    let mse = image
        .bytes
        .iter()
        .zip(&reference.bytes)
        .map(|(&a, &b)| {
            let d = f64::from(a) - f64::from(b);
            d * d
        })
        .sum::<f64>()
        / reference.bytes.len().max(1) as f64;
    10.0 * (255.0 * 255.0 / mse).log10()
}

/// The median of `values` (the mean of the middle two for an even count; 0
/// for none).
pub fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => values[n / 2],
        _ => 0.5 * (values[n / 2 - 1] + values[n / 2]),
    }
}

/// How a set of timings spreads: the least, the quartiles and the count.
/// Two configurations whose interquartile ranges overlap are not told apart
/// by these timings.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Spread {
    /// How many samples.
    pub samples: usize,
    /// The least sample.
    pub min: f64,
    /// The first quartile.
    pub p25: f64,
    /// The median.
    pub median: f64,
    /// The third quartile.
    pub p75: f64,
}

impl Spread {
    /// The spread of `values` (quartiles interpolated between the sorted
    /// samples, as numpy's default does); all zero for none.
    pub fn of(values: &[f64]) -> Spread {
        let mut sorted = values.to_vec();
        sorted.sort_by(f64::total_cmp);
        let at = |q: f64| {
            if sorted.is_empty() {
                return 0.0;
            }
            let position = q * (sorted.len() - 1) as f64;
            let (low, high) = (position.floor() as usize, position.ceil() as usize);
            sorted[low] + (sorted[high] - sorted[low]) * (position - low as f64)
        };
        Spread {
            samples: sorted.len(),
            min: sorted.first().copied().unwrap_or(0.0),
            p25: at(0.25),
            median: at(0.5),
            p75: at(0.75),
        }
    }

    /// Whether the two interquartile ranges overlap: the timings do not say
    /// which is faster.
    pub fn overlaps(&self, other: &Spread) -> bool {
        self.p25 <= other.p75 && other.p25 <= self.p75
    }
}

fn pairs<'a>(
    image: &'a [[f32; 3]],
    reference: &'a [[f32; 3]],
) -> impl Iterator<Item = (f64, f64)> + 'a {
    image
        .iter()
        .zip(reference)
        .flat_map(|(a, b)| (0..3).map(move |c| (f64::from(a[c]), f64::from(b[c]))))
}

fn channels(image: &[[f32; 3]]) -> f64 {
    (image.len() * 3).max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spread_interpolates_quartiles_and_tells_overlap() {
        let s = Spread::of(&[5.0, 1.0, 4.0, 2.0, 3.0]);
        assert_eq!(
            s,
            Spread {
                samples: 5,
                min: 1.0,
                p25: 2.0,
                median: 3.0,
                p75: 4.0
            }
        );
        // Four samples: positions 0.75, 1.5 and 2.25 between 10, 20, 30, 40.
        let four = Spread::of(&[40.0, 10.0, 30.0, 20.0]);
        assert_eq!((four.p25, four.median, four.p75), (17.5, 25.0, 32.5));
        assert!(s.overlaps(&Spread::of(&[3.5, 4.5])));
        assert!(!s.overlaps(&Spread::of(&[4.5, 5.5])));
        assert_eq!(Spread::of(&[]), Spread::default());
    }

    fn linear(values: &[[f32; 3]]) -> Vec<[f32; 3]> {
        values.to_vec()
    }

    #[test]
    fn known_differences() {
        let reference = linear(&[[1.0, 1.0, 1.0], [0.0, 0.0, 0.0]]);
        let image = linear(&[[1.5, 1.0, 1.0], [0.0, 0.1, 0.0]]);
        // squared errors 0.25 and 0.01 over 6 channels
        assert!((rmse(&image, &reference) - (0.26f64 / 6.0).sqrt()).abs() < 1e-7);
        let expected = (0.25 / 1.01 + 0.01 / 0.01) / 6.0;
        assert!((rel_mse(&image, &reference) - expected).abs() < 1e-7);
        // Twice the light, arranged differently: ratio 2; equal and black images: 1.
        let doubled = [[0.0, 0.0, 0.0], [2.0, 2.0, 2.0]];
        let flat = [[0.5, 0.5, 0.5], [0.5, 0.5, 0.5]];
        assert!((luminance_ratio(&doubled, &flat) - 2.0).abs() < 1e-12);
        assert_eq!(luminance_ratio(&[[0.0; 3]], &[[0.0; 3]]), 1.0);
        assert!(luminance_ratio(&[[1.0; 3]], &[[0.0; 3]]).is_infinite());
        assert_eq!(rmse(&reference, &reference), 0.0);
        let a = SrgbImage {
            width: 1,
            height: 1,
            bytes: vec![10, 20, 30],
        };
        let b = SrgbImage {
            width: 1,
            height: 1,
            bytes: vec![10, 20, 33],
        };
        // MSE 3 over 3 channels = 3
        assert!((psnr(&a, &b) - 10.0 * (65025.0f64 / 3.0).log10()).abs() < 1e-9);
        assert!(psnr(&a, &a).is_infinite());
    }
}
