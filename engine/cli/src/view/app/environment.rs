//! The viewer's environment map as the panel sets it: another map picked
//! (a scene loaded again, as `--environment` loads it), or the map turned
//! live about +y.

use super::super::panel::PanelAction;
use super::Viewer;
use std::path::Path;
use weft_render::{LiveRender, RenderSettings};

/// The map `live` renders with and its turn now (`turned`, the panel's, or
/// the scene's), in degrees, for the panel.
pub(super) fn environment_view<'a>(
    live: &'a LiveRender<'_>,
    turned: Option<f32>,
) -> Option<(&'a Path, f32)> {
    let map = live.scene().environment.as_ref()?;
    Some((map.file.as_path(), turned.unwrap_or(map.rotation_deg)))
}

impl Viewer<'_> {
    /// Applies the panel's environment actions to the viewer with `settings`.
    pub(super) fn apply_environment(&mut self, action: PanelAction, settings: RenderSettings) {
        match action {
            PanelAction::PickEnvironment(map) => {
                self.environment_turn = None;
                let environment = Some(map);
                self.reconfigure(RenderSettings {
                    environment,
                    ..settings
                });
            }
            PanelAction::TurnEnvironment(degrees) => {
                self.environment_turn = Some(degrees);
                println!("environment rotation_deg = {degrees}");
            }
            _ => {}
        }
    }
}
