//! Loading one model file (OBJ/MTL, glTF) by its extension, through the
//! processed-model cache, with tangents where its materials need them.

use crate::error::{Diagnostics, Location, SceneError};
use crate::guard::without_panics;
use crate::model::Model;
use crate::obj::load_obj;
use crate::tangents::generate_model_tangents;
use std::path::{Path, PathBuf};

/// Settings for loading scenes and models (`load_scene_with`).
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// Folder for the processed-model cache; `None` disables caching.
    pub cache_dir: Option<PathBuf>,
    /// An environment map that replaces the scene's (`--environment`, for a
    /// bare model file), at intensity 1 and no rotation.
    pub environment: Option<PathBuf>,
}

/// Whether the path names a model file rather than a scene file.
pub(crate) fn is_model_file(path: &Path) -> bool {
    matches!(extension(path).as_str(), "obj" | "gltf" | "glb")
}

/// The lower-case extension.
pub(crate) fn extension(path: &Path) -> String {
    path.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default()
}

/// Loads one model file by its extension, with tangents where materials need them.
pub fn load_model(
    path: &Path,
    asked_at: &Location,
    options: &LoadOptions,
    diag: &mut Diagnostics,
) -> Result<Model, SceneError> {
    crate::cache::load_cached(path, options.cache_dir.as_deref(), diag, |diag| {
        let mut model = match extension(path).as_str() {
            "obj" => without_panics(path, || load_obj(path, asked_at, diag))?,
            "gltf" | "glb" => {
                without_panics(path, || crate::gltf_import::load_gltf(path, asked_at, diag))?
            }
            other => {
                return Err(SceneError::Model {
                    at: asked_at.clone(),
                    message: format!(
                        "unsupported model format '.{other}' (use .obj, .gltf or .glb)"
                    ),
                })
            }
        };
        let without_uvs = generate_model_tangents(&mut model);
        if without_uvs > 0 {
            diag.warn(
                Location::file(path),
                format!("{without_uvs} meshes have a normal or bump map but no UVs; no tangents"),
            );
        }
        Ok(model)
    })
}
