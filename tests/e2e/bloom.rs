//! The shipped bloom fragment (graphs/bloom.ron) over a known HDR image: the
//! bright pass keeps exactly what is above the threshold, the engine-derived
//! linear-sampled blur matches a brute-force 43x43 Gaussian computed here, and
//! an image with nothing above the threshold is composited unchanged.

use weft_gpu::{Gpu, Readback, Renderer};
use weft_graph::plan::Extent;
use weft_graph::schema::ParamValue;
use weft_render::GaussianTaps;
use weft_tests as common;

const WIDTH: u32 = 128;
const HEIGHT: u32 = 96;

/// A read-back float image, RGB only.
struct Rgb {
    width: usize,
    height: usize,
    data: Vec<[f64; 3]>,
}

impl Rgb {
    fn from(readback: &Readback) -> Self {
        let img = readback.to_rgba_f32();
        let data = img
            .pixels()
            .map(|p| [f64::from(p.0[0]), f64::from(p.0[1]), f64::from(p.0[2])])
            .collect();
        Self {
            width: readback.width as usize,
            height: readback.height as usize,
            data,
        }
    }

    /// Clamp-to-edge fetch, as the engine's sampler addresses.
    fn at(&self, x: i64, y: i64) -> [f64; 3] {
        let x = x.clamp(0, self.width as i64 - 1) as usize;
        let y = y.clamp(0, self.height as i64 - 1) as usize;
        self.data[y * self.width + x]
    }

    fn max_abs_diff(&self, other: &Rgb) -> f64 {
        assert_eq!((self.width, self.height), (other.width, other.height));
        self.data
            .iter()
            .zip(&other.data)
            .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs()))
            .fold(0.0, f64::max)
    }

    fn peak(&self) -> f64 {
        self.data.iter().flatten().copied().fold(0.0, f64::max)
    }
}

/// Renders the fixture once with `features`, the pattern's dots at `peak`,
/// reading back the HDR input, the bright pass and the blurred result.
fn render(
    gpu: &Gpu,
    features: &[&str],
    peak: f64,
    level: f64,
) -> (Readback, Vec<(String, Readback)>) {
    let bloom_on = !features.contains(&"!bloom");
    let readback = if bloom_on {
        vec!["hdr".into(), "bloom_bright".into(), "bloom".into()]
    } else {
        vec!["hdr".into()]
    };
    let extent = Extent {
        width: WIDTH,
        height: HEIGHT,
    };
    let mut plan = common::compile(
        gpu,
        &common::graph("bloom_check.ron"),
        extent,
        features,
        readback,
    );
    let pattern = plan
        .passes
        .iter_mut()
        .find(|p| p.name == "pattern")
        .expect("pattern pass");
    pattern
        .params
        .insert("peak".into(), ParamValue::Number(peak));
    pattern
        .params
        .insert("level".into(), ParamValue::Number(level));
    let mut renderer = Renderer::new(gpu).expect("renderer");
    let report = weft_testkit::one_frame(&mut renderer, &plan).expect("frame");
    (report.output.expect("output"), report.readbacks)
}

fn named(readbacks: &[(String, Readback)], name: &str) -> Rgb {
    Rgb::from(
        &readbacks
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name} read back"))
            .1,
    )
}

/// The bright pass on the CPU: the half-resolution texel's centre lies on the
/// corner of a 2x2 block, which the linear filter averages; then the threshold.
fn bright_reference(hdr: &Rgb, threshold: f64) -> Rgb {
    let (width, height) = (hdr.width / 2, hdr.height / 2);
    let mut data = Vec::with_capacity(width * height);
    for y in 0..height as i64 {
        for x in 0..width as i64 {
            let mut c = [0.0; 3];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let t = hdr.at(2 * x + dx, 2 * y + dy);
                for k in 0..3 {
                    c[k] += 0.25 * t[k];
                }
            }
            let peak = c[0].max(c[1]).max(c[2]);
            let keep = if peak > threshold {
                (peak - threshold) / peak
            } else {
                0.0
            };
            data.push(c.map(|v| v * keep));
        }
    }
    Rgb {
        width,
        height,
        data,
    }
}

/// The full 2D Gaussian: every one of the 43x43 texels around each pixel,
/// weighted exp(-(dx^2 + dy^2) / (2 sigma^2)), clamped at the edges.
fn brute_force_gaussian(image: &Rgb, sigma: f64, radius: i64) -> Rgb {
    let one_d = GaussianTaps::discrete(sigma, radius as u32).expect("kernel");
    let w = |d: i64| one_d.weights[d.unsigned_abs() as usize];
    let mut data = Vec::with_capacity(image.data.len());
    for y in 0..image.height as i64 {
        for x in 0..image.width as i64 {
            let mut sum = [0.0; 3];
            for dy in -radius..=radius {
                for dx in -radius..=radius {
                    let weight = w(dx) * w(dy);
                    let t = image.at(x + dx, y + dy);
                    for k in 0..3 {
                        sum[k] += weight * t[k];
                    }
                }
            }
            data.push(sum);
        }
    }
    Rgb {
        width: image.width,
        height: image.height,
        data,
    }
}

#[test]
fn blur_matches_a_brute_force_43x43_gaussian() {
    let gpu = common::gpu();
    let (_, linear) = render(&gpu, &[], 6.0, 0.9);
    let (_, naive) = render(&gpu, &["bloom_naive"], 6.0, 0.9);
    let hdr = named(&linear, "hdr");
    assert!(
        hdr.peak() >= 6.0,
        "the pattern has values above the threshold"
    );

    // Bright pass: the RGBA16F result holds the reference to half precision.
    let bright = named(&linear, "bloom_bright");
    let expected_bright = bright_reference(&hdr, 1.0);
    let bright_error = bright.max_abs_diff(&expected_bright);
    assert!(
        bright_error <= 2e-3 * expected_bright.peak(),
        "bright pass differs by {bright_error}"
    );

    // Blur: compared with the brute-force Gaussian of the bright image the GPU
    // produced, so only the blur's own error is measured. The tolerance covers
    // two roundings to the RGBA16F intermediates (relative 2^-11 each, summed
    // over the taps) and, for the paired taps, the filter's sub-texel weight
    // precision; relative to the peak. Measured on lavapipe: 1.5e-3 for both.
    let reference = brute_force_gaussian(&bright, 9.0, 21);
    let peak = reference.peak();
    let linear_error = named(&linear, "bloom").max_abs_diff(&reference) / peak;
    let naive_error = named(&naive, "bloom").max_abs_diff(&reference) / peak;
    eprintln!("max error relative to peak: linear {linear_error:.2e}, naive {naive_error:.2e}");
    assert!(naive_error <= 2.5e-3, "one tap per texel: {naive_error}");
    assert!(linear_error <= 2.5e-3, "paired taps: {linear_error}");
    common::assert_no_validation_messages(gpu);
}

#[test]
fn nothing_above_the_threshold_comes_out_unchanged() {
    let gpu = common::gpu();
    // Dots at exactly the threshold and a ramp below it.
    let (with_bloom, readbacks) = render(&gpu, &[], 1.0, 0.9);
    let (without_bloom, _) = render(&gpu, &["!bloom"], 1.0, 0.9);
    let bright = named(&readbacks, "bloom_bright");
    assert_eq!(bright.peak(), 0.0, "the bright pass keeps nothing");
    assert_eq!(named(&readbacks, "bloom").peak(), 0.0);
    assert_eq!(with_bloom.pixels, without_bloom.pixels);
    common::assert_no_validation_messages(gpu);
}
