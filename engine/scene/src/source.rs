//! Reading input files through weft's one reader ([`weft_io::read`]), turning
//! its errors into located scene errors.

use crate::error::{Location, SceneError};
use std::path::Path;
use weft_io::ReadError;

/// The largest `.scene` file accepted: hand-written scenes are small, so a bigger one is a mistake.
pub const MAX_SCENE_BYTES: u64 = weft_io::read::MAX_TEXT_BYTES;
/// The largest model file accepted (OBJ, MTL, glTF, GLB, buffers).
pub const MAX_MODEL_BYTES: u64 = 2 << 30;

/// Reads a whole regular file of at most `limit` bytes ([`weft_io::read_capped`]).
/// `asked_at` is where the file was named.
pub fn read_capped(path: &Path, asked_at: &Location, limit: u64) -> Result<Vec<u8>, SceneError> {
    weft_io::read_capped(path, limit).map_err(|e| located(e, asked_at))
}

/// Reads a text file ([`weft_io::read_text`]): the line of the first byte
/// that is not UTF-8 is reported, a byte-order mark dropped.
pub fn read_text(path: &Path, asked_at: &Location, limit: u64) -> Result<String, SceneError> {
    weft_io::read_text(path, limit).map_err(|e| located(e, asked_at))
}

/// The reader's error at the place the file was asked for.
fn located(error: ReadError, asked_at: &Location) -> SceneError {
    match error {
        ReadError::Missing { path } => SceneError::MissingFile {
            at: asked_at.clone(),
            path,
        },
        ReadError::NotRegular { path, kind } => SceneError::NotRegular {
            at: asked_at.clone(),
            path,
            kind: kind.describe(),
        },
        ReadError::TooLarge { path, size, limit } => SceneError::TooLarge {
            at: Location::file(&path),
            size,
            limit,
        },
        ReadError::NotUtf8 { path, line } => {
            SceneError::syntax(&path, line, "text is not valid UTF-8")
        }
        ReadError::Io { path, source } => SceneError::Io {
            at: asked_at.clone(),
            path,
            source,
        },
    }
}
