//! `weft render`: a scene through a graph to an image, with validation,
//! per-pass timings and a JSON summary.

use crate::progress::Progress;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_gpu::{format_timings, Gpu, GpuOptions, TimingMode};
use weft_graph::plan::Extent;
use weft_graph::schema::ParamValue;
use weft_render::{render_with_progress, RenderSettings, Rendered};

/// Which per-pass times `--timings` measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Timings {
    /// GPU timestamps around each pass, one submission per frame.
    Gpu,
    /// Host wall time of each pass submitted and waited for alone.
    Cpu,
}

/// Arguments of `weft render`.
#[derive(Args)]
pub struct RenderArgs {
    /// The scene file.
    scene: PathBuf,
    /// The render graph.
    #[arg(long, default_value = "graphs/forward.ron", value_parser = crate::graphs::graph_path)]
    graph: PathBuf,
    /// Output size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Frames to render (at least 1); the last one is saved.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    frames: u32,
    /// Scene time in seconds at the first frame (frames are 1/60 s apart).
    #[arg(long, default_value_t = 0.0, value_parser = parse_time, allow_negative_numbers = true)]
    time: f64,
    /// Camera name; the scene's first camera by default.
    #[arg(long)]
    camera: Option<String>,
    /// An equirectangular HDR map (OpenEXR or Radiance .hdr) that lights the
    /// scene in place of its own `environment` (for a bare glTF or OBJ),
    /// at intensity 1 and no rotation.
    #[arg(long)]
    environment: Option<PathBuf>,
    /// How passes that trace rays traverse the scene: `software` (the BVH
    /// walk, any device), `hardware` (ray queries: VK_KHR_ray_query and
    /// VK_KHR_acceleration_structure) or `auto` (hardware on a GPU that
    /// offers them, software elsewhere).
    #[arg(long, default_value = "auto")]
    backend: weft_render::TraceBackend,
    /// Output image: .png (the graph's tonemapped sRGB output) or .exr (the first
    /// image read back, where there is one — the graph's `readback` list or
    /// --readback — else the output as floats); default out/<scene stem>.png.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Enable the validation layer with synchronization validation; any error or
    /// warning makes the command fail.
    #[arg(long)]
    validate: bool,
    /// Print per-pass times: `gpu` timestamps (default) or `cpu` wall time per pass.
    #[arg(long, num_args = 0..=1, default_missing_value = "gpu")]
    timings: Option<Timings>,
    /// Print a JSON summary instead of text.
    #[arg(long)]
    json: bool,
    /// Feature toggles added after the scene's features (`name` on, `!name` off).
    #[arg(long, value_delimiter = ',')]
    features: Vec<String>,
    /// Set a top-level graph parameter, NAME=VALUE (a number, true/false, or a
    /// comma-separated vector); repeatable.
    #[arg(long = "param", value_parser = parse_param)]
    params: Vec<(String, ParamValue)>,
    /// Read back this graph image too (comma-separated or repeated), replacing the
    /// graph's `readback` list; each is also written beside --out as
    /// STEM.NAME.exr, in linear floats.
    #[arg(long, value_delimiter = ',')]
    readback: Vec<String>,
    /// Progressive graphs (graphs/pathtrace.ron): render until this many samples
    /// per pixel, at a fixed scene time, instead of --frames frames.
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..))]
    spp: Option<u64>,
    /// Stop early once another frame would end past this many seconds (the
    /// samples reached are reported); at least one frame is drawn.
    #[arg(long, value_parser = parse_seconds)]
    time_limit: Option<f64>,
    /// Random seed: sets the graph parameter `seed` (the path tracer's), so a
    /// seed renders the same image every run.
    #[arg(long)]
    seed: Option<u32>,
    /// Do not read or write cached data (imported models in `models/`,
    /// compiled shaders in `spirv/` and the ray tracer's BVH, kept in
    /// $WEFT_CACHE_DIR, else $XDG_CACHE_HOME/weft or ~/.cache/weft).
    #[arg(long)]
    no_cache: bool,
    /// Use the first device whose name contains this.
    #[arg(long)]
    device: Option<String>,
    /// Keep running: re-render whenever the graph, its includes, its shaders or the
    /// scene change, replacing --out atomically and printing one line per change;
    /// stop with Ctrl-C (SIGINT) or SIGTERM.
    #[arg(long)]
    watch: bool,
}

/// Parses a positive, finite number of seconds.
fn parse_seconds(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 => Ok(s),
        _ => Err(format!(
            "expected a positive number of seconds, found \"{text}\""
        )),
    }
}

/// Parses `NAME=VALUE` as `--param` takes it.
pub(crate) fn parse_param(text: &str) -> Result<(String, ParamValue), String> {
    let (name, value) = text
        .split_once('=')
        .ok_or_else(|| format!("a parameter must look like name=value, found \"{text}\""))?;
    let number = |v: &str| {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|n| n.is_finite())
            .ok_or_else(|| format!("\"{v}\" in --param {name} is not a number"))
    };
    let value = match value.trim() {
        "true" => ParamValue::Bool(true),
        "false" => ParamValue::Bool(false),
        v if v.contains(',') => {
            ParamValue::Vector(v.split(',').map(number).collect::<Result<_, _>>()?)
        }
        v => ParamValue::Number(number(v)?),
    };
    Ok((name.trim().to_string(), value))
}

/// A scene time in seconds: a finite number (NaN or infinity would make every
/// animated light and camera vanish).
pub fn parse_time(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(t) if t.is_finite() => Ok(t),
        Ok(_) => Err(format!(
            "time must be a finite number of seconds, found \"{text}\""
        )),
        Err(_) => Err(format!("expected a number of seconds, found \"{text}\"")),
    }
}

/// The images to read back besides the output: `--readback`, else the
/// graph's own `readback` list (none while the graph does not load).
fn readback_names(args: &RenderArgs, graph: Option<&weft_graph::Prepared>) -> Vec<String> {
    match graph {
        _ if !args.readback.is_empty() => args.readback.clone(),
        Some(graph) => graph.graph().readback_names(),
        None => Vec::new(),
    }
}

/// The image `--readback NAME` asks for: one the plan read back, or the
/// graph's output (read back every frame as the PNG's source); else why not.
fn read_back<'a>(
    rendered: &'a weft_render::Rendered,
    name: &str,
) -> Result<&'a weft_gpu::Readback> {
    if let Some(image) = rendered.report.first_read_back(&[name.to_string()]) {
        return Ok(image);
    }
    let plan = &rendered.plan;
    if plan.resources[plan.output].name == name {
        return rendered
            .report
            .output
            .as_ref()
            .with_context(|| format!("--readback {name}: the frame produced no output image"));
    }
    bail!(
        "--readback {name}: no pass wrote \"{name}\" in the last frame, so there is nothing to read back (its passes are culled under these features; `weft graph plan` lists them)"
    )
}

/// `out` with `.NAME.exr` in place of its extension: where `--readback NAME` goes.
fn readback_path(out: &Path, name: &str) -> PathBuf {
    let stem = out
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    out.with_file_name(format!("{stem}.{name}.exr"))
}

fn default_out(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "render".into());
    Path::new("out").join(format!("{stem}.png"))
}

/// Progress on stderr for renders to a sample count or a time limit: a bar
/// on a terminal, a line every 10 s or tenth elsewhere (none with --json).
fn progress_bar(args: &RenderArgs) -> Progress {
    if args.json || (args.spp.is_none() && args.time_limit.is_none()) {
        return Progress::hidden();
    }
    Progress::new(
        "render",
        "frame",
        "{elapsed_precise} [{bar:30}] frame {pos}/{len} {msg} (ETA {eta})",
    )
}

/// The render settings the arguments ask for.
fn settings(args: &RenderArgs, extra_readback: Vec<String>) -> RenderSettings {
    RenderSettings {
        graph: args.graph.clone(),
        extent: args.size,
        frames: args.frames,
        time: args.time,
        camera: args.camera.clone(),
        features: args.features.clone(),
        timing: match args.timings {
            None => TimingMode::Off,
            Some(Timings::Gpu) => TimingMode::GpuTimestamps,
            Some(Timings::Cpu) => TimingMode::CpuPerPass,
        },
        readback: true,
        extra_readback,
        params: args
            .params
            .iter()
            .cloned()
            .chain(
                args.seed
                    .map(|k| ("seed".to_string(), ParamValue::Number(f64::from(k)))),
            )
            .collect(),
        samples: args.spp,
        time_limit: args.time_limit,
        cache_dir: if args.no_cache {
            None
        } else {
            weft_scene::cache::user_cache_dir()
        },
        environment: args.environment.clone(),
        trace_backend: args.backend,
        ..RenderSettings::default()
    }
}

/// Runs `weft render`.
pub fn run(args: RenderArgs) -> Result<ExitCode> {
    if args.no_cache {
        weft_gpu::spirv_cache::set_dir(None);
    }
    let out = args.out.clone().unwrap_or_else(|| default_out(&args.scene));
    let exr = match out.extension().and_then(|e| e.to_str()) {
        Some("png") => false,
        Some("exr") => true,
        _ => bail!("--out {}: use a .png or .exr file name", out.display()),
    };
    if let Some(dir) = args
        .out
        .as_deref()
        .and_then(Path::parent)
        .filter(|d| !d.as_os_str().is_empty() && !d.is_dir())
    {
        bail!(
            "--out {}: the folder {} does not exist (only the default, out/, is created)",
            out.display(),
            dir.display()
        );
    }
    weft_io::check_output(&out).with_context(|| format!("--out {}", out.display()))?;
    for name in &args.readback {
        let path = readback_path(&out, name);
        weft_io::check_output(&path).with_context(|| format!("--readback {name}"))?;
    }
    let mut settings = settings(&args, Vec::new());
    // Loaded once: a render --watch waits for a graph that does not load yet;
    // a render reports it.
    let loaded = weft_render::load_graph(&settings);
    if let Ok(graph) = &loaded {
        crate::graphs::check_features(graph, &args.features)?;
    }
    settings.extra_readback = readback_names(&args, loaded.as_ref().ok());
    settings.readback_asked = !args.readback.is_empty();
    // An EXR file gets the first of these the frame reads back.
    let exr_images: Vec<String> = if exr {
        settings.extra_readback.clone()
    } else {
        Vec::new()
    };
    if args.watch && (args.spp.is_some() || args.time_limit.is_some()) {
        bail!("--spp and --time-limit render once; use them without --watch (`weft view` shows a progressive graph converging)");
    }
    if args.watch {
        return crate::watch_cmd::run(crate::watch_cmd::WatchRequest {
            scene: &args.scene,
            out: &out,
            images: &exr_images,
            graph: loaded.ok(),
            settings,
            gpu: GpuOptions {
                validation: args.validate,
                device: args.device.clone(),
            },
        });
    }
    let graph = loaded?;
    let scene = weft_render::load_scene(
        &args.scene,
        settings.cache_dir.as_deref(),
        settings.environment.as_deref(),
    )
    .with_context(|| format!("loading {}", args.scene.display()))?;
    for w in &scene.warnings {
        eprintln!("warning: {}: {}", w.at, w.message);
    }
    let gpu = Gpu::new(&GpuOptions {
        validation: args.validate,
        device: args.device.clone(),
    })?;
    let log = gpu.validation();
    let device = gpu.info().name.clone();
    if !args.json {
        println!("device: {device} ({:?})", gpu.info().kind);
    }
    let bar = progress_bar(&args);
    let rendered = render_with_progress(&gpu, &scene, &graph, &settings, &mut |p| {
        bar.set_length(p.planned_frames.into());
        bar.set_position(p.frames.into());
        if let Some(samples) = p.samples {
            let per_second = samples as f64 / p.elapsed.max(1e-9);
            let pixels = f64::from(args.size.width) * f64::from(args.size.height);
            bar.set_message(format!(
                "{samples} spp, {per_second:.1} spp/s, {:.2} M samples/s",
                per_second * pixels / 1e6
            ));
        }
    })?;
    bar.finish_and_clear();
    drop(gpu);
    let output = rendered
        .report
        .first_read_back(&exr_images)
        .or(rendered.report.output.as_ref())
        .context("the frame produced no output image")?;
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    output.save(&out)?;
    for name in &args.readback {
        let image = read_back(&rendered, name)?;
        let path = readback_path(&out, name);
        image.save(&path)?;
        if !args.json {
            println!("wrote {} ({name})", path.display());
        }
    }
    for w in rendered
        .warnings
        .iter()
        .chain(&weft_gpu::spirv_cache::take_warnings())
    {
        eprintln!("warning: {w}");
    }
    let counts = log.counts();
    for m in log.messages() {
        eprintln!("validation {:?}: {}: {}", m.severity, m.id, m.text);
    }
    let passes: Vec<&str> = rendered
        .plan
        .passes
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    let record_ms = Rendered::steady_mean(&rendered.record_ms);
    let frame_ms = Rendered::steady_mean(&rendered.frame_ms);
    let pixels = f64::from(args.size.width) * f64::from(args.size.height);
    let rays = rendered.rays.last().map(Vec::as_slice).unwrap_or_default();
    if args.json {
        let timings: Vec<_> = rendered
            .report
            .timings
            .iter()
            .map(|t| serde_json::json!({ "pass": t.pass, "source": t.source.label(), "ms": t.ms }))
            .collect();
        let summary = serde_json::json!({
            "device": device,
            "scene": args.scene,
            "graph": args.graph,
            "size": [args.size.width, args.size.height],
            "frames": rendered.frame_ms.len(),
            "samples_per_pixel": rendered.samples,
            "camera": rendered.camera,
            "features": rendered.plan.features,
            "passes": passes,
            "culled": rendered.plan.culled.iter().map(|c| &c.name).collect::<Vec<_>>(),
            "output": out,
            "draw_calls": rendered.draw_calls,
            "culling": rendered.culling.iter().map(|c| serde_json::json!({
                "view": c.view,
                "drawn": c.drawn,
                "culled": c.culled,
                "kept": c.kept,
            })).collect::<Vec<_>>(),
            "record_ms": record_ms,
            "frame_ms": frame_ms,
            "prepare_ms": rendered.prepare_ms,
            "timings": timings,
            "rays": rays.iter().map(|r| serde_json::json!({
                "pass": r.pass,
                "rays": r.rays,
                "per_pixel": r.rays as f64 / pixels,
            })).collect::<Vec<_>>(),
            "statistics": rendered.report.statistics,
            "views": rendered.views
                .iter()
                .map(|(name, summary)| (name.clone(), serde_json::json!(summary)))
                .collect::<serde_json::Map<String, serde_json::Value>>(),
            "transient_bytes": rendered.report.transient_bytes,
            "device_memory_bytes": rendered.report.memory.allocated_bytes,
            "validation": {
                "enabled": args.validate,
                "errors": counts.errors,
                "warnings": counts.warnings,
                "performance": counts.performance,
            },
        });
        println!("{}", serde_json::to_string_pretty(&summary)?);
    } else {
        println!(
            "{} through {} at {}x{} ({} frame(s), camera \"{}\"): {}",
            args.scene.display(),
            args.graph.display(),
            args.size.width,
            args.size.height,
            rendered.frame_ms.len(),
            rendered.camera,
            passes.join(" -> ")
        );
        if let Some(samples) = rendered.samples {
            let seconds = rendered.frame_ms.iter().sum::<f64>() / 1e3;
            println!(
                "samples: {samples} per pixel in {seconds:.2} s ({:.0} samples per second)",
                samples as f64 * f64::from(args.size.width) * f64::from(args.size.height)
                    / seconds.max(1e-9)
            );
        }
        println!(
            "draw calls: {}; host recording: {record_ms:.3} ms per frame; frame: {frame_ms:.3} ms wall{}; \
             pipelines and scene data built in {:.0} ms before the first frame",
            rendered.draw_calls,
            if rendered.frame_ms.len() > 1 {
                " (mean after the first frame)"
            } else {
                " (one frame)"
            },
            rendered.prepare_ms
        );
        if !rendered.culling.is_empty() {
            let views: Vec<String> = rendered
                .culling
                .iter()
                .map(|c| {
                    if c.kept {
                        format!("{} kept from the last frame", c.view)
                    } else {
                        format!("{} {} of {}", c.view, c.culled, c.drawn + c.culled)
                    }
                })
                .collect();
            println!("meshes outside each view, not drawn: {}", views.join("; "));
        }
        if !rendered.report.timings.is_empty() {
            print!("{}", format_timings(&rendered.report.timings));
        }
        if !rays.is_empty() {
            let per_pass: Vec<String> = rays
                .iter()
                .map(|r| format!("{} {:.3}", r.pass, r.rays as f64 / pixels))
                .collect();
            println!("rays per pixel, last frame: {}", per_pass.join(", "));
        }
        if args.validate {
            println!("validation: {counts}");
        }
        println!("wrote {}", out.display());
    }
    Ok(if counts.is_clean() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn params_parse_as_numbers_bools_and_vectors() {
        assert_eq!(
            parse_param("exposure=2.5"),
            Ok(("exposure".into(), ParamValue::Number(2.5)))
        );
        assert_eq!(
            parse_param("linear_taps=false"),
            Ok(("linear_taps".into(), ParamValue::Bool(false)))
        );
        assert_eq!(
            parse_param("direction=1,0"),
            Ok(("direction".into(), ParamValue::Vector(vec![1.0, 0.0])))
        );
        assert_eq!(
            parse_param("exposure"),
            Err("a parameter must look like name=value, found \"exposure\"".into())
        );
        assert_eq!(
            parse_param("exposure=bright"),
            Err("\"bright\" in --param exposure is not a number".into())
        );
    }
}
