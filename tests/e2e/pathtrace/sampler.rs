//! The path tracer's Sobol sampler (`shaders/pathtrace/random.glsl`), run on
//! the GPU by `tests/graphs/sobol.ron`: 256 samples of 64 pixels, two draws
//! each. The properties that make it lower the variance, and the ones that
//! keep it unbiased, held exactly or to a stated tolerance:
//!
//! - every aligned block of 2^k samples (k = 0..8) of a pixel's draw puts
//!   each of its four numbers alone in a different one of 2^k equal
//!   intervals, and each pair of them in a (t, k, 2)-net: 2^t points in each
//!   of the 2^(k-t) boxes of every shape 2^-a x 2^-(k-t-a). t is the
//!   unscrambled Sobol points' own (0 for the first two numbers, so one
//!   point per box; 1 or 2 for the others), which Owen scrambling keeps;
//! - different pixels are scrambled differently, and a pixel's two draws are
//!   uncorrelated (|r| < 0.04 over 16,384 pairs, 5 standard errors; a
//!   shared scramble would give r near 1).

use std::collections::BTreeMap;

const SAMPLES: usize = 256;
const PIXELS: usize = 64;

/// Point `sample` of `pixel`'s draw, from an image of 4-float texels.
fn point(draw: &[f32], pixel: usize, sample: usize) -> [f32; 4] {
    let at = (pixel * SAMPLES + sample) * 4;
    [draw[at], draw[at + 1], draw[at + 2], draw[at + 3]]
}

/// Pairs of a draw's numbers and the t of the (t, k, 2)-nets that aligned
/// blocks of unscrambled Sobol points form in them (computed from the
/// direction numbers; the same for every k from t to 8).
const PAIR_T: [(usize, usize, u32); 6] = [
    (0, 1, 0),
    (0, 2, 1),
    (0, 3, 2),
    (1, 2, 1),
    (1, 3, 2),
    (2, 3, 2),
];

/// How many of `points` fall in each of `cells` cells, `cell` saying which.
fn cell_counts(points: &[[f32; 4]], cells: usize, cell: impl Fn(&[f32; 4]) -> usize) -> Vec<u32> {
    let mut counts = vec![0u32; cells];
    for p in points {
        counts[cell(p)] += 1;
    }
    counts
}

/// Where `points` fail to be a (t, k, 2)-net in a pair of their numbers, or
/// to stratify each number alone, with k = log2 of their count.
fn net_failures(points: &[[f32; 4]]) -> Vec<String> {
    let k = points.len().trailing_zeros();
    let mut failures = Vec::new();
    for (x, y, t) in PAIR_T.into_iter().filter(|&(_, _, t)| t <= k) {
        for a in 0..=k - t {
            let (columns, rows) = (1usize << a, 1usize << (k - t - a));
            let counts = cell_counts(points, columns * rows, |p| {
                (p[y] * rows as f32) as usize * columns + (p[x] * columns as f32) as usize
            });
            if counts.iter().any(|&n| n != 1 << t) {
                failures.push(format!("numbers {x} and {y}, boxes {columns}x{rows}"));
            }
        }
    }
    let cells = points.len();
    for dimension in 0..4 {
        let counts = cell_counts(points, cells, |p| (p[dimension] * cells as f32) as usize);
        if counts.iter().any(|&n| n != 1) {
            failures.push(format!("number {dimension} alone"));
        }
    }
    failures
}

/// Every aligned block of 2^k of `points` (k = 0..8) that fails
/// [`net_failures`], and how.
fn block_failures(points: &[[f32; 4]]) -> Vec<String> {
    (0..=8)
        .flat_map(|k| points.chunks(1 << k))
        .flat_map(|block| {
            net_failures(block)
                .into_iter()
                .map(move |f| format!("{} samples: {f}", block.len()))
        })
        .collect()
}

/// Pearson's correlation of two equally long series.
fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let cov: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let vx: f64 = x.iter().map(|a| (a - mx) * (a - mx)).sum();
    let vy: f64 = y.iter().map(|b| (b - my) * (b - my)).sum();
    cov / (vx * vy).sqrt()
}

#[test]
fn sobol_draws_stratify_every_power_of_two_block_and_stay_independent() {
    let (first, second) =
        weft_tests::render::fixture_floats("sobol.ron", "second", BTreeMap::new());
    let mut failures = Vec::new();
    for (name, draw) in [("first", &first), ("second", &second)] {
        for pixel in 0..PIXELS {
            let points: Vec<[f32; 4]> = (0..SAMPLES).map(|s| point(draw, pixel, s)).collect();
            assert!(
                points.iter().flatten().all(|&u| (0.0..1.0).contains(&u)),
                "numbers in [0, 1)"
            );
            for failure in block_failures(&points) {
                failures.push(format!("{name} draw, pixel {pixel}, {failure}"));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "{} failures, first: {:?}",
        failures.len(),
        &failures[..failures.len().min(5)]
    );

    let differ = (1..PIXELS)
        .filter(|&p| point(&first, p, 0) != point(&first, 0, 0))
        .count();
    assert_eq!(
        differ,
        PIXELS - 1,
        "each pixel's sample 0 is scrambled differently"
    );
    for dimension in 0..4 {
        let series = |draw: &[f32]| -> Vec<f64> {
            (0..PIXELS * SAMPLES)
                .map(|i| f64::from(draw[i * 4 + dimension]))
                .collect()
        };
        let r = correlation(&series(&first), &series(&second));
        println!("number {dimension}: correlation of the two draws {r:.4}");
        assert!(
            r.abs() < 0.04,
            "number {dimension}: the draws correlate, r = {r}"
        );
    }
}
