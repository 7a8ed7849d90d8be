//! The reference cache: a path-traced reference is slow, so it is kept as an
//! EXR under the user cache (`$WEFT_CACHE_DIR`, else
//! `$XDG_CACHE_HOME/weft` or `~/.cache/weft`, beside the scene and BVH
//! caches) in `references/KEY.exr`. The key hashes everything the image
//! depends on: the content of every file (scene, models, materials,
//! textures, graph, shaders), the camera, size, samples, seed, parameters
//! and features. An entry that cannot be read, or has the wrong size, is a
//! miss and is rendered again.

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
    /// The cache folder could not be made.
    #[error("creating the reference cache {path}: {source}")]
    Folder {
        /// The folder.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The entry could not be written.
    #[error(transparent)]
    Write(#[from] ImageError),
    /// The written entry could not be moved into place.
    #[error("storing {path}: {source}")]
    Rename {
        /// The entry.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
}

/// 64-bit FNV-1a, stable across builds and platforms (unlike std's hasher).
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    /// Writes a length first, so that adjacent fields cannot run together.
    fn field(&mut self, bytes: &[u8]) {
        self.write(&(bytes.len() as u64).to_le_bytes());
        self.write(bytes);
    }
}

impl ReferenceKey {
    /// The key as 16 hex digits.
    pub fn digest(&self) -> Result<String, CacheError> {
        let mut h = Fnv::new();
        h.field(b"weft reference 1");
        let mut files = self.files.clone();
        files.sort();
        files.dedup();
        for path in &files {
            let bytes = std::fs::read(path).map_err(|source| CacheError::Read {
                path: path.clone(),
                source,
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
        Ok(format!("{:016x}", h.0))
    }
}

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
        self.dir.join(format!("{digest}.exr"))
    }

    /// The cached image for `digest` when there is a readable one of this size.
    pub fn load(&self, digest: &str, width: u32, height: u32) -> Option<LinearImage> {
        LinearImage::read_exr(&self.path(digest))
            .ok()
            .filter(|image| (image.width, image.height) == (width, height))
    }

    /// Stores `image` for `digest`, written aside and renamed into place so a
    /// reader never sees half a file.
    pub fn store(&self, digest: &str, image: &LinearImage) -> Result<PathBuf, CacheError> {
        std::fs::create_dir_all(&self.dir).map_err(|source| CacheError::Folder {
            path: self.dir.clone(),
            source,
        })?;
        let path = self.path(digest);
        let partial = self
            .dir
            .join(format!("{digest}.{}.partial.exr", std::process::id()));
        image.write_exr(&partial)?;
        std::fs::rename(&partial, &path).map_err(|source| CacheError::Rename {
            path: path.clone(),
            source,
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
        assert_eq!(cache.load("abc", 2, 1), None);
        cache.store("abc", &image).expect("store");
        assert_eq!(cache.load("abc", 2, 1), Some(image));
        assert_eq!(cache.load("abc", 3, 1), None, "wrong size");
        std::fs::write(cache.path("abc"), b"not an exr").expect("corrupt");
        assert_eq!(cache.load("abc", 2, 1), None);
    }
}
