//! A refused reload, located at the file and line to fix, whichever step
//! refused it (scene, graph, shader or device).

use crate::error::RenderError;
use std::fmt;
use std::path::{Path, PathBuf};
use weft_gpu::{GpuError, ShaderError};
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
}

impl fmt::Display for ReloadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file.display(), self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl ReloadError {
    pub(crate) fn new(file: &Path, line: Option<u32>, message: &str) -> Self {
        Self {
            file: file.to_path_buf(),
            line,
            message: message
                .lines()
                .next()
                .map(|l| l.strip_prefix("error: ").unwrap_or(l).trim())
                .unwrap_or_default()
                .to_string(),
        }
    }

    pub(crate) fn scene(err: &SceneError) -> Self {
        let at = err.location();
        let line = at.line.and_then(|l| u32::try_from(l).ok());
        Self::new(&at.file, line, &err.message())
    }

    /// Locates a render error; errors that name no file are put on `fallback`.
    pub(crate) fn render(err: RenderError, fallback: &Path) -> Self {
        match err {
            RenderError::Graph(diagnostics) => diagnostics
                .iter()
                .find(|d| d.is_error())
                .or(diagnostics.first())
                .map(|d| Self::new(&d.file, Some(d.pos.line), &d.message))
                .unwrap_or_else(|| Self::new(fallback, None, "the graph did not compile")),
            RenderError::Gpu(err) => Self::gpu(err, fallback),
            RenderError::AtPass { at, error } => {
                Self::new(&at.file, Some(at.pos.line), &error.to_string())
            }
            other => Self::new(fallback, None, &other.to_string()),
        }
    }

    pub(crate) fn gpu(err: GpuError, fallback: &Path) -> Self {
        match err {
            GpuError::Shader(ShaderError::Compile(diagnostics)) => diagnostics
                .iter()
                .find(|d| d.message.starts_with("error"))
                .or(diagnostics.first())
                .map(|d| Self::new(&d.file, d.line, &d.message))
                .unwrap_or_else(|| Self::new(fallback, None, "shader compilation failed")),
            other => Self::new(fallback, None, &other.to_string()),
        }
    }
}
