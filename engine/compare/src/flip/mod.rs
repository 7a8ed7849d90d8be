//! FLIP (Andersson et al. 2020, 2021): LDR-FLIP on float images
//! ([`ldr`], in [`colour`]'s spaces) and HDR-FLIP built on it the way the
//! reference implementation builds it: the reference's exposure range from
//! its luminance, then at each exposure both images exposed, tonemapped with
//! FLIP's ACES fit, clamped, and compared by LDR-FLIP in float, keeping each
//! pixel's largest error. Tests hold the results to the reference
//! implementation's (`flip-evaluator` 1.7) values on hand-made pairs and on
//! real renders.

mod colour;
mod ldr;

use crate::image_io::{LinearImage, SrgbImage};

/// Pixels per degree of visual angle FLIP assumes: a 0.7 m wide, 3840-pixel
/// monitor seen from 0.7 m (FLIP's default, 0.7 × 3840 / 0.7 × π / 180).
pub const PIXELS_PER_DEGREE: f32 = 67.020_64;

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
        SrgbImage {
            width: self.width,
            height: self.height,
            bytes: self
                .map
                .iter()
                .flat_map(|&e| {
                    let step = (e.clamp(0.0, 1.0) * 255.0).round() as usize;
                    let c = colorous::MAGMA.eval_rational(step, 256);
                    [c.r, c.g, c.b]
                })
                .collect(),
        }
    }
}

/// LDR-FLIP between two 8-bit sRGB images of the same size.
pub fn ldr_flip(reference: &SrgbImage, test: &SrgbImage) -> FlipResult {
    let linear = |image: &SrgbImage| -> Vec<[f32; 3]> {
        image
            .bytes
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]].map(|b| colour::srgb_to_linear(f32::from(b) / 255.0)))
            .collect()
    };
    let map = ldr_map(
        reference.width,
        reference.height,
        &linear(reference),
        &linear(test),
    );
    FlipResult::from_map(reference.width, reference.height, map, None)
}

fn ldr_map(width: u32, height: u32, reference: &[[f32; 3]], test: &[[f32; 3]]) -> Vec<f32> {
    ldr::error_map(
        reference,
        test,
        width as usize,
        height as usize,
        PIXELS_PER_DEGREE,
    )
}

/// FLIP's ACES fit of one linear value.
pub fn aces(x: f32) -> f32 {
    let [a, b, c, d, e, f] = ACES;
    (x * x * a + x * b + c) / (x * x * d + x * e + f)
}

/// The exposure range HDR-FLIP compares over, from the reference: from the
/// exposure that maps its brightest pixel to where the tonemapper reaches
/// 0.85, to the one that maps its median luminance there; and how many
/// exposures (one per stop, at least 2). As in the reference implementation,
/// a median below `f32::EPSILON` (a black background over half the frame)
/// counts as `f32::EPSILON`, so the range ends 23 stops below 0.85. Non-finite
/// pixels are left out; an image with no light gives exposure 0.
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
    let median = *luminance.select_nth_unstable_by(middle, f32::total_cmp).1;
    let start = (x_max / y_max).log2();
    let stop = (x_max / median.max(f32::EPSILON)).log2();
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
        let exposed = |image: &LinearImage| -> Vec<[f32; 3]> {
            image
                .pixels
                .iter()
                .map(|p| p.map(|c| aces(c * scale).clamp(0.0, 1.0)))
                .collect()
        };
        let exposure = ldr_map(
            reference.width,
            reference.height,
            &exposed(reference),
            &exposed(test),
        );
        for (m, e) in map.iter_mut().zip(exposure) {
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
    /// NaN pixel give finite exposure ranges: a median of 0 counts as
    /// `f32::EPSILON`, as in the reference implementation.
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
        // start maps luminance 1 to 0.85, stop maps 2^-23: 23 stops on
        assert!(
            start.is_finite() && (stop - start - 23.0).abs() < 1e-5,
            "{start} {stop}"
        );
        assert_eq!(count, 23);
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
    /// exposures -0.18402869 to 0.76261032 in 2 steps. Measured: LDR
    /// 0.36355050, HDR 0.03144903 (both under 1e-7 off); held to 1e-6.
    #[test]
    fn matches_the_reference_implementation() {
        let (r, t) = ldr_pair();
        let ldr = ldr_flip(&r, &t).mean;
        assert!((ldr - 0.363_550_54).abs() < 1e-6, "{ldr}");
        let (r, t) = hdr_pair();
        let (start, stop, count) = exposure_range(&r);
        assert!((start - -0.184_028_69).abs() < 1e-5, "{start}");
        assert!((stop - 0.762_610_3).abs() < 1e-5, "{stop}");
        assert_eq!(count, 2);
        let hdr = hdr_flip(&r, &t).mean;
        assert!(
            (hdr - 0.031_449_10).abs() < 1e-6,
            "{hdr}: {:.2e} from the reference implementation",
            (hdr - 0.031_449_10).abs()
        );
    }

    fn testdata(name: &str) -> std::path::PathBuf {
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("testdata/flip")
            .join(name)
    }

    fn exr(name: &str) -> LinearImage {
        LinearImage::read_exr(&testdata(&format!("{name}.exr"))).expect(name)
    }

    fn png(name: &str) -> SrgbImage {
        let rgb = image::open(testdata(&format!("{name}.png")))
            .expect(name)
            .into_rgb8();
        SrgbImage {
            width: rgb.width(),
            height: rgb.height(),
            bytes: rgb.into_raw(),
        }
    }

    /// Real renders (weft's, 320×180, stored as half floats in
    /// `testdata/flip`): the demo's 64-spp path-traced reference, the same
    /// with the next seed, its forward and deferred renders, the flight
    /// helmet's reference and deferred render. Expected values are the
    /// reference implementation's (`pip install flip-evaluator`, version
    /// 1.7: `flip_evaluator.evaluate(reference, test, "HDR")` on the EXRs
    /// read as float32, and `"LDR"` on the PNGs' bytes / 255), from FLIP 0.003
    /// to 0.19, where differences of 0.001 decide sweeps. Measured: within
    /// 6.3e-7 of every value; held to 1e-5.
    #[test]
    fn matches_the_reference_implementation_on_renders() {
        let hdr_pairs = [
            ("demo_reference", "demo_forward", 0.189_693_93),
            ("demo_reference", "demo_reference_seed1", 0.075_850_77),
            ("demo_forward", "demo_deferred", 0.002_734_77),
            ("helmet_reference", "helmet_deferred", 0.059_050_78),
        ];
        for (reference, test, expected) in hdr_pairs {
            let flip = hdr_flip(&exr(reference), &exr(test)).mean;
            assert!(
                (flip - expected).abs() < 1e-5,
                "{reference} against {test}: {flip:.8}, the reference implementation {expected:.8}"
            );
        }
        let ldr = ldr_flip(&png("demo_reference"), &png("demo_forward")).mean;
        assert!((ldr - 0.122_833_86).abs() < 1e-5, "{ldr:.8}");
    }
}
