//! A versioned binary cache of imported models, so the second load of a large model skips
//! parsing. A cache entry is used only when its format version matches and every file the
//! import looked at (model, material libraries, buffers, textures, missing ones included) has
//! the same size and modification time as when the entry was written; otherwise the model is
//! imported again and the entry rewritten. A damaged entry is a miss, never an error.
//!
//! An entry is framed by [`weft_io::entry`] (format version, the model's absolute
//! path as its key, a checksum), so a damaged entry, or one copied onto another
//! model's name, is a miss with a warning. Its payload is two postcard messages:
//! the header (source stamps and the import's warnings), read first so a stale
//! entry costs no model decoding, and the model.

use crate::error::{Diagnostics, Location, SceneError, Warning};
use crate::model::Model;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::UNIX_EPOCH;

/// Bumped whenever the encoding or the importers' output changes; older entries are ignored.
pub const CACHE_FORMAT_VERSION: u32 = 11;

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

/// The entry file for a model in cache folder `dir`.
pub fn cache_file_for(dir: &Path, model: &Path) -> PathBuf {
    let absolute = std::path::absolute(model).unwrap_or_else(|_| model.to_path_buf());
    let name = absolute
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.join(format!(
        "{name}-{}.weftcache",
        weft_io::hash::hex(weft_io::hash::hash(absolute.to_string_lossy().as_bytes()))
    ))
}

/// Returns the cached model for `path` when its entry is current; otherwise runs `import`,
/// writes a new entry, and returns its result. Warnings of the import are stored and replayed.
/// A damaged entry, or one stored for another model, is a miss with a warning.
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
    let key = entry_key(path);
    match weft_io::entry::read(&entry, KIND, key.as_bytes(), crate::source::MAX_MODEL_BYTES) {
        Ok(Some(payload)) => match decode(&payload) {
            Decoded::Current(mut model, warnings) => {
                model.path = path.to_path_buf();
                diag.warnings.extend(warnings);
                return Ok(model);
            }
            Decoded::Stale => {}
            Decoded::Damaged => damaged(diag, &entry, path, "its model does not decode"),
        },
        Ok(None) => {}
        Err(damage) => damaged(diag, &entry, path, &damage.to_string()),
    }
    let first = diag.warnings.len();
    let model = import(diag)?;
    let warnings = diag.warnings[first..].to_vec();
    if let Err(e) = write_entry(&entry, &key, &model, &warnings) {
        diag.warn(
            Location::file(&entry),
            format!("cannot write the model cache: {e}"),
        );
    }
    Ok(model)
}

/// The entry kind of imported models ([`weft_io::entry`]).
const KIND: weft_io::entry::Kind = weft_io::entry::Kind {
    name: "model",
    version: CACHE_FORMAT_VERSION,
};

/// The full key an entry is stored under: the model's absolute path, and
/// whether files outside its folder were allowed (such an import is never
/// served to a process that does not allow them).
fn entry_key(model: &Path) -> String {
    let path = std::path::absolute(model).unwrap_or_else(|_| model.to_path_buf());
    let outside = if crate::outside::allowed() {
        "\n--allow-outside"
    } else {
        ""
    };
    format!("{}{outside}", path.to_string_lossy())
}

fn damaged(diag: &mut Diagnostics, entry: &Path, model: &Path, why: &str) {
    diag.warn(
        Location::file(entry),
        format!(
            "the model cache entry for {} is damaged ({why}); imported again",
            model.display()
        ),
    );
}

/// What an entry's payload holds.
enum Decoded {
    Current(Model, Vec<Warning>),
    /// A source file changed since the entry was written: an ordinary miss.
    Stale,
    Damaged,
}

/// Decodes an entry's payload: the header, then (when every source is unchanged) the model.
fn decode(bytes: &[u8]) -> Decoded {
    let Ok((header, rest)) = postcard::take_from_bytes::<Header>(bytes) else {
        return Decoded::Damaged;
    };
    if header.stamps.iter().any(|s| Stamp::of(&s.path) != *s) {
        return Decoded::Stale;
    }
    let Ok((model, rest)) = postcard::take_from_bytes::<Model>(rest) else {
        return Decoded::Damaged;
    };
    let sound = model
        .meshes
        .iter()
        .all(|m| m.is_consistent() && m.material.is_none_or(|i| i < model.materials.len()));
    if rest.is_empty() && sound {
        Decoded::Current(model, header.warnings)
    } else {
        Decoded::Damaged
    }
}

/// Writes an entry atomically ([`weft_io::entry::write`]).
fn write_entry(
    entry: &Path,
    key: &str,
    model: &Model,
    warnings: &[Warning],
) -> std::io::Result<()> {
    let header = Header {
        // Absolute paths, so an entry stays valid when read from another working folder.
        stamps: model
            .sources
            .iter()
            .map(|s| Stamp::of(&std::path::absolute(s).unwrap_or_else(|_| s.clone())))
            .collect(),
        warnings: warnings.to_vec(),
    };
    let encode = |e: postcard::Error| std::io::Error::other(e.to_string());
    let mut payload = postcard::to_extend(&header, Vec::new()).map_err(encode)?;
    payload = postcard::to_extend(model, payload).map_err(encode)?;
    weft_io::entry::write(entry, KIND, key.as_bytes(), &payload)
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
            assert_eq!(
                diag.warnings.iter().filter(|w| w.message == "w").count(),
                1,
                "the import's warning, stored and replayed"
            );
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
        bytes[16..20].copy_from_slice(&(CACHE_FORMAT_VERSION + 1).to_le_bytes());
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

    #[test]
    fn swapped_or_device_entries_are_misses_with_a_warning() {
        let dir = std::env::temp_dir().join(format!("weft-cache-swap-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        let cache = dir.join("cache");
        let (bunny, dragon) = (dir.join("bunny.obj"), dir.join("dragon.obj"));
        std::fs::write(&bunny, "v 0 0 0\n").expect("write");
        std::fs::write(&dragon, "v 1 1 1\n").expect("write");
        let load = |src: &Path, name: &str| {
            let mut diag = Diagnostics::default();
            let m =
                load_cached(src, Some(&cache), &mut diag, |_| Ok(model(src, name))).expect("loads");
            let warnings: Vec<String> = diag.warnings.iter().map(|w| w.message.clone()).collect();
            (m.materials[0].name.clone(), warnings)
        };
        load(&bunny, "bunny");
        load(&dragon, "dragon");
        let (b, d) = (
            cache_file_for(&cache, &bunny),
            cache_file_for(&cache, &dragon),
        );
        let (b_bytes, d_bytes) = (std::fs::read(&b).expect("b"), std::fs::read(&d).expect("d"));
        std::fs::write(&b, &d_bytes).expect("swap");
        std::fs::write(&d, &b_bytes).expect("swap");
        let (name, warnings) = load(&bunny, "bunny again");
        assert_eq!(name, "bunny again", "never the dragon");
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(
            warnings[0]
                .contains("bunny.obj is damaged (it was stored for another input); imported again"),
            "{warnings:?}"
        );
        assert_eq!(
            load(&bunny, "unused").0,
            "bunny again",
            "the entry was rewritten"
        );
        std::fs::remove_file(&d).expect("rm");
        std::os::unix::fs::symlink("/dev/zero", &d).expect("link");
        let (name, warnings) = load(&dragon, "dragon again");
        assert_eq!(name, "dragon again");
        assert!(warnings[0].contains("(it is a device)"), "{warnings:?}");
        assert_eq!(
            load(&dragon, "unused").0,
            "dragon again",
            "the link was replaced"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
