//! Reading input files with a size limit, turning I/O failures into located errors.

use crate::error::{Location, SceneError};
use std::io::Read;
use std::path::Path;

/// The largest `.scene` file accepted: hand-written scenes are small, so a bigger one is a mistake.
pub const MAX_SCENE_BYTES: u64 = 16 << 20;
/// The largest model file accepted (OBJ, MTL, glTF, GLB, buffers).
pub const MAX_MODEL_BYTES: u64 = 2 << 30;

/// Reads a whole regular file, refusing devices, FIFOs and directories, and
/// files over `limit` bytes; the limit caps the bytes actually read, since a
/// file can grow after its metadata was read. `asked_at` is where the file was named.
pub fn read_capped(path: &Path, asked_at: &Location, limit: u64) -> Result<Vec<u8>, SceneError> {
    let meta = std::fs::metadata(path).map_err(|source| io_error(path, asked_at, source))?;
    if !meta.is_file() {
        return Err(SceneError::NotRegular {
            at: asked_at.clone(),
            path: path.to_path_buf(),
            kind: file_kind(&meta),
        });
    }
    if meta.len() > limit {
        return Err(SceneError::TooLarge {
            at: Location::file(path),
            size: meta.len(),
            limit,
        });
    }
    let file = std::fs::File::open(path).map_err(|source| io_error(path, asked_at, source))?;
    let mut bytes = Vec::with_capacity(usize::try_from(meta.len()).unwrap_or(0));
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|source| io_error(path, asked_at, source))?;
    if bytes.len() as u64 > limit {
        return Err(SceneError::TooLarge {
            at: Location::file(path),
            size: bytes.len() as u64,
            limit,
        });
    }
    Ok(bytes)
}

/// What a path that is not a regular file is, for the error message.
fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let kind = meta.file_type();
    if kind.is_dir() {
        "a directory"
    } else if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else if kind.is_socket() {
        "a socket"
    } else {
        "not a regular file"
    }
}

/// Reads a text file, reporting the line of the first byte that is not UTF-8.
/// A leading UTF-8 byte-order mark (some Windows editors write one) is dropped.
pub fn read_text(path: &Path, asked_at: &Location, limit: u64) -> Result<String, SceneError> {
    let mut bytes = read_capped(path, asked_at, limit)?;
    if bytes.starts_with(UTF8_BOM) {
        bytes.drain(..UTF8_BOM.len());
    }
    String::from_utf8(bytes).map_err(|e| {
        let valid = e.utf8_error().valid_up_to();
        let line = 1 + e.as_bytes()[..valid]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        SceneError::syntax(path, line, "text is not valid UTF-8")
    })
}

/// The UTF-8 encoding of U+FEFF, the byte-order mark.
const UTF8_BOM: &[u8] = b"\xEF\xBB\xBF";

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
