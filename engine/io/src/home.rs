//! Where weft finds the graphs (and, beside them, the shaders) it ships, so
//! `weft render ~/my.scene` works from any folder: a relative graph path is
//! looked up under `$WEFT_HOME`, then the install's share folder
//! (`PREFIX/share/weft` beside `PREFIX/bin/weft`, as `make install` lays it
//! out), then the current folder. A path that is absolute, or starts with
//! `./` or `../`, names one file and is used as it is.

use std::path::{Component, Path, PathBuf};

/// The variable naming a weft tree (a checkout, or an install's share
/// folder) searched first.
pub const HOME_VAR: &str = "WEFT_HOME";

/// The folders a relative graph path is looked up in, in order, each with
/// what it is: `$WEFT_HOME` (when set), the install's share folder, the
/// current folder.
pub fn search_roots() -> Vec<(PathBuf, &'static str)> {
    let mut roots = Vec::new();
    if let Some(home) = std::env::var_os(HOME_VAR).filter(|h| !h.is_empty()) {
        roots.push((PathBuf::from(home), "$WEFT_HOME"));
    }
    if let Some(share) = install_share() {
        roots.push((share, "the install's share folder"));
    }
    roots.push((PathBuf::new(), "the current folder"));
    roots
}

/// `PREFIX/share/weft` for the running `PREFIX/bin/weft`, when it exists.
fn install_share() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    let share = exe.parent()?.parent()?.join("share").join("weft");
    share.is_dir().then_some(share)
}

/// Whether `path` names one file wherever weft runs: absolute, or
/// starting with `./` or `../`.
fn explicit(path: &Path) -> bool {
    path.is_absolute()
        || matches!(
            path.components().next(),
            Some(Component::CurDir | Component::ParentDir)
        )
}

/// The file `path` names on the search path ([`search_roots`]): the first
/// root holding it, or `None` when none does (or the path is explicit and
/// missing).
pub fn locate(path: &Path) -> Option<PathBuf> {
    if explicit(path) {
        return path.exists().then(|| path.to_path_buf());
    }
    search_roots()
        .into_iter()
        .map(|(root, _)| root.join(path))
        .find(|candidate| candidate.exists())
}

/// Where [`locate`] looked for `path`, for a "not found" message.
pub fn looked_in(path: &Path) -> String {
    if explicit(path) {
        return format!("{} (a path used as given)", path.display());
    }
    let mut places: Vec<String> = search_roots()
        .into_iter()
        .map(|(root, what)| format!("{} ({what})", root.join(path).display()))
        .collect();
    if std::env::var_os(HOME_VAR).is_none() {
        places.insert(0, "$WEFT_HOME (unset)".to_string());
    }
    places.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn explicit_paths_are_used_as_given_and_others_searched() {
        assert!(explicit(Path::new("/abs/g.ron")));
        assert!(explicit(Path::new("./g.ron")));
        assert!(explicit(Path::new("../graphs/g.ron")));
        assert!(!explicit(Path::new("graphs/g.ron")));
        assert_eq!(locate(Path::new("./no-such-file.ron")), None);
        // The current folder is always searched, last.
        let roots = search_roots();
        assert_eq!(roots.last().map(|r| r.1), Some("the current folder"));
        assert!(looked_in(Path::new("graphs/x.ron")).contains("graphs/x.ron (the current folder)"));
    }
}
