//! A sweep's grid (`sweep.grid`: every point of the whole sweep, in the order
//! it measures them) and the check every resumed or merged `sweep.csv`
//! passes: each point measured once and, where the grid is known, each a
//! point of it that the folder's shard measures.

use super::{cells, header_with, point_of, SweepError, SweepPoint, SweepRow};
use std::collections::HashMap;
use std::path::Path;

/// The file beside `sweep.csv` that lists the sweep's grid.
pub const GRID_FILE: &str = "sweep.grid";

/// The largest grid file read back.
const MAX_GRID_BYTES: u64 = 256 << 20;

/// `sweep.grid`'s text for `points` over the columns `names`: a header of
/// the names and `features`, then a line per point in the sweep's order.
pub fn grid_document(names: &[String], points: &[SweepPoint]) -> String {
    points.iter().fold(header_with(names, 1) + "\n", |text, p| {
        text + cells(p, names).join(",").as_str() + "\n"
    })
}

/// The grid in `path`, written by [`grid_document`] for `names`.
pub fn read_grid(path: &Path, names: &[String]) -> Result<Vec<SweepPoint>, SweepError> {
    let shown = path.display().to_string();
    let text = weft_io::read_text(path, MAX_GRID_BYTES).map_err(|e| SweepError::Io {
        path: shown.clone(),
        source: e.into_io(),
    })?;
    let mut lines = text.lines().enumerate();
    let expected = header_with(names, 1);
    match lines.next() {
        Some((_, found)) if found == expected => {}
        found => {
            return Err(SweepError::Format {
                path: shown,
                line: 1,
                message: format!(
                    "the header is \"{}\", but this sweep's grid is \"{expected}\"",
                    found.map_or("", |(_, f)| f)
                ),
            })
        }
    }
    lines
        .map(|(i, line)| {
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != names.len() + 1 {
                return Err(SweepError::Format {
                    path: shown.clone(),
                    line: i + 1,
                    message: format!("{} fields, expected {}", fields.len(), names.len() + 1),
                });
            }
            Ok(point_of(names, &fields))
        })
        .collect()
}

/// A sweep's grid and which of its points (by index) a folder measures.
pub type Owned<'a> = (&'a [SweepPoint], &'a dyn Fn(usize) -> bool);

/// An error unless every row of `path` (row i on line i + 2) is a point
/// measured once and, when `grid` is given, a point of it whose index
/// `owned` holds (the points of the folder's shard).
pub fn check_rows(
    path: &Path,
    rows: &[SweepRow],
    grid: Option<Owned<'_>>,
) -> Result<(), SweepError> {
    let index: HashMap<&SweepPoint, usize> = grid
        .map(|(points, _)| points.iter().enumerate().map(|(i, p)| (p, i)).collect())
        .unwrap_or_default();
    let mut seen: HashMap<&SweepPoint, usize> = HashMap::new();
    for (i, row) in rows.iter().enumerate() {
        let line = i + 2;
        let bad = |message: String| SweepError::Format {
            path: path.display().to_string(),
            line,
            message,
        };
        if let Some(first) = seen.insert(&row.point, line) {
            return Err(bad(format!(
                "point \"{}\" is measured twice (lines {first} and {line}); remove one of them",
                row.point.label()
            )));
        }
        if let Some((_, owned)) = grid {
            match index.get(&row.point) {
                None => {
                    return Err(bad(format!(
                        "point \"{}\" is not in this sweep's grid ({GRID_FILE})",
                        row.point.label()
                    )))
                }
                Some(&at) if !owned(at) => {
                    return Err(bad(format!(
                        "point \"{}\" (number {} of the grid) belongs to another shard",
                        row.point.label(),
                        at + 1
                    )))
                }
                Some(_) => {}
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(radius: &str) -> SweepPoint {
        SweepPoint {
            graph: None,
            params: [("radius".to_string(), radius.to_string())].into(),
            features: String::new(),
        }
    }

    fn row(radius: &str) -> SweepRow {
        SweepRow {
            point: point(radius),
            flip: 0.5,
            rmse: 0.25,
            frame_ms: 2.0,
            device_bytes: 7,
            frame_iqr: (1.5, 2.5),
        }
    }

    #[test]
    fn the_grid_round_trips() {
        let dir = std::env::temp_dir().join(format!("weft-sweep-grid-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let names = vec!["radius".to_string()];
        let grid = vec![point("1"), point("2"), point("3")];
        let text = grid_document(&names, &grid);
        assert_eq!(text, "radius,features\n1,\n2,\n3,\n");
        std::fs::write(dir.join(GRID_FILE), &text).expect("write");
        assert_eq!(read_grid(&dir.join(GRID_FILE), &names).expect("read"), grid);
        let other = vec!["size".to_string()];
        let error = read_grid(&dir.join(GRID_FILE), &other).expect_err("other columns");
        assert!(
            error
                .to_string()
                .contains(":1: the header is \"radius,features\""),
            "{error}"
        );
        std::fs::remove_dir_all(&dir).expect("clean up");
    }

    #[test]
    fn rows_are_measured_once_in_the_grid_and_the_shard() {
        let path = Path::new("s/sweep.csv");
        let grid = vec![point("1"), point("2"), point("3"), point("4")];
        let first_of_two = |i: usize| i.is_multiple_of(2);
        assert!(check_rows(path, &[row("1"), row("3")], Some((&grid, &first_of_two))).is_ok());
        let twice = check_rows(path, &[row("1"), row("3"), row("1")], None).expect_err("twice");
        assert_eq!(
            twice.to_string(),
            "s/sweep.csv:4: point \"radius=1\" is measured twice (lines 2 and 4); remove one of them"
        );
        let outside =
            check_rows(path, &[row("9")], Some((&grid, &first_of_two))).expect_err("outside");
        assert_eq!(
            outside.to_string(),
            "s/sweep.csv:2: point \"radius=9\" is not in this sweep's grid (sweep.grid)"
        );
        let other =
            check_rows(path, &[row("2")], Some((&grid, &first_of_two))).expect_err("other shard");
        assert_eq!(
            other.to_string(),
            "s/sweep.csv:2: point \"radius=2\" (number 2 of the grid) belongs to another shard"
        );
    }
}
