//! Material records for the GPU and the material filters passes draw by: MTL
//! Blinn-Phong parameters as given, glTF metallic-roughness factors for the GGX
//! shading in `shaders/include/lighting.glsl`.

use crate::gpu_types::GpuMaterial;
use glam::{Vec3, Vec4};
use weft_graph::schema::MaterialFilter;
use weft_scene::material::{AlphaMode, ShadingModel};
use weft_scene::Material;

/// Bytes of one material record (`struct Material` in `shaders/include/scene.glsl`).
pub const MATERIAL_BYTES: usize = std::mem::size_of::<GpuMaterial>();
/// Shading-model code of MTL materials (`SHADING_BLINN_PHONG`).
pub const BLINN_PHONG: f32 = 0.0;
/// Shading-model code of glTF materials (`SHADING_METALLIC_ROUGHNESS`).
pub const METALLIC_ROUGHNESS: f32 = 1.0;
/// Shading-model code of MTL materials with `illum` 3 or 5 (`SHADING_MIRROR`):
/// the path tracer reflects `Ks` as a perfect mirror; raster passes shade
/// them as Blinn-Phong.
pub const MIRROR: f32 = 2.0;

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

/// A smooth dielectric as the path tracer sees it (`shaders/pathtrace/dielectric.glsl`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    /// Index of refraction of the inside (the outside is air, 1).
    pub ior: f32,
    /// Tint of reflected light (MTL `Ks`).
    pub reflection: Vec3,
    /// Tint of refracted light, at every crossing (MTL `Tf`).
    pub transmission: Vec3,
    /// Beer–Lambert coefficient σ per world unit inside (`.scene` `absorption`).
    pub absorption: Vec3,
}

/// The dielectric an MTL material describes: `illum` 4, 6 or 7 (glass,
/// refraction) with index `Ni`, reflection tint `Ks` and transmission tint
/// `Tf`. `Ks 1 1 1`, `Tf 1 1 1`, `Ni 1.5`, `illum 7` is clear glass.
pub fn dielectric(m: &Material) -> Option<Dielectric> {
    let glass = m.shading == ShadingModel::BlinnPhong && matches!(m.illum, Some(4 | 6 | 7));
    (glass && m.ior.is_finite() && m.ior > 0.0).then_some(Dielectric {
        ior: m.ior,
        reflection: m.specular,
        transmission: m.transmission_filter,
        absorption: m.absorption,
    })
}

/// Whether an MTL material is a mirror (`illum` 3 or 5): the path tracer
/// reflects its Ks perfectly.
pub fn is_mirror(m: &Material) -> bool {
    m.shading == ShadingModel::BlinnPhong && matches!(m.illum, Some(3 | 5))
}

/// Blinn-Phong parameters of an MTL material: (diffuse, specular, shininess,
/// ambient reflectance). The ambient reflectance is `Ka`, or `Kd` where `Ka` is
/// black, as most exporters leave it.
pub fn blinn_phong(m: &Material) -> (Vec3, Vec3, f32, Vec3) {
    let base = m.base_color.truncate();
    let ambient = if m.ambient.max_element() > 0.0 {
        m.ambient
    } else {
        base
    };
    (base, m.specular, m.shininess.max(0.0), ambient)
}

/// One material record; `normal_mapped` says whether a normal map is
/// bound, whose strength (`normal_scale`) goes in the ambient slot's w (0: none).
/// glTF materials keep their metallic and roughness factors (which the shaders
/// multiply by the metallicRoughness texture) in the specular slot.
pub fn pack_material(m: &Material, normal_mapped: bool) -> GpuMaterial {
    let normal_scale = if normal_mapped && m.normal_scale.is_finite() {
        m.normal_scale
    } else {
        0.0
    };
    match m.shading {
        ShadingModel::BlinnPhong => {
            let (diffuse, specular, shininess, ambient) = blinn_phong(m);
            let glass = dielectric(m);
            GpuMaterial {
                diffuse: diffuse.extend(m.base_color.w),
                specular: specular.extend(shininess),
                ambient: ambient.extend(normal_scale),
                emissive: m
                    .emissive
                    .extend(if is_mirror(m) { MIRROR } else { BLINN_PHONG }),
                transmission: glass.map_or(Vec4::ZERO, |d| d.transmission.extend(d.ior)),
                reflection: glass.map_or(Vec4::ZERO, |d| d.reflection.extend(0.0)),
                absorption: glass.map_or(Vec4::ZERO, |d| d.absorption.extend(0.0)),
            }
        }
        ShadingModel::MetallicRoughness => {
            let factors = Vec4::new(
                finite_unit(m.metallic, 0.0),
                finite_unit(m.roughness, 1.0),
                0.0,
                0.0,
            );
            GpuMaterial {
                diffuse: m.base_color,
                specular: factors,
                ambient: Vec3::ZERO.extend(normal_scale),
                emissive: m.emissive.extend(METALLIC_ROUGHNESS),
                transmission: Vec4::ZERO,
                reflection: Vec4::ZERO,
                absorption: Vec4::ZERO,
            }
        }
    }
}

/// `v` clamped to [0, 1], or `fallback` when it is not a number.
fn finite_unit(v: f32, fallback: f32) -> f32 {
    if v.is_nan() {
        fallback
    } else {
        v.clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn ambient_falls_back_to_diffuse_and_gltf_keeps_its_factors() {
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
        let w = pack_material(&m, false);
        let floats = |w: &GpuMaterial| bytemuck::cast_slice::<GpuMaterial, f32>(&[*w]).to_vec();
        assert_eq!(
            floats(&w),
            [
                0.5,
                0.25,
                1.0,
                1.0,
                0.3,
                0.3,
                0.3,
                9.0,
                0.2,
                0.2,
                0.2,
                0.0,
                0.0,
                0.0,
                0.0,
                BLINN_PHONG,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0
            ]
        );
        m.shading = ShadingModel::MetallicRoughness;
        m.metallic = 1.5;
        m.roughness = 0.25;
        m.emissive = Vec3::new(2.0, 3.0, 4.0);
        m.normal_scale = 0.5;
        let w = pack_material(&m, true);
        assert_eq!(
            floats(&w),
            [
                0.5,
                0.25,
                1.0,
                1.0,
                1.0,
                0.25,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.5,
                2.0,
                3.0,
                4.0,
                METALLIC_ROUGHNESS,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0
            ]
        );
        m.roughness = f32::NAN;
        let w = pack_material(&m, true);
        assert_eq!(w.specular.y, 1.0, "NaN roughness falls back to rough");
        m.shading = ShadingModel::BlinnPhong;
        m.illum = Some(7);
        m.ior = 1.33;
        m.transmission_filter = Vec3::new(0.9, 0.8, 0.7);
        let glass = pack_material(&m, false);
        assert_eq!(glass.transmission, Vec4::new(0.9, 0.8, 0.7, 1.33));
        assert_eq!(glass.reflection, Vec4::new(0.3, 0.3, 0.3, 0.0));
        m.illum = Some(2);
        assert_eq!(pack_material(&m, false).transmission, Vec4::ZERO);
    }
}
