//! The panel's environment section: a picker over the maps beside the one
//! that lights the scene (another is a scene loaded again, as
//! `--environment` loads it: intensity 1, no rotation), and the map's turn
//! about +y, set live (two numbers of the `Frame` block: nothing reloads,
//! and a progressive graph starts again).

use super::{Panel, PanelAction, PanelView};
use egui::Ui;
use std::path::{Path, PathBuf};
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
                let name = |p: &Path| {
                    p.file_name()
                        .unwrap_or(p.as_os_str())
                        .to_string_lossy()
                        .into_owned()
                };
                let combo = egui::ComboBox::from_id_salt("environment")
                    .selected_text(name(file))
                    .show_ui(ui, |ui| {
                        for map in maps_beside(file) {
                            let selected = crate::view::controls::same_file(&map, file);
                            let item = ui.selectable_label(selected, name(&map));
                            if item.clicked() && !selected {
                                actions.push(PanelAction::PickEnvironment(map.clone()));
                            }
                            self.remember(format!("environment:{}", name(&map)), &item);
                        }
                    });
                self.remember(
                    "environment".into(),
                    &combo.response.on_hover_text(file.display().to_string()),
                );
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

/// The OpenEXR and Radiance HDR files in `map`'s folder, by name.
fn maps_beside(map: &Path) -> Vec<PathBuf> {
    let folder = map.parent().unwrap_or(Path::new("."));
    let mut maps: Vec<PathBuf> = std::fs::read_dir(folder)
        .into_iter()
        .flatten()
        .filter_map(|e| Some(e.ok()?.path()))
        .filter(|p| {
            let ext = p
                .extension()
                .map(|e| e.to_string_lossy().to_ascii_lowercase());
            matches!(ext.as_deref(), Some("exr" | "hdr")) && p.is_file()
        })
        .collect();
    maps.sort();
    maps
}
