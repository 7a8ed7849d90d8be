//! `weft bench pathtrace`: the path tracer's speed (samples per second, after
//! the first frame, which builds pipelines and the BVH) and, given a reference
//! image, its convergence: relative MSE against the reference at each sample
//! count, plotted against render time. `tools/pathtrace_vs_mitsuba.py` runs it
//! beside Mitsuba 3 on the same scene.

use crate::plot::{write_png, LinePlot, Series};
use anyhow::{bail, Context, Result};
use clap::Args;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use weft_compare::rel_mse;
use weft_gpu::{Gpu, GpuOptions, Pixels};
use weft_graph::plan::Extent;
use weft_graph::schema::ParamValue;
use weft_render::{render, RenderSettings};

/// Options of `weft bench pathtrace`.
#[derive(Args)]
pub struct PathtraceArgs {
    /// The scene.
    #[arg(long, default_value = "scenes/cornell.scene")]
    scene: PathBuf,
    /// The progressive graph.
    #[arg(long, default_value = "graphs/pathtrace.ron")]
    graph: PathBuf,
    /// Image size.
    #[arg(long, default_value = "256x256", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Sample counts to render, each a render of its own; the last is the
    /// one whose speed is reported.
    #[arg(long, value_delimiter = ',', default_value = "4,16,64", value_parser = clap::value_parser!(u64).range(1..=1_000_000))]
    spp: Vec<u64>,
    /// Path length limit (`max_depth`, the camera ray counting as 1).
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(1..=1024))]
    max_depth: u32,
    /// Samples per pixel per frame (`samples_per_frame`), at most half of
    /// each count so that a frame after the first (which builds pipelines)
    /// is timed. A graph without that parameter keeps its own (the
    /// wavefront path tracer: one).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=1024))]
    samples_per_frame: u32,
    /// A converged image of the same scene, camera and size (linear EXR) to
    /// measure relative MSE against.
    #[arg(long)]
    reference: Option<PathBuf>,
    /// Where the CSV and the plot go (`pathtrace_bench.csv`,
    /// `pathtrace_convergence.png`, the plot only with --reference).
    /// Default: the user's cache (`~/.cache/weft/bench/pathtrace`); `docs`
    /// refreshes the committed figures.
    #[arg(long)]
    out_dir: Option<PathBuf>,
    /// Also write the last render here (linear EXR).
    #[arg(long)]
    image: Option<PathBuf>,
    /// How rays traverse the scene: `software` (the BVH walk), `hardware`
    /// (ray queries) or `auto` (docs/hardware_rt.md).
    #[arg(long, default_value = "auto")]
    backend: weft_render::TraceBackend,
    /// Print the figures as JSON.
    #[arg(long)]
    json: bool,
}

/// One render's figures.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    pub spp: u64,
    /// Seconds of rendering after the first frame, scaled to the whole count.
    pub seconds: f64,
    pub samples_per_second: f64,
    /// Relative MSE against the reference, when one is given.
    pub rel_mse: Option<f64>,
}

pub fn csv(samples: &[Sample]) -> String {
    let mut out = String::from("spp,seconds,samples_per_second,rel_mse\n");
    for s in samples {
        let rel = s.rel_mse.map(|r| format!("{r:.6e}")).unwrap_or_default();
        out.push_str(&format!(
            "{},{:.4},{:.0},{rel}\n",
            s.spp, s.seconds, s.samples_per_second
        ));
    }
    out
}

/// Runs `weft bench pathtrace`.
pub fn run(args: PathtraceArgs) -> Result<ExitCode> {
    if args.spp.is_empty() || args.spp.contains(&0) {
        bail!("--spp: give sample counts of at least 1");
    }
    let reference = match &args.reference {
        Some(path) => {
            let image = weft_compare::LinearImage::read_exr(path)?;
            let extent = Extent {
                width: image.width,
                height: image.height,
            };
            let pixels = image.pixels;
            if extent != args.size {
                bail!(
                    "{} is {}x{}, the render is {}x{}",
                    path.display(),
                    extent.width,
                    extent.height,
                    args.size.width,
                    args.size.height
                );
            }
            Some(pixels)
        }
        None => None,
    };
    let scene = weft_scene::load_scene(&args.scene)
        .with_context(|| format!("loading {}", args.scene.display()))?;
    let gpu = Gpu::new(&GpuOptions::default())?;
    let pixels = f64::from(args.size.width) * f64::from(args.size.height);
    // A graph with a fixed number of samples a frame (the wavefront path
    // tracer: one) takes no `samples_per_frame`.
    let sets_samples_per_frame = weft_graph::load(&args.graph)
        .settable_params()
        .contains("samples_per_frame");
    let mut samples = Vec::new();
    let mut last_image = None;
    for &spp in &args.spp {
        // At least two frames where spp allows: the first builds pipelines
        // and the BVH and is not timed, so a one-frame render would time
        // the builds.
        let per_frame = if sets_samples_per_frame {
            args.samples_per_frame
                .min(u32::try_from(spp / 2).unwrap_or(u32::MAX).max(1))
        } else {
            1
        };
        let mut params = BTreeMap::from([(
            "max_depth".into(),
            ParamValue::Number(args.max_depth.into()),
        )]);
        if sets_samples_per_frame {
            params.insert(
                "samples_per_frame".into(),
                ParamValue::Number(per_frame.into()),
            );
        }
        let settings = RenderSettings {
            graph: args.graph.clone(),
            extent: args.size,
            samples: Some(spp),
            extra_readback: vec!["hdr".into()],
            params,
            trace_backend: args.backend,
            ..RenderSettings::default()
        };
        let rendered = render(&gpu, &scene, &settings)?;
        let reached = rendered.samples.context("the graph is progressive")?;
        // The first frame builds pipelines and the BVH: time the rest and
        // scale to the whole count.
        let per_frame = u64::from(per_frame);
        let (steady_ms, steady_samples) = if rendered.frame_ms.len() > 1 {
            (
                rendered.frame_ms[1..].iter().sum::<f64>(),
                reached - per_frame,
            )
        } else {
            (rendered.frame_ms[0], reached)
        };
        let samples_per_second = steady_samples as f64 * pixels / (steady_ms / 1e3);
        let (_, hdr) = rendered
            .report
            .readbacks
            .first()
            .context("the graph reads back hdr")?;
        let Pixels::RgbaF32(values) = &hdr.pixels else {
            bail!("hdr is not a float image");
        };
        let image: Vec<[f32; 3]> = values.chunks(4).map(|p| [p[0], p[1], p[2]]).collect();
        samples.push(Sample {
            spp: reached,
            seconds: reached as f64 * pixels / samples_per_second,
            samples_per_second,
            rel_mse: reference.as_ref().map(|r| rel_mse(&image, r)),
        });
        last_image = Some(hdr.clone());
    }
    let out_dir = crate::output::out_dir(args.out_dir.as_deref(), "pathtrace")?;
    let csv_path = out_dir.join("pathtrace_bench.csv");
    weft_io::write_output(&csv_path, csv(&samples).as_bytes())?;
    if let Some(path) = &args.image {
        last_image.context("at least one render")?.save(path)?;
    }
    if reference.is_some() {
        let plot = LinePlot {
            title: format!(
                "path tracer convergence: {} at {}x{}",
                args.scene.display(),
                args.size.width,
                args.size.height
            ),
            x_label: "render time (s)".into(),
            y_label: "relative MSE against the reference".into(),
            log_x: true,
            log_y: true,
            x_ticks: Vec::new(),
            series: vec![Series {
                name: "weft (lavapipe)".into(),
                points: samples
                    .iter()
                    .filter_map(|s| s.rel_mse.map(|r| (s.seconds, r)))
                    .collect(),
            }],
        };
        write_png(&plot, &out_dir.join("pathtrace_convergence.png"), 900, 600)?;
    }
    if args.json {
        let rows: Vec<_> = samples
            .iter()
            .map(|s| {
                serde_json::json!({
                    "spp": s.spp,
                    "seconds": s.seconds,
                    "samples_per_second": s.samples_per_second,
                    "rel_mse": s.rel_mse,
                })
            })
            .collect();
        println!(
            "{}",
            serde_json::json!({
                "scene": args.scene,
                "size": [args.size.width, args.size.height],
                "max_depth": args.max_depth,
                "device": gpu.info().name,
                "backend": args.backend.name(),
                "renders": rows,
                "image": args.image,
            })
        );
    } else {
        println!(
            "{} on {}, --backend {}",
            args.scene.display(),
            gpu.info().name,
            args.backend.name()
        );
        println!("| spp | seconds | samples/s | rel. MSE |\n|---|---|---|---|");
        for s in &samples {
            let rel = s.rel_mse.map(|r| format!("{r:.3e}")).unwrap_or("-".into());
            println!(
                "| {} | {:.2} | {:.0} | {rel} |",
                s.spp, s.seconds, s.samples_per_second
            );
        }
        println!("wrote {}", csv_path.display());
    }
    Ok(ExitCode::SUCCESS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rel_mse_of_an_image_against_itself_is_zero_and_scales_with_the_error() {
        let reference = [[1.0, 0.5, 0.0], [0.2, 0.2, 0.2]];
        assert_eq!(rel_mse(&reference, &reference), 0.0);
        let off = [[1.1, 0.5, 0.0], [0.2, 0.2, 0.2]];
        let expected = 0.01 / 1.01 / 6.0;
        assert!((rel_mse(&off, &reference) - expected).abs() < 1e-9);
    }

    #[test]
    fn csv_lists_every_render() {
        let samples = [Sample {
            spp: 16,
            seconds: 1.5,
            samples_per_second: 700_000.0,
            rel_mse: Some(0.012),
        }];
        assert_eq!(
            csv(&samples),
            "spp,seconds,samples_per_second,rel_mse\n16,1.5000,700000,1.200000e-2\n"
        );
    }
}
