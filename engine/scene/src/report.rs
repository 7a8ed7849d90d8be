//! `weft scene check`: a summary of a loaded scene for people (`Display`) and tools (serde).

use crate::bounds::Aabb;
use crate::error::{Location, SceneError, Warning};
use crate::light::{energy_cut_share, Light, RadiusSource};
use crate::load::load_scene_with;
use crate::material::{declared_size, decode_refusal, fit_within, TextureSource, MAX_TEXTURE_SIDE};
use crate::model_file::LoadOptions;
use crate::scene::Scene;
use serde::Serialize;
use std::collections::BTreeSet;
use std::fmt;
use std::path::{Path, PathBuf};

/// One model file in the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModelSummary {
    /// The file.
    pub file: PathBuf,
    /// How many times the scene places it.
    pub instances: usize,
    /// Its meshes.
    pub meshes: usize,
    /// Its triangles (once, not per instance).
    pub triangles: usize,
    /// Its materials.
    pub materials: usize,
    /// Distinct textures its materials use.
    pub textures: usize,
}

/// Lights by type.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
pub struct LightCounts {
    /// Directional lights.
    pub sun: usize,
    /// Spotlights.
    pub spot: usize,
    /// Point lights.
    pub point: usize,
    /// Area lights.
    pub area: usize,
}

/// How point-light radii were chosen and what the cutoff costs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RadiusSummary {
    /// Radii given in the scene.
    pub given: usize,
    /// Radii derived from attenuation and the luminance threshold.
    pub derived: usize,
    /// Radii from glTF `range`.
    pub range: usize,
    /// The largest share of a light's energy (within the scene's extent) that its cutoff drops.
    pub max_energy_cut: f32,
    /// The mean of those shares.
    pub mean_energy_cut: f32,
}

/// Everything `weft scene check` prints.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneReport {
    /// The checked file.
    pub file: PathBuf,
    /// Model files, in first-use order.
    pub models: Vec<ModelSummary>,
    /// Placed models.
    pub instances: usize,
    /// Meshes over all model files.
    pub meshes: usize,
    /// Triangles drawn, counting every instance.
    pub triangles: usize,
    /// Materials over all model files.
    pub materials: usize,
    /// Distinct textures over the scene.
    pub textures: usize,
    /// Lights by type.
    pub lights: LightCounts,
    /// Point-light radii, when there are point lights.
    pub point_light_radius: Option<RadiusSummary>,
    /// Camera names; the first is the starting camera.
    pub cameras: Vec<String>,
    /// World bounds of the geometry, `None` when there is none.
    pub bounds: Option<Aabb>,
    /// The point the loaded positions are relative to (`Scene::origin`):
    /// zero unless the scene's first camera is 512 units or more from zero.
    pub origin: [f64; 3],
    /// Warnings, in the order found.
    pub warnings: Vec<Warning>,
}

/// Loads `path` and summarises it; an `Err` is the located reason it does not load.
pub fn check_report(path: &Path) -> Result<SceneReport, SceneError> {
    check_report_with(path, &LoadOptions::default())
}

/// [`check_report`] with load options (e.g. a cache folder).
pub fn check_report_with(path: &Path, options: &LoadOptions) -> Result<SceneReport, SceneError> {
    Ok(SceneReport::of(&load_scene_with(path, options)?))
}

/// A stable key for a texture, to count distinct ones.
fn texture_key(source: &TextureSource) -> String {
    match source {
        TextureSource::File(p) => p.display().to_string(),
        TextureSource::Embedded { id, .. } => id.clone(),
    }
}

impl SceneReport {
    /// Summarises a loaded scene.
    pub fn of(scene: &Scene) -> Self {
        let mut all_textures = BTreeSet::new();
        let models: Vec<ModelSummary> = scene
            .models
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let textures: BTreeSet<String> = m
                    .materials
                    .iter()
                    .flat_map(|mat| mat.textures.iter())
                    .map(|t| texture_key(&t.source))
                    .collect();
                all_textures.extend(textures.iter().cloned());
                ModelSummary {
                    file: m.path.clone(),
                    instances: scene
                        .instances
                        .iter()
                        .filter(|inst| inst.model == i)
                        .count(),
                    meshes: m.meshes.len(),
                    triangles: m.triangle_count(),
                    materials: m.materials.len(),
                    textures: textures.len(),
                }
            })
            .collect();
        let mut lights = LightCounts::default();
        let extent = scene.effective_bounds().diagonal();
        let (mut radius, mut cut_sum) = (
            RadiusSummary {
                given: 0,
                derived: 0,
                range: 0,
                max_energy_cut: 0.0,
                mean_energy_cut: 0.0,
            },
            0.0f64,
        );
        for light in &scene.lights {
            match light {
                Light::Sun(_) => lights.sun += 1,
                Light::Spot(_) => lights.spot += 1,
                Light::Area(_) => lights.area += 1,
                Light::Point(p) => {
                    lights.point += 1;
                    match p.radius_source {
                        RadiusSource::Given => radius.given += 1,
                        RadiusSource::Derived => radius.derived += 1,
                        RadiusSource::Range => radius.range += 1,
                    }
                    let cut = energy_cut_share(&p.attenuation, p.radius, extent);
                    radius.max_energy_cut = radius.max_energy_cut.max(cut);
                    cut_sum += f64::from(cut);
                }
            }
        }
        let point_light_radius = (lights.point > 0).then(|| RadiusSummary {
            mean_energy_cut: (cut_sum / lights.point as f64) as f32,
            ..radius
        });
        SceneReport {
            file: scene.path.clone(),
            instances: scene.instances.len(),
            meshes: models.iter().map(|m| m.meshes).sum(),
            triangles: scene.triangle_count(),
            materials: models.iter().map(|m| m.materials).sum(),
            textures: all_textures.len(),
            models,
            lights,
            point_light_radius,
            cameras: scene.cameras.iter().map(|c| c.name.clone()).collect(),
            bounds: (!scene.bounds.is_empty()).then(|| Aabb {
                min: (scene.bounds.min.as_dvec3() + scene.origin).as_vec3(),
                max: (scene.bounds.max.as_dvec3() + scene.origin).as_vec3(),
            }),
            origin: scene.origin.to_array(),
            warnings: scene
                .warnings
                .iter()
                .cloned()
                .chain(oversized_textures(scene))
                .collect(),
        }
    }
}

/// A warning for each distinct texture with a side over [`MAX_TEXTURE_SIDE`],
/// which the renderer downscales before upload.
fn oversized_textures(scene: &Scene) -> Vec<Warning> {
    let mut seen = BTreeSet::new();
    let mut warnings = Vec::new();
    for texture in scene
        .models
        .iter()
        .flat_map(|m| m.materials.iter())
        .flat_map(|mat| mat.textures.iter())
    {
        if !seen.insert(texture_key(&texture.source)) {
            continue;
        }
        let Some((width, height, decoded)) = declared_size(&texture.source) else {
            continue;
        };
        let at = match &texture.source {
            TextureSource::File(path) => Location::file(path),
            TextureSource::Embedded { id, .. } => Location::file(Path::new(id)),
        };
        if let Some(message) = decode_refusal(width, height, decoded) {
            warnings.push(Warning { at, message });
            continue;
        }
        let (fit_width, fit_height) = fit_within(width, height, MAX_TEXTURE_SIDE);
        if (fit_width, fit_height) != (width, height) {
            warnings.push(Warning {
                at,
                message: format!(
                    "texture is {width}x{height}, over {MAX_TEXTURE_SIDE} texels per side (maxImageDimension2D): it is downscaled to {fit_width}x{fit_height} before upload"
                ),
            });
        }
    }
    warnings
}

impl fmt::Display for SceneReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{}", self.file.display())?;
        writeln!(
            f,
            "  models: {} files, {} instances; {} meshes, {} triangles, {} materials, {} textures",
            self.models.len(),
            self.instances,
            self.meshes,
            self.triangles,
            self.materials,
            self.textures
        )?;
        for m in &self.models {
            writeln!(
                f,
                "    {} x{}: {} meshes, {} triangles, {} materials, {} textures",
                m.file.display(),
                m.instances,
                m.meshes,
                m.triangles,
                m.materials,
                m.textures
            )?;
        }
        let l = &self.lights;
        writeln!(
            f,
            "  lights: {} sun, {} spot, {} point, {} area",
            l.sun, l.spot, l.point, l.area
        )?;
        if let Some(r) = &self.point_light_radius {
            writeln!(
                f,
                "  point-light radii: {} given, {} derived, {} from glTF range; energy cut off: max {:.1}%, mean {:.1}%",
                r.given,
                r.derived,
                r.range,
                r.max_energy_cut * 100.0,
                r.mean_energy_cut * 100.0
            )?;
        }
        writeln!(f, "  cameras: {}", self.cameras.join(", "))?;
        match &self.bounds {
            Some(b) => writeln!(
                f,
                "  bounds: ({}, {}, {}) .. ({}, {}, {})",
                b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z
            )?,
            None => writeln!(f, "  bounds: empty")?,
        }
        if self.origin != [0.0; 3] {
            let [x, y, z] = self.origin;
            writeln!(f, "  positions stored relative to ({x}, {y}, {z})")?;
        }
        writeln!(f, "  warnings: {}", self.warnings.len())?;
        for w in &self.warnings {
            writeln!(f, "    {w}")?;
        }
        Ok(())
    }
}
