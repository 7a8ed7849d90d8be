//! A versioned binary cache of imported models, so the second load of a large model skips
//! parsing. A cache entry is used only when its format version matches and every file the
//! import looked at (model, material libraries, buffers, textures, missing ones included) has
//! the same size and modification time as when the entry was written; otherwise the model is
//! imported again and the entry rewritten. A damaged entry is a miss, never an error.
//!
//! An entry is the magic bytes, the format version (u32, little endian), then two
//! postcard messages: the header (source stamps and the import's warnings), read
//! first so a stale entry costs no model decoding, and the model.

use crate::error::{Diagnostics, Location, SceneError, Warning};
use crate::model::Model;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

/// Bumped whenever the encoding or the importers' output changes; older entries are ignored.
pub const CACHE_FORMAT_VERSION: u32 = 9;

/// The first bytes of every entry.
const MAGIC: [u8; 8] = *b"WEFTMDL\0";

/// What a source file looked like when the entry was written.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
struct Stamp {
    path: PathBuf,
    present: bool,
    len: u64,
    modified_ns: u64,
}

/// Everything in an entry before the model.
#[derive(Serialize, Deserialize)]
struct Header {
    stamps: Vec<Stamp>,
    warnings: Vec<Warning>,
}

impl Stamp {
    /// The file's current stamp.
    fn of(path: &Path) -> Stamp {
        let meta = std::fs::metadata(path).ok();
        let modified_ns = meta
            .as_ref()
            .and_then(|m| m.modified().ok())
            .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
            .map_or(0, |d| d.as_nanos() as u64);
        Stamp {
            path: path.to_path_buf(),
            present: meta.is_some(),
            len: meta.map_or(0, |m| m.len()),
            modified_ns,
        }
    }
}

/// The user's cache folder for weft: `$WEFT_CACHE_DIR`, else
/// `$XDG_CACHE_HOME/weft`, else `$HOME/.cache/weft`; `None` when none is set.
pub fn user_cache_dir() -> Option<PathBuf> {
    let var = |name| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("WEFT_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("weft")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("weft")))
}

/// The 64-bit FNV-1a hash, to name entries after the model's absolute path.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The entry file for a model in cache folder `dir`.
pub fn cache_file_for(dir: &Path, model: &Path) -> PathBuf {
    let absolute = std::path::absolute(model).unwrap_or_else(|_| model.to_path_buf());
    let name = absolute
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.join(format!(
        "{name}-{:016x}.weftcache",
        fnv1a(absolute.to_string_lossy().as_bytes())
    ))
}

/// Returns the cached model for `path` when its entry is current; otherwise runs `import`,
/// writes a new entry, and returns its result. Warnings of the import are stored and replayed.
pub(crate) fn load_cached(
    path: &Path,
    cache_dir: Option<&Path>,
    diag: &mut Diagnostics,
    import: impl FnOnce(&mut Diagnostics) -> Result<Model, SceneError>,
) -> Result<Model, SceneError> {
    let Some(dir) = cache_dir else {
        return import(diag);
    };
    let entry = cache_file_for(dir, path);
    if let Some((mut model, warnings)) = std::fs::read(&entry).ok().and_then(|b| decode(&b)) {
        model.path = path.to_path_buf();
        diag.warnings.extend(warnings);
        return Ok(model);
    }
    let first = diag.warnings.len();
    let model = import(diag)?;
    let warnings = diag.warnings[first..].to_vec();
    if let Err(e) = write_entry(dir, &entry, &model, &warnings) {
        diag.warn(
            Location::file(&entry),
            format!("cannot write the model cache: {e}"),
        );
    }
    Ok(model)
}

/// Decodes an entry, `None` when it is damaged, of another version, or stale.
fn decode(bytes: &[u8]) -> Option<(Model, Vec<Warning>)> {
    let rest = bytes.strip_prefix(&MAGIC)?;
    let (version, rest) = rest.split_first_chunk::<4>()?;
    if u32::from_le_bytes(*version) != CACHE_FORMAT_VERSION {
        return None;
    }
    let (header, rest) = postcard::take_from_bytes::<Header>(rest).ok()?;
    if header.stamps.iter().any(|s| Stamp::of(&s.path) != *s) {
        return None;
    }
    let (model, rest) = postcard::take_from_bytes::<Model>(rest).ok()?;
    let sound = model
        .meshes
        .iter()
        .all(|m| m.is_consistent() && m.material.is_none_or(|i| i < model.materials.len()));
    (rest.is_empty() && sound).then_some((model, header.warnings))
}

/// Writes an entry atomically (a temporary file renamed into place).
fn write_entry(
    dir: &Path,
    entry: &Path,
    model: &Model,
    warnings: &[Warning],
) -> std::io::Result<()> {
    std::fs::create_dir_all(dir)?;
    let header = Header {
        // Absolute paths, so an entry stays valid when read from another working folder.
        stamps: model
            .sources
            .iter()
            .map(|s| Stamp::of(&std::path::absolute(s).unwrap_or_else(|_| s.clone())))
            .collect(),
        warnings: warnings.to_vec(),
    };
    let mut bytes = MAGIC.to_vec();
    bytes.extend_from_slice(&CACHE_FORMAT_VERSION.to_le_bytes());
    let encode = |e: postcard::Error| std::io::Error::other(e.to_string());
    bytes = postcard::to_extend(&header, bytes).map_err(encode)?;
    bytes = postcard::to_extend(model, bytes).map_err(encode)?;
    let temp = entry.with_extension(format!("tmp{}", std::process::id()));
    std::fs::write(&temp, &bytes)?;
    std::fs::rename(&temp, entry)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounds::Aabb;

    fn model(path: &Path, name: &str) -> Model {
        Model {
            path: path.to_path_buf(),
            meshes: Vec::new(),
            materials: vec![crate::material::Material {
                name: name.to_string(),
                ..Default::default()
            }],
            lights: Vec::new(),
            cameras: Vec::new(),
            bounds: Aabb::EMPTY,
            sources: vec![path.to_path_buf(), path.with_extension("missing")],
        }
    }

    #[test]
    fn hit_miss_on_change_version_and_damage() {
        let dir = std::env::temp_dir().join(format!("weft-cache-unit-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        let src = dir.join("m.obj");
        std::fs::write(&src, "v 0 0 0\n").expect("write");
        let cache = dir.join("cache");
        let mut calls = 0;
        let load = |name: &str, calls: &mut i32| {
            let mut diag = Diagnostics::default();
            let m = load_cached(&src, Some(&cache), &mut diag, |d| {
                *calls += 1;
                d.warn(Location::file(&src), "w");
                Ok(model(&src, name))
            })
            .expect("loads");
            assert_eq!(diag.warnings.len(), 1);
            m.materials[0].name.clone()
        };
        assert_eq!(load("first", &mut calls), "first");
        assert_eq!(load("second", &mut calls), "first");
        assert_eq!(calls, 1);
        // A changed source (different size) is a miss.
        std::fs::write(&src, "v 0 0 0\nv 1 0 0\n").expect("write");
        assert_eq!(load("third", &mut calls), "third");
        // A missing source that appears is a miss.
        std::fs::write(src.with_extension("missing"), "x").expect("write");
        assert_eq!(load("fourth", &mut calls), "fourth");
        assert_eq!(calls, 3);
        // Another format version is a miss.
        let entry = cache_file_for(&cache, &src);
        let mut bytes = std::fs::read(&entry).expect("entry");
        bytes[8..12].copy_from_slice(&(CACHE_FORMAT_VERSION + 1).to_le_bytes());
        std::fs::write(&entry, &bytes).expect("write");
        assert_eq!(load("fifth", &mut calls), "fifth");
        // Damage anywhere is a miss, never a panic.
        let good = std::fs::read(&entry).expect("entry");
        for cut in [0, 5, 12, good.len() / 2, good.len() - 1] {
            std::fs::write(&entry, &good[..cut]).expect("write");
            assert_eq!(load("again", &mut calls), "again");
        }
        assert_eq!(calls, 9);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
