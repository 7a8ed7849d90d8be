//! A sweep's report: `pareto.png`, error against time with the frontier
//! drawn, and `sweep.md`, the frontier and the dominated points tabled.

use super::folder::NoiseFloor;
use anyhow::Result;
use std::path::Path;
use weft_compare::pareto::{dominated_marks, frontier, write_plot, Point};
use weft_compare::report::{within_budget, within_noise};
use weft_compare::sweep::SweepRow;

/// sweep.md's paragraph on the noise floor: which points' HDR-FLIP lies
/// within it of the most accurate point's, so no one ranks them by accuracy.
fn noise_floor_note((seed, floor): NoiseFloor, labels: &[(String, f64)]) -> String {
    let (best, tied) = within_noise(floor, labels.iter().map(|(l, f)| (l.as_str(), *f)));
    format!(
        "Reference noise floor: HDR-FLIP {floor:.4} between the reference and its render with seed {seed}. \
         Points whose HDR-FLIP differs by less are not told apart by this reference; within it of the most accurate ({best:.4}): {}.\n\n",
        tied.join(", ")
    )
}

/// `pareto.png` and `sweep.md` for the measured points `rows` of a sweep of
/// `scene` through `graph`: the frontier plotted and tabled.
pub(super) fn write_report(
    out: &Path,
    (scene, graph): (&str, &str),
    rows: &[&SweepRow],
    (budget_ms, noise_floor): (Option<f64>, Option<NoiseFloor>),
) -> Result<()> {
    let plotted: Vec<Point> = rows
        .iter()
        .map(|r| Point {
            label: r.point.label(),
            time: r.frame_ms,
            time_iqr: r.frame_iqr,
            error: r.flip,
        })
        .collect();
    let on = frontier(&plotted);
    // The plot's title names graphs by file stem, as its points are labelled.
    let stems: Vec<String> = graph
        .split(", ")
        .map(|g| {
            Path::new(g)
                .file_stem()
                .map_or_else(|| g.to_string(), |s| s.to_string_lossy().into_owned())
        })
        .collect();
    // Error and time are drawn on log axes: a point with an HDR-FLIP of 0
    // (the reference itself) has no place there, and a sweep of only such
    // points still gets its table.
    let drawable = plotted
        .iter()
        .any(|p| p.time > 0.0 && p.error > 0.0 && p.time.is_finite() && p.error.is_finite());
    let plot = out.join("pareto.png");
    if drawable {
        write_plot(
            &plotted,
            &format!("{}: HDR-FLIP against frame time", stems.join(", ")),
            ("HDR-FLIP", budget_ms, noise_floor.map(|(_, flip)| flip)),
            &plot,
        )?;
    } else if let Err(e) = std::fs::remove_file(&plot) {
        if e.kind() != std::io::ErrorKind::NotFound {
            return Err(e.into());
        }
    }
    let mut table = format!("# weft sweep: {scene} through {graph}\n\n");
    if let Some(budget) = budget_ms {
        let labels: Vec<String> = rows.iter().map(|r| r.point.label()).collect();
        let candidates = rows
            .iter()
            .zip(&labels)
            .map(|(r, label)| (label.as_str(), r.flip, r.frame_ms));
        table += &within_budget(budget, candidates, "point");
        table += "\n\n";
    }
    table += &format!(
        "Pareto frontier of HDR-FLIP against frame time ({} of {} points; the rest are dominated):\n\n| # | setting | HDR-FLIP | RMSE | frame ms: median (IQR) | device (MiB) |\n|---|---|---|---|---|---|\n",
        on.len(),
        rows.len()
    );
    let mut marked: Vec<(String, f64)> = Vec::new();
    for (rank, &i) in on.iter().enumerate() {
        let mark = format!("#{}", rank + 1);
        table += &table_row(&mark[1..], rows[i]);
        marked.push((mark, rows[i].flip));
    }
    let dominated = dominated_marks(&plotted);
    if !dominated.is_empty() {
        table += "\nDominated points (another point is both faster and more accurate):\n\n| mark | setting | HDR-FLIP | RMSE | frame ms: median (IQR) | device (MiB) |\n|---|---|---|---|---|---|\n";
        for (i, mark) in &dominated {
            table += &table_row(mark, rows[*i]);
            marked.push((mark.clone(), rows[*i].flip));
        }
    }
    if let Some(floor) = noise_floor {
        table += "\n";
        table += &noise_floor_note(floor, &marked);
    }
    if drawable {
        table += "\nThe numbers and letters label the points in `pareto.png`.\n\n![error against time](pareto.png)\n";
    } else {
        table += "\nNo `pareto.png`: no point has both an HDR-FLIP and a frame time above 0 (an HDR-FLIP of 0 matches the reference exactly), and the plot's axes are logarithmic.\n";
    }
    weft_io::write_output(&out.join("sweep.md"), table.as_bytes())?;
    print!("{table}");
    println!("wrote {}", out.display());
    Ok(())
}

/// One point's line in sweep.md's tables, under its number or letter.
fn table_row(label: &str, r: &SweepRow) -> String {
    format!(
        "| {label} | {} | {:.4} | {:.4e} | {:.2} ({:.2}–{:.2}) | {:.1} |\n",
        r.point.label(),
        r.flip,
        r.rmse,
        r.frame_ms,
        r.frame_iqr.0,
        r.frame_iqr.1,
        r.device_bytes as f64 / (1024.0 * 1024.0)
    )
}
