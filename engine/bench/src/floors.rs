//! `weft bench floors`: each pass against its floor in the same frame. The
//! bench graphs of `graphs/bench/` include a shipped graph and the floors
//! beside it: the scene's meshes with a constant fragment shader, and one
//! fullscreen read of the G-buffer. A pass that draws meshes at the output's
//! size is set against the first; a pass that samples every image the second
//! samples (a deferred lighting pass) against the second. Per-pass CPU wall
//! time, mean over the frames after the first.

use anyhow::{Context, Result};
use clap::Args;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::ExitCode;
use weft_gpu::{Gpu, GpuOptions, TimingMode};
use weft_graph::plan::{Extent, Plan, PlanPass};
use weft_graph::schema::Draw;
use weft_render::{load_graph, render_with_progress, RenderSettings};

/// Arguments of `weft bench floors`.
#[derive(Args)]
pub struct FloorsArgs {
    /// The scene rendered.
    #[arg(default_value = "scenes/demo.scene")]
    scene: PathBuf,
    /// Graphs measured, comma-separated: each includes a graph and the floors.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "graphs/bench/forward_floors.ron,graphs/bench/deferred_floors.ron,graphs/bench/tiled_floors.ron"
    )]
    graphs: Vec<PathBuf>,
    /// Output size.
    #[arg(long, default_value = "1280x720", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Frames per graph; the first (pipeline builds) is left out of the mean.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(2..=10_000))]
    frames: u32,
    /// The pass whose time is the floor of mesh passes.
    #[arg(long, default_value = "floor_meshes")]
    mesh_floor: String,
    /// The pass whose time is the floor of passes that read the G-buffer.
    #[arg(long, default_value = "floor_gbuffer_read")]
    gbuffer_floor: String,
    /// Use the first device whose name contains this.
    #[arg(long)]
    device: Option<String>,
}

/// The floor `pass` is measured against, if any.
fn floor_of<'p>(plan: &'p Plan, pass: &PlanPass, args: &FloorsArgs) -> Option<&'p str> {
    if pass.name == args.mesh_floor || pass.name == args.gbuffer_floor {
        return None;
    }
    let find = |name: &str| plan.passes.iter().find(|p| p.name == name);
    let at_output_size = pass
        .render_pass
        .as_ref()
        .is_some_and(|rp| rp.extent == plan.extent);
    if matches!(pass.draw, Some(Draw::Meshes(_))) && at_output_size {
        return find(&args.mesh_floor).map(|p| p.name.as_str());
    }
    let floor = find(&args.gbuffer_floor)?;
    let reads = |p: &PlanPass, r| p.bindings.iter().any(|b| b.resource == r);
    let all_read = floor.bindings.iter().all(|b| reads(pass, b.resource));
    all_read.then_some(floor.name.as_str())
}

/// Runs `weft bench floors`.
pub fn run(args: FloorsArgs) -> Result<ExitCode> {
    let scene = weft_scene::load_scene(&args.scene)
        .with_context(|| format!("loading {}", args.scene.display()))?;
    let gpu = Gpu::new(&GpuOptions {
        validation: false,
        device: args.device.clone(),
    })?;
    println!(
        "{} at {}x{}, per-pass CPU wall time, mean of frames 2..{} (`weft bench floors`)\n",
        args.scene.display(),
        args.size.width,
        args.size.height,
        args.frames
    );
    println!("| graph | pass | ms | floor | floor ms | pass / floor |\n|---|---|---|---|---|---|");
    for graph in &args.graphs {
        let mut settings = RenderSettings {
            graph: graph.clone(),
            extent: args.size,
            frames: args.frames,
            timing: TimingMode::CpuPerPass,
            ..RenderSettings::default()
        };
        let prepared = load_graph(&settings)?;
        settings.extra_readback = prepared.graph().readback_names();
        let rendered = render_with_progress(&gpu, &scene, &prepared, &settings, &mut |_| {})
            .with_context(|| format!("rendering through {}", graph.display()))?;
        let mut ms: BTreeMap<&str, f64> = BTreeMap::new();
        let measured = &rendered.timings[1..];
        for frame in measured {
            for t in frame {
                *ms.entry(t.pass.as_str()).or_default() += t.ms / measured.len() as f64;
            }
        }
        let stem = graph.file_stem().map_or_else(
            || graph.display().to_string(),
            |s| s.to_string_lossy().into_owned(),
        );
        for pass in &rendered.plan.passes {
            let Some(floor) = floor_of(&rendered.plan, pass, &args) else {
                continue;
            };
            let (Some(&own), Some(&base)) = (ms.get(pass.name.as_str()), ms.get(floor)) else {
                continue;
            };
            println!(
                "| {stem} | {} | {own:.1} | {floor} | {base:.1} | {:.1}× |",
                pass.name,
                own / base.max(1e-9)
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}
