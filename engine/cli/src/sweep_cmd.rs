//! `weft sweep`: one graph over the cartesian product of parameter values and
//! feature sets, every point measured against one cached reference, the
//! Pareto frontier of error against time plotted and tabled
//! (docs/compare.md). Resumable: points already in `sweep.csv` are skipped.

use crate::compare_cmd::{Common, Session};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::io::Write as _;
use std::path::PathBuf;
use std::process::ExitCode;
use weft_compare::pareto::{frontier, write_plot, Point};
use weft_compare::sweep::{header, line, points, read, SweepPoint, SweepRow};
use weft_graph::schema::ParamValue;
use weft_render::RenderSettings;

/// Arguments of `weft sweep`.
#[derive(Args)]
pub struct SweepArgs {
    #[command(flatten)]
    common: Common,
    /// The graph swept.
    #[arg(long, default_value = "graphs/forward.ron")]
    graph: PathBuf,
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

/// What every point of a sweep shares; a resumed sweep must share it too.
fn settings_text(args: &SweepArgs) -> String {
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
        "scene {}\ngraph {}\nsize {}x{}\ncamera {}\nreference {reference}\nfeatures {}\nframes {}\n",
        c.scene.display(),
        args.graph.display(),
        c.size.width,
        c.size.height,
        c.camera.as_deref().unwrap_or("(first)"),
        c.features.join(","),
        c.frames
    )
}

/// Records the sweep's settings beside its CSV (`sweep.settings`), or, when
/// resuming, refuses to mix points measured with other settings.
fn check_settings(args: &SweepArgs) -> Result<()> {
    let path = args.out.join("sweep.settings");
    let wanted = settings_text(args);
    match weft_io::read_text(&path, weft_io::read::MAX_TEXT_BYTES) {
        Ok(found) if found == wanted => Ok(()),
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
fn point_settings(args: &SweepArgs, point: &SweepPoint) -> RenderSettings {
    let mut features = args.common.features.clone();
    features.extend(point.features.split_whitespace().map(String::from));
    RenderSettings {
        graph: args.graph.clone(),
        features,
        params: point
            .params
            .iter()
            .map(|(k, v)| (k.clone(), value(v)))
            .collect(),
        ..RenderSettings::default()
    }
}

/// Runs `weft sweep`.
pub fn run(args: SweepArgs) -> Result<ExitCode> {
    let common = &args.common;
    if args.params.is_empty() && args.features_set.is_none() {
        bail!("nothing to sweep: give --param NAME=v1,v2,... or --features-set a,b;c");
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
    let all = points(&args.params, &sets);
    // The graph loaded with every point's parameters and features before the
    // reference renders: a misspelt parameter or value fails at once.
    let mut graphs = crate::graphs::Loaded::default();
    for point in &all {
        graphs.get(&point_settings(&args, point))?;
    }
    let names: Vec<String> = args.params.iter().map(|(n, _)| n.clone()).collect();
    let csv = args.out.join("sweep.csv");
    check_settings(&args)?;
    let mut rows = read(&csv, &names)?;
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
    if !todo.is_empty() {
        let mut session = Session::open(common, &args.out, graphs)?;
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
                &args.graph,
                &settings.features,
                &params,
            )?;
            let row = SweepRow {
                point: point.clone(),
                flip: measured.configuration.flip,
                rmse: measured.configuration.rmse,
                frame_ms: measured.configuration.frame_ms,
                device_bytes: measured.configuration.device_bytes,
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
    let plotted: Vec<Point> = wanted
        .iter()
        .map(|r| Point {
            label: r.point.label(),
            time: r.frame_ms,
            error: r.flip,
        })
        .collect();
    let on = frontier(&plotted);
    write_plot(
        &plotted,
        &format!("{}: HDR-FLIP against frame time", args.graph.display()),
        "HDR-FLIP",
        &args.out.join("pareto.png"),
    )?;
    let mut table = format!(
        "# weft sweep: {} through {}\n\nPareto frontier of HDR-FLIP against frame time ({} of {} points; the rest are dominated):\n\n| # | setting | HDR-FLIP | RMSE | frame (ms) | device (MiB) |\n|---|---|---|---|---|---|\n",
        common.scene.display(),
        args.graph.display(),
        on.len(),
        wanted.len()
    );
    for (rank, &i) in on.iter().enumerate() {
        let r = wanted[i];
        table += &format!(
            "| {} | {} | {:.4} | {:.4e} | {:.2} | {:.1} |\n",
            rank + 1,
            r.point.label(),
            r.flip,
            r.rmse,
            r.frame_ms,
            r.device_bytes as f64 / (1024.0 * 1024.0)
        );
    }
    table += "\nThe numbers label the frontier's points in `pareto.png`.\n\n![error against time](pareto.png)\n";
    std::fs::write(args.out.join("sweep.md"), &table)?;
    print!("{table}");
    println!("wrote {}", args.out.display());
    Ok(exit)
}
