//! Loading scenes the way renders do: through the model cache (imported
//! meshes, tangents and materials kept by `weft-scene`) in the `models`
//! folder of the render's cache directory, so a warm start re-parses no
//! OBJ or glTF file that has not changed.

use std::path::Path;
use weft_scene::{LoadOptions, Scene, SceneError};

/// Loads `path`, caching imported models under `cache_dir/models` (the
/// settings' `cache_dir`; `None` caches nothing), lit by `environment` in
/// place of the scene's own map when given (`--environment`).
pub fn load_scene(
    path: &Path,
    cache_dir: Option<&Path>,
    environment: Option<&Path>,
) -> Result<Scene, SceneError> {
    weft_scene::load_scene_with(
        path,
        &LoadOptions {
            cache_dir: cache_dir.map(|d| d.join("models")),
            environment: environment.map(Path::to_path_buf),
        },
    )
}
