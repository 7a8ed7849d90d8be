//! The reference cache: a path-traced reference is slow, so it is kept as an
//! EXR under the user cache (`$WEFT_CACHE_DIR`, else
//! `$XDG_CACHE_HOME/weft` or `~/.cache/weft`, beside the scene and BVH
//! caches) in `references/KEY.weftref`, an OpenEXR file framed by
//! [`weft_io::entry`] (the key and a checksum). The key hashes everything the image
//! depends on: the content of every file (scene, models, materials,
//! textures, graph, shaders), the camera, size, samples, seed, parameters
//! and features. An entry that is damaged, stored for another key or of the
//! wrong size is a miss with a warning and is rendered again.

use crate::image_io::{ImageError, LinearImage};
use std::path::{Path, PathBuf};

/// Everything a reference render depends on.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceKey {
    /// Every file read: their contents are hashed (with their paths).
    pub files: Vec<PathBuf>,
    /// The camera's name.
    pub camera: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u64,
    /// The random seed.
    pub seed: u32,
    /// Graph parameters and feature toggles, as given (`name=value`, `feature`).
    pub settings: Vec<String>,
}

/// Why a key could not be made or an entry stored.
#[derive(Debug, thiserror::Error)]
pub enum CacheError {
    /// A file the key hashes could not be read.
    #[error("reading {path} for the reference cache key: {source}")]
    Read {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The entry could not be encoded.
    #[error(transparent)]
    Encode(#[from] ImageError),
    /// The entry could not be written.
    #[error("storing {path}: {source}")]
    Write {
        /// The entry.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

impl ReferenceKey {
    /// The key as 32 hex digits ([`weft_io::hash`]); files are read through
    /// weft's one reader (regular files only).
    pub fn digest(&self) -> Result<String, CacheError> {
        let mut h = weft_io::hash::Hasher::new();
        h.field(b"weft reference 2");
        let mut files = self.files.clone();
        files.sort();
        files.dedup();
        for path in &files {
            let bytes =
                weft_io::read_capped(path, MAX_INPUT_BYTES).map_err(|e| CacheError::Read {
                    path: path.clone(),
                    source: e.into_io(),
                })?;
            h.field(path.to_string_lossy().as_bytes());
            h.field(&bytes);
        }
        h.field(self.camera.as_bytes());
        h.field(&self.width.to_le_bytes());
        h.field(&self.height.to_le_bytes());
        h.field(&self.spp.to_le_bytes());
        h.field(&self.seed.to_le_bytes());
        for s in &self.settings {
            h.field(s.as_bytes());
        }
        Ok(weft_io::hash::hex(h.finish()))
    }
}

/// The largest input file hashed into a key (models and textures included).
const MAX_INPUT_BYTES: u64 = 2 << 30;

/// The entry kind of references ([`weft_io::entry`]): the payload is the
/// reference as an OpenEXR file.
const KIND: weft_io::entry::Kind = weft_io::entry::Kind {
    name: "ref",
    version: 1,
};

/// The largest entry read (a 16384×16384 RGB float EXR is 3 GiB).
const MAX_ENTRY_BYTES: u64 = 4 << 30;

/// The folder of cached references.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceCache {
    dir: PathBuf,
}

impl ReferenceCache {
    /// The cache under `user_cache` (the user cache folder).
    pub fn new(user_cache: &Path) -> Self {
        Self {
            dir: user_cache.join("references"),
        }
    }

    /// Where the entry for `digest` lives.
    pub fn path(&self, digest: &str) -> PathBuf {
        self.dir.join(format!("{digest}.weftref"))
    }

    /// The cached image for `digest` when there is a sound entry of this
    /// size; `Err` says why an entry that is there was not used (damaged,
    /// stored for another key, not a regular file, another size).
    pub fn load(
        &self,
        digest: &str,
        width: u32,
        height: u32,
    ) -> Result<Option<LinearImage>, String> {
        let path = self.path(digest);
        let damaged = |why: String| {
            format!(
                "the cached reference {} is damaged ({why}); rendered again",
                path.display()
            )
        };
        let exr = match weft_io::entry::read(&path, KIND, digest.as_bytes(), MAX_ENTRY_BYTES) {
            Ok(Some(exr)) => exr,
            Ok(None) => return Ok(None),
            Err(damage) => return Err(damaged(damage.to_string())),
        };
        let image = LinearImage::decode_exr(&exr, &path).map_err(|e| damaged(e.to_string()))?;
        if (image.width, image.height) != (width, height) {
            return Err(damaged(format!(
                "it is {}x{}, not {width}x{height}",
                image.width, image.height
            )));
        }
        Ok(Some(image))
    }

    /// Stores `image` for `digest`, written aside and renamed into place so a
    /// reader never sees half an entry and concurrent writers never mix theirs.
    pub fn store(&self, digest: &str, image: &LinearImage) -> Result<PathBuf, CacheError> {
        let path = self.path(digest);
        let exr = image.encode_exr(&path)?;
        weft_io::entry::write(&path, KIND, digest.as_bytes(), &exr).map_err(|source| {
            CacheError::Write {
                path: path.clone(),
                source,
            }
        })?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("weft-compare-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        dir
    }

    #[test]
    fn the_key_changes_when_any_input_changes() {
        let dir = temp("key");
        let scene = dir.join("a.scene");
        std::fs::write(&scene, "model { file \"x.obj\" }\n").expect("write");
        let key = ReferenceKey {
            files: vec![scene.clone()],
            camera: "front".into(),
            width: 64,
            height: 32,
            spp: 256,
            seed: 0,
            settings: vec!["max_depth=8".into()],
        };
        let base = key.digest().expect("digest");
        assert_eq!(key.digest().expect("digest"), base, "stable");
        let changed = [
            ReferenceKey {
                camera: "side".into(),
                ..key.clone()
            },
            ReferenceKey {
                width: 65,
                ..key.clone()
            },
            ReferenceKey {
                height: 33,
                ..key.clone()
            },
            ReferenceKey {
                spp: 512,
                ..key.clone()
            },
            ReferenceKey {
                seed: 1,
                ..key.clone()
            },
            ReferenceKey {
                settings: vec!["max_depth=9".into()],
                ..key.clone()
            },
        ];
        for other in &changed {
            assert_ne!(other.digest().expect("digest"), base, "{other:?}");
        }
        std::fs::write(&scene, "model { file \"y.obj\" }\n").expect("write");
        assert_ne!(key.digest().expect("digest"), base, "file content");
        std::fs::remove_file(&scene).expect("remove");
        assert!(matches!(key.digest(), Err(CacheError::Read { .. })));
    }

    #[test]
    fn entries_round_trip_and_a_corrupt_one_is_a_miss() {
        let cache = ReferenceCache::new(&temp("store"));
        let image = LinearImage {
            width: 2,
            height: 1,
            pixels: vec![[0.5, 1.0, 2.0], [0.0, 0.25, 8.0]],
        };
        assert_eq!(cache.load("abc", 2, 1), Ok(None));
        cache.store("abc", &image).expect("store");
        assert_eq!(cache.load("abc", 2, 1), Ok(Some(image.clone())));
        let wrong = cache.load("abc", 3, 1).expect_err("wrong size");
        assert!(wrong.contains("it is 2x1, not 3x1"), "{wrong}");
        let good = std::fs::read(cache.path("abc")).expect("entry");
        std::fs::write(cache.path("abc"), b"not an exr").expect("corrupt");
        let junk = cache.load("abc", 2, 1).expect_err("junk");
        assert!(junk.contains("not a weft cache entry"), "{junk}");
        let mut flipped = good.clone();
        let last = flipped.len() - 1;
        flipped[last] ^= 0x10;
        std::fs::write(cache.path("abc"), &flipped).expect("flip");
        assert!(cache
            .load("abc", 2, 1)
            .expect_err("flip")
            .contains("checksum"));
        // Another key's entry under this name: refused, never served.
        cache.store("def", &image).expect("store");
        std::fs::copy(cache.path("def"), cache.path("abc")).expect("swap");
        assert!(cache
            .load("abc", 2, 1)
            .expect_err("swapped")
            .contains("stored for another input"));
        std::fs::remove_file(cache.path("abc")).expect("rm");
        std::os::unix::fs::symlink("/dev/zero", cache.path("abc")).expect("link");
        assert!(cache
            .load("abc", 2, 1)
            .expect_err("device")
            .contains("it is a device"));
        cache.store("abc", &image).expect("a link is replaced");
        assert_eq!(cache.load("abc", 2, 1), Ok(Some(image)));
    }
}
