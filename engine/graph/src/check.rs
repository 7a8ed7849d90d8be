//! `weft graph check`: validation across every combination of the features a graph
//! mentions, so no toggle or scene can produce an invalid configuration.

use crate::compile::cull::unneeded_warning;
use crate::compile::{compile_ir, CompileOptions};
use crate::diagnostic::Diagnostic;
use crate::load::LoadedGraph;
use crate::plan::Extent;
use crate::resolve::resolve;
use crate::resolve::{feature_names, pass_feature_names, Ir};
use std::collections::BTreeSet;

/// Feature sets tried exhaustively up to this many feature names; beyond it, all-off,
/// all-on and each feature alone.
const EXHAUSTIVE_FEATURES: usize = 10;

/// The second output size every feature set is compiled at: odd and not
/// 16:9, so sizes that match only at the default 1280x720 differ here.
const ODD_EXTENT: Extent = Extent {
    width: 997,
    height: 541,
};

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
        // Each distinct diagnostic with the feature sets it appears under,
        // and every pass that runs under some feature set.
        let mut found: Vec<(Diagnostic, Vec<String>)> = Vec::new();
        let mut ran: BTreeSet<String> = BTreeSet::new();
        for features in &sets {
            let label = describe(&names, features);
            let options = CompileOptions {
                features: features.clone(),
                readback: graph.readback_names(),
                ..CompileOptions::default()
            };
            let mut diagnostics = match compile_ir(graph, &ir, &options) {
                Ok(plan) => {
                    ran.extend(plan.passes.iter().map(|p| p.name.clone()));
                    plan.warnings
                }
                Err(errors) => errors,
            };
            // Size rules that agree at one output size only are found at
            // a second, odd one.
            let odd = CompileOptions {
                extent: ODD_EXTENT,
                ..options
            };
            if let Err(errors) = compile_ir(graph, &ir, &odd) {
                for e in errors {
                    if !diagnostics
                        .iter()
                        .any(|d| d.file == e.file && d.pos == e.pos)
                    {
                        diagnostics.push(e);
                    }
                }
            }
            for d in diagnostics {
                match found.iter_mut().find(|(seen, _)| *seen == d) {
                    Some((_, labels)) => labels.push(label.clone()),
                    None => found.push((d, vec![label.clone()])),
                }
            }
        }
        // A pass culled as unneeded under some feature sets but run under
        // others is culling doing its job (a shadow map no one reads while
        // shadows are traced); one that no feature set needs is a mistake.
        let needed_somewhere =
            |d: &Diagnostic| ran.iter().any(|name| d.message == unneeded_warning(name));
        found.retain(|(d, _)| d.is_error() || !needed_somewhere(d));
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
/// to ten features; beyond that none, all, each alone and each pair, and
/// all but each one and all but each pair, so every interaction of two
/// features is tried both ways.
pub fn feature_sets(names: &[String]) -> Vec<BTreeSet<String>> {
    if names.len() <= EXHAUSTIVE_FEATURES {
        return every_combination(names);
    }
    let all: BTreeSet<String> = names.iter().cloned().collect();
    let mut sets = vec![BTreeSet::new(), all.clone()];
    for (i, a) in names.iter().enumerate() {
        sets.push(BTreeSet::from([a.clone()]));
        sets.push(&all - &BTreeSet::from([a.clone()]));
        for b in &names[i + 1..] {
            let pair = BTreeSet::from([a.clone(), b.clone()]);
            sets.push(&all - &pair);
            sets.push(pair);
        }
    }
    sets
}

/// The feature sets shader checks compile variants under (each set is a
/// shader compile per pass whose defines it changes): every combination of up
/// to ten features; beyond that none, all and each alone, and for each pass
/// every combination of the features that decide whether it runs and what it
/// reads and writes, so a pass that runs only under three features together
/// (spot lights, shadow casters, no traced shadows) is compiled and checked
/// with every set of bindings it can have.
pub fn variant_sets(ir: &Ir) -> Vec<BTreeSet<String>> {
    let names: Vec<String> = feature_names(ir).into_iter().collect();
    if names.len() <= EXHAUSTIVE_FEATURES {
        return every_combination(&names);
    }
    let mut sets = vec![BTreeSet::new(), names.iter().cloned().collect()];
    sets.extend(names.iter().map(|n| BTreeSet::from([n.clone()])));
    for pass in &ir.passes {
        let own: Vec<String> = pass_feature_names(pass, false).into_iter().collect();
        let combinations = if own.len() <= EXHAUSTIVE_FEATURES {
            every_combination(&own)
        } else {
            feature_sets(&own)
        };
        for set in combinations {
            if !sets.contains(&set) {
                sets.push(set);
            }
        }
    }
    sets
}

fn every_combination(names: &[String]) -> Vec<BTreeSet<String>> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: usize) -> Vec<String> {
        (0..n).map(|i| format!("f{i}")).collect()
    }

    /// A graph whose pass `p{i}` runs under feature `f{i}`, `n` of them, and
    /// whose pass `spot` runs under `spot` and reads `shadow` only under
    /// `casters` and not `traced`.
    fn graph_of(n: usize) -> Ir {
        let passes: String = (0..n)
            .map(|i| {
                format!(
                    r#"Pass(name: "p{i}", kind: Fullscreen, shaders: (fragment: "p.frag"),
                         color: [(image: "out", load: Load)], enabled_if: ["f{i}"]),"#
                )
            })
            .collect();
        let text = format!(
            r#"Graph(
            output: "out",
            resources: [
                Image(name: "out", format: R8G8B8A8_UNORM),
                Image(name: "shadow", format: R8G8B8A8_UNORM),
            ],
            passes: [
                Pass(name: "s", kind: Fullscreen, shaders: (fragment: "s.frag"), color: [(image: "shadow")]),
                Pass(name: "base", kind: Fullscreen, shaders: (fragment: "b.frag"), color: [(image: "out")]),
                {passes}
                Pass(name: "spot", kind: Fullscreen, shaders: (fragment: "spot.frag"),
                     sampled: [(name: "shadow", enabled_if: ["casters", "!traced"])],
                     color: [(image: "out", load: Load)], enabled_if: ["spot"]),
            ],
        )"#
        );
        crate::compile::fixture::resolved(&text).1
    }

    #[test]
    fn up_to_ten_features_every_combination_is_tried() {
        assert_eq!(feature_sets(&names(10)).len(), 1024);
        // f0, casters, spot, traced.
        assert_eq!(variant_sets(&graph_of(1)).len(), 16);
    }

    #[test]
    fn beyond_ten_every_pair_is_tried_on_and_off() {
        let n = names(12);
        let sets = feature_sets(&n);
        // None, all, 12 singles and their complements, 66 pairs and theirs.
        assert_eq!(sets.len(), 2 + 2 * 12 + 2 * 66);
        let all: BTreeSet<String> = n.iter().cloned().collect();
        for a in &n {
            for b in &n {
                let pair = BTreeSet::from([a.clone(), b.clone()]);
                assert!(sets.contains(&pair), "{pair:?}");
                assert!(sets.contains(&(&all - &pair)), "all but {pair:?}");
            }
        }
    }

    #[test]
    fn beyond_ten_each_pass_is_compiled_under_every_combination_of_its_own_features() {
        // 12 passes of one feature each, and `spot`'s three.
        let sets = variant_sets(&graph_of(12));
        for casters in [false, true] {
            for traced in [false, true] {
                let mut want = BTreeSet::from(["spot".to_string()]);
                if casters {
                    want.insert("casters".into());
                }
                if traced {
                    want.insert("traced".into());
                }
                assert!(sets.contains(&want), "{want:?}");
            }
        }
        // None, all, 15 alone, then what the passes add: `spot`'s 8
        // combinations less the none and 3 singles already there.
        assert_eq!(sets.len(), 2 + 15 + 4);
    }
}
