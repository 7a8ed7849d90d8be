//! A last line of defence around third-party parsers (gltf-json has index panics on some
//! malformed files): a panic inside becomes a located error instead of taking the caller down.

use crate::error::{Location, SceneError};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

/// Runs `import` for `path`; a panic inside it becomes a [`SceneError::Model`] naming the file.
pub(crate) fn without_panics<T>(
    path: &Path,
    import: impl FnOnce() -> Result<T, SceneError>,
) -> Result<T, SceneError> {
    catch_unwind(AssertUnwindSafe(import)).unwrap_or_else(|payload| {
        let reason = payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown reason".to_string());
        Err(SceneError::Model {
            at: Location::file(path),
            message: format!("the importer failed on malformed input ({reason})"),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panics_become_errors() {
        let ok: Result<u8, SceneError> = without_panics(Path::new("m.glb"), || Ok(3));
        assert_eq!(ok.ok(), Some(3));
        let err = without_panics::<u8>(Path::new("m.glb"), || panic!("index 2 of 0"))
            .expect_err("caught");
        assert_eq!(
            err.to_string(),
            "m.glb: the importer failed on malformed input (index 2 of 0)"
        );
    }
}
