//! Where a path leads: inside a folder tree, or into the system folders
//! whose files describe the machine and must never be echoed.

use std::path::Path;

/// Whether `path` lies under the folder `root` once both are resolved (links,
/// `..`); a path that does not exist is judged by its existing parent.
pub fn is_within(path: &Path, root: &Path) -> bool {
    let resolve = |p: &Path| {
        p.canonicalize().ok().or_else(|| {
            let parent = p.parent()?.canonicalize().ok()?;
            Some(parent.join(p.file_name()?))
        })
    };
    match (resolve(path), root.canonicalize()) {
        (Some(path), Ok(root)) => path.starts_with(root),
        _ => false,
    }
}

/// Whether `path` is under a system folder whose files describe the running
/// machine or process (`/proc`, `/sys`, `/dev`, `/etc`), whose contents must
/// never be echoed in an error.
pub fn is_system(path: &Path) -> bool {
    let resolved = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    ["/proc", "/sys", "/dev", "/etc"]
        .iter()
        .any(|root| resolved.starts_with(root))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn within_and_system_paths() {
        let dir = crate::test_dir("within");
        std::fs::create_dir_all(dir.join("a/b")).expect("dirs");
        assert!(is_within(&dir.join("a/b/x.ron"), &dir));
        assert!(is_within(&dir.join("a/../a/b"), &dir));
        assert!(!is_within(&dir.join("../outside.ron"), &dir));
        assert!(!is_within(Path::new("/etc/passwd"), &dir));
        assert!(is_system(Path::new("/proc/self/environ")));
        assert!(is_system(Path::new("/etc/passwd")));
        assert!(!is_system(&dir));
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
