//! `weft graph check --shaders` as a library call: the graph's own checks,
//! then every shader it runs compiled, reflected and compared with the graph
//! and the engine's scene bindings, under every feature set the graph check
//! enumerates (features change the shader variants through defines).

use crate::scene_interface::check_plan_shaders;
use weft_gpu::pipeline::PipelineCache;
use weft_gpu::{GpuError, ShaderProblem};
use weft_graph::check::variant_sets;
use weft_graph::compile::feature_names;
use weft_graph::{CompileOptions, Diagnostic, LoadedGraph, Prepared};

/// Every diagnostic of `graph`: its own checks and, when those find no error
/// and it is not a fragment, its shaders' problems, each located at the
/// declaration of its pass.
pub fn check_graph_and_shaders(graph: &LoadedGraph) -> Result<Vec<Diagnostic>, GpuError> {
    let mut diags = weft_graph::check(graph);
    diags.extend(crate::providers::check(graph));
    if graph.is_fragment || diags.iter().any(Diagnostic::is_error) {
        return Ok(diags);
    }
    let prepared = match Prepared::new(graph) {
        Ok(p) => p,
        Err(errors) => {
            diags.extend(errors);
            return Ok(diags);
        }
    };
    let names: Vec<String> = feature_names(prepared.ir()).into_iter().collect();
    let mut cache = PipelineCache::new()?;
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
        for ShaderProblem { pass, message } in check_plan_shaders(&mut cache, &plan) {
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
