//! Which files a scene may make weft read: a `.scene`'s `script` must lie in
//! the scene's folder tree (as Rhai `import`s must), and a glTF file's
//! buffer and image URIs in the glTF file's folder tree, so a downloaded
//! scene cannot read `../../../../etc/passwd` as vertex data. The binary's
//! `--allow-outside` switch lifts the rule for users who keep assets
//! elsewhere; it is set once, at start, for the whole process.

use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};

static ALLOWED: AtomicBool = AtomicBool::new(false);

/// Lets scenes and glTF files name files outside their folder tree (`--allow-outside`).
pub fn allow_outside(allowed: bool) {
    ALLOWED.store(allowed, Ordering::Relaxed);
}

/// Whether `--allow-outside` was given.
pub fn allowed() -> bool {
    ALLOWED.load(Ordering::Relaxed)
}

/// Why `file`, named by a scene or model in the folder `root`, may not be
/// read; `None` when it may (inside the tree, or `--allow-outside` given).
pub fn refusal(file: &Path, root: &Path, what: &str) -> Option<String> {
    let root = if root.as_os_str().is_empty() {
        Path::new(".")
    } else {
        root
    };
    (!allowed() && !weft_io::paths::is_within(file, root)).then(|| {
        format!(
            "{what} {} lies outside {} (the folder tree it is named from); weft reads it only with --allow-outside",
            file.display(),
            root.display()
        )
    })
}
