//! The graph parameters a user can set (`--param` and the panel), with their
//! current values and declared ranges.

use weft_graph::schema::{ParamRange, ParamValue};
use weft_graph::LoadedGraph;

/// One settable parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamEntry {
    /// The name `--param` takes: `exposure` for the root graph's,
    /// `shadows.resolution` for a fragment the root includes.
    pub key: String,
    /// Its value in the live graph (default or override).
    pub value: ParamValue,
    /// What it accepts (`param_ranges`), default when undeclared.
    pub range: ParamRange,
}

/// The parameters of `graph` reachable by `--param`, root first, then each
/// directly included file's as `stem.name`; one whose value follows another
/// parameter (a `$reference` in its file or at its include site) is left out:
/// the one it follows is offered.
pub fn graph_params(graph: &LoadedGraph) -> Vec<ParamEntry> {
    let mut entries: Vec<ParamEntry> = Vec::new();
    for (key, source, name) in graph.settable() {
        let value = &source.params[name];
        let follows = matches!(value, ParamValue::Reference(_)) || source.follows.contains(name);
        if follows || entries.iter().any(|e| e.key == key) {
            continue;
        }
        entries.push(ParamEntry {
            key,
            value: value.clone(),
            range: source.ranges.get(name).cloned().unwrap_or_default(),
        });
    }
    entries
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_deferred_graph_offers_its_own_and_its_fragments_parameters_with_ranges() {
        let graph = weft_graph::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../graphs/deferred.ron"
        )));
        assert!(!graph.has_errors(), "{:?}", graph.diagnostics);
        let params = graph_params(&graph);
        let keys: Vec<&str> = params.iter().map(|p| p.key.as_str()).collect();
        assert!(keys.contains(&"exposure"), "{keys:?}");
        let pcf = params
            .iter()
            .find(|p| p.key.ends_with(".pcf_radius") || p.key == "pcf_radius")
            .unwrap_or_else(|| panic!("no pcf_radius in {keys:?}"));
        assert!(pcf.range.min.is_some() || pcf.range.integer, "{pcf:?}");
        assert!(
            keys.contains(&"shadows.resolution"),
            "a fragment's parameter its include site sets to a number stays: {keys:?}"
        );
        let mut unique = keys.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), keys.len(), "{keys:?}");
    }

    #[test]
    fn a_fragment_parameter_that_follows_the_roots_is_offered_once_as_the_roots() {
        let graph = weft_graph::load(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../graphs/pathtrace.ron"
        )));
        let keys: Vec<String> = graph_params(&graph).into_iter().map(|p| p.key).collect();
        assert!(keys.contains(&"max_depth".to_string()), "{keys:?}");
        let fragment: Vec<&String> = keys
            .iter()
            .filter(|k| k.starts_with("path_tracer."))
            .collect();
        assert_eq!(
            fragment,
            vec!["path_tracer.accumulate"],
            "path_tracer.ron's parameters follow pathtrace.ron's `$max_depth`, ...; only the one its include sets to a number stays"
        );
    }
}
