//! Golden-image comparison: a rendered image against a stored PNG with a
//! stated per-channel tolerance and a mean-error bound; on failure a
//! difference image is written beside the golden (`NAME.diff.png`, ignored by git).

use image::{Rgba, RgbaImage};
use std::path::{Path, PathBuf};

/// How far a rendering may drift from its golden image.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Largest allowed absolute difference of any channel of any pixel (0-255).
    pub per_channel: u8,
    /// Largest allowed mean absolute channel difference over the image.
    pub mean: f64,
}

/// Measured differences between two images.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Comparison {
    /// Largest absolute channel difference of any pixel.
    pub max_difference: u8,
    /// Mean absolute channel difference over the image.
    pub mean_difference: f64,
    /// Pixels with a channel over the per-channel tolerance.
    pub pixels_over: usize,
}

/// Why a golden comparison failed.
#[derive(Debug, thiserror::Error)]
pub enum GoldenError {
    /// No golden image at the path (set `WEFT_UPDATE_GOLDEN=1` to write it).
    #[error("golden image {} is missing; rerun with WEFT_UPDATE_GOLDEN=1 to create it", .0.display())]
    Missing(PathBuf),
    /// The images differ in size.
    #[error("image is {actual:?} but golden {} is {expected:?}", path.display())]
    Size {
        /// The golden image.
        path: PathBuf,
        /// Width and height of the rendering.
        actual: (u32, u32),
        /// Width and height of the golden image.
        expected: (u32, u32),
    },
    /// The images differ by more than the tolerance.
    #[error("{} differs: max channel difference {} (allowed {}), mean {:.4} (allowed {}), {} pixel(s) over; difference image: {}", path.display(), comparison.max_difference, tolerance.per_channel, comparison.mean_difference, tolerance.mean, comparison.pixels_over, diff.display())]
    Mismatch {
        /// The golden image.
        path: PathBuf,
        /// What was measured.
        comparison: Comparison,
        /// What was allowed.
        tolerance: Tolerance,
        /// Where the difference image was written.
        diff: PathBuf,
    },
    /// Reading or writing an image failed.
    #[error("{}: {message}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        message: String,
    },
}

/// Compares two images of equal size channel by channel.
pub fn compare(actual: &RgbaImage, expected: &RgbaImage, tolerance: &Tolerance) -> Comparison {
    let mut max = 0u8;
    let mut sum = 0u64;
    let mut over = 0usize;
    for (a, e) in actual.pixels().zip(expected.pixels()) {
        let mut pixel_max = 0u8;
        for c in 0..4 {
            let d = a.0[c].abs_diff(e.0[c]);
            sum += u64::from(d);
            pixel_max = pixel_max.max(d);
        }
        max = max.max(pixel_max);
        if pixel_max > tolerance.per_channel {
            over += 1;
        }
    }
    let channels = (actual.width() as u64 * actual.height() as u64 * 4).max(1);
    Comparison {
        max_difference: max,
        mean_difference: sum as f64 / channels as f64,
        pixels_over: over,
    }
}

/// The difference image: absolute differences scaled up, pixels over the
/// tolerance in opaque red.
pub fn difference_image(
    actual: &RgbaImage,
    expected: &RgbaImage,
    tolerance: &Tolerance,
) -> RgbaImage {
    let mut out = RgbaImage::new(actual.width(), actual.height());
    for ((a, e), d) in actual.pixels().zip(expected.pixels()).zip(out.pixels_mut()) {
        let diff: Vec<u8> = (0..4).map(|c| a.0[c].abs_diff(e.0[c])).collect();
        let worst = diff.iter().copied().max().unwrap_or(0);
        *d = if worst > tolerance.per_channel {
            Rgba([255, 0, 0, 255])
        } else {
            let scale = |v: u8| v.saturating_mul(16);
            Rgba([scale(diff[0]), scale(diff[1]), scale(diff[2]), 255])
        };
    }
    out
}

/// Where the difference image for a golden path goes.
pub fn diff_path(golden: &Path) -> PathBuf {
    golden.with_extension("diff.png")
}

/// Compares `actual` with the golden PNG at `golden`. With
/// `WEFT_UPDATE_GOLDEN=1` in the environment the golden is (re)written instead.
pub fn check_golden(
    actual: &RgbaImage,
    golden: &Path,
    tolerance: &Tolerance,
) -> Result<Comparison, GoldenError> {
    let io = |e: image::ImageError| GoldenError::Io {
        path: golden.to_path_buf(),
        message: e.to_string(),
    };
    if std::env::var_os("WEFT_UPDATE_GOLDEN").is_some_and(|v| v == "1") {
        actual.save(golden).map_err(io)?;
    }
    if !golden.is_file() {
        return Err(GoldenError::Missing(golden.to_path_buf()));
    }
    let expected = image::open(golden).map_err(io)?.to_rgba8();
    if expected.dimensions() != actual.dimensions() {
        return Err(GoldenError::Size {
            path: golden.to_path_buf(),
            actual: actual.dimensions(),
            expected: expected.dimensions(),
        });
    }
    let comparison = compare(actual, &expected, tolerance);
    let diff = diff_path(golden);
    if comparison.max_difference > tolerance.per_channel
        || comparison.mean_difference > tolerance.mean
    {
        difference_image(actual, &expected, tolerance)
            .save(&diff)
            .map_err(|e| GoldenError::Io {
                path: diff.clone(),
                message: e.to_string(),
            })?;
        return Err(GoldenError::Mismatch {
            path: golden.to_path_buf(),
            comparison,
            tolerance: *tolerance,
            diff,
        });
    }
    if diff.is_file() {
        // A stale difference image from an earlier failure would mislead.
        let _ = std::fs::remove_file(&diff);
    }
    Ok(comparison)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solid(w: u32, h: u32, c: [u8; 4]) -> RgbaImage {
        RgbaImage::from_pixel(w, h, Rgba(c))
    }

    #[test]
    fn measures_max_and_mean() {
        let a = solid(2, 2, [10, 10, 10, 255]);
        let mut b = a.clone();
        b.put_pixel(1, 1, Rgba([14, 10, 10, 255]));
        let c = compare(
            &a,
            &b,
            &Tolerance {
                per_channel: 3,
                mean: 1.0,
            },
        );
        assert_eq!(c.max_difference, 4);
        assert_eq!(c.mean_difference, 4.0 / 16.0);
        assert_eq!(c.pixels_over, 1);
        let d = difference_image(
            &a,
            &b,
            &Tolerance {
                per_channel: 3,
                mean: 1.0,
            },
        );
        assert_eq!(d.get_pixel(1, 1).0, [255, 0, 0, 255]);
        assert_eq!(d.get_pixel(0, 0).0, [0, 0, 0, 255]);
    }

    #[test]
    fn writes_a_difference_image_on_failure() {
        let dir = std::env::temp_dir().join(format!("weft-golden-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let golden = dir.join("g.png");
        solid(4, 4, [0, 0, 0, 255])
            .save(&golden)
            .expect("write golden");
        let tol = Tolerance {
            per_channel: 2,
            mean: 0.5,
        };
        let same =
            check_golden(&solid(4, 4, [1, 0, 0, 255]), &golden, &tol).expect("within tolerance");
        assert_eq!(same.max_difference, 1);
        let err =
            check_golden(&solid(4, 4, [9, 0, 0, 255]), &golden, &tol).expect_err("too different");
        let GoldenError::Mismatch {
            diff, comparison, ..
        } = err
        else {
            panic!("expected a mismatch, got {err}");
        };
        assert_eq!(diff, dir.join("g.diff.png"));
        assert_eq!(comparison.max_difference, 9);
        assert_eq!(comparison.pixels_over, 16);
        let written = image::open(&diff).expect("diff image").to_rgba8();
        assert_eq!(written.get_pixel(2, 2).0, [255, 0, 0, 255]);
        let missing = check_golden(&solid(4, 4, [0; 4]), &dir.join("none.png"), &tol);
        assert!(matches!(missing, Err(GoldenError::Missing(_))));
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
