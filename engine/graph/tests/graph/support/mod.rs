//! Helpers shared by the graph crate's integration tests (each test crate uses a
//! different subset, hence `dead_code` is allowed).

pub mod checker;
pub mod random_graph;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use weft_graph::{Diagnostic, LoadedGraph};

/// Loads graphs from an in-memory file system: `files` maps paths to contents.
pub fn load_files(root: &str, files: &[(&str, &str)]) -> LoadedGraph {
    let map: HashMap<PathBuf, String> = files
        .iter()
        .map(|(p, t)| (PathBuf::from(p), t.to_string()))
        .collect();
    let read = move |p: &Path| {
        map.get(p).cloned().ok_or_else(|| {
            std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "No such file or directory (os error 2)",
            )
        })
    };
    weft_graph::load_with(Path::new(root), &read)
}

/// The diagnostics `weft graph check` reports for a single in-memory graph file.
pub fn check_text(text: &str) -> Vec<Diagnostic> {
    weft_graph::check(&load_files("g.ron", &[("g.ron", text)]))
}

/// The repository root.
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Cases per fuzzing property: `default` under `make test`, `WEFT_FUZZ_CASES`
/// under `make fuzz` (see docs/fuzzing.md).
pub fn fuzz_cases(default: u32) -> u32 {
    std::env::var("WEFT_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}
