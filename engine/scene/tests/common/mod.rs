//! Helpers shared by the integration tests: asset paths and warning text.

#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// A file under `../shared/assets` (read in place, never copied).
pub fn asset(rel: &str) -> PathBuf {
    Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/assets"
    ))
    .join(rel)
}

/// A file under the repository's `scenes/`.
pub fn repo_scene(rel: &str) -> PathBuf {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes")).join(rel)
}

/// Warnings as `basename:line: message`, so expectations do not depend on the checkout path.
pub fn short_warnings(warnings: &[weft_scene::Warning]) -> Vec<String> {
    warnings
        .iter()
        .map(|w| {
            let name =
                w.at.file
                    .file_name()
                    .map(|n| n.to_string_lossy().into_owned())
                    .unwrap_or_default();
            match w.at.line {
                Some(l) => format!("{name}:{l}: {}", w.message),
                None => format!("{name}: {}", w.message),
            }
        })
        .collect()
}

/// A fresh empty folder under the system temp folder, unique to this test.
pub fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-scene-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("create temp dir");
    dir
}
