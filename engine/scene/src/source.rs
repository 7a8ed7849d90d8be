//! Reading input files with a size limit, turning I/O failures into located errors.

use crate::error::{Location, SceneError};
use std::path::Path;

/// The largest `.scene` file accepted: hand-written scenes are small, so a bigger one is a mistake.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// The largest model file accepted (OBJ, MTL, glTF, GLB, buffers).
pub const MAX_MODEL_BYTES: u64 = 2 << 30;

/// Reads a whole file, refusing ones over `limit` bytes; `asked_at` is where the file was named.
pub(crate) fn read_bytes(
    path: &Path,
    asked_at: &Location,
    limit: u64,
) -> Result<Vec<u8>, SceneError> {
    let meta = std::fs::metadata(path).map_err(|source| io_error(path, asked_at, source))?;
    if meta.len() > limit {
        return Err(SceneError::TooLarge {
            at: Location::file(path),
            size: meta.len(),
            limit,
        });
    }
    std::fs::read(path).map_err(|source| io_error(path, asked_at, source))
}

/// Reads a text file, reporting the line of the first byte that is not UTF-8.
pub(crate) fn read_text(
    path: &Path,
    asked_at: &Location,
    limit: u64,
) -> Result<String, SceneError> {
    let bytes = read_bytes(path, asked_at, limit)?;
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..valid]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        SceneError::syntax(path, line, "text is not valid UTF-8")
    })
}

/// Maps an I/O error to a missing-file error when the file does not exist.
fn io_error(path: &Path, asked_at: &Location, source: std::io::Error) -> SceneError {
    if source.kind() == std::io::ErrorKind::NotFound {
        SceneError::MissingFile {
            at: asked_at.clone(),
            path: path.to_path_buf(),
        }
    } else {
        SceneError::Io {
            at: asked_at.clone(),
            path: path.to_path_buf(),
            source,
        }
    }
}
