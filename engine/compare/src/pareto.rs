//! The Pareto frontier of (time, error) points — the settings no other setting
//! beats on both — and its plot: error against time, every point, the
//! frontier drawn through its points and labelled.

use crate::image_io::ImageError;
use plotters::prelude::*;
use std::path::Path;

/// A measured setting.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// What the setting was (`resolution=1024 radius=2`).
    pub label: String,
    /// Cost: milliseconds per frame (the median).
    pub time: f64,
    /// The frame times' interquartile range, drawn as a bar through the point.
    pub time_iqr: (f64, f64),
    /// Error against the reference.
    pub error: f64,
}

/// Indices of the points on the frontier, by increasing time: each is
/// strictly better than every faster point in error, and no point is at
/// least as good in both with one strictly better. Points with a
/// non-finite coordinate are never on it.
pub fn frontier(points: &[Point]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..points.len())
        .filter(|&i| points[i].time.is_finite() && points[i].error.is_finite())
        .collect();
    order.sort_by(|&a, &b| {
        points[a]
            .time
            .total_cmp(&points[b].time)
            .then(points[a].error.total_cmp(&points[b].error))
    });
    let mut best = f64::INFINITY;
    let mut on = Vec::new();
    for i in order {
        if points[i].error < best {
            best = points[i].error;
            on.push(i);
        }
    }
    on
}

/// Marks for the points off the frontier, in point order: `a`, `b`, …, `z`,
/// `aa`, `ab`, … (the frontier's points are numbered by rank), so every
/// point of a plot can be found in its table.
pub fn dominated_marks(points: &[Point]) -> Vec<(usize, String)> {
    let on = frontier(points);
    (0..points.len())
        .filter(|i| !on.contains(i))
        .enumerate()
        .map(|(n, i)| (i, letters(n)))
        .collect()
}

/// `a` … `z`, then `aa`, `ab`, …: the n-th mark from 0.
fn letters(mut n: usize) -> String {
    let mut out = Vec::new();
    loop {
        out.push(b'a' + (n % 26) as u8);
        if n < 26 {
            break;
        }
        n = n / 26 - 1;
    }
    out.reverse();
    String::from_utf8(out).unwrap_or_default()
}

/// Writes error against time, every point in grey with its frame-time
/// interquartile range, the frontier in red with each of its points numbered
/// 1, 2, ... by increasing time as the frontier table lists them, the others
/// lettered; a budget as a vertical line, and the reference's noise floor as
/// a band above the best error (errors within it are not told apart).
pub fn write_plot(
    points: &[Point],
    title: &str,
    (error_name, budget_ms, noise_floor): (&str, Option<f64>, Option<f64>),
    path: &Path,
) -> Result<(), ImageError> {
    let fail = |e: &dyn std::fmt::Display| ImageError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let usable: Vec<&Point> = points
        .iter()
        .filter(|p| p.time > 0.0 && p.error > 0.0 && p.time.is_finite() && p.error.is_finite())
        .collect();
    if usable.is_empty() {
        return Err(fail(&"no point with a positive time and error to plot"));
    }
    // Each axis padded by a tenth of its span; the error axis also above by
    // two fifths, so the legend in the upper right covers no point.
    let range = |f: &dyn Fn(&Point) -> f64, extra_hi: f64, top: f64| {
        let lo = usable.iter().map(|p| f(p)).fold(f64::INFINITY, f64::min);
        let hi = usable.iter().map(|p| f(p)).fold(extra_hi, f64::max);
        let span = if hi > lo { hi - lo } else { hi };
        ((lo - 0.1 * span).max(0.0), hi + top * span)
    };
    let (t0, _) = range(&|p| p.time_iqr.0.min(p.time), 0.0, 0.1);
    let (_, t1) = range(&|p| p.time_iqr.1.max(p.time), 0.0, 0.1);
    // A budget inside the drawn range is drawn; one beyond it is said in the table.
    let budget = budget_ms.filter(|b| (t0..=t1).contains(b));
    let best = usable.iter().map(|p| p.error).fold(f64::INFINITY, f64::min);
    // The band of errors the reference's own noise cannot tell from the best.
    let band = noise_floor.filter(|f| *f > 0.0).map(|f| (best, best + f));
    let (e0, e1) = range(&|p| p.error, band.map_or(0.0, |b| b.1), 0.4);
    let on = frontier(points);
    crate::report::draw_png(900, 600, path, |root| {
        let mut chart = ChartBuilder::on(root)
            .caption(title, (crate::report::FAMILY, 22))
            .margin(16)
            .x_label_area_size(48)
            .y_label_area_size(72)
            .build_cartesian_2d(t0..t1, e0..e1)
            .map_err(|e| fail(&e))?;
        chart
            .configure_mesh()
            .x_desc("frame time (ms)")
            .y_desc(error_name)
            .label_style((crate::report::FAMILY, 14))
            .draw()
            .map_err(|e| fail(&e))?;
        if let Some((lo, hi)) = band {
            let colour = RGBColor(120, 170, 230);
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(t0, lo), (t1, hi)],
                    colour.mix(0.25).filled(),
                )))
                .map_err(|e| fail(&e))?
                .label(format!(
                    "within the reference noise ({:.4}) of the best",
                    hi - lo
                ))
                .legend(move |(x, y)| {
                    Rectangle::new([(x, y - 5), (x + 20, y + 5)], colour.mix(0.25).filled())
                });
        }
        chart
            .draw_series(usable.iter().map(|p| {
                PathElement::new(
                    vec![(p.time_iqr.0, p.error), (p.time_iqr.1, p.error)],
                    RGBColor(90, 90, 90).stroke_width(1),
                )
            }))
            .map_err(|e| fail(&e))?
            .label("frame time IQR")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RGBColor(90, 90, 90)));
        chart
            .draw_series(
                usable
                    .iter()
                    .map(|p| Circle::new((p.time, p.error), 4, RGBColor(150, 150, 150).filled())),
            )
            .map_err(|e| fail(&e))?
            .label("dominated")
            .legend(|(x, y)| Circle::new((x, y), 4, RGBColor(150, 150, 150).filled()));
        let frontier_points: Vec<(f64, f64)> = on
            .iter()
            .map(|&i| (points[i].time, points[i].error))
            .filter(|(t, e)| *t > 0.0 && *e > 0.0)
            .collect();
        chart
            .draw_series(LineSeries::new(
                frontier_points.clone(),
                RED.stroke_width(2),
            ))
            .map_err(|e| fail(&e))?
            .label("Pareto frontier")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], RED.stroke_width(2)));
        chart
            .draw_series(
                frontier_points
                    .iter()
                    .map(|&(t, e)| Circle::new((t, e), 5, RED.filled())),
            )
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(
                on.iter()
                    .enumerate()
                    .filter(|(_, &i)| points[i].time > 0.0 && points[i].error > 0.0)
                    .map(|(rank, &i)| {
                        EmptyElement::at((points[i].time, points[i].error))
                            + Text::new(
                                (rank + 1).to_string(),
                                (6, -18),
                                (crate::report::FAMILY, 13).into_font().color(&BLACK),
                            )
                    }),
            )
            .map_err(|e| fail(&e))?;
        chart
            .draw_series(
                dominated_marks(points)
                    .into_iter()
                    .filter(|(i, _)| points[*i].time > 0.0 && points[*i].error > 0.0)
                    .map(|(i, mark)| {
                        EmptyElement::at((points[i].time, points[i].error))
                            + Text::new(
                                mark,
                                (6, 4),
                                (crate::report::FAMILY, 12)
                                    .into_font()
                                    .color(&RGBColor(110, 110, 110)),
                            )
                    }),
            )
            .map_err(|e| fail(&e))?;
        if let Some(b) = budget {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    vec![(b, e0), (b, e1)],
                    RGBColor(30, 90, 200).stroke_width(2),
                )))
                .map_err(|e| fail(&e))?
                .label(format!("budget {b} ms"))
                .legend(|(x, y)| {
                    PathElement::new(
                        vec![(x, y), (x + 20, y)],
                        RGBColor(30, 90, 200).stroke_width(2),
                    )
                });
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperRight)
            .border_style(BLACK)
            .background_style(WHITE.mix(0.8))
            .label_font((crate::report::FAMILY, 14))
            .draw()
            .map_err(|e| fail(&e))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(label: &str, time: f64, error: f64) -> Point {
        Point {
            label: label.into(),
            time,
            time_iqr: (time, time),
            error,
        }
    }

    #[test]
    fn every_point_off_the_frontier_gets_a_mark() {
        let points = [
            p("a", 1.0, 0.5),
            p("b", 2.0, 0.6),
            p("c", 3.0, 0.1),
            p("d", 4.0, 0.2),
        ];
        assert_eq!(frontier(&points), [0, 2]);
        assert_eq!(
            dominated_marks(&points),
            [(1, "a".to_string()), (3, "b".to_string())]
        );
        assert_eq!(letters(25), "z");
        assert_eq!(letters(26), "aa");
        assert_eq!(letters(27), "ab");
        assert_eq!(letters(26 + 26 * 26), "aaa");
    }

    #[test]
    fn the_frontier_of_a_known_set() {
        let points = [
            p("a", 10.0, 0.5),
            p("b", 20.0, 0.3),
            p("c", 15.0, 0.6), // slower and worse than a
            p("d", 30.0, 0.3), // ties b's error, slower
            p("e", 40.0, 0.1),
            p("f", 5.0, 0.9),
            p("g", 10.0, 0.7), // ties a's time, worse
            p("h", f64::NAN, 0.0),
        ];
        assert_eq!(frontier(&points), [5, 0, 1, 4]);
        assert!(frontier(&[]).is_empty());
        assert_eq!(frontier(&[p("x", 1.0, 1.0), p("y", 1.0, 1.0)]), [0]);
    }
}
