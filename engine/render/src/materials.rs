//! Material records for the GPU and the material filters passes draw by: MTL
//! Blinn-Phong parameters as given, glTF metallic-roughness mapped onto them.

use crate::packing::Words;
use glam::Vec3;
use weft_graph::schema::MaterialFilter;
use weft_scene::material::{AlphaMode, ShadingModel};
use weft_scene::Material;

/// Bytes of one material record (`struct Material` in `shaders/include/scene.glsl`).
pub const MATERIAL_BYTES: usize = 64;

/// Whether a mesh with this material is drawn by a pass with `filter`.
pub fn matches(filter: MaterialFilter, m: &Material) -> bool {
    let blended = m.alpha_mode == AlphaMode::Blend;
    match filter {
        MaterialFilter::All => true,
        MaterialFilter::Opaque | MaterialFilter::ShadowCasters => !blended,
        MaterialFilter::Transparent => blended,
        MaterialFilter::Emissive => m.emissive.max_element() > 0.0,
    }
}

/// Blinn-Phong parameters: (diffuse, specular, shininess, ambient reflectance).
/// The ambient reflectance is `Ka`, or `Kd` where `Ka` is black, as most exporters
/// leave it; glTF materials map metallic-roughness onto the same terms.
pub fn blinn_phong(m: &Material) -> (Vec3, Vec3, f32, Vec3) {
    let base = m.base_color.truncate();
    match m.shading {
        ShadingModel::BlinnPhong => {
            let ambient = if m.ambient.max_element() > 0.0 {
                m.ambient
            } else {
                base
            };
            (base, m.specular, m.shininess.max(0.0), ambient)
        }
        ShadingModel::MetallicRoughness => {
            let metallic = m.metallic.clamp(0.0, 1.0);
            let diffuse = base * (1.0 - metallic);
            let specular = Vec3::splat(0.04).lerp(base, metallic);
            let alpha = (m.roughness.clamp(0.0, 1.0)).powi(2).max(1e-3);
            let shininess = (2.0 / (alpha * alpha) - 2.0).clamp(1.0, 2048.0);
            (diffuse, specular, shininess, diffuse)
        }
    }
}

/// Appends one material record; `textured` says whether it samples a base-colour texture.
pub fn pack_material(words: &mut Words, m: &Material, textured: bool) {
    let (diffuse, specular, shininess, ambient) = blinn_phong(m);
    words
        .vec3w(diffuse, m.base_color.w)
        .vec3w(specular, shininess)
        .vec3w(ambient, if textured { 1.0 } else { 0.0 })
        .vec3w(m.emissive, 0.0);
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    #[test]
    fn filters_follow_alpha_and_emission() {
        let opaque = Material::default();
        let glass = Material {
            alpha_mode: AlphaMode::Blend,
            ..Material::default()
        };
        let lamp = Material {
            emissive: Vec3::new(17.0, 12.0, 4.0),
            ..Material::default()
        };
        assert!(matches(MaterialFilter::Opaque, &opaque));
        assert!(!matches(MaterialFilter::Opaque, &glass));
        assert!(matches(MaterialFilter::Transparent, &glass));
        assert!(!matches(MaterialFilter::ShadowCasters, &glass));
        assert!(matches(MaterialFilter::Emissive, &lamp));
        assert!(!matches(MaterialFilter::Emissive, &opaque));
        assert!(matches(MaterialFilter::All, &glass));
    }

    #[test]
    fn ambient_falls_back_to_diffuse_and_gltf_maps_to_phong() {
        let mut m = Material {
            base_color: Vec4::new(0.5, 0.25, 1.0, 1.0),
            specular: Vec3::splat(0.3),
            shininess: 9.0,
            ..Material::default()
        };
        assert_eq!(
            blinn_phong(&m),
            (
                Vec3::new(0.5, 0.25, 1.0),
                Vec3::splat(0.3),
                9.0,
                Vec3::new(0.5, 0.25, 1.0)
            )
        );
        m.ambient = Vec3::splat(0.2);
        assert_eq!(blinn_phong(&m).3, Vec3::splat(0.2));
        m.shading = ShadingModel::MetallicRoughness;
        m.metallic = 1.0;
        m.roughness = 0.5;
        let (d, s, n, _) = blinn_phong(&m);
        assert_eq!(d, Vec3::ZERO);
        assert_eq!(s, Vec3::new(0.5, 0.25, 1.0));
        assert_eq!(n, 30.0);
        let mut w = Words::default();
        pack_material(&mut w, &m, true);
        assert_eq!(w.byte_len(), MATERIAL_BYTES);
        assert_eq!(f32::from_bits(w.0[11]), 1.0);
    }
}
