//! `weft compare`: configurations (graphs) of one scene against one trusted
//! reference — a path-traced render, cached on disk, or a given EXR — with
//! image error (HDR-FLIP, LDR-FLIP, RMSE, relative MSE, PSNR) beside time
//! and memory (docs/compare.md).

use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_compare::cache::{ReferenceCache, ReferenceKey};
use weft_compare::metrics::Spread;
use weft_compare::report::{
    write_contact_sheet, write_flip_map, Configuration, PassTime, ReferenceInfo, Report,
    SheetColumn, ViewNumbers,
};
use weft_compare::{
    hdr_flip, ldr_flip, luminance_ratio, psnr, rel_mse, rmse, LinearImage, SrgbImage,
};
use weft_gpu::{DeviceKind, Gpu, GpuOptions, Readback, TimingMode};
use weft_graph::plan::Extent;
use weft_graph::schema::ParamValue;
use weft_render::{render_with_progress, RenderSettings, Rendered};

mod reference;
mod session;

pub use session::Session;

/// How per-pass times are taken.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Timer {
    /// GPU timestamps (meaningless for compute on lavapipe).
    Gpu,
    /// CPU wall time of each pass submitted alone.
    Cpu,
}

/// What `weft compare` and `weft sweep` share: the scene, the view, the
/// reference and how configurations are measured.
#[derive(Args)]
pub struct Common {
    /// The scene file.
    #[arg(required = true)]
    scene: Option<PathBuf>,
    /// Feature toggles for every configuration (`name` on, `!name` off).
    #[arg(long, value_delimiter = ',')]
    pub features: Vec<String>,
    /// Camera name; the scene's first camera by default.
    #[arg(long)]
    pub camera: Option<String>,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x360", value_parser = clap::value_parser!(Extent))]
    pub size: Extent,
    /// The reference graph (progressive), rendered to --spp samples.
    #[arg(
        long,
        default_value = "graphs/pathtrace.ron",
        conflicts_with = "reference_image",
        value_parser = crate::graphs::graph_path
    )]
    pub reference: PathBuf,
    /// Samples per pixel of the reference render.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u64).range(1..))]
    pub spp: u64,
    /// The reference render's seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u32,
    /// A parameter of the reference graph, NAME=VALUE (`max_depth=2` for
    /// direct light only); repeatable.
    #[arg(long = "reference-param", value_parser = crate::render_cmd::parse_param)]
    pub reference_params: Vec<(String, ParamValue)>,
    /// Also render the reference with the next seed and report the HDR-FLIP
    /// between the two: the reference's own noise, below which differences
    /// between configurations mean nothing (cached like the reference).
    #[arg(long, conflicts_with = "reference_image")]
    pub noise_floor: bool,
    /// A linear EXR to use as the reference instead of rendering one; it must
    /// have the size asked for.
    #[arg(long)]
    pub reference_image: Option<PathBuf>,
    /// A frame-time budget in milliseconds: the report (compare) or the
    /// frontier table and plot (sweep) name the most accurate configuration
    /// whose median frame time is within it.
    #[arg(long, value_parser = parse_budget)]
    pub budget_ms: Option<f64>,
    /// Measure LDR-FLIP and PSNR on each graph's own output, post effects
    /// (bloom) included; by default they measure its HDR image through the
    /// reference's tonemap, as the reference models no post effects.
    #[arg(long)]
    pub post: bool,
    /// Frames measured per configuration, after one warm-up frame.
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(1..))]
    pub frames: u32,
    /// Per-pass timer: `gpu` timestamps, or `cpu` wall time per pass; by
    /// default `cpu` on a software device (lavapipe), `gpu` elsewhere.
    #[arg(long)]
    pub timer: Option<Timer>,
    /// Read and write no cached data: render the reference even when the
    /// cache has it (and do not store it), import every model and compile
    /// every shader again.
    #[arg(long)]
    pub no_cache: bool,
    /// Use the first device whose name contains this.
    #[arg(long)]
    pub device: Option<String>,
    /// Enable the validation layer with synchronization validation; any error or
    /// warning makes the command fail.
    #[arg(long)]
    pub validate: bool,
}

impl Common {
    /// The scene file. Required on the command line; absent only where a
    /// subcommand that takes none (`weft sweep merge`) stands in for it.
    pub fn scene(&self) -> &Path {
        self.scene.as_deref().unwrap_or(Path::new(""))
    }
}

/// Arguments of `weft compare`.
#[derive(Args)]
pub struct CompareArgs {
    #[command(flatten)]
    common: Common,
    /// The configurations: graph files, comma-separated.
    #[arg(long, value_delimiter = ',', required = true, value_parser = crate::graphs::graph_path)]
    graphs: Vec<PathBuf>,
    /// A parameter for every configuration, NAME=VALUE; repeatable.
    #[arg(long = "param", value_parser = crate::render_cmd::parse_param)]
    params: Vec<(String, ParamValue)>,
    /// Where the images and reports go.
    #[arg(long, default_value = "out/compare")]
    out: PathBuf,
    /// Rounds of measurement: the configurations take turns (A B C A B C),
    /// each round one warm-up frame and --frames measured, so a drift in the
    /// machine's speed falls on every configuration alike.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..))]
    rounds: u32,
}

/// A budget: a positive, finite number of milliseconds.
pub(crate) fn parse_budget(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(ms) if ms.is_finite() && ms > 0.0 => Ok(ms),
        _ => Err(format!("{text:?} is not a positive number of milliseconds")),
    }
}

/// The reference graph's exposure and the tonemap every raster graph ends
/// with (`shaders/tonemap.frag`: Reinhard per channel, then sRGB), for the
/// LDR measures of a reference that exists only as linear floats.
pub(crate) fn tonemap(image: &LinearImage) -> SrgbImage {
    SrgbImage {
        width: image.width,
        height: image.height,
        bytes: image
            .pixels
            .iter()
            .flat_map(|p| {
                p.map(|c| {
                    let c = if c.is_finite() { c.max(0.0) } else { 0.0 };
                    weft_compare::image_io::to_byte(weft_compare::image_io::linear_to_srgb(
                        c / (1.0 + c),
                    ))
                })
            })
            .collect(),
    }
}

/// A readback as linear RGB.
pub(crate) fn linear(image: &Readback) -> LinearImage {
    let rgba = image.to_rgba_f32();
    LinearImage {
        width: rgba.width(),
        height: rgba.height(),
        pixels: rgba.pixels().map(|p| [p.0[0], p.0[1], p.0[2]]).collect(),
    }
}

/// A readback as 8-bit sRGB.
fn srgb(image: &Readback) -> SrgbImage {
    let rgba = image.to_rgba8();
    SrgbImage {
        width: rgba.width(),
        height: rgba.height(),
        bytes: rgba
            .pixels()
            .flat_map(|p| [p.0[0], p.0[1], p.0[2]])
            .collect(),
    }
}

/// Progress of one render labelled `label` (`reference`, a graph's name).
fn bar(label: &str) -> crate::progress::Progress {
    crate::progress::Progress::new(
        label,
        "frame",
        &format!(
            "{label:>12} [{{bar:30}}] frame {{pos}}/{{len}} {{msg}} ({{elapsed}}, ETA {{eta}})"
        ),
    )
}

/// Renders with a progress bar labelled `label`.
fn render(
    gpu: &Gpu,
    scene: &weft_scene::Scene,
    graph: &weft_graph::Prepared,
    settings: &RenderSettings,
    label: &str,
) -> Result<Rendered> {
    let bar = bar(label);
    let rendered = render_with_progress(gpu, scene, graph, settings, &mut |p| {
        bar.set_length(p.planned_frames.into());
        bar.set_position(p.frames.into());
        if let Some(samples) = p.samples {
            let rate = samples as f64 / p.elapsed.max(1e-9);
            bar.set_message(format!("{samples} spp, {rate:.1} spp/s"));
        }
    })
    .with_context(|| format!("rendering {}", settings.graph.display()))?;
    bar.finish_and_clear();
    Ok(rendered)
}

/// The image a graph reads back first (its linear `hdr`).
fn first_readback<'a>(rendered: &'a Rendered, graph: &Path) -> Result<&'a Readback> {
    rendered
        .report
        .readbacks
        .first()
        .map(|(_, image)| image)
        .with_context(|| {
            format!(
                "{} reads back no linear image to compare; add `readback: [\"hdr\"]` naming its HDR image",
                graph.display()
            )
        })
}

pub(crate) fn param_text(value: &ParamValue) -> String {
    match value {
        ParamValue::Bool(b) => b.to_string(),
        ParamValue::Number(n) => n.to_string(),
        ParamValue::Vector(v) => v.iter().map(f64::to_string).collect::<Vec<_>>().join(","),
        ParamValue::Reference(r) => format!("${r}"),
    }
}

/// One pass's measured times: its name, its timer's label, the
/// milliseconds of every measured frame and, for a pass that traces, the rays
/// per pixel it traced in each.
struct PassSamples {
    name: String,
    timer: String,
    ms: Vec<f64>,
    rays_per_pixel: Vec<f64>,
}

/// A configuration's measured frames, from one round or several: every
/// frame's wall milliseconds and every pass's.
#[derive(Default)]
pub struct Timings {
    frames: Vec<f64>,
    passes: Vec<PassSamples>,
}

impl Timings {
    /// The frames of a render after the first (the warm-up), passes in frame
    /// order.
    fn of(rendered: &Rendered) -> Self {
        let mut timings = Timings {
            frames: rendered.frame_ms[1.min(rendered.frame_ms.len())..].to_vec(),
            passes: Vec::new(),
        };
        for frame in &rendered.timings[1.min(rendered.timings.len())..] {
            for t in frame {
                timings.add_pass(&t.pass, t.source.label(), &[t.ms]);
            }
        }
        let pixels = f64::from(rendered.plan.extent.width) * f64::from(rendered.plan.extent.height);
        for frame in &rendered.rays[1.min(rendered.rays.len())..] {
            for r in frame {
                if let Some(p) = timings.passes.iter_mut().find(|p| p.name == r.pass) {
                    p.rays_per_pixel.push(r.rays as f64 / pixels);
                }
            }
        }
        timings
    }

    /// `ms` more of pass `name`, measured by `timer`.
    fn add_pass(&mut self, name: &str, timer: &str, ms: &[f64]) {
        self.pass(name, timer).ms.extend(ms);
    }

    /// Pass `name`'s samples, a new entry when it has none yet.
    fn pass(&mut self, name: &str, timer: &str) -> &mut PassSamples {
        let at = match self.passes.iter().position(|p| p.name == name) {
            Some(at) => at,
            None => {
                self.passes.push(PassSamples {
                    name: name.to_string(),
                    timer: timer.to_string(),
                    ms: Vec::new(),
                    rays_per_pixel: Vec::new(),
                });
                self.passes.len() - 1
            }
        };
        &mut self.passes[at]
    }

    /// These timings and `other`'s together.
    fn extend(&mut self, other: &Timings) {
        self.frames.extend(&other.frames);
        for p in &other.passes {
            let mine = self.pass(&p.name, &p.timer);
            mine.ms.extend(&p.ms);
            mine.rays_per_pixel.extend(&p.rays_per_pixel);
        }
    }

    /// The frames' spread, and each pass's median and spread.
    fn summary(&self) -> (Spread, Vec<PassTime>) {
        let passes = self
            .passes
            .iter()
            .map(|p| {
                let spread = Spread::of(&p.ms);
                PassTime {
                    name: p.name.clone(),
                    ms: spread.median,
                    spread,
                    timer: p.timer.clone(),
                    rays_per_pixel: (!p.rays_per_pixel.is_empty())
                        .then(|| Spread::of(&p.rays_per_pixel).median),
                }
            })
            .collect();
        (Spread::of(&self.frames), passes)
    }
}

/// Distinct short names for the configurations: each graph's file stem,
/// numbered when two share one.
fn names(graphs: &[PathBuf]) -> Vec<String> {
    let stems: Vec<String> = graphs
        .iter()
        .map(|g| {
            g.file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| "graph".into())
        })
        .collect();
    stems
        .iter()
        .enumerate()
        .map(|(i, s)| {
            if stems.iter().filter(|o| *o == s).count() > 1 {
                format!("{s}-{}", i + 1)
            } else {
                s.clone()
            }
        })
        .collect()
}

/// Runs `weft compare`.
pub fn run(args: CompareArgs) -> Result<ExitCode> {
    let common = &args.common;
    // Every graph loaded (and its toggles checked) before the reference renders.
    let mut graphs = crate::graphs::Loaded::default();
    for graph in &args.graphs {
        graphs.get(&RenderSettings {
            graph: graph.clone(),
            features: common.features.clone(),
            params: args.params.iter().cloned().collect(),
            ..RenderSettings::default()
        })?;
    }
    // Session::open writes reference.exr.
    let mut session = Session::open(common, &args.out, graphs)?;
    session
        .reference_ldr
        .write_png(&args.out.join("reference.png"))?;
    let names = names(&args.graphs);
    // The configurations take turns: every round but the last is timed only;
    // the last is timed and measured (its images are every round's).
    let mut earlier: Vec<Timings> = args.graphs.iter().map(|_| Timings::default()).collect();
    for _ in 1..args.rounds {
        for ((graph, name), timings) in args.graphs.iter().zip(&names).zip(&mut earlier) {
            timings.extend(&session.time(common, name, graph, &common.features, &args.params)?);
        }
    }
    let mut measured = Vec::new();
    for ((graph, name), earlier) in args.graphs.iter().zip(names).zip(earlier) {
        let mut m = session.measure(
            common,
            &name,
            graph,
            (&common.features, &args.params),
            earlier,
        )?;
        let files = [
            args.out.join(format!("{name}.png")),
            args.out.join(format!("{name}.exr")),
            args.out.join(format!("{name}.flip.png")),
        ];
        m.output.write_png(&files[0])?;
        m.image.write_exr(&files[1])?;
        write_flip_map(&m.flip, &format!("{name} HDR-FLIP"), &files[2])?;
        m.configuration.files = files.to_vec();
        measured.push(m);
    }
    let report = Report {
        scene: common.scene().to_path_buf(),
        camera: session.camera.clone(),
        width: common.size.width,
        height: common.size.height,
        device: session.device.clone(),
        frames: common.frames,
        rounds: args.rounds,
        budget_ms: common.budget_ms,
        post_effects: common.post,
        reference: session.info.clone(),
        configurations: measured.iter().map(|m| m.configuration.clone()).collect(),
    };
    let mut columns = vec![SheetColumn {
        label: "reference".into(),
        image: &session.reference_ldr,
        flip: None,
    }];
    columns.extend(measured.iter().map(|m| SheetColumn {
        label: m.configuration.name.clone(),
        image: &m.output,
        flip: Some(&m.flip),
    }));
    write_contact_sheet(&columns, &args.out.join("contact_sheet.png"))?;
    weft_io::write_output(
        &args.out.join("report.json"),
        (serde_json::to_string_pretty(&report)? + "\n").as_bytes(),
    )?;
    weft_io::write_output(&args.out.join("report.md"), report.markdown().as_bytes())?;
    print!("{}", report.table());
    println!("wrote {}", args.out.display());
    Ok(session.finish(common.validate))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_stems_numbered_when_shared() {
        assert_eq!(
            names(&[
                PathBuf::from("graphs/forward.ron"),
                PathBuf::from("graphs/deferred.ron"),
                PathBuf::from("other/forward.ron"),
            ]),
            ["forward-1", "deferred", "forward-3"]
        );
    }

    #[test]
    fn the_cpu_tonemap_is_reinhard_then_srgb() {
        let image = LinearImage {
            width: 2,
            height: 1,
            pixels: vec![[0.0, 1.0, f32::INFINITY], [3.0, -1.0, f32::NAN]],
        };
        // 1 -> 0.5 -> sRGB 0.7354 -> 188; 3 -> 0.75 -> 0.8808 -> 225
        assert_eq!(tonemap(&image).bytes, [0, 188, 0, 225, 0, 0]);
    }
}
