//! Errors and warnings, each located at a file and (where known) a line.

use serde::ser::SerializeStruct;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};

/// Where a problem is: a file and, when the problem belongs to one line, that line (1-based).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Location {
    /// The file, as the user named it (resolved against the including file).
    pub file: PathBuf,
    /// The 1-based line, or `None` when the problem concerns the whole file.
    pub line: Option<usize>,
    /// The 1-based column, where the source gives one (scripts); shown in
    /// messages, not stored (the model cache's format stays as it is).
    #[serde(skip)]
    pub column: Option<usize>,
}

impl Location {
    /// A location on one line of a file.
    pub fn line(file: &Path, line: usize) -> Self {
        Self {
            file: file.to_path_buf(),
            line: Some(line),
            column: None,
        }
    }

    /// A location for a whole file.
    pub fn file(file: &Path) -> Self {
        Self {
            file: file.to_path_buf(),
            line: None,
            column: None,
        }
    }

    /// A location at one line and column of a file.
    pub fn column(file: &Path, line: usize, column: usize) -> Self {
        Self {
            file: file.to_path_buf(),
            line: Some(line),
            column: Some(column),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match (self.line, self.column) {
            (Some(line), Some(column)) => write!(f, "{}:{line}:{column}", self.file.display()),
            (Some(line), None) => write!(f, "{}:{line}", self.file.display()),
            (None, _) => write!(f, "{}", self.file.display()),
        }
    }
}

/// Something the loader accepted but that the author should look at (unknown names, quirks).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Warning {
    /// Where it was found.
    pub at: Location,
    /// What was found and what the loader did about it.
    pub message: String,
}

impl Warning {
    /// The warning as weft's one diagnostic type.
    pub fn diagnostic(&self) -> weft_diagnostic::Diagnostic {
        let line = self.at.line.and_then(|l| u32::try_from(l).ok());
        weft_diagnostic::Diagnostic {
            severity: weft_diagnostic::Severity::Warning,
            ..weft_diagnostic::Diagnostic::in_file(&self.at.file, line, &self.message)
        }
    }
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: warning: {}", self.at, self.message)
    }
}

/// Collects warnings while loading, so every stage reports them the same way.
#[derive(Debug, Default)]
pub struct Diagnostics {
    /// The warnings so far, in the order they were found.
    pub warnings: Vec<Warning>,
}

impl Diagnostics {
    /// Records a warning.
    pub fn warn(&mut self, at: Location, message: impl Into<String>) {
        self.warnings.push(Warning {
            at,
            message: message.into(),
        });
    }
}

/// Why a scene or model could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// A file could not be read.
    #[error("{at}: cannot read {}: {source}", path.display())]
    Io {
        /// Where the file was asked for (the file itself when it is the top-level one).
        at: Location,
        /// The file that could not be read.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A file named by the scene does not exist.
    #[error("{at}: missing file {}", path.display())]
    MissingFile {
        /// The line that names the file.
        at: Location,
        /// The resolved path that does not exist.
        path: PathBuf,
    },
    /// A path that names a device, FIFO, socket or directory instead of a file.
    #[error("{at}: {} is {kind}, not a regular file", path.display())]
    NotRegular {
        /// Where the file was asked for.
        at: Location,
        /// The path.
        path: PathBuf,
        /// What it is instead.
        kind: &'static str,
    },
    /// A file is larger than the loader accepts.
    #[error("{at}: file is {size} bytes, over the limit of {limit} bytes")]
    TooLarge {
        /// The file.
        at: Location,
        /// Its size.
        size: u64,
        /// The limit.
        limit: u64,
    },
    /// Text that does not follow the format.
    #[error("{at}: {message}")]
    Syntax {
        /// Where.
        at: Location,
        /// What is wrong.
        message: String,
    },
    /// A model file (OBJ, MTL, glTF) that could not be imported.
    #[error("{at}: {message}")]
    Model {
        /// The model file and, when known, the line.
        at: Location,
        /// What is wrong.
        message: String,
    },
}

impl SceneError {
    /// A syntax error at one line.
    pub(crate) fn syntax(file: &Path, line: usize, message: impl Into<String>) -> Self {
        Self::Syntax {
            at: Location::line(file, line),
            message: message.into(),
        }
    }

    /// The reason without the location prefix (for JSON output next to [`SceneError::location`]).
    pub fn message(&self) -> String {
        let full = self.to_string();
        let prefix = format!("{}: ", self.location());
        full.strip_prefix(&prefix)
            .map_or(full.clone(), str::to_string)
    }

    /// The error as weft's one diagnostic type, for printing it like graph and
    /// shader errors (with the source line) or as JSON.
    pub fn diagnostic(&self) -> weft_diagnostic::Diagnostic {
        let at = self.location();
        weft_diagnostic::Diagnostic::in_file(
            &at.file,
            at.line.and_then(|l| u32::try_from(l).ok()),
            self.message(),
        )
    }

    /// Where the error is.
    pub fn location(&self) -> &Location {
        match self {
            Self::Io { at, .. }
            | Self::MissingFile { at, .. }
            | Self::NotRegular { at, .. }
            | Self::TooLarge { at, .. }
            | Self::Syntax { at, .. }
            | Self::Model { at, .. } => at,
        }
    }
}

/// Serialises as `{"at": {"file", "line"}, "message"}`, for `weft scene check --json`.
impl Serialize for SceneError {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut s = serializer.serialize_struct("SceneError", 2)?;
        s.serialize_field("at", self.location())?;
        s.serialize_field("message", &self.message())?;
        s.end()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn message_and_json() {
        let e = SceneError::syntax(Path::new("a.scene"), 3, "malformed number '1x'");
        assert_eq!(e.to_string(), "a.scene:3: malformed number '1x'");
        assert_eq!(e.message(), "malformed number '1x'");
        let json = serde_json::to_string(&e).expect("json");
        assert_eq!(
            json,
            r#"{"at":{"file":"a.scene","line":3},"message":"malformed number '1x'"}"#
        );
    }
}
