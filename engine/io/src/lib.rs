//! How weft reads input and cache files. Every file weft reads — graphs,
//! includes, shaders, scenes, scripts, models, reference images and cache
//! entries — goes through [`read::read_capped`]: regular files only (a FIFO or
//! `/dev/zero` is refused, never waited on), and never more than a stated
//! limit, however the file grows. Texts read are kept in [`sources`] so error
//! printers show the offending line without reading the file again.
//! [`hash`] is the one stable hasher; [`entry`] frames cache entries so a
//! damaged, swapped or foreign entry is a miss, never a wrong answer.
//! [`exr`] is the one OpenEXR writer (scanline float files every reader reads).
//! [`home`] is where the graphs and shaders weft ships are found from any
//! folder. [`write`] is the one rule for outputs: regular files only, written whole
//! and renamed into place.

pub mod entry;
pub mod exr;
pub mod hash;
pub mod home;
pub mod paths;
pub mod read;
pub mod sources;
pub mod write;

pub use read::{open_regular, read_capped, read_text, FileKind, ReadError, MAX_TEXT_BYTES};
pub use write::{check_output, write_output, WriteError};

/// A fresh folder for one unit test, under the system's temporary folder.
#[cfg(test)]
pub(crate) fn test_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-io-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}
