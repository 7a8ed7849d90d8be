//! `weft sweep`: a graph (or several) over the cartesian product of parameter
//! values and feature sets, every point measured against one cached reference, the
//! Pareto frontier of error against time plotted and tabled
//! (docs/compare.md). Resumable: points already in `sweep.csv` are skipped.

use crate::compare_cmd::{Common, Session, Timings};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::collections::{BTreeMap, BTreeSet};
use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_compare::pareto::{dominated_marks, frontier, write_plot, Point};
use weft_compare::report::{within_budget, within_noise};
use weft_compare::sweep::{
    document, header, line, points, read_named, read_with_form, Setting, SweepPoint, SweepRow,
    GRAPH_COLUMN,
};
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
    #[arg(long, default_value = "graphs/forward.ron", conflicts_with = "graphs")]
    graph: PathBuf,
    /// Several graphs swept as one more dimension (comma-separated), every
    /// point of each against the same reference, on one frontier; sweep.csv
    /// names each point's graph in its first column. Each graph is swept over
    /// the --param parameters it has and the --features-set sets whose every
    /// toggle names one of its features.
    #[arg(long, value_delimiter = ',')]
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

/// A fingerprint of the contents of every file the sweep's points are
/// rendered from: the scene and its includes, and each measured graph's
/// files, shaders and their includes ([`weft_render::graph_source_files`]).
/// A resumed sweep must match it, so an edited shader or graph never mixes
/// old points with new ones; a missing file hashes as missing.
fn sources_fingerprint(args: &SweepRun) -> Result<String> {
    let mut files = weft_render::scene_path_files(args.common.scene());
    for graph in args.graph_names() {
        let prepared = weft_render::load_graph(&RenderSettings {
            graph: PathBuf::from(&graph),
            ..RenderSettings::default()
        })?;
        files.extend(weft_render::graph_source_files(&prepared));
    }
    let mut hasher = weft_io::hash::Hasher::new();
    for file in &files {
        hasher.field(file.to_string_lossy().as_bytes());
        match std::fs::read(file) {
            Ok(bytes) => hasher.field(b"present").field(&bytes),
            Err(_) => hasher.field(b"missing"),
        };
    }
    Ok(format!(
        "{} ({} files)",
        weft_io::hash::hex(hasher.finish()),
        files.len()
    ))
}

/// What every point of a sweep shares; a resumed sweep must share it too:
/// the settings, and `sources`, the fingerprint of the files the points
/// are rendered from ([`sources_fingerprint`]).
fn settings_text(args: &SweepRun, sources: &str) -> String {
    let c = &args.common;
    let reference = match &c.reference_image {
        Some(image) => format!("image {}", image.display()),
        None => format!(
            "{} at {} spp, seed {}, params {:?}",
            c.reference.display(),
            c.spp,
            c.seed,
            c.reference_params
        ),
    };
    format!(
        "scene {}\ngraph {}\nsize {}x{}\ncamera {}\nreference {reference}\nfeatures {}\nframes {}\nsources {sources}\n",
        c.scene().display(),
        args.graph_names().join(","),
        c.size.width,
        c.size.height,
        c.camera.as_deref().unwrap_or("(first)"),
        c.features.join(","),
        c.frames
    ) + args
        .shard
        .map(|s| format!("{SHARD_LINE}{}/{}\n", s.k, s.n))
        .unwrap_or_default()
        .as_str()
}

/// The `sources` line's fingerprint in a `sweep.settings` text.
fn sources_line(settings: &str) -> Option<&str> {
    settings.lines().find_map(|l| l.strip_prefix("sources "))
}

/// A `sweep.settings` text without its `sources` line.
fn without_sources(settings: &str) -> String {
    settings
        .lines()
        .filter(|l| !l.starts_with("sources "))
        .collect::<Vec<_>>()
        .join("\n")
}

/// How `sweep.settings` names a shard.
const SHARD_LINE: &str = "shard ";

/// The file a sweep run with `--noise-floor` keeps the reference's noise
/// floor in (`SEED FLIP`), so a resumed or merged sweep still reports it.
const NOISE_FLOOR_FILE: &str = "noise_floor";

/// The reference's noise floor: the other seed and the HDR-FLIP between the
/// two renders.
type NoiseFloor = (u32, f64);

/// The noise floor recorded in `dir`, if a run there measured one.
fn read_noise_floor(dir: &Path) -> Result<Option<NoiseFloor>> {
    let path = dir.join(NOISE_FLOOR_FILE);
    let text = match weft_io::read_text(&path, weft_io::read::MAX_TEXT_BYTES) {
        Ok(text) => text,
        Err(weft_io::ReadError::Missing { .. }) => return Ok(None),
        Err(e) => return Err(e.into_io()).with_context(|| format!("reading {}", path.display())),
    };
    let parsed = text
        .split_once(' ')
        .and_then(|(seed, flip)| Some((seed.parse().ok()?, flip.trim().parse().ok()?)));
    parsed
        .map(Some)
        .with_context(|| format!("{}: expected `SEED FLIP`, found {text:?}", path.display()))
}

fn write_noise_floor(dir: &Path, (seed, flip): NoiseFloor) -> Result<()> {
    let path = dir.join(NOISE_FLOOR_FILE);
    std::fs::write(&path, format!("{seed} {flip:.6}\n"))
        .with_context(|| format!("writing {}", path.display()))
}

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

/// Records the sweep's settings beside its CSV (`sweep.settings`), or, when
/// resuming, refuses to mix points measured with other settings.
fn check_settings(args: &SweepRun) -> Result<()> {
    let path = args.out.join("sweep.settings");
    let wanted = settings_text(args, &sources_fingerprint(args)?);
    match weft_io::read_text(&path, weft_io::read::MAX_TEXT_BYTES) {
        Ok(found) if found == wanted => Ok(()),
        Ok(found) if without_sources(&found) == without_sources(&wanted) => bail!(
            "{} holds points measured from other sources: a graph, shader or scene file has changed since (sources {}, now {}); use another --out or remove the folder",
            args.out.display(),
            sources_line(&found).unwrap_or("not recorded"),
            sources_line(&wanted).unwrap_or("not recorded"),
        ),
        Ok(found) => bail!(
            "{} holds points measured with other settings:\n{found}this sweep:\n{wanted}use another --out or remove the folder",
            args.out.display()
        ),
        Err(_) if args.out.join("sweep.csv").exists() => bail!(
            "{} has a sweep.csv but no sweep.settings saying how it was measured; use another --out or remove the folder",
            args.out.display()
        ),
        Err(_) => {
            std::fs::create_dir_all(&args.out)
                .with_context(|| format!("creating {}", args.out.display()))?;
            std::fs::write(&path, wanted).with_context(|| format!("writing {}", path.display()))
        }
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
        Some(SweepCommand::Merge(merge)) => merge_shards(&merge),
        None => run_sweep(args.sweep),
    }
}

/// `pareto.png` and `sweep.md` for the measured points `rows` of a sweep of
/// `scene` through `graph`: the frontier plotted and tabled.
fn write_report(
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
    write_plot(
        &plotted,
        &format!("{}: HDR-FLIP against frame time", stems.join(", ")),
        ("HDR-FLIP", budget_ms, noise_floor.map(|(_, flip)| flip)),
        &out.join("pareto.png"),
    )?;
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
    table += "\nThe numbers and letters label the points in `pareto.png`.\n\n![error against time](pareto.png)\n";
    std::fs::write(out.join("sweep.md"), &table)?;
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
        .into_iter()
        .enumerate()
        .filter(|(i, _)| args.shard.is_none_or(|s| s.takes(*i)))
        .map(|(_, p)| p)
        .collect();
    let names = args.columns();
    let csv = args.out.join("sweep.csv");
    check_settings(&args)?;
    let (mut rows, old_form) = read_with_form(&csv, &names)?;
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
            std::fs::write(&csv, header(&names) + "\n")
                .with_context(|| format!("writing {}", csv.display()))?;
        }
        let overall = indicatif::ProgressBar::new(todo.len() as u64);
        overall.set_style(
            indicatif::ProgressStyle::with_template(
                "{elapsed_precise} [{bar:30}] point {pos}/{len} {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
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
    write_report(
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

/// One shard folder of a sharded sweep: its settings (less the shard line),
/// which shard it is, and its rows.
struct ShardFolder {
    dir: PathBuf,
    settings: String,
    shard: Shard,
    names: Vec<String>,
    rows: Vec<SweepRow>,
}

/// Reads a shard's `sweep.settings` and `sweep.csv`.
fn read_shard(dir: &Path) -> Result<ShardFolder> {
    let path = dir.join("sweep.settings");
    let text = weft_io::read_text(&path, weft_io::read::MAX_TEXT_BYTES)
        .with_context(|| format!("reading {}", path.display()))?;
    let mut settings = String::new();
    let mut shard = None;
    for line in text.lines() {
        match line.strip_prefix(SHARD_LINE) {
            Some(k_of_n) => shard = Some(parse_shard(k_of_n).map_err(anyhow::Error::msg)?),
            None => settings += &format!("{line}\n"),
        }
    }
    let shard = shard.with_context(|| {
        format!(
            "{} is not a shard's: it names no `shard K/N`",
            path.display()
        )
    })?;
    let (names, rows) = read_named(&dir.join("sweep.csv"))?;
    Ok(ShardFolder {
        dir: dir.to_path_buf(),
        settings,
        shard,
        names,
        rows,
    })
}

/// Runs `weft sweep merge`: every shard of one sweep, with the same
/// settings, joined in the order the unsharded sweep measures its points.
fn merge_shards(args: &MergeArgs) -> Result<ExitCode> {
    let mut shards = args
        .shards
        .iter()
        .map(|dir| read_shard(dir))
        .collect::<Result<Vec<_>>>()?;
    shards.sort_by_key(|s| s.shard.k);
    let first = &shards[0];
    let n = first.shard.n;
    for s in &shards {
        if s.settings != first.settings || s.names != first.names || s.shard.n != n {
            bail!(
                "{} was measured with other settings than shard {}/{n}; only shards of one sweep merge",
                s.dir.display(),
                first.shard.k
            );
        }
    }
    let found: Vec<usize> = shards.iter().map(|s| s.shard.k).collect();
    let missing: Vec<String> = (1..=n)
        .filter(|k| !found.contains(k))
        .map(|k| format!("{k}/{n}"))
        .collect();
    if !missing.is_empty() || found.len() != n {
        bail!(
            "the shards given are {:?} of {n}; missing: {}",
            found,
            if missing.is_empty() {
                "none, but one is given twice".to_string()
            } else {
                missing.join(", ")
            }
        );
    }
    // Point i of the whole sweep is point i / n of shard i % n + 1.
    let longest = shards.iter().map(|s| s.rows.len()).max().unwrap_or(0);
    let mut rows: Vec<&SweepRow> = Vec::new();
    for position in 0..longest {
        rows.extend(shards.iter().filter_map(|s| s.rows.get(position)));
    }
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    std::fs::write(
        args.out.join("sweep.csv"),
        document(&first.names, rows.iter().copied()),
    )?;
    std::fs::write(args.out.join("sweep.settings"), &first.settings)?;
    let field = |name: &str| {
        first
            .settings
            .lines()
            .find_map(|l| l.strip_prefix(name))
            .unwrap_or_default()
            .to_string()
    };
    println!("{} points from {n} shards", rows.len());
    let noise_floor = read_noise_floor(&first.dir)?;
    if let Some(floor) = noise_floor {
        write_noise_floor(&args.out, floor)?;
    }
    write_report(
        &args.out,
        (&field("scene "), &field("graph ")),
        &rows,
        (args.budget_ms, noise_floor),
    )?;
    Ok(ExitCode::SUCCESS)
}
