//! The graph parameters a user can set (`--param` and the panel), with their
//! current values and declared ranges.

use egui::Ui;
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

/// A parameter's editor: a slider for a bounded number, a drag field for an
/// unbounded one, a checkbox for a switch, a field per component for a
/// vector. Returns the widget's response and whether an edit is complete
/// (a typed value entered, a drag let go, a click).
pub(super) fn param_widget(
    ui: &mut Ui,
    key: &str,
    value: &mut ParamValue,
    range: &ParamRange,
) -> (egui::Response, bool) {
    let id = egui::Id::new(("param", key));
    match value {
        ParamValue::Number(x) => {
            // A bounded number gets a slider, and every number a field to
            // drag or click and type into (the widget scripts name).
            let slid = match (range.min, range.max) {
                (Some(min), Some(max)) => {
                    let mut slider = egui::Slider::new(x, min..=max).show_value(false);
                    if range.integer {
                        slider = slider.integer();
                    }
                    Some(ui.add(slider))
                }
                _ => None,
            };
            let speed = 0.01 * x.abs().max(1.0);
            // Held to the declared range and to what a 32-bit float holds,
            // typed or dragged.
            let most = f64::from(f32::MAX);
            let low = range.min.unwrap_or(-most).max(-most);
            let high = range.max.unwrap_or(most).min(most);
            let mut drag = egui::DragValue::new(x)
                .speed(speed)
                .custom_parser(finite_number)
                .range(low..=high);
            if range.integer {
                drag = drag.fixed_decimals(0).speed(1.0);
            }
            let response = ui.push_id(id, |ui| ui.add(drag)).inner;
            let complete = |r: &egui::Response| {
                r.drag_stopped() || (r.changed() && !r.dragged()) || r.lost_focus()
            };
            let done = complete(&response) || slid.as_ref().is_some_and(complete);
            if !range.one_of.is_empty() {
                *x = nearest(&range.one_of, *x);
            }
            (response, done)
        }
        ParamValue::Bool(b) => {
            let response = ui.checkbox(b, "");
            let done = response.changed();
            (response, done)
        }
        ParamValue::Vector(components) => {
            let mut done = false;
            let mut rect: Option<egui::Rect> = None;
            let mut last = None;
            for (i, c) in components.iter_mut().enumerate() {
                let response = ui
                    .push_id((id, i), |ui| {
                        ui.add(
                            egui::DragValue::new(c)
                                .speed(0.01)
                                .custom_parser(finite_number),
                        )
                    })
                    .inner;
                done |= response.drag_stopped()
                    || (response.changed() && !response.dragged())
                    || response.lost_focus();
                rect = Some(rect.map_or(response.rect, |r| r.union(response.rect)));
                last = Some(response);
            }
            let response = match last {
                Some(r) => r.with_new_rect(rect.unwrap_or(egui::Rect::NOTHING)),
                None => ui.label("(empty)"),
            };
            (response, done)
        }
        ParamValue::Reference(name) => {
            let response = ui.label(format!("follows {name}"));
            (response, false)
        }
    }
}

/// A typed parameter value: a number a shader's 32-bit float holds. Text
/// that is not one (`nan`, `inf`, `1e39`) leaves the value as it was.
fn finite_number(text: &str) -> Option<f64> {
    text.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && v.abs() <= f64::from(f32::MAX))
}

fn nearest(values: &[f64], x: f64) -> f64 {
    values
        .iter()
        .copied()
        .min_by(|a, b| (a - x).abs().total_cmp(&(b - x).abs()))
        .unwrap_or(x)
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
