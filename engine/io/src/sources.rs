//! The texts weft has read, by path, so error printers show the offending
//! line without reading a file again (a file can change, or be a device,
//! between the read and the error). The newest read of a path wins; a file
//! whose text must not be echoed (a system file) is never remembered.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

fn texts() -> &'static Mutex<HashMap<PathBuf, Arc<str>>> {
    static TEXTS: OnceLock<Mutex<HashMap<PathBuf, Arc<str>>>> = OnceLock::new();
    TEXTS.get_or_init(Default::default)
}

/// Keeps `text` as what `path` holds, unless `path` is a system file.
pub fn remember(path: &Path, text: &str) {
    if crate::paths::is_system(path) {
        return;
    }
    let mut texts = texts().lock().unwrap_or_else(|p| p.into_inner());
    texts.insert(path.to_path_buf(), Arc::from(text));
}

/// Forgets what `path` held, so its content is never shown.
pub fn forget(path: &Path) {
    let mut texts = texts().lock().unwrap_or_else(|p| p.into_inner());
    texts.remove(path);
}

/// The text last read from `path`, if weft read it.
pub fn text_of(path: &Path) -> Option<Arc<str>> {
    let texts = texts().lock().unwrap_or_else(|p| p.into_inner());
    texts.get(path).cloned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_newest_text_wins_and_system_files_are_never_kept() {
        let path = Path::new("/tmp/weft-io-sources-test.ron");
        remember(path, "one");
        remember(path, "two");
        assert_eq!(text_of(path).as_deref(), Some("two"));
        forget(path);
        assert_eq!(text_of(path), None);
        remember(Path::new("/proc/self/environ"), "SECRET=1");
        assert_eq!(text_of(Path::new("/proc/self/environ")), None);
    }
}
