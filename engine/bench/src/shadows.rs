//! `weft bench shadows`: shadow-map resolution and PCF radius against error and
//! time. Error is the share of pixels whose sun visibility differs from a CPU
//! ray-traced reference of the same view (`crate::shadow_reference`);
//! time is the shadow pass plus what the lookups add to the shading pass (GPU
//! timestamps). Writes a CSV and two PNG plots.

use crate::plot::{self, LinePlot, Series};
use crate::shadow_reference::{compare, scene_sun_visibility};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_gpu::{Gpu, GpuOptions, Pixels, TimingMode};
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings, Rendered};
use weft_scene::{Light, Scene};

/// The shadow pass's name in `graphs/shadows.ron`.
const SHADOW_PASS: &str = "shadow_sun";

/// Arguments of `weft bench shadows`.
#[derive(Args)]
pub struct ShadowsArgs {
    /// The scene; only its first sun is kept, without ambient light.
    #[arg(long, default_value = "scenes/demo.scene")]
    scene: PathBuf,
    /// Camera name; the scene's first camera by default.
    #[arg(long)]
    camera: Option<String>,
    /// The graph whose `shadows.ron` include is varied.
    #[arg(long, default_value = "graphs/forward.ron")]
    graph: PathBuf,
    /// Shadow-map resolutions.
    #[arg(long, value_delimiter = ',', default_value = "512,1024,2048,4096", value_parser = clap::value_parser!(u32).range(16..=16384))]
    resolutions: Vec<u32>,
    /// PCF kernel radii.
    #[arg(long, value_delimiter = ',', default_value = "0,1,2,3", value_parser = clap::value_parser!(u32).range(0..=16))]
    radii: Vec<u32>,
    /// Sun cascades.
    #[arg(long, default_value_t = 1)]
    cascades: u32,
    /// Output size, WIDTHxHEIGHT.
    #[arg(long, default_value = "960x540", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Frames per render; times are the last frame's.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    frames: u32,
    /// Renders per configuration; times are the fastest render's (the machine is
    /// shared, and interference only ever adds time).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=1000))]
    repeats: u32,
    /// Where the CSV and plots go (`shadows_bench.csv`, `shadows_error.png`, `shadows_time.png`).
    /// Default: the user's cache (`~/.cache/weft/bench/shadows`); `docs`
    /// refreshes the committed figures.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Use the first device whose name contains this.
    #[arg(long)]
    device: Option<String>,
}

/// One configuration's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Shadow-map texels per side.
    pub resolution: u32,
    /// PCF kernel radius.
    pub radius: u32,
    /// Pixels compared with the reference.
    pub compared: usize,
    /// Of those, pixels whose visibility differs.
    pub differing: usize,
    /// Shadow pass, milliseconds.
    pub shadow_ms: f64,
    /// Every other pass (shading with shadow lookups, tonemapping), milliseconds.
    pub other_ms: f64,
    /// `other_ms` minus the same passes without shadows: the lookups' cost.
    pub lookup_ms: f64,
}

impl Sample {
    /// Differing pixels as a percentage of those compared.
    pub fn error_percent(&self) -> f64 {
        100.0 * self.differing as f64 / self.compared.max(1) as f64
    }
}

/// `graph` (its text, from directory `dir`) rewritten to be loaded from
/// anywhere: relative shader and include paths made absolute, and the
/// `shadows.ron` include given `params` (RON map entries), replacing its own.
pub fn graph_variant(text: &str, dir: &Path, params: &str) -> Result<String> {
    let start = text
        .find("(file: \"shadows.ron\"")
        .context("the graph does not include shadows.ron")?;
    let end = start
        + text[start..]
            .find(')')
            .context("unterminated shadows.ron include")?;
    let include = format!(
        "(file: \"{}\", params: {{ {params} }})",
        dir.join("shadows.ron").display()
    );
    let text = format!("{}{include}{}", &text[..start], &text[end + 1..]);
    let shaders = dir.join("../shaders");
    Ok(
        absolute_includes(&text, dir)
            .replace("\"../shaders/", &format!("\"{}/", shaders.display())),
    )
}

/// `text` with every include given relative to `dir` made absolute.
fn absolute_includes(text: &str, dir: &Path) -> String {
    const INCLUDE: &str = "(file: \"";
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(at) = rest.find(INCLUDE) {
        let (before, after) = rest.split_at(at + INCLUDE.len());
        out.push_str(before);
        if !after.starts_with('/') {
            out.push_str(&format!("{}/", dir.display()));
        }
        rest = after;
    }
    out.push_str(rest);
    out
}

/// The scene reduced to its first sun, without ambient light, and the same
/// with that sun switched off (what ambient and emission alone give).
fn sun_only(scene: &Scene) -> Result<(Scene, Scene)> {
    let sun = scene
        .lights
        .iter()
        .find_map(|l| match l {
            Light::Sun(s) => Some(s.clone()),
            _ => None,
        })
        .context("the scene has no sun")?;
    let mut lit = scene.clone();
    let mut sun = sun;
    sun.ambient = Default::default();
    lit.lights = vec![Light::Sun(sun.clone())];
    let mut dark = lit.clone();
    sun.color = Default::default();
    dark.lights = vec![Light::Sun(sun)];
    Ok((lit, dark))
}

/// Per pixel, r + g + b of the HDR image read back.
fn hdr_sums(rendered: &Rendered) -> Result<Vec<f32>> {
    let (_, hdr) = rendered
        .report
        .readbacks
        .iter()
        .find(|(name, _)| name == "hdr")
        .context("no hdr readback")?;
    let Pixels::RgbaF32(values) = &hdr.pixels else {
        bail!("hdr is not a float image");
    };
    Ok(values.chunks(4).map(|p| p[0] + p[1] + p[2]).collect())
}

/// Milliseconds of the last frame's passes named `name` (`shadow_sun`), and of all the others.
fn pass_ms(rendered: &Rendered, name: &str) -> (f64, f64) {
    rendered
        .report
        .timings
        .iter()
        .fold((0.0, 0.0), |(a, b), t| {
            if t.pass == name {
                (a + t.ms, b)
            } else {
                (a, b + t.ms)
            }
        })
}

/// The samples as CSV.
pub fn csv(samples: &[Sample]) -> String {
    let mut text = String::from(
        "resolution,pcf_radius,error_percent,differing,compared,shadow_ms,other_ms,lookup_ms\n",
    );
    for s in samples {
        let _ = writeln!(
            text,
            "{},{},{:.4},{},{},{:.3},{:.3},{:.3}",
            s.resolution,
            s.radius,
            s.error_percent(),
            s.differing,
            s.compared,
            s.shadow_ms,
            s.other_ms,
            s.lookup_ms
        );
    }
    text
}

/// Runs `weft bench shadows`.
pub fn run(args: ShadowsArgs) -> Result<ExitCode> {
    if args.resolutions.is_empty() || args.radii.is_empty() {
        bail!("--resolutions and --radii must name at least one each");
    }
    let graph_text = weft_graph::load::read_from_disk(&args.graph).with_context(|| {
        format!(
            "reading {} (run from the repository root)",
            args.graph.display()
        )
    })?;
    let graph_dir = std::fs::canonicalize(args.graph.parent().unwrap_or(Path::new(".")))?;
    let stem = args
        .graph
        .file_stem()
        .map_or("graph".into(), |s| s.to_string_lossy().into_owned());
    let scene = weft_scene::load_scene(&args.scene)
        .with_context(|| format!("loading {}", args.scene.display()))?;
    let (lit, dark) = sun_only(&scene)?;
    let camera = match &args.camera {
        Some(name) => lit
            .camera(name)
            .with_context(|| format!("no camera {name}"))?,
        None => lit.cameras.first().context("the scene has no camera")?,
    };
    let size = [args.size.width, args.size.height];
    let started = std::time::Instant::now();
    let reference = scene_sun_visibility(&lit, camera, size).context("no sun")?;
    println!(
        "reference: {} pixels ray traced in {:.1} s",
        reference.len(),
        started.elapsed().as_secs_f64()
    );
    let gpu = Gpu::new(&GpuOptions {
        validation: false,
        device: args.device.clone(),
    })?;
    let work = std::env::temp_dir().join(format!("weft-bench-shadows-{}", std::process::id()));
    std::fs::create_dir_all(&work)?;
    let settings = |graph: PathBuf, features: &[&str]| RenderSettings {
        graph,
        extent: args.size,
        frames: args.frames.max(2),
        camera: Some(camera.name.clone()),
        features: features.iter().map(|f| f.to_string()).collect(),
        timing: TimingMode::GpuTimestamps,
        extra_readback: vec!["hdr".into()],
        ..RenderSettings::default()
    };
    let variant = |name: &str, params: &str| -> Result<PathBuf> {
        let path = work.join(format!("{stem}-{name}.ron"));
        std::fs::write(&path, graph_variant(&graph_text, &graph_dir, params)?)?;
        Ok(path)
    };
    let base = variant("base", "")?;
    let unshadowed = render(
        &gpu,
        &lit,
        &settings(base.clone(), &["!bloom", "!shadow_casters"]),
    )?;
    let ambient = render(&gpu, &dark, &settings(base, &["!bloom", "!shadow_casters"]))?;
    let (unshadowed_hdr, ambient_hdr) = (hdr_sums(&unshadowed)?, hdr_sums(&ambient)?);
    let sun_alone: Vec<f32> = unshadowed_hdr
        .iter()
        .zip(&ambient_hdr)
        .map(|(u, a)| u - a)
        .collect();
    let mut plain_ms = pass_ms(&unshadowed, SHADOW_PASS).1;
    for _ in 1..args.repeats.max(1) {
        let again = render(
            &gpu,
            &lit,
            &settings(variant("base", "")?, &["!bloom", "!shadow_casters"]),
        )?;
        plain_ms = plain_ms.min(pass_ms(&again, SHADOW_PASS).1);
    }
    println!(
        "device: {}; {}x{}; passes without shadows: {plain_ms:.2} ms",
        gpu.info().name,
        args.size.width,
        args.size.height,
    );
    let mut samples = Vec::new();
    for &resolution in &args.resolutions {
        for &radius in &args.radii {
            let params = format!(
                "\"resolution\": {resolution}, \"pcf_radius\": {radius}, \"cascades\": {}",
                args.cascades
            );
            let g = variant(&format!("{resolution}-{radius}"), &params)?;
            let shadowed_settings = settings(g, &["!bloom", "shadow_casters"]);
            let r = render(&gpu, &lit, &shadowed_settings)
                .with_context(|| format!("resolution {resolution}, radius {radius}"))?;
            let (mut shadow_ms, mut other_ms) = pass_ms(&r, SHADOW_PASS);
            for _ in 1..args.repeats.max(1) {
                let again = pass_ms(&render(&gpu, &lit, &shadowed_settings)?, SHADOW_PASS);
                shadow_ms = shadow_ms.min(again.0);
                other_ms = other_ms.min(again.1);
            }
            let shadowed: Vec<f32> = hdr_sums(&r)?
                .iter()
                .zip(&ambient_hdr)
                .map(|(s, a)| s - a)
                .collect();
            let d = compare(&reference, &shadowed, &sun_alone, 0.01);
            let s = Sample {
                resolution,
                radius,
                compared: d.compared,
                differing: d.differing,
                shadow_ms,
                other_ms,
                lookup_ms: other_ms - plain_ms,
            };
            println!(
                "{resolution:>5} r={radius}: error {:.3}% ({} of {}), shadow {:.2} ms, lookups +{:.2} ms",
                s.error_percent(),
                s.differing,
                s.compared,
                s.shadow_ms,
                s.lookup_ms
            );
            samples.push(s);
        }
    }
    let _ = std::fs::remove_dir_all(&work);
    let out_dir = crate::output::out_dir(args.out_dir.as_deref(), "shadows")?;
    let csv_path = out_dir.join("shadows_bench.csv");
    weft_io::write_output(&csv_path, csv(&samples).as_bytes())?;
    let series = |y: &dyn Fn(&Sample) -> f64| -> Vec<Series> {
        args.radii
            .iter()
            .map(|&r| Series {
                name: format!("pcf_radius {r}"),
                points: samples
                    .iter()
                    .filter(|s| s.radius == r)
                    .map(|s| (f64::from(s.resolution), y(s)))
                    .collect(),
            })
            .collect()
    };
    let title = |what: &str| {
        format!(
            "{what} vs shadow-map resolution, {}x{} ({})",
            args.size.width,
            args.size.height,
            gpu.info().name
        )
    };
    let error_png = out_dir.join("shadows_error.png");
    plot::write_png(
        &LinePlot {
            title: title("Visibility error"),
            x_label: "shadow-map resolution (texels per side)".into(),
            y_label: "pixels differing from ray-traced visibility (%)".into(),
            log_x: true,
            log_y: false,
            x_ticks: args.resolutions.iter().map(|&r| f64::from(r)).collect(),
            series: series(&|s| s.error_percent()),
        },
        &error_png,
        960,
        600,
    )?;
    let time_png = out_dir.join("shadows_time.png");
    plot::write_png(
        &LinePlot {
            title: title("Shadow cost"),
            x_label: "shadow-map resolution (texels per side)".into(),
            y_label: "shadow pass + lookup cost (ms)".into(),
            log_x: true,
            log_y: false,
            x_ticks: args.resolutions.iter().map(|&r| f64::from(r)).collect(),
            series: series(&|s| s.shadow_ms + s.lookup_ms),
        },
        &time_png,
        960,
        600,
    )?;
    println!(
        "wrote {}, {} and {}",
        csv_path.display(),
        error_png.display(),
        time_png.display()
    );
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shadows_include_gets_the_params_and_paths_become_absolute() {
        let text = "include: [\n (file: \"shadows.ron\", params: { \"resolution\": 2048 }),\n (file: \"bloom.ron\"),\n],\nshaders: (vertex: \"../shaders/mesh.vert\"),";
        let out =
            graph_variant(text, Path::new("/r/graphs"), "\"pcf_radius\": 2").expect("rewrites");
        assert_eq!(
            out,
            "include: [\n (file: \"/r/graphs/shadows.ron\", params: { \"pcf_radius\": 2 }),\n (file: \"/r/graphs/bloom.ron\"),\n],\nshaders: (vertex: \"/r/graphs/../shaders/mesh.vert\"),"
        );
        assert!(graph_variant("no include", Path::new("/"), "").is_err());
    }

    #[test]
    fn csv_has_one_row_per_sample_with_the_error_share() {
        let s = Sample {
            resolution: 1024,
            radius: 1,
            compared: 400,
            differing: 3,
            shadow_ms: 1.5,
            other_ms: 10.0,
            lookup_ms: 2.25,
        };
        assert_eq!(
            csv(&[s]),
            "resolution,pcf_radius,error_percent,differing,compared,shadow_ms,other_ms,lookup_ms\n1024,1,0.7500,3,400,1.500,10.000,2.250\n"
        );
    }
}
