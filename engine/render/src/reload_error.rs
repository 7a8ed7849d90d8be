//! A refused reload, located at the file and line to fix, whichever step
//! refused it (scene, graph, shader or device). It is built from the refusing
//! step's own diagnostic, not from its message text.

use crate::error::RenderError;
use std::fmt;
use std::path::{Path, PathBuf};
use weft_gpu::GpuError;
use weft_graph::Diagnostic;
use weft_scene::SceneError;

/// Why a reload was refused, located at the file and line to fix.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct ReloadError {
    /// The file with the problem.
    pub file: PathBuf,
    /// Its 1-based line, when known.
    pub line: Option<u32>,
    /// What is wrong, on one line.
    pub message: String,
    /// How to fix it, when the refusing step knows.
    pub hint: Option<String>,
}

impl fmt::Display for ReloadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file.display(), self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl From<Diagnostic> for ReloadError {
    fn from(d: Diagnostic) -> Self {
        Self {
            line: d.line(),
            file: d.file,
            message: d.message,
            hint: d.hint,
        }
    }
}

impl ReloadError {
    /// A refusal with no diagnostic behind it (a device error, a race), put on `file`.
    pub(crate) fn new(file: &Path, line: Option<u32>, message: &str) -> Self {
        let first_line = message.lines().next().unwrap_or_default().trim();
        Diagnostic::in_file(file, line, first_line).into()
    }

    /// The refusal as weft's one diagnostic type, hint included.
    pub fn diagnostic(&self) -> Diagnostic {
        let mut d = Diagnostic::in_file(&self.file, self.line, &self.message);
        d.hint = self.hint.clone();
        d
    }

    pub(crate) fn scene(err: &SceneError) -> Self {
        err.diagnostic().into()
    }

    /// Locates a render error at its first error diagnostic; errors that name
    /// no file are put on `fallback`.
    pub(crate) fn render(err: RenderError, fallback: &Path) -> Self {
        let diagnostics = err.diagnostics();
        match diagnostics
            .iter()
            .find(|d| d.is_error())
            .or(diagnostics.first())
        {
            Some(d) => d.clone().into(),
            None => Self::new(fallback, None, &err.to_string()),
        }
    }

    pub(crate) fn gpu(err: GpuError, fallback: &Path) -> Self {
        Self::render(RenderError::Gpu(err), fallback)
    }
}
