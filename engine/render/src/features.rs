//! Scene features a graph's `enabled_if` conditions test: what the scene has,
//! so passes for things it lacks (spot lights, shadow casters) are culled.

use crate::lights::is_cone;
use crate::materials::{coat, dielectric, is_mirror, matches};
use crate::vocabulary::MeshFilter;
use weft_scene::material::ShadingModel;
use weft_scene::{AreaShape, Light, Scene};

/// The features `scene` switches on: `shadow_casters` when a placed mesh casts
/// and a light casts shadows (a sun, a point light, a spot narrow enough for a
/// cone, an area light or emissive geometry that lights raster passes),
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
/// `metallic_roughness` for glTF materials, `specular_lobes` for any of the
/// last five (the lobes ray-traced specular traces); `textures` when a placed mesh has a
/// base colour, metallic-roughness, normal or emissive texture, `normal_maps` when one
/// has a normal texture with a non-zero scale, `emission_occlusion_maps` when
/// one has an emissive or occlusion texture; `environment` when the scene has
/// an environment map.
pub fn scene_features(scene: &Scene) -> Vec<String> {
    // Only the names graphs can rely on (crate::vocabulary::SCENE_FEATURES).
    fn set(features: &mut Vec<String>, name: &'static str) {
        debug_assert!(
            crate::vocabulary::scene_feature_reason(name).is_some(),
            "{name}"
        );
        features.push(name.to_string());
    }
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
            Light::Sun(_) | Light::Area(_) | Light::Point(_) => true,
            Light::Spot(s) => is_cone(s.angle),
        });
    if shadowing_light && placed().any(|m| matches(MeshFilter::ShadowCasters, &m)) {
        set(&mut features, "shadow_casters");
    }
    if placed().any(|m| matches(MeshFilter::Emissive, &m)) {
        set(&mut features, "emissive");
    }
    if placed().any(|m| matches(MeshFilter::Transparent, &m)) {
        set(&mut features, "transparent");
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Sun(_))) {
        set(&mut features, "suns");
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Point(_))) {
        set(&mut features, "point_lights");
    }
    if scene.lights.iter().any(|l| matches!(l, Light::Spot(_))) {
        set(&mut features, "spot_lights");
    }
    if emitter_lights || scene.lights.iter().any(|l| matches!(l, Light::Area(_))) {
        set(&mut features, "area_lights");
    }
    let area_shape = |disc: bool| {
        scene.lights.iter().any(
            |l| matches!(l, Light::Area(a) if matches!(a.shape, AreaShape::Disc { .. }) == disc),
        )
    };
    if emitter_lights || area_shape(false) {
        set(&mut features, "rect_lights");
    }
    if area_shape(true) {
        set(&mut features, "disc_lights");
    }
    if scene
        .lights
        .iter()
        .any(|l| matches!(l, Light::Sun(_) | Light::Point(_) | Light::Spot(_)))
    {
        set(&mut features, "punctual_lights");
    }
    if placed().any(|m| {
        m.shading == ShadingModel::BlinnPhong
            && !is_mirror(&m)
            && coat(&m).is_none()
            && m.specular.max_element() > 0.0
            && m.shininess > 0.0
    }) {
        set(&mut features, "glossy");
    }
    if placed().any(|m| dielectric(&m).is_some()) {
        set(&mut features, "dielectrics");
    }
    if placed().any(|m| is_mirror(&m)) {
        set(&mut features, "mirrors");
    }
    if placed().any(|m| coat(&m).is_some()) {
        set(&mut features, "coated");
    }
    if placed().any(|m| m.shading == ShadingModel::MetallicRoughness) {
        set(&mut features, "metallic_roughness");
    }
    // What ray-traced specular traces (graphs/rt_specular.ron), as one
    // feature: a pass keyed on the five above would have 32 times the
    // variants where one bit does.
    let traced = [
        "glossy",
        "dielectrics",
        "mirrors",
        "coated",
        "metallic_roughness",
    ];
    if features.iter().any(|f| traced.contains(&f.as_str())) {
        set(&mut features, "specular_lobes");
    }
    if placed().any(|m| m.shading != ShadingModel::MetallicRoughness) {
        set(&mut features, "blinn_phong");
    }
    if placed().any(|m| m.textures.emissive.is_some() || m.textures.occlusion.is_some()) {
        set(&mut features, "emission_occlusion_maps");
    }
    if placed().any(|m| m.textures.normal.is_some() && m.normal_scale != 0.0) {
        set(&mut features, "normal_maps");
    }
    if scene.environment.is_some() {
        set(&mut features, "environment");
    }
    if placed().any(|m| {
        m.textures.base_color.is_some()
            || m.textures.metallic_roughness.is_some()
            || m.textures.normal.is_some()
            || m.textures.emissive.is_some()
    }) {
        set(&mut features, "textures");
    }
    features
}
