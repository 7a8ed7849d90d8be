//! `weft sweep`: a graph (or several) over the cartesian product of parameter
//! values and feature sets, every point measured against one cached reference, the
//! Pareto frontier of error against time plotted and tabled
//! (docs/compare.md). Resumable: points already in `sweep.csv` are skipped.

use crate::compare_cmd::{Common, Session, Timings};
use anyhow::{bail, Context, Result};
use clap::Args;
use folder::{check_settings, lock_folder, read_noise_floor, write_grid, write_noise_floor};
use std::collections::{BTreeMap, BTreeSet};
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use weft_compare::sweep::{
    check_rows, document, header, line, points, read_with_form, Setting, SweepPoint, SweepRow,
    GRAPH_COLUMN,
};

mod folder;
mod merge;
mod report;
use weft_graph::schema::ParamValue;
use weft_render::RenderSettings;

/// Arguments of `weft sweep`: a sweep (or one shard of it), or `weft sweep
/// merge` joining shards.
#[derive(Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SweepArgs {
    #[command(subcommand)]
    command: Option<SweepCommand>,
    #[command(flatten)]
    sweep: SweepRun,
}

/// What `weft sweep` can do besides sweeping.
#[derive(clap::Subcommand)]
enum SweepCommand {
    /// Joins the folders of a sharded sweep (`--shard K/N`) into one:
    /// sweep.csv, pareto.png and sweep.md over every shard's points.
    Merge(MergeArgs),
}

/// Arguments of `weft sweep merge`.
#[derive(Args)]
struct MergeArgs {
    /// The shards' output folders.
    #[arg(required = true)]
    shards: Vec<PathBuf>,
    /// Where the joined sweep goes.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    /// A frame-time budget in milliseconds, as for a sweep.
    #[arg(long, value_parser = crate::compare_cmd::parse_budget)]
    budget_ms: Option<f64>,
}

/// Arguments of one sweep.
#[derive(Args)]
struct SweepRun {
    #[command(flatten)]
    common: Common,
    /// The graph swept.
    #[arg(
        long,
        default_value = "graphs/forward.ron",
        conflicts_with = "graphs",
        value_parser = crate::graphs::graph_path
    )]
    graph: PathBuf,
    /// Several graphs swept as one more dimension (comma-separated), every
    /// point of each against the same reference, on one frontier; sweep.csv
    /// names each point's graph in its first column. Each graph is swept over
    /// the --param parameters it has and the --features-set sets whose every
    /// toggle names one of its features.
    #[arg(long, value_delimiter = ',', value_parser = crate::graphs::graph_path)]
    graphs: Vec<PathBuf>,
    /// A parameter and its values, NAME=v1,v2,...; repeatable (the points are
    /// every combination).
    #[arg(long = "param", value_parser = parse_values)]
    params: Vec<(String, Vec<String>)>,
    /// Feature sets to sweep, separated by `;`, each a comma-separated list of
    /// toggles (`bloom,!shadows;bloom`); one empty set by default.
    #[arg(long)]
    features_set: Option<String>,
    /// Where `sweep.csv`, `pareto.png` and `sweep.md` go.
    #[arg(long, default_value = "out/sweep")]
    out: PathBuf,
    /// Measure only shard K of N (`K/N`, K from 1): every N-th point of the
    /// sweep's order from the K-th, so N machines share a sweep; join their
    /// folders with `weft sweep merge`.
    #[arg(long, value_parser = parse_shard)]
    shard: Option<Shard>,
}

/// Shard K of N (K from 1).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Shard {
    k: usize,
    n: usize,
}

impl Shard {
    /// Whether the sweep's `index`-th point (from 0) is this shard's.
    fn takes(&self, index: usize) -> bool {
        index % self.n == self.k - 1
    }
}

fn parse_shard(text: &str) -> Result<Shard, String> {
    let parsed = text
        .split_once('/')
        .and_then(|(k, n)| Some((k.trim().parse().ok()?, n.trim().parse().ok()?)));
    match parsed {
        Some((k, n)) if (1..=n).contains(&k) => Ok(Shard { k, n }),
        _ => Err(format!(
            "\"{text}\" is not a shard K/N with 1 <= K <= N (e.g. 2/4)"
        )),
    }
}

/// Parses `NAME=v1,v2,...`: each value a number or true/false.
fn parse_values(text: &str) -> Result<(String, Vec<String>), String> {
    let (name, values) = text.split_once('=').ok_or_else(|| {
        format!("a swept parameter must look like name=v1,v2,..., found \"{text}\"")
    })?;
    let values: Vec<String> = values.split(',').map(|v| v.trim().to_string()).collect();
    for v in &values {
        let ok = v == "true" || v == "false" || v.parse::<f64>().is_ok_and(f64::is_finite);
        if !ok {
            return Err(format!(
                "\"{v}\" in --param {name} is not a number or true/false"
            ));
        }
    }
    Ok((name.trim().to_string(), values))
}

fn value(text: &str) -> ParamValue {
    match text {
        "true" => ParamValue::Bool(true),
        "false" => ParamValue::Bool(false),
        number => ParamValue::Number(number.parse().unwrap_or(0.0)),
    }
}

impl SweepRun {
    /// The graphs of `--graphs`, as the CSV names them (none without it).
    fn swept_graphs(&self) -> Vec<String> {
        self.graphs
            .iter()
            .map(|g| g.display().to_string())
            .collect()
    }

    /// The graphs measured, as the settings and reports name them.
    fn graph_names(&self) -> Vec<String> {
        let swept = self.swept_graphs();
        if swept.is_empty() {
            vec![self.graph.display().to_string()]
        } else {
            swept
        }
    }

    /// The columns before `features` in sweep.csv: the graph's in a sweep
    /// over graphs, then the parameters'.
    fn columns(&self) -> Vec<String> {
        let graph = (!self.graphs.is_empty()).then(|| GRAPH_COLUMN.to_string());
        graph
            .into_iter()
            .chain(self.params.iter().map(|(n, _)| n.clone()))
            .collect()
    }
}

/// The graph, features (the command's, then the point's) and parameters one
/// sweep point renders with.
fn point_settings(args: &SweepRun, point: &SweepPoint) -> RenderSettings {
    let mut features = args.common.features.clone();
    features.extend(point.features.split_whitespace().map(String::from));
    RenderSettings {
        graph: point
            .graph
            .as_ref()
            .map_or_else(|| args.graph.clone(), PathBuf::from),
        features,
        params: point
            .params
            .iter()
            .map(|(k, v)| (k.clone(), value(v)))
            .collect(),
        ..RenderSettings::default()
    }
}

/// What one swept graph takes: the parameters `--param` reaches and the
/// sweep's feature toggles that name one of its features.
struct Takes {
    params: BTreeSet<String>,
    toggles: BTreeSet<String>,
}

/// Each of the swept `graphs`, loaded once, with what it takes of the
/// sweep's `toggles`; an error for a toggle no graph knows (a misspelt
/// feature). Empty for a sweep of one graph, which checks its parameters
/// and toggles when it loads each point.
fn graph_takes(graphs: &[String], toggles: &[String]) -> Result<BTreeMap<String, Takes>> {
    let mut takes = BTreeMap::new();
    for graph in graphs {
        let prepared = weft_render::load_graph(&RenderSettings {
            graph: PathBuf::from(graph),
            ..RenderSettings::default()
        })?;
        takes.insert(
            graph.clone(),
            Takes {
                params: prepared.graph().settable_params(),
                toggles: prepared.known_toggles(toggles).into_iter().collect(),
            },
        );
    }
    if takes.is_empty() {
        return Ok(takes);
    }
    if let Some(unknown) = toggles
        .iter()
        .find(|t| !takes.values().any(|k: &Takes| k.toggles.contains(*t)))
    {
        bail!(
            "--features-set: none of the swept graphs has the feature in `{unknown}` ({})",
            graphs.join(", ")
        );
    }
    Ok(takes)
}

/// Runs `weft sweep` or `weft sweep merge`.
pub fn run(args: SweepArgs) -> Result<ExitCode> {
    match args.command {
        Some(SweepCommand::Merge(args)) => merge::merge_shards(&args),
        None => run_sweep(args.sweep),
    }
}

/// Runs one sweep (or one shard of it).
fn run_sweep(args: SweepRun) -> Result<ExitCode> {
    let common = &args.common;
    if args.params.is_empty() && args.features_set.is_none() && args.graphs.len() < 2 {
        bail!("nothing to sweep: give --param NAME=v1,v2,..., --features-set a,b;c or --graphs a.ron,b.ron");
    }
    let sets: Vec<String> = args
        .features_set
        .as_deref()
        .map(|s| {
            s.split(';')
                .map(|set| {
                    set.split(',')
                        .map(str::trim)
                        .filter(|f| !f.is_empty())
                        .collect::<Vec<_>>()
                        .join(" ")
                })
                .collect()
        })
        .unwrap_or_default();
    if !args.graphs.is_empty() && args.params.iter().any(|(n, _)| n == GRAPH_COLUMN) {
        bail!("--param {GRAPH_COLUMN}=... cannot be swept with --graphs: sweep.csv's `{GRAPH_COLUMN}` column names each point's graph");
    }
    // Over several graphs, each is swept over the parameters it has and the
    // feature sets whose toggles it knows.
    let toggles: Vec<String> = sets
        .iter()
        .flat_map(|set| set.split_whitespace().map(str::to_string))
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    let offered = graph_takes(&args.swept_graphs(), &toggles)?;
    if !offered.is_empty() {
        if let Some((name, _)) = args
            .params
            .iter()
            .find(|(name, _)| !offered.values().any(|t| t.params.contains(name)))
        {
            bail!(
                "--param {name}: none of the swept graphs has this parameter ({})",
                offered
                    .iter()
                    .map(|(g, t)| format!(
                        "{g}: {}",
                        t.params.iter().cloned().collect::<Vec<_>>().join(" ")
                    ))
                    .collect::<Vec<_>>()
                    .join("; ")
            );
        }
    }
    let takes = |graph: Option<&str>, setting: Setting| {
        graph.is_none_or(|g| {
            offered.get(g).is_some_and(|t| match setting {
                Setting::Param(name) => t.params.contains(name),
                Setting::Toggle(toggle) => t.toggles.contains(toggle),
            })
        })
    };
    let every = points(&args.swept_graphs(), &args.params, &sets, &takes);
    // The graph loaded with every point's parameters and features before the
    // reference renders: a misspelt parameter or value fails at once.
    let mut graphs = crate::graphs::Loaded::default();
    for point in &every {
        graphs.get(&point_settings(&args, point))?;
    }
    let all: Vec<SweepPoint> = every
        .iter()
        .enumerate()
        .filter(|(i, _)| args.shard.is_none_or(|s| s.takes(*i)))
        .map(|(_, p)| p.clone())
        .collect();
    let names = args.columns();
    let csv = args.out.join("sweep.csv");
    // Held until the sweep ends: a second sweep into this folder fails at once.
    let _lock = lock_folder(&args.out)?;
    let (grid_text, grid_line) = folder::grid(&names, &every);
    check_settings(&args, &grid_line)?;
    write_grid(&args.out, &grid_text)?;
    let (mut rows, old_form) = read_with_form(&csv, &names)?;
    // A shard's rows are its points of the grid; an unsharded folder may
    // also hold points of a wider grid measured before.
    let owned = |i: usize| args.shard.is_none_or(|s| s.takes(i));
    check_rows(
        &csv,
        &rows,
        args.shard
            .map(|_| (every.as_slice(), &owned as &dyn Fn(usize) -> bool)),
    )?;
    if old_form {
        // Rewritten in the current form (each old row's range its median),
        // atomically, before new rows are appended to it.
        weft_io::entry::write_atomic(&csv, document(&names, &rows).as_bytes())
            .with_context(|| format!("rewriting {}", csv.display()))?;
    }
    let todo: Vec<&SweepPoint> = all
        .iter()
        .filter(|p| !rows.iter().any(|r| &r.point == *p))
        .collect();
    println!(
        "{} points, {} already in {}",
        all.len(),
        all.len() - todo.len(),
        csv.display()
    );
    let mut exit = ExitCode::SUCCESS;
    let mut noise_floor = read_noise_floor(&args.out)?;
    if !todo.is_empty() || (common.noise_floor && noise_floor.is_none()) {
        let mut session = Session::open(common, &args.out, graphs)?;
        if let Some(floor) = &session.info.noise_floor {
            noise_floor = Some((floor.seed, floor.flip));
            write_noise_floor(&args.out, (floor.seed, floor.flip))?;
        }
        if !csv.exists() {
            weft_io::write_output(&csv, (header(&names) + "\n").as_bytes())?;
        }
        let overall = crate::progress::Progress::new(
            "sweep",
            "point",
            "{elapsed_precise} [{bar:30}] point {pos}/{len} {msg}",
        );
        overall.set_length(todo.len() as u64);
        for point in todo {
            overall.set_message(point.label());
            let settings = point_settings(&args, point);
            let params: Vec<(String, ParamValue)> = settings.params.into_iter().collect();
            let measured = session.measure(
                common,
                &point.label(),
                &settings.graph,
                (&settings.features, &params),
                Timings::default(),
            )?;
            let row = SweepRow {
                point: point.clone(),
                flip: measured.configuration.flip,
                rmse: measured.configuration.rmse,
                frame_ms: measured.configuration.frame_ms,
                device_bytes: measured.configuration.device_bytes,
                frame_iqr: (
                    measured.configuration.frame_spread.p25,
                    measured.configuration.frame_spread.p75,
                ),
            };
            // Appended at once, so an interrupted sweep keeps what it measured.
            let mut file = std::fs::OpenOptions::new()
                .append(true)
                .open(&csv)
                .with_context(|| format!("appending to {}", csv.display()))?;
            writeln!(file, "{}", line(&row, &names))?;
            rows.push(row);
            overall.inc(1);
        }
        overall.finish_and_clear();
        exit = session.finish(common.validate);
    }
    let wanted: Vec<&SweepRow> = rows.iter().filter(|r| all.contains(&r.point)).collect();
    report::write_report(
        &args.out,
        (
            &common.scene().display().to_string(),
            &args.graph_names().join(", "),
        ),
        &wanted,
        (common.budget_ms, noise_floor),
    )?;
    Ok(exit)
}
