//! glTF 2.0 import (`.gltf` with external or embedded buffers, `.glb`): meshes with node
//! transforms baked in, metallic-roughness materials with the emissive-strength,
//! transmission, IOR and volume extensions, KHR_lights_punctual lights and cameras.

mod checks;
mod materials;

use checks::{check_accessor_bounds, check_glb_header, check_node_graph};
pub use checks::{MAX_EXPANDED_TRIANGLES, MAX_NODE_INSTANCES};
use materials::{image_sources, material};

use crate::bounds::Aabb;
use crate::camera::{Camera, CameraOrigin};
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::{
    derive_radius, Attenuation, Light, PointLight, RadiusSource, SpotLight, SunLight,
    DEFAULT_LUMINANCE_THRESHOLD,
};
use crate::material::{AlphaMode, Material, Optics, ShadingModel, TextureRef, TextureSource};
use crate::mesh::{compute_normals, Mesh};
use crate::model::Model;
use crate::source::{read_capped, MAX_MODEL_BYTES};
use crate::uri::{decode_data_uri, percent_decode};
use glam::{Mat3, Mat4, Vec2, Vec3, Vec4};
use std::path::{Path, PathBuf};

/// Loads a `.gltf` or `.glb` file; `asked_at` is where it was named.
pub fn load_gltf(
    path: &Path,
    asked_at: &Location,
    diag: &mut Diagnostics,
) -> Result<Model, SceneError> {
    let bytes = read_capped(path, asked_at, MAX_MODEL_BYTES)?;
    let model_error = |message: String| SceneError::Model {
        at: Location::file(path),
        message,
    };
    check_glb_header(&bytes).map_err(model_error)?;
    let gltf = gltf::Gltf::from_slice(&bytes)
        .map_err(|e| model_error(format!("glTF does not parse: {e}")))?;
    check_version(&gltf.document.as_json().asset).map_err(model_error)?;
    let dir = path.parent().unwrap_or(Path::new(""));
    let mut sources = vec![path.to_path_buf()];
    let buffers = load_buffers(&gltf, dir, path, &mut sources)?;
    let doc = &gltf.document;
    let images = image_sources(doc, &buffers, dir, path, diag, &mut sources);
    let materials: Vec<Material> = doc.materials().map(|m| material(&m, &images)).collect();
    let mut out = Model {
        path: path.to_path_buf(),
        meshes: Vec::new(),
        materials,
        lights: Vec::new(),
        cameras: Vec::new(),
        bounds: Aabb::EMPTY,
        sources,
    };
    let roots: Vec<gltf::Node<'_>> = match doc.default_scene().or_else(|| doc.scenes().next()) {
        Some(scene) => scene.nodes().collect(),
        // No scene: every node that is no other node's child is a root.
        None => {
            let children: std::collections::HashSet<usize> = doc
                .nodes()
                .flat_map(|n| n.children().map(|c| c.index()).collect::<Vec<_>>())
                .collect();
            doc.nodes()
                .filter(|n| !children.contains(&n.index()))
                .collect()
        }
    };
    // Every triangle primitive's accessors within their views, before the
    // node graph is counted or any mesh read.
    for mesh in doc.meshes() {
        for (i, primitive) in mesh.primitives().enumerate() {
            if primitive.mode() != gltf::mesh::Mode::Triangles {
                continue;
            }
            let accessors = primitive.attributes().map(|(_, a)| a);
            accessors
                .chain(primitive.indices())
                .try_for_each(|a| check_accessor_bounds(&a, &buffers))
                .map_err(|m| {
                    let name = mesh.name().unwrap_or("mesh");
                    model_error(format!("primitive '{name}#{i}': {m}"))
                })?;
        }
    }
    check_node_graph(doc, &roots, path, diag).map_err(model_error)?;
    // Depth-first in document order: children are pushed reversed so the first pops first.
    let mut stack: Vec<(gltf::Node<'_>, Mat4, usize)> = roots
        .into_iter()
        .rev()
        .map(|n| (n, Mat4::IDENTITY, 0))
        .collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > 256 {
            return Err(model_error(
                "node hierarchy deeper than 256 (a cycle?)".to_string(),
            ));
        }
        let world = parent * Mat4::from_cols_array_2d(&node.transform().matrix());
        if let Some(mesh) = node.mesh() {
            for (i, primitive) in mesh.primitives().enumerate() {
                let name = format!("{}#{i}", mesh.name().or(node.name()).unwrap_or("mesh"));
                if let Some(m) = primitive_mesh(&primitive, &buffers, &world, name, path, diag)? {
                    out.meshes.push(m);
                }
            }
        }
        if let Some(light) = node.light() {
            out.lights.push(punctual(&light, &world));
        }
        if let Some(camera) = node.camera() {
            if let Some(c) = camera_of(&camera, &node, &world, out.cameras.len(), path, diag) {
                out.cameras.push(c);
            }
        }
        let children: Vec<gltf::Node<'_>> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
    }
    out.update_bounds();
    Ok(out)
}

/// Every buffer's bytes: the GLB chunk, a data URI, or a file beside the glTF.
fn load_buffers(
    gltf: &gltf::Gltf,
    dir: &Path,
    path: &Path,
    sources: &mut Vec<PathBuf>,
) -> Result<Vec<Vec<u8>>, SceneError> {
    gltf.document
        .buffers()
        .map(|buffer| {
            let data = match buffer.source() {
                gltf::buffer::Source::Bin => {
                    gltf.blob.clone().ok_or_else(|| SceneError::Model {
                        at: Location::file(path),
                        message: "buffer refers to a GLB chunk the file lacks".to_string(),
                    })?
                }
                gltf::buffer::Source::Uri(uri) => match decode_data_uri(uri) {
                    Some(decoded) => {
                        decoded
                            .map_err(|e| SceneError::Model {
                                at: Location::file(path),
                                message: format!("buffer {}: {e}", buffer.index()),
                            })?
                            .1
                    }
                    None => {
                        let file = dir.join(percent_decode(uri));
                        if let Some(message) = crate::outside::refusal(&file, dir, "buffer") {
                            return Err(SceneError::Model {
                                at: Location::file(path),
                                message: format!("buffer {}: {message}", buffer.index()),
                            });
                        }
                        sources.push(file.clone());
                        read_capped(&file, &Location::file(path), MAX_MODEL_BYTES)?
                    }
                },
            };
            if data.len() < buffer.length() {
                return Err(SceneError::Model {
                    at: Location::file(path),
                    message: format!(
                        "buffer {} has {} bytes, fewer than the {} declared",
                        buffer.index(),
                        data.len(),
                        buffer.length()
                    ),
                });
            }
            Ok(data)
        })
        .collect()
}

/// glTF 2.0 only: `asset.version` (and `minVersion`, when given) must be
/// 2.x, as the specification requires of a loader.
fn check_version(asset: &gltf::json::Asset) -> Result<(), String> {
    let major = |v: &str| v.split('.').next().and_then(|m| m.parse::<u32>().ok());
    if major(&asset.version) != Some(2) {
        return Err(format!(
            "asset.version is \"{}\"; weft reads glTF 2.x",
            asset.version
        ));
    }
    match asset.min_version.as_deref() {
        Some(min) if major(min) != Some(2) => Err(format!(
            "asset.minVersion is \"{min}\"; weft reads glTF 2.x"
        )),
        _ => Ok(()),
    }
}

/// Each attribute's and the indices' accessor has the type and component
/// type the glTF 2.0 specification allows it (§3.7.2.1 and §3.7.2.2):
/// POSITION and NORMAL float VEC3, TANGENT float VEC4, TEXCOORD_n VEC2 of
/// floats or normalized unsigned bytes or shorts, COLOR_n VEC3 or VEC4,
/// indices unsigned scalar integers.
fn check_accessors(primitive: &gltf::Primitive<'_>) -> Result<(), String> {
    use gltf::accessor::{DataType as D, Dimensions as V};
    use gltf::Semantic as S;
    let normalized_unsigned =
        |a: &gltf::Accessor<'_>| a.normalized() && matches!(a.data_type(), D::U8 | D::U16);
    let float = |a: &gltf::Accessor<'_>| a.data_type() == D::F32;
    for (semantic, accessor) in primitive.attributes() {
        let (allowed, wanted) = match &semantic {
            S::Positions | S::Normals => (
                accessor.dimensions() == V::Vec3 && float(&accessor),
                "float VEC3",
            ),
            S::Tangents => (
                accessor.dimensions() == V::Vec4 && float(&accessor),
                "float VEC4",
            ),
            S::TexCoords(_) => (
                accessor.dimensions() == V::Vec2
                    && (float(&accessor) || normalized_unsigned(&accessor)),
                "VEC2 of floats or normalized unsigned bytes or shorts",
            ),
            S::Colors(_) => (
                matches!(accessor.dimensions(), V::Vec3 | V::Vec4)
                    && (float(&accessor) || normalized_unsigned(&accessor)),
                "VEC3 or VEC4 of floats or normalized unsigned bytes or shorts",
            ),
            _ => (true, ""),
        };
        if !allowed {
            return Err(format!(
                "attribute {} is accessor {} of {:?} {:?}; the glTF 2.0 specification allows {wanted}",
                semantic.to_string(),
                accessor.index(),
                accessor.data_type(),
                accessor.dimensions()
            ));
        }
    }
    if let Some(indices) = primitive.indices() {
        if indices.dimensions() != V::Scalar
            || !matches!(indices.data_type(), D::U8 | D::U16 | D::U32)
        {
            return Err(format!(
                "indices are accessor {} of {:?} {:?}; the glTF 2.0 specification allows unsigned SCALAR integers",
                indices.index(),
                indices.data_type(),
                indices.dimensions()
            ));
        }
    }
    Ok(())
}

/// One triangle primitive as a mesh in model space; `None` (with a warning) for points,
/// lines and primitives without positions.
fn primitive_mesh(
    primitive: &gltf::Primitive<'_>,
    buffers: &[Vec<u8>],
    world: &Mat4,
    name: String,
    path: &Path,
    diag: &mut Diagnostics,
) -> Result<Option<Mesh>, SceneError> {
    if primitive.mode() != gltf::mesh::Mode::Triangles {
        diag.warn(
            Location::file(path),
            format!(
                "primitive '{name}' has mode {:?}; only triangle lists are imported",
                primitive.mode()
            ),
        );
        return Ok(None);
    }
    check_accessors(primitive).map_err(|m| SceneError::Model {
        at: Location::file(path),
        message: format!("primitive '{name}': {m}"),
    })?;
    let reader = primitive.reader(|b| buffers.get(b.index()).map(Vec::as_slice));
    let Some(positions) = reader.read_positions() else {
        diag.warn(
            Location::file(path),
            format!("primitive '{name}' has no positions; skipped"),
        );
        return Ok(None);
    };
    let local: Vec<Vec3> = positions.map(Vec3::from_array).collect();
    let indices: Vec<u32> = match reader.read_indices() {
        Some(i) => i.into_u32().collect(),
        None => (0..local.len() as u32).collect(),
    };
    let bad = |message: String| SceneError::Model {
        at: Location::file(path),
        message: format!("primitive '{name}': {message}"),
    };
    if !indices.len().is_multiple_of(3) {
        return Err(bad(format!(
            "{} indices is not a whole number of triangles",
            indices.len()
        )));
    }
    if indices.iter().any(|&i| i as usize >= local.len()) {
        return Err(bad("an index is past the vertex count".to_string()));
    }
    if local.iter().any(|p| !p.is_finite()) {
        return Err(bad("a position is NaN or infinite".to_string()));
    }
    let normal_matrix = Mat3::from_mat4(*world).inverse().transpose();
    let flip = world.determinant() < 0.0;
    let positions: Vec<Vec3> = local.iter().map(|&p| world.transform_point3(p)).collect();
    let mut indices = indices;
    if flip {
        for tri in indices.chunks_exact_mut(3) {
            tri.swap(1, 2);
        }
    }
    let normals = match reader.read_normals() {
        Some(n) => n
            .map(|n| {
                (normal_matrix * Vec3::from_array(n))
                    .try_normalize()
                    .unwrap_or(Vec3::Y)
            })
            .collect::<Vec<_>>(),
        None => compute_normals(&positions, &indices),
    };
    let uvs: Vec<Vec2> = reader
        .read_tex_coords(0)
        .map(|t| t.into_f32().map(Vec2::from_array).collect())
        .unwrap_or_default();
    let uvs1: Vec<Vec2> = reader
        .read_tex_coords(1)
        .map(|t| t.into_f32().map(Vec2::from_array).collect())
        .unwrap_or_default();
    let colors: Vec<Vec4> = reader
        .read_colors(0)
        .map(|c| c.into_rgba_f32().map(Vec4::from_array).collect())
        .unwrap_or_default();
    let handedness = if flip { -1.0 } else { 1.0 };
    let tangents: Vec<Vec4> = reader
        .read_tangents()
        .map(|t| {
            t.map(|t| {
                let xyz = (Mat3::from_mat4(*world) * Vec3::new(t[0], t[1], t[2]))
                    .try_normalize()
                    .unwrap_or(Vec3::X);
                xyz.extend(t[3] * handedness)
            })
            .collect()
        })
        .unwrap_or_default();
    let count = positions.len();
    if normals.len() != count
        || (!uvs.is_empty() && uvs.len() != count)
        || (!tangents.is_empty() && tangents.len() != count)
        || (!uvs1.is_empty() && uvs1.len() != count)
        || (!colors.is_empty() && colors.len() != count)
    {
        return Err(bad("attribute counts differ".to_string()));
    }
    let bounds = Aabb::from_points(&positions);
    Ok(Some(Mesh {
        name,
        positions,
        normals,
        uvs,
        uvs1,
        colors,
        tangents,
        indices,
        material: primitive.material().index(),
        bounds,
    }))
}

/// Lumens per watt in the conversion of photometric glTF intensities to
/// radiometric ones, as Blender's glTF importer does by default ("Standard"
/// lighting mode, `PBR_WATTS_TO_LUMENS`).
pub const LUMENS_PER_WATT: f32 = 683.0;

/// The `.scene` colour of a KHR_lights_punctual light of `color` and
/// `intensity` (candela for point and spot lights, lux for directional ones):
/// irradiance intensity / 683 at 1 unit head-on, which is pi times the colour
/// (scenes/FORMAT.md, "Units").
pub fn punctual_color(color: Vec3, intensity: f32) -> Vec3 {
    color * (intensity / (LUMENS_PER_WATT * std::f32::consts::PI))
}

/// A KHR_lights_punctual light placed by its node (lights shine down the node's -Z).
fn punctual(light: &gltf::khr_lights_punctual::Light<'_>, world: &Mat4) -> Light {
    let color = punctual_color(Vec3::from_array(light.color()), light.intensity());
    let position = world.transform_point3(Vec3::ZERO);
    let direction = world
        .transform_vector3(Vec3::NEG_Z)
        .try_normalize()
        .unwrap_or(Vec3::NEG_Z);
    let (radius, radius_source) = match light.range() {
        Some(r) => (r, RadiusSource::Range),
        None => (
            derive_radius(
                color,
                &Attenuation::INVERSE_SQUARE,
                DEFAULT_LUMINANCE_THRESHOLD,
            )
            .unwrap_or(f32::INFINITY),
            RadiusSource::Derived,
        ),
    };
    match light.kind() {
        gltf::khr_lights_punctual::Kind::Directional => Light::Sun(SunLight {
            direction,
            color,
            ambient: Vec3::ZERO,
            motion: None,
        }),
        gltf::khr_lights_punctual::Kind::Point => Light::Point(PointLight {
            position,
            color,
            velocity: 0.0,
            amplitude: 0.0,
            attenuation: Attenuation::INVERSE_SQUARE,
            radius,
            radius_source,
        }),
        gltf::khr_lights_punctual::Kind::Spot {
            inner_cone_angle,
            outer_cone_angle,
        } => Light::Spot(SpotLight {
            position,
            direction,
            color,
            exponent: 0.0,
            angle: outer_cone_angle.to_degrees(),
            inner_angle: Some(inner_cone_angle.to_degrees()),
            length: light.range(),
            attenuation: Attenuation::INVERSE_SQUARE,
            swivel: None,
        }),
    }
}

/// A perspective camera node; orthographic ones are skipped with a warning.
fn camera_of(
    camera: &gltf::Camera<'_>,
    node: &gltf::Node<'_>,
    world: &Mat4,
    index: usize,
    path: &Path,
    diag: &mut Diagnostics,
) -> Option<Camera> {
    let name = camera
        .name()
        .or(node.name())
        .map_or_else(|| format!("gltf-camera{index}"), str::to_string);
    let gltf::camera::Projection::Perspective(p) = camera.projection() else {
        diag.warn(
            Location::file(path),
            format!("camera '{name}' is orthographic; skipped"),
        );
        return None;
    };
    let (_, rotation, translation) = world.to_scale_rotation_translation();
    Some(Camera {
        name,
        position: translation,
        orientation: rotation.normalize(),
        fov_y: p.yfov(),
        near: p.znear(),
        far: p.zfar().unwrap_or(p.znear() * 1e6),
        path: Vec::new(),
        origin: CameraOrigin::Gltf,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn punctual_directions_follow_the_node() {
        let world = Mat4::from_rotation_translation(
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            Vec3::Y,
        );
        assert!(world.transform_vector3(Vec3::NEG_Z).distance(Vec3::NEG_Y) < 1e-6);
        assert_eq!(world.transform_point3(Vec3::ZERO), Vec3::Y);
    }
}
