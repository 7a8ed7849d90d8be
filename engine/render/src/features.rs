//! Scene features a graph's `enabled_if` conditions test: what the scene has,
//! so passes for things it lacks (spot lights, shadow casters) are culled.

use crate::lights::is_cone;
use crate::materials::{coat, dielectric, is_mirror, matches};
use weft_graph::schema::MaterialFilter;
use weft_scene::material::ShadingModel;
use weft_scene::{AreaShape, Light, Scene};

/// The features `scene` switches on: `shadow_casters` when a placed mesh casts
/// and a light casts shadows (a sun, a spot narrow enough for a cone, an area
/// light or emissive geometry that lights raster passes),
/// `suns` / `point_lights` / `spot_lights` when there are such lights, `emissive` when a
/// placed mesh glows, `transparent` when a placed mesh blends, `area_lights` when
/// there are area lights or emissive geometry that lights raster passes
/// (`rect_lights` for four-cornered ones: rectangles and emissive polygons,
/// `disc_lights` for discs), `punctual_lights` when there is a sun, point or spot
/// light; and by the shading models placed meshes use (so shaders compile only
/// the models a scene has): `blinn_phong` for any material raster passes shade
/// with Blinn-Phong (MTL materials, mirrors and coats included), `glossy` for a
/// Blinn-Phong material with a
/// specular lobe (Ks and Ns above 0), `mirrors` for MTL `illum` 3,
/// `coated` for MTL `illum` 5 (a Fresnel coat over Lambert), `dielectrics`
/// for glass (MTL `illum` 4, 6 or 7, the dissolve rule, glTF transmission),
/// `metallic_roughness` for glTF materials; `textures` when a placed mesh has a
/// base colour, metallic-roughness, normal or emissive texture, `normal_maps` when one
/// has a normal texture with a non-zero scale, `emission_occlusion_maps` when
/// one has an emissive or occlusion texture.
pub fn scene_features(scene: &Scene) -> Vec<String> {
    let placed = || {
        scene
            .instances
            .iter()
            .filter_map(|i| Some((scene.models.get(i.model)?, i.material)))
            .flat_map(|(m, overrides)| {
                m.meshes.iter().map(move |mesh| {
                    overrides.apply(
                        &mesh
                            .material
                            .and_then(|i| m.materials.get(i))
                            .cloned()
                            .unwrap_or_default(),
                    )
                })
            })
    };
    let mut features = Vec::new();
    // Emissive geometry lights raster passes as four-cornered area lights
    // (crate::emitter_lights), and casts shadows as they do.
    let emitter_lights = placed().any(|m| crate::emitter_lights::lights_raster(&m));
    let shadowing_light = emitter_lights
        || scene.lights.iter().any(|l| match l {
            Light::Sun(_) | Light::Area(_) => true,
            Light::Spot(s) => is_cone(s.angle),
            _ => false,
        });
    if shadowing_light && placed().any(|m| matches(MaterialFilter::ShadowCasters, &m)) {
        features.push("shadow_casters".to_string());
    }
    if placed().any(|m| matches(MaterialFilter::Emissive, &m)) {
        features.push("emissive".to_string());
    }
    if placed().any(|m| matches(MaterialFilter::Transparent, &m)) {
        features.push("transparent".to_string());
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Sun(_))) {
        features.push("suns".to_string());
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Point(_))) {
        features.push("point_lights".to_string());
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Spot(_))) {
        features.push("spot_lights".to_string());
    }
    if emitter_lights || scene.lights.iter().any(|l| matches!(l, Light::Area(_))) {
        features.push("area_lights".to_string());
    }
    let area_shape = |disc: bool| {
        scene.lights.iter().any(
            |l| matches!(l, Light::Area(a) if matches!(a.shape, AreaShape::Disc { .. }) == disc),
        )
    };
    if emitter_lights || area_shape(false) {
        features.push("rect_lights".to_string());
    }
    if area_shape(true) {
        features.push("disc_lights".to_string());
    }
    if scene
        .lights
        .iter()
        .any(|l| matches!(l, Light::Sun(_) | Light::Point(_) | Light::Spot(_)))
    {
        features.push("punctual_lights".to_string());
    }
    if placed().any(|m| {
        m.shading == ShadingModel::BlinnPhong
            && !is_mirror(&m)
            && coat(&m).is_none()
            && m.specular.max_element() > 0.0
            && m.shininess > 0.0
    }) {
        features.push("glossy".to_string());
    }
    if placed().any(|m| dielectric(&m).is_some()) {
        features.push("dielectrics".to_string());
    }
    if placed().any(|m| is_mirror(&m)) {
        features.push("mirrors".to_string());
    }
    if placed().any(|m| coat(&m).is_some()) {
        features.push("coated".to_string());
    }
    if placed().any(|m| m.shading == ShadingModel::MetallicRoughness) {
        features.push("metallic_roughness".to_string());
    }
    if placed().any(|m| m.shading != ShadingModel::MetallicRoughness) {
        features.push("blinn_phong".to_string());
    }
    if placed().any(|m| m.textures.emissive.is_some() || m.textures.occlusion.is_some()) {
        features.push("emission_occlusion_maps".to_string());
    }
    if placed().any(|m| m.textures.normal.is_some() && m.normal_scale != 0.0) {
        features.push("normal_maps".to_string());
    }
    if placed().any(|m| {
        m.textures.base_color.is_some()
            || m.textures.metallic_roughness.is_some()
            || m.textures.normal.is_some()
            || m.textures.emissive.is_some()
    }) {
        features.push("textures".to_string());
    }
    features
}
