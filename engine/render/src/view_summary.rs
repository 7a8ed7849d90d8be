//! The numbers `weft render --json` prints for a debug view (a graph's
//! `views`): mean, median, p95, max, a histogram and the share of pixels
//! above the view's threshold, from the view's single-channel image.
//!
//! Counts (`R32_UINT`: overdraw, overshading, lights per pixel) are summarised
//! over every pixel, since 0 is a real count (nothing drawn there); their
//! quantiles, maximum and total are exact integers and their histogram has one
//! bin per count (wider bins, still whole numbers, past 64 bins). Measures
//! (`R32_SFLOAT`: triangles per pixel) are summarised over the pixels that
//! hold one (finite and above 0; 0 is "no surface"), with a histogram in
//! powers of two.

use serde::Serialize;
use weft_gpu::readback::{Pixels, Readback};
use weft_graph::Plan;

/// Most bins a count histogram has before bins widen.
const MAX_COUNT_BINS: u64 = 64;
/// Measures' histogram: powers of two from 2^-LOG2_SPAN to 2^LOG2_SPAN, plus
/// a bin each side for what lies beyond.
const LOG2_SPAN: i32 = 10;

/// One histogram bin: values `from <= v < to` (`to` is `null` for the last,
/// open bin of a measure; counts' `to` is exclusive too).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bin {
    /// Smallest value in the bin.
    pub from: f64,
    /// The bin's exclusive end; `None` when open-ended.
    pub to: Option<f64>,
    /// Pixels in the bin.
    pub pixels: u64,
}

/// A view's summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViewSummary {
    /// `count` (integers, every pixel) or `measure` (floats, pixels that hold one).
    pub kind: &'static str,
    /// Pixels summarised.
    pub pixels: u64,
    /// Sum over those pixels (exact for counts).
    pub total: f64,
    /// `total / pixels`.
    pub mean: f64,
    /// The nearest-rank median.
    pub median: f64,
    /// The nearest-rank 95th percentile.
    pub p95: f64,
    /// The largest value.
    pub max: f64,
    /// The view's threshold (`share_above`).
    pub threshold: f64,
    /// Share of the summarised pixels whose value is above `threshold`.
    pub share_above: f64,
    /// Counts or powers of two, low to high.
    pub histogram: Vec<Bin>,
}

/// The summaries of a plan's views, by name in declaration order, from the
/// images a frame read back (views whose image was not read back are left out).
pub fn plan_views(plan: &Plan, readbacks: &[(String, Readback)]) -> Vec<(String, ViewSummary)> {
    plan.views
        .iter()
        .filter_map(|v| {
            let image = &plan.resources[v.image].name;
            let (_, readback) = readbacks.iter().find(|(name, _)| name == image)?;
            Some((v.name.clone(), summarise(&readback.pixels, v.threshold)?))
        })
        .collect()
}

/// Summarises a view's pixels; `None` for colour images, which are not views.
pub fn summarise(pixels: &Pixels, threshold: f64) -> Option<ViewSummary> {
    match pixels {
        Pixels::CountU32(counts) => Some(counts_summary(counts, threshold)),
        Pixels::ValueF32(values) => Some(measures_summary(values, threshold)),
        Pixels::Rgba8(_) | Pixels::RgbaF32(_) => None,
    }
}

/// The value at quantile `q` of sorted values: the smallest value with at
/// least `q` of them at or below it (nearest rank, so counts stay integers).
fn quantile<T: Copy>(sorted: &[T], q: f64) -> Option<T> {
    let n = sorted.len();
    if n == 0 {
        return None;
    }
    let rank = ((q * n as f64).ceil() as usize).clamp(1, n);
    Some(sorted[rank - 1])
}

fn counts_summary(counts: &[u32], threshold: f64) -> ViewSummary {
    let mut sorted = counts.to_vec();
    sorted.sort_unstable();
    let total: u64 = counts.iter().map(|&c| u64::from(c)).sum();
    let max = sorted.last().copied().unwrap_or(0);
    let width = (u64::from(max) + 1).div_ceil(MAX_COUNT_BINS).max(1);
    let bins = (u64::from(max) + 1).div_ceil(width);
    let mut histogram: Vec<Bin> = (0..bins)
        .map(|b| Bin {
            from: (b * width) as f64,
            to: Some(((b + 1) * width) as f64),
            pixels: 0,
        })
        .collect();
    for &c in counts {
        histogram[(u64::from(c) / width) as usize].pixels += 1;
    }
    let n = counts.len() as u64;
    let above = counts.iter().filter(|&&c| f64::from(c) > threshold).count() as u64;
    ViewSummary {
        kind: "count",
        pixels: n,
        total: total as f64,
        mean: if n > 0 { total as f64 / n as f64 } else { 0.0 },
        median: f64::from(quantile(&sorted, 0.5).unwrap_or(0)),
        p95: f64::from(quantile(&sorted, 0.95).unwrap_or(0)),
        max: f64::from(max),
        threshold,
        share_above: if n > 0 { above as f64 / n as f64 } else { 0.0 },
        histogram,
    }
}

fn measures_summary(values: &[f32], threshold: f64) -> ViewSummary {
    let mut sorted: Vec<f64> = values
        .iter()
        .filter(|v| v.is_finite() && **v > 0.0)
        .map(|&v| f64::from(v))
        .collect();
    sorted.sort_unstable_by(f64::total_cmp);
    let n = sorted.len() as u64;
    let total: f64 = sorted.iter().sum();
    let edges: Vec<f64> = (-LOG2_SPAN..=LOG2_SPAN).map(|e| 2f64.powi(e)).collect();
    let mut histogram = vec![Bin {
        from: 0.0,
        to: Some(edges[0]),
        pixels: 0,
    }];
    histogram.extend(edges.windows(2).map(|w| Bin {
        from: w[0],
        to: Some(w[1]),
        pixels: 0,
    }));
    histogram.push(Bin {
        from: edges[edges.len() - 1],
        to: None,
        pixels: 0,
    });
    for &v in &sorted {
        let bin = edges.partition_point(|&e| e <= v);
        histogram[bin].pixels += 1;
    }
    let above = sorted.iter().filter(|&&v| v > threshold).count() as u64;
    ViewSummary {
        kind: "measure",
        pixels: n,
        total,
        mean: if n > 0 { total / n as f64 } else { 0.0 },
        median: quantile(&sorted, 0.5).unwrap_or(0.0),
        p95: quantile(&sorted, 0.95).unwrap_or(0.0),
        max: sorted.last().copied().unwrap_or(0.0),
        threshold,
        share_above: if n > 0 { above as f64 / n as f64 } else { 0.0 },
        histogram,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_are_summarised_exactly_over_every_pixel() {
        // 10 pixels: 0 x3, 1 x2, 2 x2, 5 x2, 9 x1.
        let counts = [0, 0, 0, 1, 1, 2, 2, 5, 5, 9];
        let s = summarise(&Pixels::CountU32(counts.to_vec()), 2.0).unwrap();
        assert_eq!(s.kind, "count");
        assert_eq!(s.pixels, 10);
        assert_eq!(s.total, 25.0);
        assert_eq!(s.mean, 2.5);
        assert_eq!(s.median, 1.0, "the 5th of 10 sorted values");
        assert_eq!(s.p95, 9.0, "the 10th of 10");
        assert_eq!(s.max, 9.0);
        assert_eq!(s.share_above, 0.3, "5, 5 and 9 exceed 2");
        assert_eq!(s.histogram.len(), 10, "one bin per count 0..=9");
        let pixels: Vec<u64> = s.histogram.iter().map(|b| b.pixels).collect();
        assert_eq!(pixels, [3, 2, 2, 0, 0, 2, 0, 0, 0, 1]);
        assert_eq!((s.histogram[5].from, s.histogram[5].to), (5.0, Some(6.0)));
    }

    #[test]
    fn large_counts_share_wider_whole_bins() {
        let counts: Vec<u32> = (0..1000).collect();
        let s = summarise(&Pixels::CountU32(counts), 500.0).unwrap();
        assert_eq!(s.histogram.len(), 63, "bins 16 wide cover 0..1008");
        assert!(s.histogram.iter().all(|b| b.to.unwrap() - b.from == 16.0));
        assert_eq!(s.histogram.iter().map(|b| b.pixels).sum::<u64>(), 1000);
        assert_eq!(s.histogram[62].pixels, 8, "992..1008 holds 992..=999");
        assert_eq!(s.median, 499.0);
        assert_eq!(s.share_above, 0.499);
    }

    #[test]
    fn measures_skip_pixels_without_a_surface() {
        let values = [0.0, 0.0, f32::NAN, 0.25, 1.0, 1.5, 4.0, 4096.0];
        let s = summarise(&Pixels::ValueF32(values.to_vec()), 1.0).unwrap();
        assert_eq!(s.kind, "measure");
        assert_eq!(s.pixels, 5);
        assert_eq!(s.median, 1.5);
        assert_eq!(s.max, 4096.0);
        assert_eq!(s.share_above, 0.6);
        let find = |v: f64| {
            s.histogram
                .iter()
                .position(|b| b.from <= v && b.to.is_none_or(|t| v < t))
                .unwrap()
        };
        assert_eq!(s.histogram[find(0.25)].pixels, 1);
        assert_eq!(s.histogram[find(1.0)].from, 1.0, "1 opens the [1, 2) bin");
        assert_eq!(s.histogram[find(1.0)].pixels, 2, "1.0 and 1.5");
        assert_eq!(s.histogram.last().unwrap().pixels, 1, "4096 is past 2^10");
        assert_eq!(s.histogram.iter().map(|b| b.pixels).sum::<u64>(), 5);
    }

    #[test]
    fn colour_images_are_not_views() {
        assert!(summarise(&Pixels::Rgba8(vec![0; 4]), 1.0).is_none());
    }
}
