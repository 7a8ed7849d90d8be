//! `weft graph check --shaders` as a library call: the graph's own checks,
//! then every shader it runs compiled, reflected and compared with the graph
//! and the engine's scene bindings, under every feature set the graph check
//! enumerates (features change the shader variants through defines).

use weft_gpu::check::check_with;
use weft_gpu::pipeline::PipelineCache;
use weft_gpu::{Gpu, GpuError, ShaderProblem, ShaderSupport};
use weft_graph::check::variant_sets;
use weft_graph::feature_names;
use weft_graph::{CompileOptions, Diagnostic, LoadedGraph, Prepared};

/// The device shaders are checked for: its name and what it offers.
#[derive(Debug, Clone)]
pub struct ShaderTarget {
    /// The device's name, as refusals print it.
    pub device: String,
    /// Its optional capabilities and compute limits.
    pub support: ShaderSupport,
}

impl ShaderTarget {
    /// The device `gpu` runs on.
    pub fn of(gpu: &Gpu) -> Self {
        Self {
            device: gpu.info().name.clone(),
            support: gpu.info().shaders,
        }
    }

    /// Any Vulkan 1.3 device: no optional capability, the required minimum limits.
    pub fn minimum() -> Self {
        Self {
            device: "any Vulkan 1.3 device (required minimums)".into(),
            support: ShaderSupport::core(),
        }
    }
}

/// Every diagnostic of `graph`: its own checks and, when those find no error
/// and it is not a fragment, its shaders' problems, each located at the
/// declaration of its pass: disagreements with the graph and the engine's
/// bindings, and what `target` does not offer (capabilities, extensions,
/// compute limits).
pub fn check_graph_and_shaders(
    graph: &LoadedGraph,
    target: &ShaderTarget,
) -> Result<Vec<Diagnostic>, GpuError> {
    let mut diags = weft_graph::check(graph);
    diags.extend(crate::providers::check(graph));
    if graph.is_fragment || diags.iter().any(Diagnostic::is_error) {
        return Ok(diags);
    }
    let prepared = match Prepared::new(graph.clone()) {
        Ok(p) => p,
        Err(errors) => {
            diags.extend(errors);
            return Ok(diags);
        }
    };
    let names: Vec<String> = feature_names(prepared.ir()).into_iter().collect();
    let mut cache = PipelineCache::new()?;
    let scene = crate::bindings::scene_interface();
    for features in variant_sets(&names) {
        let options = CompileOptions {
            features,
            readback: graph.readback_names(),
            ..CompileOptions::default()
        };
        let Ok(mut plan) = prepared.compile(&options) else {
            continue; // reported by `weft_graph::check`
        };
        if let Err(errors) = crate::providers::derive_values(&mut plan) {
            for d in errors {
                if !diags.contains(&d) {
                    diags.push(d);
                }
            }
            continue;
        }
        let mut problems = check_with(&mut cache, &plan, Some(&scene));
        problems.extend(unoffered(&mut cache, &plan, target));
        for ShaderProblem { pass, message } in problems {
            let at = plan
                .passes
                .iter()
                .find(|p| p.name == pass)
                .map(|p| p.declared_at.clone())
                .unwrap_or_default();
            let d = Diagnostic::error(at.file, at.pos, format!("pass \"{pass}\": {message}"));
            if !diags.contains(&d) {
                diags.push(d);
            }
        }
    }
    Ok(diags)
}

/// Each shader of `plan` that needs what `target` does not offer, as a
/// problem of its pass.
fn unoffered(
    cache: &mut PipelineCache,
    plan: &weft_graph::plan::Plan,
    target: &ShaderTarget,
) -> Vec<ShaderProblem> {
    let mut problems = Vec::new();
    for pass in &plan.passes {
        let keys = match weft_gpu::check::pass_shaders(pass) {
            Ok(Some(shaders)) => shaders.keys().into_iter().cloned().collect(),
            Ok(None) => crate::sources::scene_pass_keys(pass),
            Err(_) => continue, // reported by `check_with`
        };
        for key in keys {
            let Ok(module) = cache.shader(&key) else {
                continue; // reported by `check_with`
            };
            if let Some(refusal) = target.support.refusal(&target.device, &module.compiled) {
                let problem = ShaderProblem {
                    pass: pass.name.clone(),
                    message: format!("{} {refusal}", key.path.display()),
                };
                if !problems.contains(&problem) {
                    problems.push(problem);
                }
            }
        }
    }
    problems
}
