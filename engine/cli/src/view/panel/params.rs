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
/// directly included file's as `stem.name`; a value that is a `$reference`
/// is left out (it follows the parameter it names).
pub fn graph_params(graph: &LoadedGraph) -> Vec<ParamEntry> {
    let mut entries: Vec<ParamEntry> = Vec::new();
    for source in &graph.sources {
        let Some(qualifier) = &source.qualifier else {
            continue;
        };
        for (name, value) in &source.params {
            if matches!(value, ParamValue::Reference(_)) {
                continue;
            }
            let key = if qualifier.is_empty() {
                name.clone()
            } else {
                format!("{qualifier}.{name}")
            };
            if entries.iter().any(|e| e.key == key) {
                continue;
            }
            entries.push(ParamEntry {
                key,
                value: value.clone(),
                range: source.ranges.get(name).cloned().unwrap_or_default(),
            });
        }
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
        let mut unique = keys.clone();
        unique.sort_unstable();
        unique.dedup();
        assert_eq!(unique.len(), keys.len(), "{keys:?}");
    }
}
