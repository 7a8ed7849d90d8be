//! Where a benchmark writes its figures when no `--out-dir` is given: a folder
//! of the user's weft cache (`$WEFT_CACHE_DIR/bench/NAME`, else
//! `$XDG_CACHE_HOME/weft/bench/NAME` or `~/.cache/weft/bench/NAME`), never the
//! current directory, so a run inside the repository does not overwrite the
//! committed figures in `docs/` unless `--out-dir docs` asks for it.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

/// The folder benchmark `name` writes into: `given`, else the user's cache.
pub fn out_dir(given: Option<&Path>, name: &str) -> Result<PathBuf> {
    let dir = match given {
        Some(dir) => dir.to_path_buf(),
        None => default_out_dir(weft_scene::cache::user_cache_dir(), name).context(
            "no --out-dir given and no user cache folder: set WEFT_CACHE_DIR or HOME, or give --out-dir",
        )?,
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    Ok(dir)
}

/// `cache/bench/name`, when there is a cache folder.
fn default_out_dir(cache: Option<PathBuf>, name: &str) -> Option<PathBuf> {
    cache.map(|c| c.join("bench").join(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn without_out_dir_figures_go_to_the_user_cache_not_the_current_directory() {
        assert_eq!(
            default_out_dir(Some(PathBuf::from("/home/u/.cache/weft")), "bloom"),
            Some(PathBuf::from("/home/u/.cache/weft/bench/bloom"))
        );
        assert_eq!(default_out_dir(None, "bloom"), None);
    }

    #[test]
    fn a_given_out_dir_is_used_and_created() {
        let dir = std::env::temp_dir().join(format!("weft-bench-out-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(out_dir(Some(&dir), "bloom").expect("created"), dir);
        assert!(dir.is_dir());
        std::fs::remove_dir_all(&dir).expect("removed");
    }
}
