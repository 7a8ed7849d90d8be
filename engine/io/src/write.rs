//! The one rule for files weft writes as output (images, tables, plots,
//! reports): regular files only — a FIFO, device, socket or folder in the
//! way is refused, never opened (opening a FIFO to write blocks until a
//! reader comes) — written whole to a temporary file beside the target and
//! renamed over it, so a reader sees the old file or the new one, never
//! part of one.

use crate::read::FileKind;
use std::path::{Path, PathBuf};

/// Why an output could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// Something that is not a regular file is where the output goes.
    #[error("{} is {}, not a regular file: weft writes outputs only to regular files", path.display(), kind.describe())]
    NotRegular {
        /// The output path.
        path: PathBuf,
        /// What is there.
        kind: FileKind,
    },
    /// Creating the folder, writing or renaming failed.
    #[error("writing {}: {source}", path.display())]
    Io {
        /// The output path.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
}

impl WriteError {
    /// What is wrong, without the path (for messages that name it already).
    pub fn reason(&self) -> String {
        match self {
            Self::NotRegular { kind, .. } => format!(
                "it is {}, not a regular file: weft writes outputs only to regular files",
                kind.describe()
            ),
            Self::Io { source, .. } => source.to_string(),
        }
    }
}

/// An error unless `path` is free for an output: absent, or a regular file
/// (a link is followed to what it names). Called before long work, so a
/// bad `--out` fails at once rather than after the render.
pub fn check_output(path: &Path) -> Result<(), WriteError> {
    match std::fs::metadata(path) {
        Ok(meta) if !meta.is_file() => Err(WriteError::NotRegular {
            path: path.to_path_buf(),
            kind: FileKind::of(&meta),
        }),
        _ => Ok(()),
    }
}

/// Writes `bytes` to `path` by the rule above ([`check_output`], then
/// [`crate::entry::write_atomic`]); creates the folder.
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<(), WriteError> {
    check_output(path)?;
    crate::entry::write_atomic(path, bytes).map_err(|source| WriteError::Io {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fifos_and_folders_are_refused_and_files_replaced_whole() {
        let dir = crate::test_dir("write-output");
        let fifo = dir.join("out.png");
        let made = std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .expect("mkfifo");
        assert!(made.success());
        let err = write_output(&fifo, b"x").expect_err("a FIFO is refused");
        assert_eq!(
            err.to_string(),
            format!(
                "{} is a FIFO, not a regular file: weft writes outputs only to regular files",
                fifo.display()
            )
        );
        let err = write_output(&dir, b"x").expect_err("a folder is refused");
        assert!(err
            .to_string()
            .contains("is a directory, not a regular file"));
        let file = dir.join("sub/table.csv");
        write_output(&file, b"old").expect("written, folder made");
        write_output(&file, b"new").expect("replaced");
        assert_eq!(std::fs::read(&file).expect("read"), b"new");
        let left: Vec<_> = std::fs::read_dir(dir.join("sub"))
            .expect("list")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert_eq!(left, vec![std::ffi::OsString::from("table.csv")]);
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
