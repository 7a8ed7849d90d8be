//! FLIP (Andersson et al. 2020, 2021): LDR-FLIP through NVIDIA's own C++
//! (the `nv-flip` crate) and HDR-FLIP built on it the way the reference
//! implementation builds it: the reference's exposure range from its
//! luminance, then at each exposure both images exposed, tonemapped with
//! FLIP's ACES fit, clamped, and compared by LDR-FLIP, keeping each pixel's
//! largest error. `nv-flip` takes 8-bit sRGB, so each exposure is quantised
//! to bytes before it is compared; tests hold the result to the reference
//! implementation's (`flip-evaluator` 1.7) values.

use crate::image_io::{linear_to_srgb, to_byte, LinearImage, SrgbImage};

/// Pixels per degree of visual angle FLIP assumes: a 0.7 m wide, 3840-pixel
/// monitor seen from 0.7 m (FLIP's default, 67.02).
pub const PIXELS_PER_DEGREE: f32 = nv_flip::DEFAULT_PIXELS_PER_DEGREE;

/// FLIP's ACES filmic fit, as its HDR mode tonemaps: (x (a x + b) + c) /
/// (x (d x + e) + f), the 0.6 pre-exposure folded into the constants.
const ACES: [f32; 6] = [
    0.6 * 0.6 * 2.51,
    0.6 * 0.03,
    0.0,
    0.6 * 0.6 * 2.43,
    0.6 * 0.59,
    0.14,
];

/// A FLIP error map and its mean.
#[derive(Debug, Clone, PartialEq)]
pub struct FlipResult {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Per-pixel error in [0, 1], row by row from the top.
    pub map: Vec<f32>,
    /// The mean of `map`: the FLIP value reported.
    pub mean: f64,
    /// HDR-FLIP: the exposures compared (start, stop, count).
    pub exposures: Option<(f32, f32, u32)>,
}

impl FlipResult {
    fn from_map(
        width: u32,
        height: u32,
        map: Vec<f32>,
        exposures: Option<(f32, f32, u32)>,
    ) -> Self {
        let mean = map.iter().map(|&v| f64::from(v)).sum::<f64>() / map.len().max(1) as f64;
        Self {
            width,
            height,
            map,
            mean,
            exposures,
        }
    }

    /// The error map coloured with FLIP's magma map (black 0 to yellow-white 1).
    pub fn magma(&self) -> SrgbImage {
        let map = nv_flip::FlipImageFloat::with_data(self.width, self.height, &self.map);
        let coloured = map.apply_color_lut(&nv_flip::magma_lut());
        SrgbImage {
            width: self.width,
            height: self.height,
            bytes: coloured.to_vec(),
        }
    }
}

/// LDR-FLIP between two 8-bit sRGB images of the same size.
pub fn ldr_flip(reference: &SrgbImage, test: &SrgbImage) -> FlipResult {
    let map = ldr_map(reference, test);
    FlipResult::from_map(reference.width, reference.height, map, None)
}

fn ldr_map(reference: &SrgbImage, test: &SrgbImage) -> Vec<f32> {
    let r = nv_flip::FlipImageRgb8::with_data(reference.width, reference.height, &reference.bytes);
    let t = nv_flip::FlipImageRgb8::with_data(test.width, test.height, &test.bytes);
    nv_flip::flip(r, t, PIXELS_PER_DEGREE).to_vec()
}

/// FLIP's ACES fit of one linear value.
pub fn aces(x: f32) -> f32 {
    let [a, b, c, d, e, f] = ACES;
    (x * x * a + x * b + c) / (x * x * d + x * e + f)
}

/// The exposure range HDR-FLIP compares over, from the reference: from the
/// exposure that maps its brightest pixel to where the tonemapper reaches
/// 0.85, to the one that maps its median luminance there; and how many
/// exposures (one per stop, at least 2). Where the reference implementation
/// would divide by zero — a median luminance of 0, as in a render with a black
/// background over half the frame, or an all-black image — the median of the
/// lit pixels is used, or exposure 0; and the range is held to 32 stops.
pub fn exposure_range(reference: &LinearImage) -> (f32, f32, u32) {
    // The input x at which the tonemapper gives t: a x^2 + b x + c = 0.
    let t = 0.85f32;
    let [a0, b0, c0, d0, e0, f0] = ACES;
    let (a, b, c) = (a0 - t * d0, b0 - t * e0, c0 - t * f0);
    let x_max = if a == 0.0 {
        -c / b
    } else {
        let d1 = -0.5 * (b / a);
        d1 + ((d1 * d1) - (c / a)).sqrt()
    };
    let mut luminance: Vec<f32> = reference
        .pixels
        .iter()
        .map(|p| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2])
        .collect();
    luminance.retain(|y| y.is_finite());
    let y_max = luminance.iter().copied().fold(0.0, f32::max);
    if y_max <= 0.0 {
        return (0.0, 0.0, 2);
    }
    let middle = luminance.len() / 2;
    let mut median = *luminance.select_nth_unstable_by(middle, f32::total_cmp).1;
    if median <= 0.0 {
        luminance.retain(|&y| y > 0.0);
        let middle = luminance.len() / 2;
        median = *luminance.select_nth_unstable_by(middle, f32::total_cmp).1;
    }
    let start = (x_max / y_max).log2();
    let stop = (x_max / median).log2().min(start + 32.0);
    let count = (stop - start).ceil().max(2.0) as u32;
    (start, stop, count)
}

/// HDR-FLIP between two linear images of the same size.
pub fn hdr_flip(reference: &LinearImage, test: &LinearImage) -> FlipResult {
    let (start, stop, count) = exposure_range(reference);
    let step = (stop - start) / (count - 1) as f32;
    let mut map = vec![0.0f32; reference.pixels.len()];
    for i in 0..count {
        let scale = (start + i as f32 * step).exp2();
        let exposed = |image: &LinearImage| SrgbImage {
            width: image.width,
            height: image.height,
            bytes: image
                .pixels
                .iter()
                .flat_map(|p| p.map(|c| to_byte(linear_to_srgb(aces(c * scale)))))
                .collect(),
        };
        for (m, e) in map
            .iter_mut()
            .zip(ldr_map(&exposed(reference), &exposed(test)))
        {
            *m = m.max(e);
        }
    }
    FlipResult::from_map(
        reference.width,
        reference.height,
        map,
        Some((start, stop, count)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The hand-made LDR pair: a gradient, and the same with a white square
    /// and the red channel of the right quarter inverted.
    fn ldr_pair() -> (SrgbImage, SrgbImage) {
        let (mut r, mut t) = (Vec::new(), Vec::new());
        for y in 0..32u32 {
            for x in 0..32u32 {
                let c = [(x * 8) & 255, (y * 8) & 255, ((x + y) * 4) & 255].map(|v| v as u8);
                let mut d = c;
                if (8..16).contains(&x) && (8..16).contains(&y) {
                    d = [255; 3];
                }
                if x >= 24 {
                    d[0] = 255 - d[0];
                }
                r.extend(c);
                t.extend(d);
            }
        }
        let image = |bytes| SrgbImage {
            width: 32,
            height: 32,
            bytes,
        };
        (image(r), image(t))
    }

    /// The hand-made HDR pair: a linear gradient up to 4, and the same 1.5
    /// times brighter in a square.
    fn hdr_pair() -> (LinearImage, LinearImage) {
        let (mut r, mut t) = (Vec::new(), Vec::new());
        for y in 0..32u32 {
            for x in 0..32u32 {
                let c = [
                    (x + 1) as f32 / 8.0,
                    (y + 1) as f32 / 16.0,
                    ((x + y) % 7 + 1) as f32 / 4.0,
                ];
                let k = if (8..16).contains(&x) && (8..16).contains(&y) {
                    1.5
                } else {
                    1.0
                };
                r.push(c);
                t.push(c.map(|v| v * k));
            }
        }
        let image = |pixels| LinearImage {
            width: 32,
            height: 32,
            pixels,
        };
        (image(r), image(t))
    }

    /// A black background over most of the frame, a black image, and a
    /// NaN pixel give finite exposure ranges.
    #[test]
    fn dark_references_give_finite_exposures() {
        let mut pixels = vec![[0.0f32; 3]; 100];
        pixels[0] = [1.0, 1.0, 1.0];
        pixels[1] = [0.25, 0.25, 0.25];
        pixels[2] = [f32::NAN, 0.0, 0.0];
        let image = LinearImage {
            width: 10,
            height: 10,
            pixels,
        };
        let (start, stop, count) = exposure_range(&image);
        // the lit median is 1 (of 1 and 0.25, the upper middle); x_max / 1
        assert!(
            start.is_finite() && (stop - start).abs() < 1e-6,
            "{start} {stop}"
        );
        assert_eq!(count, 2);
        let black = LinearImage {
            width: 2,
            height: 1,
            pixels: vec![[0.0; 3]; 2],
        };
        assert_eq!(exposure_range(&black), (0.0, 0.0, 2));
        assert_eq!(hdr_flip(&black, &black).mean, 0.0);
    }

    #[test]
    fn flip_of_an_image_with_itself_is_zero() {
        let (r, _) = ldr_pair();
        assert_eq!(ldr_flip(&r, &r).mean, 0.0);
        let (h, _) = hdr_pair();
        assert_eq!(hdr_flip(&h, &h).mean, 0.0);
    }

    /// The reference implementation's values for the same pairs
    /// (`pip install flip-evaluator`, version 1.7:
    /// `flip_evaluator.evaluate(ref, test, "LDR")` on the bytes / 255, and
    /// `"HDR"` on the linear floats): LDR 0.36355054, HDR 0.03144910 with
    /// exposures -0.18402869 to 0.76261032 in 2 steps. `nv-flip` carries an
    /// earlier version of the same C++, and HDR-FLIP here compares 8-bit sRGB
    /// exposures where the reference keeps floats; both agree within 1e-4
    /// (measured: LDR 0.36352351, 2.7e-5 off; HDR 0.03138648, 6.3e-5 off).
    #[test]
    fn matches_the_reference_implementation() {
        let (r, t) = ldr_pair();
        let ldr = ldr_flip(&r, &t).mean;
        assert!((ldr - 0.363_550_54).abs() < 1e-4, "{ldr}");
        let (r, t) = hdr_pair();
        let (start, stop, count) = exposure_range(&r);
        assert!((start - -0.184_028_69).abs() < 1e-5, "{start}");
        assert!((stop - 0.762_610_3).abs() < 1e-5, "{stop}");
        assert_eq!(count, 2);
        let hdr = hdr_flip(&r, &t).mean;
        assert!(
            (hdr - 0.031_449_10).abs() < 1e-4,
            "{hdr}: {:.2e} from the reference implementation",
            (hdr - 0.031_449_10).abs()
        );
    }
}
