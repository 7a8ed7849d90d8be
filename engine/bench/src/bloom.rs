//! `weft bench bloom`: the bloom blur with paired linear-filtered taps (the
//! default) against one fetch per texel (`bloom_naive`), over kernel radii:
//! GPU time of the two blur passes and the largest difference between the two
//! results, written as a CSV and a plot.
//!
//! The input is a deterministic HDR pattern (shaders/hdr_pattern.frag) fed to
//! the shipped graphs/bloom.ron, with `sigma` scaled with the radius as in the
//! default (sigma 9 for radius 21).

use crate::plot::{self, LinePlot, Series};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use weft_gpu::{
    memory_requirements, FrameOptions, Gpu, GpuOptions, NoDraws, Readback, Renderer, TimingMode,
};
use weft_graph::plan::Extent;
use weft_graph::CompileOptions;

/// Arguments of `weft bench bloom`.
#[derive(Args)]
pub struct BloomArgs {
    /// Kernel radii (taps either side); the naive shader holds up to 21.
    #[arg(long, value_delimiter = ',', default_value = "3,7,11,15,21", value_parser = clap::value_parser!(u32).range(1..=128))]
    radii: Vec<u32>,
    /// Output size, WIDTHxHEIGHT (bloom runs at half of it).
    #[arg(long, default_value = "1920x1080", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Frames per measurement; the first (pipeline builds) is left out of the mean.
    #[arg(long, default_value_t = 6, value_parser = clap::value_parser!(u32).range(1..=10_000))]
    frames: u32,
    /// Where the CSV and the plot go (`bloom_bench.csv`, `bloom_bench.png`).
    /// Default: the user's cache (`~/.cache/weft/bench/bloom`); `docs`
    /// refreshes the committed figures.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Use the first device whose name contains this.
    #[arg(long)]
    device: Option<String>,
}

/// One kernel measured both ways.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Taps either side.
    pub radius: u32,
    /// Gaussian sigma in pixels.
    pub sigma: f64,
    /// Mean GPU time of both blur passes, paired taps, in milliseconds.
    pub linear_ms: f64,
    /// The same with one fetch per texel.
    pub naive_ms: f64,
    /// Largest channel difference between the two results over the largest value.
    pub max_rel_error: f64,
}

/// Fetches per pixel per direction: the centre plus both sides.
pub fn fetches(radius: u32, linear: bool) -> u32 {
    if linear {
        1 + 2 * radius.div_ceil(2)
    } else {
        1 + 2 * radius
    }
}

/// Sigma for a radius, keeping the default's ratio (9 at 21).
pub fn sigma_for(radius: u32) -> f64 {
    f64::from(radius) * 9.0 / 21.0
}

/// The samples as CSV.
pub fn csv(samples: &[Sample]) -> String {
    let mut text = String::from(
        "radius,sigma,fetches_linear,fetches_naive,linear_ms,naive_ms,max_rel_error\n",
    );
    for s in samples {
        let _ = writeln!(
            text,
            "{},{:.4},{},{},{:.3},{:.3},{:.3e}",
            s.radius,
            s.sigma,
            fetches(s.radius, true),
            fetches(s.radius, false),
            s.linear_ms,
            s.naive_ms,
            s.max_rel_error
        );
    }
    text
}

/// The bench graph: the pattern, the shipped bloom fragment with this kernel,
/// and the shipped tonemap, referring to the repository's files by absolute path.
fn bench_graph(root: &Path, radius: u32) -> String {
    let graphs = root.join("graphs");
    let shaders = root.join("shaders");
    format!(
        r#"Graph(
    name: "bloom_bench",
    include: [(file: "{bloom}", params: {{ "sigma": {sigma}, "radius": {radius} }})],
    resources: [
        Image(name: "hdr", format: R16G16B16A16_SFLOAT),
        Image(name: "ldr", format: R8G8B8A8_UNORM),
    ],
    passes: [
        Pass(
            name: "pattern",
            kind: Fullscreen,
            shaders: (fragment: "{pattern}"),
            color: [(image: "hdr")],
            params: {{ "peak": 6.0, "level": 0.9 }},
        ),
        Pass(
            name: "tonemap",
            kind: Fullscreen,
            shaders: (fragment: "{tonemap}"),
            sampled: ["hdr", (name: "bloom", enabled_if: ["bloom"])],
            color: [(image: "ldr")],
            params: {{ "exposure": 1.0 }},
        ),
    ],
    output: "ldr",
)
"#,
        bloom = graphs.join("bloom.ron").display(),
        sigma = sigma_for(radius),
        pattern = shaders.join("hdr_pattern.frag").display(),
        tonemap = shaders.join("tonemap.frag").display(),
    )
}

/// Renders the bench graph and returns the mean blur time (after the first
/// frame) and the last frame's `bloom` image.
fn measure(
    gpu: &Gpu,
    graph: &Path,
    extent: Extent,
    naive: bool,
    frames: u32,
) -> Result<(f64, Readback)> {
    let prepared = match weft_graph::Prepared::new(weft_graph::load(graph)) {
        Ok(prepared) => prepared,
        Err(diagnostics) => bail!("the bench graph does not load: {diagnostics:?}"),
    };
    let memory = memory_requirements(gpu);
    let features: &[&str] = if naive { &["bloom_naive"] } else { &[] };
    let options = CompileOptions {
        extent,
        features: prepared.graph().features(features),
        memory: &memory,
        scene_values: Default::default(),
        readback: vec!["bloom".into()],
        readback_asked: true,
    };
    let plan = match weft_render::compile_plan(&prepared, &options) {
        Ok(plan) => plan,
        Err(diagnostics) => bail!("the bench graph does not compile: {diagnostics:?}"),
    };
    let mut renderer = Renderer::new(gpu)?;
    let mut resources = renderer.create_resources(&plan)?;
    let mut times = Vec::new();
    let mut bloom = None;
    for frame in 0..frames {
        let last = frame + 1 == frames;
        let report = renderer.execute(
            &plan,
            &mut resources,
            &mut NoDraws,
            &FrameOptions {
                timing: TimingMode::GpuTimestamps,
                readback: last,
                frame,
                ..FrameOptions::default()
            },
        )?;
        let blur: f64 = report
            .timings
            .iter()
            .filter(|t| t.pass.starts_with("bloom_blur_") || t.pass.starts_with("bloom_naive_"))
            .map(|t| t.ms)
            .sum();
        if frame > 0 {
            times.push(blur);
        }
        if last {
            bloom = report.readbacks.into_iter().find(|(n, _)| n == "bloom");
        }
    }
    let (_, image) = bloom.context("the bloom image was not read back")?;
    let mean = times.iter().sum::<f64>() / times.len().max(1) as f64;
    Ok((mean, image))
}

/// Largest channel difference between two float images over the largest value of `b`.
pub fn max_rel_error(a: &Readback, b: &Readback) -> f64 {
    let (a, b) = (a.to_rgba_f32(), b.to_rgba_f32());
    let mut diff = 0.0f64;
    let mut peak = 0.0f64;
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            diff = diff.max(f64::from((p.0[c] - q.0[c]).abs()));
            peak = peak.max(f64::from(q.0[c].abs()));
        }
    }
    if peak > 0.0 {
        diff / peak
    } else {
        diff
    }
}

/// Runs `weft bench bloom`.
pub fn run(args: BloomArgs) -> Result<ExitCode> {
    let root = std::env::current_dir()?;
    if !root.join("graphs/bloom.ron").is_file() {
        bail!("graphs/bloom.ron not found (run from the repository root)");
    }
    if args.radii.iter().any(|&r| r == 0 || r > 21) {
        bail!("--radii must be between 1 and 21 (the naive shader holds 22 weights)");
    }
    let gpu = Gpu::new(&GpuOptions {
        validation: false,
        device: args.device.clone(),
    })?;
    let frames = args.frames.max(2);
    println!(
        "device: {}; {}x{} (bloom at half), {} frame(s) per point (GPU timestamps, mean after the first)",
        gpu.info().name,
        args.size.width,
        args.size.height,
        frames
    );
    let dir = std::env::temp_dir().join(format!("weft-bench-bloom-{}", std::process::id()));
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut samples = Vec::new();
    for &radius in &args.radii {
        let graph = dir.join(format!("bloom_r{radius}.ron"));
        std::fs::write(&graph, bench_graph(&root, radius))
            .with_context(|| format!("writing {}", graph.display()))?;
        let (linear_ms, linear) = measure(&gpu, &graph, args.size, false, frames)?;
        let (naive_ms, naive) = measure(&gpu, &graph, args.size, true, frames)?;
        let sample = Sample {
            radius,
            sigma: sigma_for(radius),
            linear_ms,
            naive_ms,
            max_rel_error: max_rel_error(&linear, &naive),
        };
        println!(
            "radius {radius:>2} (sigma {:.2}): paired {linear_ms:.2} ms ({} fetches), naive {naive_ms:.2} ms ({} fetches), max difference {:.2e} of the peak",
            sample.sigma,
            fetches(radius, true),
            fetches(radius, false),
            sample.max_rel_error
        );
        samples.push(sample);
    }
    let _ = std::fs::remove_dir_all(&dir);
    let out_dir = crate::output::out_dir(args.out_dir.as_deref(), "bloom")?;
    let csv_path = out_dir.join("bloom_bench.csv");
    weft_io::write_output(&csv_path, csv(&samples).as_bytes())?;
    let footprint = |s: &Sample| f64::from(2 * s.radius + 1);
    let chart = LinePlot {
        title: format!(
            "Bloom blur (both passes) at {}x{}, {}",
            args.size.width / 2,
            args.size.height / 2,
            gpu.info().name
        ),
        x_label: "kernel footprint (texels per direction)".into(),
        y_label: "GPU time (ms)".into(),
        log_x: false,
        log_y: false,
        x_ticks: Vec::new(),
        series: vec![
            Series {
                name: "one fetch per texel".into(),
                points: samples.iter().map(|s| (footprint(s), s.naive_ms)).collect(),
            },
            Series {
                name: "paired linear fetches".into(),
                points: samples
                    .iter()
                    .map(|s| (footprint(s), s.linear_ms))
                    .collect(),
            },
        ],
    };
    let png_path = out_dir.join("bloom_bench.png");
    plot::write_png(&chart, &png_path, 960, 600)?;
    println!("wrote {} and {}", csv_path.display(), png_path.display());
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fetch_counts_of_the_default_kernel() {
        assert_eq!(fetches(21, true), 23);
        assert_eq!(fetches(21, false), 43);
        assert_eq!(fetches(4, true), 5);
        assert!((sigma_for(21) - 9.0).abs() < 1e-12);
    }

    #[test]
    fn csv_lists_every_sample() {
        let samples = [Sample {
            radius: 21,
            sigma: 9.0,
            linear_ms: 1.5,
            naive_ms: 2.25,
            max_rel_error: 1.5e-3,
        }];
        assert_eq!(
            csv(&samples),
            "radius,sigma,fetches_linear,fetches_naive,linear_ms,naive_ms,max_rel_error\n21,9.0000,23,43,1.500,2.250,1.500e-3\n"
        );
    }
}
