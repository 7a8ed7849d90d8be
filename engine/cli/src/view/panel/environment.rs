//! The panel's environment section: the map that lights the scene and its
//! turn about +y, set live (two numbers of the `Frame` block: nothing
//! reloads, and a progressive graph starts again).

use super::{Panel, PanelAction, PanelView};
use egui::Ui;
use weft_graph::schema::{ParamRange, ParamValue};

/// The rotation field's name for scripted clicks
/// (`--ui click:environment:rotation_deg`).
const ROTATION: &str = "environment:rotation_deg";

impl Panel {
    /// For a scene with a map: its file and a field turning it.
    pub(super) fn environment_section(
        &mut self,
        ui: &mut Ui,
        view: &PanelView<'_>,
        actions: &mut Vec<PanelAction>,
    ) {
        let Some((file, rotation)) = view.environment else {
            return;
        };
        egui::CollapsingHeader::new("environment")
            .default_open(true)
            .show(ui, |ui| {
                let name = file.file_name().unwrap_or(file.as_os_str());
                ui.label(name.to_string_lossy())
                    .on_hover_text(file.display().to_string());
                let live = ParamValue::Number(f64::from(rotation));
                let (seen, value) = self
                    .edits
                    .entry(ROTATION.to_string())
                    .or_insert_with(|| (live.clone(), live.clone()));
                if *seen != live {
                    *seen = live.clone();
                    *value = live.clone();
                }
                let range = ParamRange {
                    min: Some(-360.0),
                    max: Some(360.0),
                    ..ParamRange::default()
                };
                let (response, commit) = ui
                    .horizontal(|ui| {
                        ui.label("rotation_deg")
                            .on_hover_text("degrees about +y, as the scene's `rotation_deg`");
                        super::param_widget(ui, ROTATION, value, &range)
                    })
                    .inner;
                if let (true, ParamValue::Number(degrees)) = (commit && *value != live, &*value) {
                    actions.push(PanelAction::TurnEnvironment(*degrees as f32));
                }
                self.remember(ROTATION.to_string(), &response);
            });
    }
}
