//! Loading a scene file (or a bare model file) into a [`Scene`]: read the description, load
//! each model file once, place instances, bring glTF lights and cameras into world space,
//! bound radii, add the default camera.

use crate::bounds::Aabb;
use crate::camera::default_camera;
use crate::desc::ScriptRef;
use crate::desc::{read_scene_desc, Placement, SceneDesc};
use crate::environment::{load_environment, EnvironmentDesc};
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::Light;
use crate::material::Optics;
use crate::model::Model;
use crate::model_file::{extension, is_model_file, load_model, LoadOptions};
use crate::scene::{Instance, Scene};
use crate::script::Limits;
use glam::Mat4;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Loads a `.scene` file, a `.rhai` scene script, or an `.obj`, `.gltf` or
/// `.glb` file as a scene with one model.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    load_scene_with(path, &LoadOptions::default())
}

/// [`load_scene`] with options.
pub fn load_scene_with(path: &Path, options: &LoadOptions) -> Result<Scene, SceneError> {
    let mut diag = Diagnostics::default();
    let desc = if is_model_file(path) {
        SceneDesc {
            models: vec![Placement {
                file: path.to_path_buf(),
                at: Location::file(path),
                transform: Mat4::IDENTITY,
                absorption: None,
                ior: None,
                thin: None,
                material: Default::default(),
                smooth_normals: false,
            }],
            ..SceneDesc::default()
        }
    } else if extension(path) == "rhai" {
        SceneDesc {
            script: Some(ScriptRef {
                path: path.to_path_buf(),
                at: Location::file(path),
                first_light: 0,
                first_model: 0,
                imports: Vec::new(),
            }),
            ..SceneDesc::default()
        }
    } else {
        read_scene_desc(path, &mut diag)?
    };
    let mut desc = desc;
    let mut preloaded = HashMap::new();
    if let Some(mut script) = desc.script.take() {
        // The script's objects follow every object of the file.
        script.first_light = desc.lights.len();
        if let Some(message) = crate::outside::refusal(
            &script.path,
            path.parent().unwrap_or(Path::new(".")),
            "script",
        ) {
            return Err(SceneError::Syntax {
                at: script.at.clone(),
                message,
            });
        }
        if !script.path.is_file() {
            return Err(SceneError::Syntax {
                at: script.at.clone(),
                message: format!("script {} not found", script.path.display()),
            });
        }
        preloaded = crate::script::run_load(
            &mut script,
            path,
            &mut desc,
            &mut diag,
            (options, &Limits::default()),
        )?;
        desc.script = Some(script);
    }
    build(path, desc, (options, preloaded), &mut diag)
}

/// Turns a description into a scene; `preloaded` holds model files already
/// read (by canonical path).
fn build(
    path: &Path,
    desc: SceneDesc,
    (options, preloaded): (&LoadOptions, HashMap<PathBuf, Model>),
    diag: &mut Diagnostics,
) -> Result<Scene, SceneError> {
    let mut models: Vec<Model> = Vec::new();
    // A file is loaded once per distinct set of material overrides.
    let mut by_file: HashMap<(PathBuf, [u32; 6]), usize> = HashMap::new();
    let mut instances = Vec::new();
    let mut lights = desc.lights;
    let mut cameras = desc.cameras;
    for placement in &desc.models {
        let path = placement
            .file
            .canonicalize()
            .unwrap_or_else(|_| placement.file.clone());
        let sigma = placement
            .absorption
            .map_or([u32::MAX; 3], |s| s.to_array().map(f32::to_bits));
        let key = (
            path.clone(),
            [
                sigma[0],
                sigma[1],
                sigma[2],
                placement.ior.map_or(u32::MAX, f32::to_bits),
                placement.thin.map_or(2, u32::from),
                u32::from(placement.smooth_normals),
            ],
        );
        let index = match by_file.get(&key) {
            Some(&i) => i,
            None => {
                let mut model = match preloaded.get(&path) {
                    Some(model) => model.clone(),
                    None => load_model(&placement.file, &placement.at, options, diag)?,
                };
                override_glass(&mut model, placement);
                if placement.smooth_normals {
                    smooth_model_normals(&mut model);
                }
                models.push(model);
                by_file.insert(key, models.len() - 1);
                models.len() - 1
            }
        };
        let model = &models[index];
        let m = placement.transform;
        lights.extend(model.lights.iter().map(|l| transform_light(l, &m)));
        cameras.extend(model.cameras.iter().map(|c| {
            let mut c = c.clone();
            let (_, rotation, translation) =
                (m * Mat4::from_rotation_translation(c.orientation, c.position))
                    .to_scale_rotation_translation();
            c.position = translation;
            c.orientation = rotation;
            c
        }));
        let placed = model.bounds.transformed(&m);
        warn_if_far(&placed, &placement.at, diag);
        instances.push(Instance {
            model: index,
            transform: m,
            bounds: placed,
            material: placement.material,
        });
    }
    let bounds = instances
        .iter()
        .fold(Aabb::EMPTY, |b, i| b.union(&i.bounds));
    let environment_desc = match &options.environment {
        Some(file) => Some(EnvironmentDesc {
            file: file.clone(),
            at: Location::file(file),
            intensity: 1.0,
            rotation_deg: 0.0,
        }),
        None => desc.environment,
    };
    let environment = environment_desc
        .map(|e| load_environment(&e, diag))
        .transpose()?;
    let framing = desc.bounding_box.unwrap_or(bounds);
    bound_radii(&mut lights, &framing, path, diag);
    if cameras.is_empty() {
        cameras.push(default_camera(&framing));
    }
    Ok(Scene {
        path: path.to_path_buf(),
        models,
        instances,
        lights,
        cameras,
        bounds,
        declared_bounds: desc.bounding_box,
        origin: desc.origin,
        script: desc.script,
        environment,
        warnings: std::mem::take(&mut diag.warnings),
    })
}

/// Largest distance from the scene's origin ([`Scene::origin`]), per axis,
/// that keeps a scene within 1e6 units across; beyond it float32 positions
/// step by 1/32 unit or more.
const PRECISE_REACH: f32 = 5e5;

/// Warns, at the `model` block, when the placed model reaches past
/// [`PRECISE_REACH`] from the scene's origin (docs/stability.md).
fn warn_if_far(placed: &Aabb, at: &Location, diag: &mut Diagnostics) {
    if placed.is_empty() {
        return;
    }
    let reach = placed.min.abs().max(placed.max.abs()).max_element();
    if reach > PRECISE_REACH {
        let step = reach.next_up() - reach;
        diag.warn(
            at.clone(),
            format!(
                "this model reaches {reach:e} units from the scene's origin (its first camera, else its first position): the scene spans more than 1e6 units, where float32 positions step by {step:.2} units; keep what is drawn within 5e5 units of the first camera"
            ),
        );
    }
}

/// Applies a `model` block's `absorption`, `ior` and `thin` to the model's
/// glass (dielectric) materials.
fn override_glass(model: &mut Model, placement: &Placement) {
    for material in &mut model.materials {
        let Optics::Dielectric { fraction, thin } = material.optics else {
            continue;
        };
        material.optics = Optics::Dielectric {
            fraction,
            thin: placement.thin.unwrap_or(thin),
        };
        if let Some(sigma) = placement.absorption {
            material.absorption = sigma;
        }
        if let Some(ior) = placement.ior {
            material.ior = ior;
        }
    }
}

/// A `model` block's `smooth_normals 1`: every mesh's normals recomputed
/// smooth across its faces, and its tangents, which follow the normals,
/// generated again.
fn smooth_model_normals(model: &mut Model) {
    for mesh in &mut model.meshes {
        mesh.normals = crate::mesh::smooth_normals(&mesh.positions, &mesh.indices);
        mesh.tangents.clear();
    }
    crate::tangents::generate_model_tangents(model);
}

/// Replaces unbounded point-light radii (no falloff) by the scene's diagonal, with a warning.
fn bound_radii(lights: &mut [Light], bounds: &Aabb, path: &Path, diag: &mut Diagnostics) {
    let extent = bounds.diagonal().max(1.0);
    let mut count = 0;
    for light in lights.iter_mut() {
        if let Light::Point(p) = light {
            if !p.radius.is_finite() {
                p.radius = extent;
                count += 1;
            }
        }
    }
    if count > 0 {
        diag.warn(
            Location::file(path),
            format!("{count} point lights never fall off (no linear or quadratic attenuation); radius set to the scene diagonal {extent}"),
        );
    }
}

/// A model-space light in world space.
fn transform_light(light: &Light, m: &Mat4) -> Light {
    let dir = |d: glam::Vec3| m.transform_vector3(d).try_normalize().unwrap_or(d);
    match light {
        Light::Sun(s) => {
            let mut s = s.clone();
            s.direction = dir(s.direction);
            Light::Sun(s)
        }
        Light::Spot(s) => {
            let mut s = s.clone();
            s.position = m.transform_point3(s.position);
            s.direction = dir(s.direction);
            Light::Spot(s)
        }
        Light::Point(p) => {
            let mut p = p.clone();
            p.position = m.transform_point3(p.position);
            Light::Point(p)
        }
        Light::Area(a) => {
            let mut a = a.clone();
            let (_, rotation, translation) = (*m
                * Mat4::from_rotation_translation(a.orientation, a.position))
            .to_scale_rotation_translation();
            a.position = translation;
            a.orientation = rotation;
            Light::Area(a)
        }
    }
}
