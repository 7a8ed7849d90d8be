//! `weft graph check --shaders` as a library call: the graph's own checks,
//! then every shader it runs compiled, reflected and compared with the graph
//! and the engine's scene bindings, under every feature set the graph check
//! enumerates (features change the shader variants through defines).

use crate::providers::trace_backend;
use std::collections::HashSet;
use weft_gpu::executor::shader_check::check_pass;
use weft_gpu::pipeline::PipelineCache;
use weft_gpu::{Gpu, GpuError, ShaderProblem, ShaderSupport};
use weft_graph::check::variant_sets;
use weft_graph::plan::PlanPass;
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
    let mut cache = PipelineCache::new()?;
    let scene = crate::bindings::scene_interface();
    let mut checked: HashSet<String> = HashSet::new();
    for features in variant_sets(prepared.ir()) {
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
        // Under the ray-query feature the renderer traces in hardware, on a
        // device that offers it: the variants the hardware backend compiles.
        match traced_as_rendered(&mut plan, target) {
            Ok(true) => {}
            Ok(false) => continue,
            Err(errors) => {
                for d in errors {
                    if !diags.contains(&d) {
                        diags.push(d);
                    }
                }
                continue;
            }
        }
        // A pass whose shaders, defines and bound resources are as under a
        // set checked before gives the same problems: checked once.
        let resources = resource_signature(&plan);
        let mut problems = Vec::new();
        for pass in plan.passes.iter() {
            if checked.insert(pass_signature(pass, &resources)) {
                problems.extend(check_pass(&mut cache, &plan, pass, Some(&scene)));
                problems.extend(unoffered(&mut cache, pass, target));
            }
        }
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

/// Gives `plan`'s tracing passes the backend the renderer would: the
/// hardware walk under [`trace_backend::RAY_QUERY_FEATURE`] (asked for, so
/// a pass that traces without reading a structure the plan builds is
/// refused by its check), the software walk otherwise, where building a
/// structure is an error ([`trace_backend::built_in_software`]). `false`
/// when the plan could not be rendered on `target` as compiled: the feature
/// on a device without ray queries, which the renderer never sets.
fn traced_as_rendered(
    plan: &mut weft_graph::plan::Plan,
    target: &ShaderTarget,
) -> Result<bool, Vec<Diagnostic>> {
    if !trace_backend::compiled_for_ray_queries(plan) {
        return match trace_backend::built_in_software(plan) {
            Some(error) => Err(vec![error]),
            None => Ok(true),
        };
    }
    let device = trace_backend::DeviceTracing {
        name: target.device.clone(),
        ray_query: target.support.ray_query,
        cpu: false,
    };
    Ok(matches!(
        trace_backend::choose(plan, trace_backend::TraceBackend::Hardware, &device),
        Ok(trace_backend::Choice::Chosen)
    ))
}

/// Every resource of `plan` by name and description: bindings and
/// attachments name them by index, so a pass's signature includes them.
fn resource_signature(plan: &weft_graph::plan::Plan) -> String {
    let resources: Vec<(&str, &weft_graph::plan::ResourceDesc)> = plan
        .resources
        .iter()
        .map(|r| (r.name.as_str(), &r.desc))
        .collect();
    format!("{resources:?}")
}

/// What a pass's shader check depends on: the pass as planned less its
/// barriers (which other passes decide), and its plan's `resources`
/// ([`resource_signature`]).
fn pass_signature(pass: &PlanPass, resources: &str) -> String {
    let mut pass = pass.clone();
    pass.barriers.clear();
    pass.repeat_barriers.clear();
    format!("{pass:?}{resources}")
}

/// Each shader of `pass` that needs what `target` does not offer, as a
/// problem of the pass.
fn unoffered(
    cache: &mut PipelineCache,
    pass: &PlanPass,
    target: &ShaderTarget,
) -> Vec<ShaderProblem> {
    let keys = match weft_gpu::executor::shader_check::pass_shaders(pass) {
        Ok(Some(shaders)) => shaders.keys().into_iter().cloned().collect(),
        Ok(None) => crate::sources::scene_pass_keys(pass),
        Err(_) => return Vec::new(), // reported by `check_pass`
    };
    let mut problems = Vec::new();
    for key in keys {
        let Ok(module) = cache.shader(&key) else {
            continue; // reported by `check_pass`
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
    problems
}
