//! The points of a sweep (the cartesian product of graphs, parameter values
//! and feature sets) and `sweep.csv`, one row per measured point, which makes
//! a sweep resumable: points already in the file are skipped when it runs
//! again.

use std::collections::BTreeMap;
use std::path::Path;

mod grid;

pub use grid::{check_rows, grid_document, read_grid, Owned, GRID_FILE};

/// The CSV column naming each point's graph, in a sweep over several graphs
/// (first, before the parameters); a single-graph sweep has none.
pub const GRAPH_COLUMN: &str = "graph";

/// One setting of a sweep.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SweepPoint {
    /// The graph's path as given, in a sweep over several graphs.
    pub graph: Option<String>,
    /// Parameter values by name, as given.
    pub params: BTreeMap<String, String>,
    /// Feature toggles, space-separated (`bloom !shadows`), empty for none.
    pub features: String,
}

impl SweepPoint {
    /// A short label: the graph's file stem (in a sweep over graphs), the
    /// `name=value` pairs, then the features.
    pub fn label(&self) -> String {
        let graph = self.graph.as_deref().map(|g| {
            Path::new(g)
                .file_stem()
                .map_or_else(|| g.to_string(), |s| s.to_string_lossy().into_owned())
        });
        let mut parts: Vec<String> = graph
            .into_iter()
            .chain(self.params.iter().map(|(k, v)| format!("{k}={v}")))
            .collect();
        if !self.features.is_empty() {
            parts.push(format!("[{}]", self.features));
        }
        parts.join(" ")
    }
}

/// A measured point.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepRow {
    /// The setting.
    pub point: SweepPoint,
    /// HDR-FLIP against the reference.
    pub flip: f64,
    /// RMSE in linear HDR.
    pub rmse: f64,
    /// Median milliseconds per frame.
    pub frame_ms: f64,
    /// Device memory allocated, bytes.
    pub device_bytes: u64,
    /// The frame times' interquartile range (first and third quartile);
    /// both the median for rows written before sweeps recorded it.
    pub frame_iqr: (f64, f64),
}

/// The columns after the parameters, as written now; [`OLD_COLUMNS`] is the
/// form before the interquartile range was recorded, still read.
const COLUMNS: [&str; 7] = [
    "features",
    "flip",
    "rmse",
    "frame_ms",
    "device_bytes",
    "frame_p25",
    "frame_p75",
];
const OLD_COLUMNS: usize = 5;

/// Why `sweep.csv` could not be used.
#[derive(Debug, thiserror::Error)]
pub enum SweepError {
    /// Reading or writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// The file belongs to another sweep, or is damaged.
    #[error("{path}:{line}: {message}")]
    Format {
        /// The file.
        path: String,
        /// 1-based line.
        line: usize,
        /// What was wrong.
        message: String,
    },
}

/// What a point gives a graph, which `points` asks a graph has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting<'a> {
    /// A parameter, by name.
    Param(&'a str),
    /// A feature toggle (`name` on, `!name` off).
    Toggle(&'a str),
}

/// Every point of the product of `graphs` (an empty list means the sweep's
/// one graph), `params` (name, values) and `feature_sets` (an empty list
/// means one set with no toggles; each set's toggles space-separated), in
/// order: the last parameter varies fastest, then graphs, feature sets
/// slowest. Each graph is swept over what `takes(graph, setting)` says it
/// has (`None`: the sweep's one graph): the parameters it has, and the
/// feature sets whose every toggle names one of its features, so graphs with
/// different parameters and features share one sweep.
pub fn points(
    graphs: &[String],
    params: &[(String, Vec<String>)],
    feature_sets: &[String],
    takes: &dyn Fn(Option<&str>, Setting<'_>) -> bool,
) -> Vec<SweepPoint> {
    let sets: Vec<String> = if feature_sets.is_empty() {
        vec![String::new()]
    } else {
        feature_sets.to_vec()
    };
    let graphs: Vec<Option<String>> = if graphs.is_empty() {
        vec![None]
    } else {
        graphs.iter().cloned().map(Some).collect()
    };
    let mut out = Vec::new();
    for (features, graph) in sets.iter().flat_map(|f| graphs.iter().map(move |g| (f, g))) {
        if !features
            .split_whitespace()
            .all(|t| takes(graph.as_deref(), Setting::Toggle(t)))
        {
            continue;
        }
        let mut partial = vec![BTreeMap::new()];
        for (name, values) in params
            .iter()
            .filter(|(name, _)| takes(graph.as_deref(), Setting::Param(name)))
        {
            partial = partial
                .into_iter()
                .flat_map(|p: BTreeMap<String, String>| {
                    values.iter().map(move |v| {
                        let mut p = p.clone();
                        p.insert(name.clone(), v.clone());
                        p
                    })
                })
                .collect();
        }
        out.extend(partial.into_iter().map(|params| SweepPoint {
            graph: graph.clone(),
            params,
            features: features.clone(),
        }));
    }
    out
}

/// The CSV header for a sweep over `names` (the columns before `features`:
/// [`GRAPH_COLUMN`] in a sweep over graphs, then the parameters).
pub fn header(names: &[String]) -> String {
    header_with(names, COLUMNS.len())
}

fn header_with(names: &[String], columns: usize) -> String {
    let mut all: Vec<String> = names.to_vec();
    all.extend(COLUMNS[..columns].iter().map(|c| c.to_string()));
    all.join(",")
}

/// A point's cells: one per name (its graph, its parameters' values, empty
/// for a parameter its graph does not have), then its features.
fn cells(point: &SweepPoint, names: &[String]) -> Vec<String> {
    let mut fields: Vec<String> = names
        .iter()
        .map(|n| match n.as_str() {
            GRAPH_COLUMN => point.graph.clone().unwrap_or_default(),
            _ => point.params.get(n).cloned().unwrap_or_default(),
        })
        .collect();
    fields.push(point.features.clone());
    fields
}

/// The point whose [`cells`] are `fields` (its names' cells, then features).
fn point_of(names: &[String], fields: &[&str]) -> SweepPoint {
    let named = || names.iter().zip(fields);
    SweepPoint {
        graph: named()
            .find(|(name, _)| *name == GRAPH_COLUMN)
            .map(|(_, g)| g.to_string()),
        // An empty cell: a parameter this point's graph does not have.
        params: named()
            .filter(|(name, v)| *name != GRAPH_COLUMN && !v.is_empty())
            .map(|(name, v)| (name.clone(), v.to_string()))
            .collect(),
        features: fields
            .get(names.len())
            .copied()
            .unwrap_or_default()
            .to_string(),
    }
}

/// One CSV line.
pub fn line(row: &SweepRow, names: &[String]) -> String {
    let mut fields = cells(&row.point, names);
    fields.push(format!("{:.6}", row.flip));
    fields.push(format!("{:.6e}", row.rmse));
    fields.push(format!("{:.3}", row.frame_ms));
    fields.push(row.device_bytes.to_string());
    fields.push(format!("{:.3}", row.frame_iqr.0));
    fields.push(format!("{:.3}", row.frame_iqr.1));
    fields.join(",")
}

/// A whole `sweep.csv`: the header for `names`, then a line per row.
pub fn document<'a>(names: &[String], rows: impl IntoIterator<Item = &'a SweepRow>) -> String {
    rows.into_iter().fold(header(names) + "\n", |text, r| {
        text + line(r, names).as_str() + "\n"
    })
}

/// The largest sweep CSV read back (a million rows of a few dozen columns).
const MAX_CSV_BYTES: u64 = 1 << 30;

/// The rows already in `path` (none when it does not exist), from a file in
/// the current form or in the form before the interquartile range was
/// recorded, and whether it is in that old form (so appending to it needs it
/// rewritten first). A file whose header is not this sweep's is an error,
/// not silently mixed in.
pub fn read_with_form(path: &Path, names: &[String]) -> Result<(Vec<SweepRow>, bool), SweepError> {
    match weft_io::read_text(path, MAX_CSV_BYTES) {
        Err(weft_io::ReadError::Missing { .. }) => Ok((Vec::new(), false)),
        text => parse(path, &text.map_err(|e| io_error(path, e))?, names),
    }
}

/// A sweep.csv that must exist, with the names its header gives (the
/// columns before `features`), and its rows.
pub fn read_named(path: &Path) -> Result<(Vec<String>, Vec<SweepRow>), SweepError> {
    let text = weft_io::read_text(path, MAX_CSV_BYTES).map_err(|e| io_error(path, e))?;
    let names: Vec<String> = text
        .lines()
        .next()
        .unwrap_or_default()
        .split(',')
        .take_while(|c| *c != "features")
        .map(String::from)
        .collect();
    let (rows, _) = parse(path, &text, &names)?;
    Ok((names, rows))
}

fn io_error(path: &Path, e: weft_io::ReadError) -> SweepError {
    SweepError::Io {
        path: path.display().to_string(),
        source: e.into_io(),
    }
}

/// The rows of sweep.csv text for `names`, and whether it is in the old form.
fn parse(path: &Path, text: &str, names: &[String]) -> Result<(Vec<SweepRow>, bool), SweepError> {
    let shown = path.display().to_string();
    let mut lines = text.lines().enumerate();
    let expected = header(names);
    let columns = match lines.next() {
        Some((_, found)) if found == expected => COLUMNS.len(),
        Some((_, found)) if found == header_with(names, OLD_COLUMNS) => OLD_COLUMNS,
        Some((_, found)) => {
            return Err(SweepError::Format {
                path: shown,
                line: 1,
                message: format!(
                    "the header is \"{found}\", but this sweep writes \"{expected}\"; use another --out or remove the file"
                ),
            })
        }
        None => return Ok((Vec::new(), false)),
    };
    let mut rows = Vec::new();
    for (i, text) in lines {
        let fields: Vec<&str> = text.split(',').collect();
        let bad = |message: String| SweepError::Format {
            path: shown.clone(),
            line: i + 1,
            message,
        };
        if fields.len() != names.len() + columns {
            return Err(bad(format!(
                "{} fields, expected {}",
                fields.len(),
                names.len() + columns
            )));
        }
        // A measure is a finite number of at least 0: NaN or a negative
        // time would sort anywhere on the frontier.
        let number = |s: &str| match s.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
            Ok(_) => Err(bad(format!("\"{s}\" is not a finite number of at least 0"))),
            Err(_) => Err(bad(format!("\"{s}\" is not a number"))),
        };
        let n = names.len();
        rows.push(SweepRow {
            point: point_of(names, &fields),
            flip: number(fields[n + 1])?,
            rmse: number(fields[n + 2])?,
            frame_ms: number(fields[n + 3])?,
            device_bytes: fields[n + 4]
                .parse()
                .map_err(|_| bad(format!("\"{}\" is not a byte count", fields[n + 4])))?,
            frame_iqr: if columns == OLD_COLUMNS {
                let median = number(fields[n + 3])?;
                (median, median)
            } else {
                (number(fields[n + 5])?, number(fields[n + 6])?)
            },
        });
    }
    Ok((rows, columns == OLD_COLUMNS))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rows alone.
    fn read(path: &Path, names: &[String]) -> Result<Vec<SweepRow>, SweepError> {
        Ok(read_with_form(path, names)?.0)
    }

    #[test]
    fn points_are_the_cartesian_product() {
        let params = vec![
            ("a".to_string(), vec!["1".to_string(), "2".to_string()]),
            (
                "b".to_string(),
                vec!["x".to_string(), "y".to_string(), "z".to_string()],
            ),
        ];
        let every = |_: Option<&str>, _: Setting| true;
        let all = points(&[], &params, &["".into(), "bloom".into()], &every);
        assert_eq!(all.len(), 12);
        assert_eq!(all[0].label(), "a=1 b=x");
        assert_eq!(all[1].label(), "a=1 b=y");
        assert_eq!(all[6].label(), "a=1 b=x [bloom]");
        assert_eq!(points(&[], &[], &[], &every).len(), 1);
        let graphs = ["graphs/forward.ron".to_string(), "deferred.ron".to_string()];
        let all = points(&graphs, &params[..1], &["".into(), "bloom".into()], &every);
        let labels: Vec<String> = all.iter().map(SweepPoint::label).collect();
        assert_eq!(
            labels,
            [
                "forward a=1",
                "forward a=2",
                "deferred a=1",
                "deferred a=2",
                "forward a=1 [bloom]",
                "forward a=2 [bloom]",
                "deferred a=1 [bloom]",
                "deferred a=2 [bloom]"
            ]
        );
        assert_eq!(all[0].graph.as_deref(), Some("graphs/forward.ron"));
    }

    /// A graph is swept over the parameters it has, once when it has none
    /// of them; its CSV cells for the others are empty and read back absent.
    #[test]
    fn each_graph_is_swept_over_the_parameters_it_has() {
        let params = vec![("spf".to_string(), vec!["1".to_string(), "4".to_string()])];
        let graphs = ["forward.ron".to_string(), "denoised.ron".to_string()];
        let takes = |graph: Option<&str>, setting: Setting| {
            graph == Some("denoised.ron") && setting == Setting::Param("spf")
        };
        let all = points(&graphs, &params, &[], &takes);
        let labels: Vec<String> = all.iter().map(SweepPoint::label).collect();
        assert_eq!(labels, ["forward", "denoised spf=1", "denoised spf=4"]);
        let names = vec![GRAPH_COLUMN.to_string(), "spf".to_string()];
        let rows: Vec<SweepRow> = all
            .iter()
            .map(|point| SweepRow {
                point: point.clone(),
                flip: 0.5,
                rmse: 0.25,
                frame_ms: 2.0,
                device_bytes: 7,
                frame_iqr: (1.5, 2.5),
            })
            .collect();
        let text = document(&names, &rows);
        assert!(text.contains("\nforward.ron,,,0.500000,"), "{text}");
        let (read, old) = parse(Path::new("sweep.csv"), &text, &names).expect("parses");
        assert!(!old);
        assert_eq!(read, rows);
    }

    /// A feature set is swept on the graphs that know each of its toggles:
    /// the empty set on every graph, `!gi` only where `gi` is a feature.
    #[test]
    fn each_graph_is_swept_over_the_feature_sets_it_knows() {
        let graphs = ["forward.ron".to_string(), "hybrid.ron".to_string()];
        let sets = [
            "".to_string(),
            "!gi".to_string(),
            "!gi rt_shadows".to_string(),
        ];
        let takes = |graph: Option<&str>, setting: Setting| match setting {
            Setting::Toggle(t) => graph == Some("hybrid.ron") || t == "rt_shadows",
            Setting::Param(_) => true,
        };
        let labels: Vec<String> = points(&graphs, &[], &sets, &takes)
            .iter()
            .map(SweepPoint::label)
            .collect();
        assert_eq!(
            labels,
            [
                "forward",
                "hybrid",
                "hybrid [!gi]",
                "hybrid [!gi rt_shadows]"
            ]
        );
    }

    /// A sweep over graphs writes each point's graph in the first column and
    /// reads it back as the graph, not as a parameter.
    #[test]
    fn the_graph_column_round_trips() {
        let dir = std::env::temp_dir().join(format!("weft-sweep-graphs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("sweep.csv");
        let names = vec![GRAPH_COLUMN.to_string(), "radius".to_string()];
        let row = SweepRow {
            point: SweepPoint {
                graph: Some("graphs/tiled.ron".into()),
                params: [("radius".to_string(), "2".to_string())].into(),
                features: String::new(),
            },
            flip: 0.5,
            rmse: 0.25,
            frame_ms: 3.0,
            device_bytes: 7,
            frame_iqr: (2.5, 3.5),
        };
        let text = document(&names, [&row]);
        assert!(
            text.starts_with("graph,radius,features,flip,rmse,frame_ms,device_bytes,frame_p25,frame_p75\ngraphs/tiled.ron,2,,"),
            "{text}"
        );
        std::fs::write(&path, text).expect("write");
        assert_eq!(
            read(&path, &names).expect("read"),
            std::slice::from_ref(&row)
        );
        assert_eq!(read_named(&path).expect("named"), (names, vec![row]));
    }

    #[test]
    fn rows_round_trip_and_a_foreign_file_is_an_error() {
        let dir = std::env::temp_dir().join(format!("weft-sweep-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("dir");
        let path = dir.join("sweep.csv");
        let names = vec!["radius".to_string()];
        assert!(read(&path, &names).expect("missing is empty").is_empty());
        let row = SweepRow {
            point: SweepPoint {
                graph: None,
                params: [("radius".to_string(), "3".to_string())].into(),
                features: "bloom".into(),
            },
            flip: 0.125,
            rmse: 0.0625,
            frame_ms: 12.5,
            device_bytes: 1024,
            frame_iqr: (12.25, 13.0),
        };
        std::fs::write(
            &path,
            format!("{}\n{}\n", header(&names), line(&row, &names)),
        )
        .expect("write");
        assert_eq!(read(&path, &names).expect("read"), [row]);
        let other = vec!["size".to_string()];
        let error = read(&path, &other).expect_err("another sweep's file");
        assert!(
            error
                .to_string()
                .contains("sweep.csv:1: the header is \"radius,features"),
            "{error}"
        );
        // A file from before the interquartile range was recorded reads, each
        // row's range its median, and says it is in the old form.
        std::fs::write(
            &path,
            "radius,features,flip,rmse,frame_ms,device_bytes\n3,bloom,0.125,6.25e-2,12.5,1024\n",
        )
        .expect("write");
        let (old, is_old) = read_with_form(&path, &names).expect("old form");
        assert!(is_old);
        assert_eq!(old[0].frame_iqr, (12.5, 12.5));
        assert_eq!(old[0].frame_ms, 12.5);
        std::fs::write(
            &path,
            format!("{}\n3,bloom,abc,1,2,3,4,5\n", header(&names)),
        )
        .expect("write");
        let error = read(&path, &names).expect_err("damaged");
        assert!(
            error
                .to_string()
                .ends_with("sweep.csv:2: \"abc\" is not a number"),
            "{error}"
        );
    }
}
