//! Material records for the GPU and the material filters passes draw by: MTL
//! Blinn-Phong parameters as given, glTF metallic-roughness factors for the GGX
//! shading in `shaders/include/lighting.glsl`.

use crate::gpu_types::GpuMaterial;
use crate::optics::Coat;
use crate::sanitize;
use crate::vocabulary::MeshFilter;
use glam::{Vec3, Vec4};
use weft_scene::material::{AlphaMode, Optics, ShadingModel};
use weft_scene::Material;

/// Shading-model code of MTL materials (`SHADING_BLINN_PHONG`).
pub const BLINN_PHONG: f32 = 0.0;
/// Shading-model code of glTF materials (`SHADING_METALLIC_ROUGHNESS`).
pub const METALLIC_ROUGHNESS: f32 = 1.0;
/// Shading-model code of MTL materials with `illum` 3 or 5 (`SHADING_MIRROR`):
/// the path tracer reflects `Ks` as a perfect mirror; raster passes shade
/// them as Blinn-Phong.
pub const MIRROR: f32 = 2.0;
/// Shading-model code of MTL materials with `illum 5` (`SHADING_COATED`): the
/// path tracer puts a smooth dielectric coat over a Lambert `Kd`
/// ([`Coat`]); raster passes shade them as Blinn-Phong.
pub const COATED: f32 = 3.0;

/// Whether a mesh with this material is drawn by a pass with `filter`.
pub fn matches(filter: MeshFilter, m: &Material) -> bool {
    let blended = m.alpha_mode == AlphaMode::Blend;
    match filter {
        MeshFilter::All => true,
        MeshFilter::Opaque | MeshFilter::ShadowCasters => !blended,
        MeshFilter::Transparent => blended,
        MeshFilter::Emissive => m.emissive.max_element() > 0.0,
    }
}

/// A smooth dielectric as the path tracer sees it (`shaders/pathtrace/dielectric.glsl`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dielectric {
    /// Index of refraction of the inside (the outside is air, 1).
    pub ior: f32,
    /// Tint of reflected light (MTL `Ks`; 1 for glTF).
    pub reflection: Vec3,
    /// Tint of refracted light, at every crossing (MTL `Tf`; glTF base colour).
    pub transmission: Vec3,
    /// Beer–Lambert coefficient σ per world unit inside (`.scene` `absorption`,
    /// glTF KHR_materials_volume).
    pub absorption: Vec3,
    /// The share of hits that meet the glass; the rest meet the opaque
    /// shading model (glTF: transmission × (1 − metallic)).
    pub fraction: f32,
    /// A thin shell: light goes straight through, with no medium inside.
    pub thin: bool,
}

/// The dielectric a material describes ([`Optics::Dielectric`]): MTL glass
/// with index `Ni`, reflection tint `Ks` and transmission tint `Tf` (`Ks 1 1
/// 1`, `Tf 1 1 1`, `Ni 1.5`, `illum 7` is clear glass), or a glTF
/// transmissive material with its IOR, tinted by its base colour.
pub fn dielectric(m: &Material) -> Option<Dielectric> {
    let Optics::Dielectric { fraction, thin } = m.optics else {
        return None;
    };
    let (reflection, transmission, fraction) = match m.shading {
        ShadingModel::BlinnPhong => (m.specular, m.transmission_filter, fraction),
        ShadingModel::MetallicRoughness => (
            Vec3::ONE,
            m.base_color.truncate(),
            fraction * (1.0 - finite_unit(m.metallic, 0.0)),
        ),
    };
    let valid = m.ior.is_finite() && m.ior > 0.0 && fraction > 0.0;
    valid.then_some(Dielectric {
        ior: m.ior,
        reflection: reflection.clamp(Vec3::ZERO, Vec3::ONE),
        transmission: transmission.clamp(Vec3::ZERO, Vec3::ONE),
        absorption: m.absorption,
        fraction: fraction.min(1.0),
        thin,
    })
}

/// Whether an MTL material is a mirror (`illum` 3): the path tracer
/// reflects its Ks perfectly.
pub fn is_mirror(m: &Material) -> bool {
    m.shading == ShadingModel::BlinnPhong && m.optics == Optics::Mirror
}

/// The coat of an MTL `illum 5` material, whose normal-incidence reflectance is `Ks`.
pub fn coat(m: &Material) -> Option<Coat> {
    let coated = m.shading == ShadingModel::BlinnPhong && m.optics == Optics::Coated;
    coated.then(|| Coat::from_specular(m.specular))
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
    let glass = dielectric(m);
    let optics = glass.map_or(Vec4::ZERO, |d| {
        Vec4::new(d.fraction, if d.thin { 1.0 } else { 0.0 }, 0.0, 0.0)
    });
    let transmission = glass.map_or(Vec4::ZERO, |d| d.transmission.extend(d.ior));
    let reflection = glass.map_or(Vec4::ZERO, |d| d.reflection.extend(0.0));
    let absorption = glass.map_or(Vec4::ZERO, |d| d.absorption.extend(0.0));
    match m.shading {
        ShadingModel::BlinnPhong => {
            let (diffuse, specular, shininess, ambient) = blinn_phong(m);
            let coat = coat(m);
            let model = if is_mirror(m) {
                MIRROR
            } else if coat.is_some() {
                COATED
            } else {
                BLINN_PHONG
            };
            GpuMaterial {
                diffuse: sanitize::radiance(diffuse).extend(sanitize::bounded(m.base_color.w, 1.0)),
                specular: sanitize::radiance(specular)
                    .extend(sanitize::bounded(shininess, sanitize::RADIANCE_MAX)),
                ambient: sanitize::radiance(ambient).extend(normal_scale),
                emissive: sanitize::radiance(m.emissive).extend(model),
                transmission,
                reflection: coat.map_or(reflection, |c| c.tint.extend(0.0)),
                absorption,
                optics: coat.map_or(optics, |c| {
                    Vec4::new(0.0, 0.0, c.ior, c.internal_reflectance)
                }),
            }
        }
        ShadingModel::MetallicRoughness => {
            // The opaque part of a partly transmissive material keeps the
            // metallic share it had of the whole: metallic / (1 - glass).
            let metallic = finite_unit(m.metallic, 0.0);
            let opaque = 1.0 - optics.x;
            let metallic = if opaque > 0.0 {
                (metallic / opaque).min(1.0)
            } else {
                metallic
            };
            let factors = Vec4::new(metallic, finite_unit(m.roughness, 1.0), 0.0, 0.0);
            GpuMaterial {
                diffuse: sanitize::colour_alpha(m.base_color),
                specular: factors,
                ambient: Vec3::ZERO.extend(normal_scale),
                emissive: sanitize::radiance(m.emissive).extend(METALLIC_ROUGHNESS),
                transmission,
                reflection,
                absorption,
                optics,
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
        assert!(matches(MeshFilter::Opaque, &opaque));
        assert!(!matches(MeshFilter::Opaque, &glass));
        assert!(matches(MeshFilter::Transparent, &glass));
        assert!(!matches(MeshFilter::ShadowCasters, &glass));
        assert!(matches(MeshFilter::Emissive, &lamp));
        assert!(!matches(MeshFilter::Emissive, &opaque));
        assert!(matches(MeshFilter::All, &glass));
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
        m.optics = Optics::Dielectric {
            fraction: 1.0,
            thin: false,
        };
        m.ior = 1.33;
        m.transmission_filter = Vec3::new(0.9, 0.8, 0.7);
        let glass = pack_material(&m, false);
        assert_eq!(glass.transmission, Vec4::new(0.9, 0.8, 0.7, 1.33));
        assert_eq!(glass.reflection, Vec4::new(0.3, 0.3, 0.3, 0.0));
        assert_eq!(glass.optics, Vec4::new(1.0, 0.0, 0.0, 0.0));
        m.optics = Optics::Coated;
        m.specular = Vec3::new(0.04, 0.04, 0.02);
        let coated = pack_material(&m, false);
        assert_eq!(coated.emissive.w, COATED);
        assert_eq!(coated.transmission, Vec4::ZERO);
        assert!(
            (coated.reflection - Vec4::new(1.0, 1.0, 0.5, 0.0))
                .abs()
                .max_element()
                < 1e-6
        );
        assert!((coated.optics.z - 1.5).abs() < 1e-5 && (coated.optics.w - 0.596).abs() < 1e-3);
        m.optics = Optics::Opaque;
        assert_eq!(pack_material(&m, false).transmission, Vec4::ZERO);
    }

    /// A glTF material that transmits half its light and is 0.5 metallic:
    /// glass over (1 - 0.5) * 0.5 of the surface, and the opaque rest keeps
    /// metallic 0.5 / 0.75 so the whole is still half metal.
    #[test]
    fn gltf_transmission_splits_glass_from_the_opaque_part() {
        let m = Material {
            shading: ShadingModel::MetallicRoughness,
            base_color: Vec4::new(0.2, 0.4, 0.6, 1.0),
            metallic: 0.5,
            transmission: 0.5,
            ior: 1.4,
            optics: Optics::Dielectric {
                fraction: 0.5,
                thin: true,
            },
            ..Material::default()
        };
        let w = pack_material(&m, false);
        assert_eq!(w.optics, Vec4::new(0.25, 1.0, 0.0, 0.0));
        assert_eq!(w.transmission, Vec4::new(0.2, 0.4, 0.6, 1.4));
        assert_eq!(w.reflection, Vec4::new(1.0, 1.0, 1.0, 0.0));
        assert!((w.specular.x - 0.5 / 0.75).abs() < 1e-6);
    }
}
