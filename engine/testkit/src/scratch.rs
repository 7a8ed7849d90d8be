//! Scratch folders for tests, removed when the test process exits: nextest
//! runs every test in a process of its own, and tests name their folders by
//! the process's id, so folders left behind would pile up in the system's
//! temporary folder (they once filled 11 GB of it).

use std::path::PathBuf;
use std::sync::{Mutex, Once};

/// The folders this process has handed out.
static FOLDERS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

extern "C" fn remove_folders() {
    if let Ok(folders) = FOLDERS.lock() {
        for folder in folders.iter() {
            let _ = std::fs::remove_dir_all(folder);
        }
    }
}

/// `name` under the system's temporary folder, emptied (not created) and
/// removed when this process exits.
pub fn scratch_path(name: &str) -> PathBuf {
    static AT_EXIT: Once = Once::new();
    // SAFETY: registers a plain function once; the C runtime calls it when
    // the process exits normally, after the test harness returns.
    AT_EXIT.call_once(|| unsafe {
        libc::atexit(remove_folders);
    });
    let folder = std::env::temp_dir().join(name);
    let _ = std::fs::remove_dir_all(&folder);
    FOLDERS
        .lock()
        .expect("scratch folders")
        .push(folder.clone());
    folder
}

/// [`scratch_path`], created.
pub fn scratch(name: &str) -> PathBuf {
    let folder = scratch_path(name);
    std::fs::create_dir_all(&folder).expect("scratch folder");
    folder
}
