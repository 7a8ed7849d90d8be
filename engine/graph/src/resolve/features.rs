//! The feature names a graph may test: those its conditions mention, and
//! those the engine sets from what a scene holds.

use super::Ir;
use std::collections::BTreeSet;

/// Every feature name a graph's conditions mention.
pub fn feature_names(ir: &Ir) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for pass in &ir.passes {
        let conditions = pass
            .enabled_if
            .iter()
            .chain(pass.accesses.iter().flat_map(|a| a.conditions.iter()))
            .chain(pass.defines.iter().flat_map(|d| d.enabled_if.iter()));
        for name in conditions.flat_map(|c| crate::condition::names(c)) {
            if !name.is_empty() {
                names.insert(name.to_string());
            }
        }
    }
    names
}

/// The features the engine sets from what a scene holds (weft-render's
/// `scene_features`, which sets no other): a graph may test them without any
/// pass of its own doing so (a fragment's caveat, say).
pub const SCENE_FEATURES: [&str; 20] = [
    "shadow_casters",
    "emissive",
    "transparent",
    "suns",
    "point_lights",
    "spot_lights",
    "area_lights",
    "rect_lights",
    "disc_lights",
    "punctual_lights",
    "glossy",
    "dielectrics",
    "mirrors",
    "coated",
    "metallic_roughness",
    "specular_lobes",
    "blinn_phong",
    "emission_occlusion_maps",
    "normal_maps",
    "textures",
];
