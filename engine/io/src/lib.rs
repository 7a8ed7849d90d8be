//! How weft reads input and cache files. Every file weft reads — graphs,
//! includes, shaders, scenes, scripts, models, reference images and cache
//! entries — goes through [`read::read_capped`]: regular files only (a FIFO or
//! `/dev/zero` is refused, never waited on), and never more than a stated
//! limit, however the file grows. Texts read are kept in [`sources`] so error
//! printers show the offending line without reading the file again.
//! [`hash`] is the one stable hasher; [`entry`] frames cache entries so a
//! damaged, swapped or foreign entry is a miss, never a wrong answer.

pub mod entry;
pub mod hash;
pub mod read;
pub mod sources;

pub use read::{read_capped, read_text, FileKind, ReadError};
