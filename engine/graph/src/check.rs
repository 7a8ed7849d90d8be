//! `weft graph check`: validation across every combination of the features a graph
//! mentions, so no toggle or scene can produce an invalid configuration.

use crate::compile::{compile_ir, feature_names, CompileOptions};
use crate::diagnostic::Diagnostic;
use crate::load::LoadedGraph;
use crate::resolve::resolve;
use std::collections::BTreeSet;

/// Feature sets tried exhaustively up to this many feature names; beyond it, all-off,
/// all-on and each feature alone.
const EXHAUSTIVE_FEATURES: usize = 10;

/// Every error and warning of a graph, deduplicated, errors first.
pub fn check(graph: &LoadedGraph) -> Vec<Diagnostic> {
    if graph.has_errors() {
        return graph.diagnostics.clone();
    }
    let (ir, mut diags) = resolve(graph);
    diags.extend(graph.diagnostics.iter().cloned());
    if !graph.is_fragment && !diags.iter().any(Diagnostic::is_error) {
        let names: Vec<String> = feature_names(&ir).into_iter().collect();
        let sets = feature_sets(&names);
        // Each distinct diagnostic with the feature sets it appears under.
        let mut found: Vec<(Diagnostic, Vec<String>)> = Vec::new();
        for features in &sets {
            let label = describe(&names, features);
            let options = CompileOptions {
                features: features.clone(),
                readback: graph.readback_names(),
                ..CompileOptions::default()
            };
            let diagnostics = match compile_ir(graph, &ir, &options) {
                Ok(plan) => plan.warnings,
                Err(errors) => errors,
            };
            for d in diagnostics {
                match found.iter_mut().find(|(seen, _)| *seen == d) {
                    Some((_, labels)) => labels.push(label.clone()),
                    None => found.push((d, vec![label.clone()])),
                }
            }
        }
        for (mut d, labels) in found {
            if d.is_error() && labels.len() < sets.len() {
                d.message = format!("{} (with features {})", d.message, labels[0]);
            }
            diags.push(d);
        }
    }
    diags.sort_by_key(|d| (!d.is_error(), d.file.clone(), d.pos));
    diags
}

/// The feature sets `check` compiles a graph under: every combination of up
/// to ten features, else none, all and each alone.
pub fn feature_sets(names: &[String]) -> Vec<BTreeSet<String>> {
    if names.len() <= EXHAUSTIVE_FEATURES {
        (0u32..1 << names.len())
            .map(|mask| {
                names
                    .iter()
                    .enumerate()
                    .filter(|(i, _)| mask & (1 << i) != 0)
                    .map(|(_, n)| n.clone())
                    .collect()
            })
            .collect()
    } else {
        let mut sets = vec![BTreeSet::new(), names.iter().cloned().collect()];
        sets.extend(names.iter().map(|n| BTreeSet::from([n.clone()])));
        sets
    }
}

fn describe(names: &[String], on: &BTreeSet<String>) -> String {
    let parts: Vec<String> = names
        .iter()
        .map(|n| {
            if on.contains(n) {
                n.clone()
            } else {
                format!("!{n}")
            }
        })
        .collect();
    format!("[{}]", parts.join(", "))
}
