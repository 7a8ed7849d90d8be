//! Scene features a graph's `enabled_if` conditions test: what the scene has,
//! so passes for things it lacks (spot lights, shadow casters) are culled.

use crate::materials::matches;
use weft_graph::schema::MaterialFilter;
use weft_scene::{Light, Scene};

/// The features `scene` switches on: `shadow_casters` when a placed mesh casts,
/// `point_lights` / `spot_lights` when there are such lights, `emissive` when a
/// placed mesh glows, `transparent` when a placed mesh blends, `area_lights` when
/// there are area lights.
pub fn scene_features(scene: &Scene) -> Vec<String> {
    let placed = || {
        scene
            .instances
            .iter()
            .filter_map(|i| scene.models.get(i.model))
            .flat_map(|m| {
                m.meshes.iter().map(move |mesh| {
                    mesh.material
                        .and_then(|i| m.materials.get(i))
                        .cloned()
                        .unwrap_or_default()
                })
            })
    };
    let mut features = Vec::new();
    if placed().any(|m| matches(MaterialFilter::ShadowCasters, &m)) {
        features.push("shadow_casters".to_string());
    }
    if placed().any(|m| matches(MaterialFilter::Emissive, &m)) {
        features.push("emissive".to_string());
    }
    if placed().any(|m| matches(MaterialFilter::Transparent, &m)) {
        features.push("transparent".to_string());
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Point(_))) {
        features.push("point_lights".to_string());
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Spot(_))) {
        features.push("spot_lights".to_string());
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Area(_))) {
        features.push("area_lights".to_string());
    }
    features
}
