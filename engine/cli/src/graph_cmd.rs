//! `weft graph check|plan|dot`.

use anyhow::{Context, Result};
use clap::{Args, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;
use weft_gpu::{Gpu, GpuOptions};
use weft_graph::{CompileOptions, Diagnostic, Extent};

/// Graph subcommands.
#[derive(Subcommand)]
pub enum GraphCommand {
    /// Validate graph files; exit 1 on any error (messages on stderr).
    Check {
        #[arg(required = true, value_parser = crate::graphs::graph_path)]
        files: Vec<PathBuf>,
        /// Also compile and reflect every pass's shaders and cross-check them with
        /// the graph: bindings, push constants, outputs.
        #[arg(long)]
        shaders: bool,
        /// Print the diagnostics as JSON (an array of objects with severity,
        /// file, pos, message, hint and notes) on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Compile a graph and print its plan: pass order, culled passes, barriers, render-pass ops.
    Plan {
        #[arg(value_parser = crate::graphs::graph_path)]
        file: PathBuf,
        #[command(flatten)]
        target: Target,
        /// Print the plan as JSON with a `stats` object.
        #[arg(long)]
        json: bool,
    },
    /// Print the graph as Graphviz DOT (culled passes greyed).
    Dot {
        #[arg(value_parser = crate::graphs::graph_path)]
        file: PathBuf,
        #[command(flatten)]
        target: Target,
    },
}

/// What a graph is compiled for.
#[derive(Args)]
pub struct Target {
    /// Output size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = clap::value_parser!(Extent))]
    size: Extent,
    /// Features on (comma-separated); `!name` turns off a graph default.
    #[arg(long, value_delimiter = ',')]
    features: Vec<String>,
    /// Take features (spot_lights, shadow_casters, ...) from a scene,
    /// so the plan shows what this scene culls and why.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Size memory with the first Vulkan device's requirements, as renders,
    /// `weft compare` and the viewer do, instead of the device-free estimate
    /// (64 KiB pages).
    #[arg(long)]
    on_device: bool,
}

/// Each diagnostic with its source line and a caret under the position.
fn print_diagnostics(diags: &[Diagnostic]) {
    eprint!("{}", weft_graph::diagnostic::render(diags));
}

fn compile(file: &Path, target: &Target) -> Result<(weft_graph::Prepared, weft_graph::Plan, f64)> {
    let failed = |diags: Vec<Diagnostic>| {
        print_diagnostics(&diags);
        let errors = diags.iter().filter(|d| d.is_error()).count();
        anyhow::anyhow!(
            "{} failed to compile with {errors} error(s)",
            file.display()
        )
    };
    let graph = weft_graph::Prepared::new(weft_graph::load(file)).map_err(failed)?;
    crate::graphs::check_features(&graph, &target.features)?;
    let mut requested = Vec::new();
    let mut scene = None;
    if let Some(path) = &target.scene {
        let loaded = weft_scene::load_scene(path)
            .with_context(|| format!("loading scene {}", path.display()))?;
        let scene = scene.insert(loaded);
        let from_scene = weft_render::scene_features(scene);
        eprintln!(
            "scene {}: features [{}]",
            path.display(),
            from_scene.join(", ")
        );
        requested.extend(from_scene);
    }
    requested.extend(target.features.iter().cloned());
    let gpu = target
        .on_device
        .then(|| {
            Gpu::new(&GpuOptions {
                validation: false,
                device: None,
            })
        })
        .transpose()?;
    let device_memory = gpu.as_ref().map(weft_gpu::memory_requirements);
    let memory: &dyn Fn(&weft_graph::plan::ResourceDesc) -> weft_graph::MemoryRequirements =
        match &device_memory {
            Some(m) => m,
            None => &weft_graph::estimate_requirements,
        };
    match &gpu {
        Some(gpu) => eprintln!("memory: sized for {}", gpu.info().name),
        None => eprintln!(
            "memory: estimated without a device (64 KiB pages); --on-device sizes it for the first Vulkan device"
        ),
    }
    // The scene values a renderer measures: the structures' build scratch,
    // for a plan that traces with ray queries, where there are a scene and
    // a device with them to measure on.
    let features = graph.graph().features(&requested);
    let mut scene_values = std::collections::BTreeMap::new();
    if features.contains(weft_render::RAY_QUERY_FEATURE) {
        match (&scene, &gpu) {
            (Some(scene), Some(gpu)) if gpu.info().shaders.ray_query => {
                let bytes = weft_render::structure_scratch_bytes(gpu, scene)
                    .context("measuring the scene's acceleration-structure scratch")?;
                scene_values.insert(
                    weft_render::vocabulary::STRUCTURE_SCRATCH_BYTES.to_string(),
                    bytes as f64,
                );
            }
            _ => eprintln!(
                "note: scene values are 0 (the structures' scratch is measured with --scene on a device with ray queries, --on-device)"
            ),
        }
    }
    let options = CompileOptions {
        extent: target.size,
        features,
        memory,
        scene_values,
        ..CompileOptions::default()
    };
    let start = Instant::now();
    let result = weft_render::compile_plan(&graph, &options);
    let compile_us = start.elapsed().as_secs_f64() * 1e6;
    let plan = result.map_err(failed)?;
    Ok((graph, plan, compile_us))
}

/// The device `check --shaders` checks for: the first Vulkan device, or,
/// without one, the minimums every Vulkan 1.3 device meets (and it says so).
fn shader_target() -> weft_render::ShaderTarget {
    match Gpu::new(&GpuOptions {
        validation: false,
        device: None,
    }) {
        Ok(gpu) => weft_render::ShaderTarget::of(&gpu),
        Err(e) => {
            eprintln!("note: no Vulkan device ({e}): shaders are checked against the minimums every Vulkan 1.3 device meets");
            weft_render::ShaderTarget::minimum()
        }
    }
}

/// Runs a graph subcommand.
pub fn run(cmd: GraphCommand) -> Result<ExitCode> {
    match cmd {
        GraphCommand::Check {
            files,
            shaders,
            json,
        } => {
            let mut failed = false;
            let mut all = Vec::new();
            let target = shaders.then(shader_target);
            for file in &files {
                let graph = weft_graph::load(file);
                let diags = if let Some(target) = &target {
                    weft_render::check_graph_and_shaders(&graph, target)?
                } else {
                    let mut diags = weft_graph::check(&graph);
                    diags.extend(weft_render::check_against_renderer(&graph));
                    diags
                };
                if !json {
                    print_diagnostics(&diags);
                }
                let errors = diags.iter().filter(|d| d.is_error()).count();
                let warnings = diags.len() - errors;
                all.extend(diags);
                if errors > 0 {
                    failed = true;
                    eprintln!(
                        "{}: {errors} error(s), {warnings} warning(s)",
                        file.display()
                    );
                } else {
                    eprintln!("{}: ok ({warnings} warning(s))", file.display());
                }
            }
            if json {
                println!("{}", weft_graph::diagnostic::to_json(&all));
            }
            Ok(if failed {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            })
        }
        GraphCommand::Plan { file, target, json } => {
            let (_, plan, compile_us) = compile(&file, &target)?;
            if json {
                let mut value = serde_json::to_value(&plan).context("serialising the plan")?;
                value["stats"] = serde_json::to_value(plan.stats(compile_us))?;
                println!("{}", serde_json::to_string_pretty(&value)?);
            } else {
                print!("{}", weft_graph::text::render(&plan));
                print_diagnostics(&plan.warnings);
            }
            Ok(ExitCode::SUCCESS)
        }
        GraphCommand::Dot { file, target } => {
            let (graph, plan, _) = compile(&file, &target)?;
            print!("{}", weft_graph::dot::render(graph.graph(), &plan));
            Ok(ExitCode::SUCCESS)
        }
    }
}
