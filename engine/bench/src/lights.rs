//! `weft bench lights`: frame time against the number of point lights for
//! several graphs on one generated scene (`weft_testkit::light_scene`), written
//! as a CSV and a log-log plot, with the counts where one graph overtakes another.

use crate::plot::{self, LinePlot, Series};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_gpu::{Gpu, GpuOptions};
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings, Rendered};
use weft_testkit::light_scene;

/// Arguments of `weft bench lights`.
#[derive(Args)]
pub struct LightsArgs {
    /// Point-light counts to measure.
    #[arg(long, value_delimiter = ',', default_value = "1,16,256,1024,10000", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    counts: Vec<u32>,
    /// Graphs to compare; each is named by its file stem.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "graphs/forward.ron,graphs/deferred.ron,graphs/tiled.ron"
    )]
    graphs: Vec<PathBuf>,
    /// Output size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Frames per measurement; the first (pipeline builds) is left out of the mean.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    frames: u32,
    /// Seed of the generated lights.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Feature toggles for every graph (bloom off: it costs the same in each).
    #[arg(long, value_delimiter = ',', default_value = "!bloom")]
    features: Vec<String>,
    /// Where the CSV and the plot go (`lights_bench.csv`, `lights_bench.png`).
    /// Default: the user's cache (`~/.cache/weft/bench/lights`); `docs`
    /// refreshes the committed figures.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Keep the generated scenes (`floor.obj`, `lights_<N>.scene`) in this folder
    /// instead of a temporary one that is removed afterwards.
    #[arg(long)]
    scenes: Option<PathBuf>,
    /// Use the first device whose name contains this.
    #[arg(long)]
    device: Option<String>,
    /// Skip a graph at a count when its last frame time, scaled by the growth in
    /// lights, predicts more than this many seconds for the run (listed as skipped).
    #[arg(long, default_value_t = 120.0)]
    budget_s: f64,
}

/// Whether to skip a run predicted from the graph's previous `(lights, ms)`:
/// frame time taken as proportional to the light count (forward's worst case),
/// times `frames`, against `budget_s`.
pub fn over_budget(previous: Option<(u32, f64)>, lights: u32, frames: u32, budget_s: f64) -> bool {
    previous.is_some_and(|(n, ms)| {
        let predicted = ms * f64::from(lights) / f64::from(n.max(1)) * f64::from(frames);
        predicted / 1e3 > budget_s
    })
}

/// One measurement.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Graph name (file stem).
    pub graph: String,
    /// Point lights in the scene.
    pub lights: u32,
    /// Mean wall-clock frame time after the first frame, in milliseconds.
    pub frame_ms: f64,
    /// Frames rendered (the first left out of the mean).
    pub frames: u32,
}

/// Counts at which `b` becomes faster or slower than `a`, where the sign of the
/// difference changes between two measured counts: the crossing of the two
/// straight lines between them on log-log axes (the plot's lines). Both series
/// are (count, ms) in increasing count at the same counts.
pub fn crossovers(a: &[(f64, f64)], b: &[(f64, f64)]) -> Vec<f64> {
    let diff = |(x, ta): (f64, f64), tb: f64| (x.ln(), ta.ln() - tb.ln());
    let d: Vec<(f64, f64)> = a
        .iter()
        .zip(b)
        .filter(|(p, q)| p.0 == q.0 && p.0 > 0.0 && p.1 > 0.0 && q.1 > 0.0)
        .map(|(&p, q)| diff(p, q.1))
        .collect();
    d.windows(2)
        .filter(|w| w[0].1 * w[1].1 < 0.0 || (w[0].1 != 0.0 && w[1].1 == 0.0))
        .map(|w| {
            let t = w[0].1 / (w[0].1 - w[1].1);
            (w[0].0 + t * (w[1].0 - w[0].0)).exp()
        })
        .collect()
}

/// The graph name a file stands for.
fn graph_name(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// The samples as CSV: `graph,lights,frame_ms,frames`.
pub fn csv(samples: &[Sample]) -> String {
    let mut text = String::from("graph,lights,frame_ms,frames\n");
    for s in samples {
        let _ = writeln!(
            text,
            "{},{},{:.3},{}",
            s.graph, s.lights, s.frame_ms, s.frames
        );
    }
    text
}

/// (lights, ms) of one graph, in measured order.
fn series_of(samples: &[Sample], graph: &str) -> Vec<(f64, f64)> {
    samples
        .iter()
        .filter(|s| s.graph == graph)
        .map(|s| (f64::from(s.lights), s.frame_ms))
        .collect()
}

/// The table printed at the end: one row per count, one column per graph.
pub fn table(samples: &[Sample], graphs: &[String], counts: &[u32]) -> String {
    let mut text = format!("{:>8}", "lights");
    for g in graphs {
        let _ = write!(text, " {:>14}", format!("{g} ms"));
    }
    text.push('\n');
    for &n in counts {
        let _ = write!(text, "{n:>8}");
        for g in graphs {
            match samples.iter().find(|s| s.lights == n && &s.graph == g) {
                Some(s) => {
                    let _ = write!(text, " {:>14.1}", s.frame_ms);
                }
                None => {
                    let _ = write!(text, " {:>14}", "skipped");
                }
            }
        }
        text.push('\n');
    }
    text
}

/// Lines naming where each pair of graphs crosses over.
pub fn crossover_lines(samples: &[Sample], graphs: &[String]) -> Vec<String> {
    let mut lines = Vec::new();
    for (i, a) in graphs.iter().enumerate() {
        for b in &graphs[i + 1..] {
            let (sa, sb) = (series_of(samples, a), series_of(samples, b));
            let found = crossovers(&sa, &sb);
            if found.is_empty() {
                let faster = match (sa.first(), sb.first()) {
                    (Some(p), Some(q)) if p.1 < q.1 => a,
                    _ => b,
                };
                lines.push(format!(
                    "{a} / {b}: no crossover; {faster} is faster at every count"
                ));
            }
            for x in found {
                lines.push(format!("{a} / {b}: cross at about {x:.0} lights"));
            }
        }
    }
    lines
}

/// Runs `weft bench lights`.
pub fn run(args: LightsArgs) -> Result<ExitCode> {
    if args.counts.is_empty() || args.graphs.is_empty() {
        bail!("--counts and --graphs must name at least one each");
    }
    for g in &args.graphs {
        if !g.is_file() {
            bail!(
                "graph {} not found (run from the repository root)",
                g.display()
            );
        }
    }
    let gpu = Gpu::new(&GpuOptions {
        validation: false,
        device: args.device.clone(),
    })?;
    println!(
        "device: {}; {}x{}, {} frame(s) per point (mean after the first), features {}",
        gpu.info().name,
        args.size.width,
        args.size.height,
        args.frames,
        args.features.join(",")
    );
    let scenes = args.scenes.clone().unwrap_or_else(|| {
        std::env::temp_dir().join(format!("weft-bench-lights-{}", std::process::id()))
    });
    let names: Vec<String> = args.graphs.iter().map(|g| graph_name(g)).collect();
    let mut samples = Vec::new();
    for &n in &args.counts {
        let path = light_scene::write_light_scene(&scenes, n, args.seed)
            .with_context(|| format!("writing a scene into {}", scenes.display()))?;
        let scene =
            weft_scene::load_scene(&path).with_context(|| format!("loading {}", path.display()))?;
        for (graph, name) in args.graphs.iter().zip(&names) {
            let previous = samples
                .iter()
                .rev()
                .find(|s: &&Sample| &s.graph == name)
                .map(|s| (s.lights, s.frame_ms));
            if over_budget(previous, n, args.frames.max(1), args.budget_s) {
                println!(
                    "{name:>10} {n:>6} lights: skipped (predicted over {} s)",
                    args.budget_s
                );
                continue;
            }
            let settings = RenderSettings {
                graph: graph.clone(),
                extent: args.size,
                frames: args.frames.max(1),
                features: args.features.clone(),
                readback: false,
                ..RenderSettings::default()
            };
            let rendered = render(&gpu, &scene, &settings)
                .with_context(|| format!("{name} with {n} lights"))?;
            let frame_ms = Rendered::steady_mean(&rendered.frame_ms);
            samples.push(Sample {
                graph: name.clone(),
                lights: n,
                frame_ms,
                frames: args.frames.max(1),
            });
            println!("{name:>10} {n:>6} lights: {frame_ms:.1} ms");
        }
    }
    if args.scenes.is_none() {
        let _ = std::fs::remove_dir_all(&scenes);
    }
    let out_dir = crate::output::out_dir(args.out_dir.as_deref(), "lights")?;
    let csv_path = out_dir.join("lights_bench.csv");
    weft_io::write_output(&csv_path, csv(&samples).as_bytes())?;
    let png_path = out_dir.join("lights_bench.png");
    let chart = LinePlot {
        title: format!(
            "Frame time vs point lights, {}x{} ({})",
            args.size.width,
            args.size.height,
            gpu.info().name
        ),
        x_label: "point lights".into(),
        y_label: "frame time (ms)".into(),
        log_x: true,
        log_y: true,
        x_ticks: Vec::new(),
        series: names
            .iter()
            .map(|g| Series {
                name: g.clone(),
                points: series_of(&samples, g),
            })
            .collect(),
    };
    plot::write_png(&chart, &png_path, 960, 600)?;
    print!("\n{}", table(&samples, &names, &args.counts));
    for line in crossover_lines(&samples, &names) {
        println!("{line}");
    }
    println!("wrote {} and {}", csv_path.display(), png_path.display());
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crossing_is_interpolated_on_log_log_axes() {
        // a: 10 ms flat; b: 1 ms at 1, 100 ms at 100 (a straight line of slope 1).
        let a = [(1.0, 10.0), (100.0, 10.0)];
        let b = [(1.0, 1.0), (100.0, 100.0)];
        let x = crossovers(&a, &b);
        assert_eq!(x.len(), 1);
        assert!((x[0] - 10.0).abs() < 1e-9, "{x:?}");
    }

    #[test]
    fn lines_that_never_cross_have_no_crossover_and_two_crossings_give_two() {
        let a = [(1.0, 1.0), (10.0, 2.0), (100.0, 3.0)];
        let b = [(1.0, 5.0), (10.0, 6.0), (100.0, 7.0)];
        assert!(crossovers(&a, &b).is_empty());
        let c = [(1.0, 5.0), (10.0, 1.0), (100.0, 5.0)];
        let d = [(1.0, 2.0), (10.0, 2.0), (100.0, 2.0)];
        assert_eq!(crossovers(&c, &d).len(), 2);
    }

    #[test]
    fn runs_predicted_over_budget_are_skipped() {
        // 2 s at 16 lights predicts 32 s at 256 lights, 96 s for 3 frames.
        assert!(!over_budget(Some((16, 2000.0)), 256, 3, 100.0));
        assert!(over_budget(Some((16, 2000.0)), 256, 3, 90.0));
        assert!(!over_budget(None, 10_000, 3, 1.0));
    }

    #[test]
    fn the_table_and_csv_list_every_sample() {
        let samples = vec![
            Sample {
                graph: "forward".into(),
                lights: 1,
                frame_ms: 12.345,
                frames: 3,
            },
            Sample {
                graph: "tiled".into(),
                lights: 1,
                frame_ms: 20.0,
                frames: 3,
            },
        ];
        assert_eq!(
            csv(&samples),
            "graph,lights,frame_ms,frames\nforward,1,12.345,3\ntiled,1,20.000,3\n"
        );
        let names = vec!["forward".to_string(), "tiled".to_string()];
        let t = table(&samples, &names, &[1, 16]);
        assert_eq!(
            t.lines().collect::<Vec<_>>(),
            [
                "  lights     forward ms       tiled ms",
                "       1           12.3           20.0",
                "      16        skipped        skipped",
            ]
        );
        assert_eq!(
            crossover_lines(&samples, &names),
            ["forward / tiled: no crossover; forward is faster at every count"]
        );
    }
}
