//! Run-time GLSL compilation with shaderc: `#include` resolved relative to the
//! including file, every file a shader depends on recorded (for hot reload),
//! preprocessor defines for variants, and errors located at file:line.

use std::cell::RefCell;
use std::collections::BTreeSet;
use std::fmt;
use std::path::{Path, PathBuf};

/// Deepest `#include` nesting accepted before assuming a cycle.
const MAX_INCLUDE_DEPTH: usize = 32;

/// A pipeline stage a GLSL file is compiled for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ShaderStage {
    /// Vertex shader (`.vert`).
    Vertex,
    /// Fragment shader (`.frag`).
    Fragment,
    /// Compute shader (`.comp`).
    Compute,
}

impl ShaderStage {
    fn kind(self) -> shaderc::ShaderKind {
        match self {
            Self::Vertex => shaderc::ShaderKind::Vertex,
            Self::Fragment => shaderc::ShaderKind::Fragment,
            Self::Compute => shaderc::ShaderKind::Compute,
        }
    }

    /// The macro every shader of this stage is compiled with, so an include
    /// shared by stages can choose per stage (a fragment shader's helper
    /// invocations take part in subgroup operations; a compute shader has
    /// none).
    pub fn macro_name(self) -> &'static str {
        match self {
            Self::Vertex => "WEFT_VERTEX_SHADER",
            Self::Fragment => "WEFT_FRAGMENT_SHADER",
            Self::Compute => "WEFT_COMPUTE_SHADER",
        }
    }
}

/// One problem reported by the compiler, located in the file that has it
/// (which may be an included file).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShaderDiagnostic {
    /// The file the problem is in.
    pub file: PathBuf,
    /// 1-based line, when the compiler gave one.
    pub line: Option<u32>,
    /// The compiler's message, starting with `error:` or `warning:`.
    pub message: String,
}

impl ShaderDiagnostic {
    /// The compiler's message as weft's one diagnostic type: its `error:` or
    /// `warning:` prefix becomes the severity.
    pub fn diagnostic(&self) -> weft_diagnostic::Diagnostic {
        use weft_diagnostic::{Diagnostic, Severity};
        let text = self.message.trim();
        let (severity, message) = match text.strip_prefix("warning:") {
            Some(rest) => (Severity::Warning, rest),
            None => (Severity::Error, text.strip_prefix("error:").unwrap_or(text)),
        };
        Diagnostic {
            severity,
            ..Diagnostic::in_file(&self.file, self.line, message.trim())
        }
    }
}

impl fmt::Display for ShaderDiagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.file.display(), line, self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

/// Why a shader could not be compiled or reflected.
#[derive(Debug, thiserror::Error)]
pub enum ShaderError {
    /// The shaderc library could not be initialised.
    #[error("shader compiler unavailable: {0}")]
    Init(String),
    /// The source file could not be read.
    #[error("{}: cannot read: {message}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        message: String,
    },
    /// A define is not a valid preprocessor name (or value).
    #[error("invalid shader define `{0}`")]
    Define(String),
    /// GLSL errors, each at file:line.
    #[error("{}", join_lines(.0))]
    Compile(Vec<ShaderDiagnostic>),
    /// The SPIR-V could not be reflected, or uses something weft does not support.
    #[error("{}: {message}", path.display())]
    Reflect {
        /// The shader.
        path: PathBuf,
        /// What is unsupported or failed.
        message: String,
    },
}

fn join_lines(diagnostics: &[ShaderDiagnostic]) -> String {
    diagnostics
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join("\n")
}

/// SPIR-V for one stage and what it was built from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CompiledShader {
    /// The stage it was compiled for.
    pub stage: ShaderStage,
    /// The root file (or the name given for in-memory source).
    pub path: PathBuf,
    /// SPIR-V words.
    pub spirv: Vec<u32>,
    /// The root file and every file it includes, directly or not.
    pub dependencies: BTreeSet<PathBuf>,
}

/// A define `NAME` or `NAME=VALUE`, checked before it reaches shaderc.
fn parse_define(define: &str) -> Result<(&str, Option<&str>), ShaderError> {
    let (name, value) = match define.split_once('=') {
        Some((n, v)) => (n, Some(v)),
        None => (define, None),
    };
    let valid_name = name
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
    let valid_value = value.is_none_or(|v| !v.contains(['\0', '\n']));
    if valid_name && valid_value {
        Ok((name, value))
    } else {
        Err(ShaderError::Define(define.to_string()))
    }
}

/// Compiles GLSL to Vulkan 1.3 SPIR-V.
pub struct ShaderCompiler {
    compiler: shaderc::Compiler,
    include_dirs: Vec<PathBuf>,
}

impl ShaderCompiler {
    /// A compiler that resolves `#include "x"` relative to the including file,
    /// and `#include <x>` in `include_dirs`, then relative to the including file.
    pub fn new(include_dirs: Vec<PathBuf>) -> Result<Self, ShaderError> {
        let compiler = shaderc::Compiler::new().map_err(|e| ShaderError::Init(e.to_string()))?;
        Ok(Self {
            compiler,
            include_dirs,
        })
    }

    /// Compiles a GLSL file for `stage` with the given defines.
    pub fn compile_file(
        &self,
        path: &Path,
        stage: ShaderStage,
        defines: &[String],
    ) -> Result<CompiledShader, ShaderError> {
        let source = weft_io::read_text(path, weft_io::read::MAX_TEXT_BYTES).map_err(|e| {
            ShaderError::Read {
                path: path.to_path_buf(),
                message: e.reason(),
            }
        })?;
        self.compile_source(&source, path, stage, defines)
    }

    /// Compiles GLSL source; `path` names it in errors and anchors relative includes.
    pub fn compile_source(
        &self,
        source: &str,
        path: &Path,
        stage: ShaderStage,
        defines: &[String],
    ) -> Result<CompiledShader, ShaderError> {
        let dependencies = RefCell::new(BTreeSet::from([path.to_path_buf()]));
        let mut options =
            shaderc::CompileOptions::new().map_err(|e| ShaderError::Init(e.to_string()))?;
        options.set_target_env(
            shaderc::TargetEnv::Vulkan,
            shaderc::EnvVersion::Vulkan1_3 as u32,
        );
        options.set_generate_debug_info();
        options.add_macro_definition(stage.macro_name(), None);
        for define in defines {
            let (name, value) = parse_define(define)?;
            options.add_macro_definition(name, value);
        }
        options.set_include_callback(|requested, kind, requesting, depth| {
            self.resolve_include(requested, kind, requesting, depth, &dependencies)
        });
        let name = path.to_string_lossy();
        // With a SPIR-V cache, the preprocessed source (includes expanded)
        // names the entry; its errors are the compiler's, so they fall
        // through to the compile below.
        let key = crate::spirv_cache::dir().and_then(|_| {
            let expanded = self
                .compiler
                .preprocess(source, &name, "main", Some(&options))
                .ok()?;
            let mut key = crate::spirv_cache::Key::new();
            key.field(&[stage as u8]);
            for define in defines {
                key.field(define.as_bytes());
            }
            key.field(expanded.as_text().as_bytes());
            Some(key)
        });
        if let Some(spirv) = key.as_ref().and_then(|k| crate::spirv_cache::load(k, path)) {
            drop(options);
            return Ok(CompiledShader {
                stage,
                path: path.to_path_buf(),
                spirv,
                dependencies: dependencies.into_inner(),
            });
        }
        let result =
            self.compiler
                .compile_into_spirv(source, stage.kind(), &name, "main", Some(&options));
        drop(options);
        match result {
            Ok(artifact) => {
                let spirv = artifact.as_binary().to_vec();
                if let Some(key) = &key {
                    crate::spirv_cache::store(key, &spirv);
                }
                Ok(CompiledShader {
                    stage,
                    path: path.to_path_buf(),
                    spirv,
                    dependencies: dependencies.into_inner(),
                })
            }
            Err(shaderc::Error::CompilationError(_, text)) => {
                Err(ShaderError::Compile(parse_diagnostics(&text, path)))
            }
            Err(other) => Err(ShaderError::Compile(vec![ShaderDiagnostic {
                file: path.to_path_buf(),
                line: None,
                message: other.to_string(),
            }])),
        }
    }

    fn resolve_include(
        &self,
        requested: &str,
        kind: shaderc::IncludeType,
        requesting: &str,
        depth: usize,
        dependencies: &RefCell<BTreeSet<PathBuf>>,
    ) -> shaderc::IncludeCallbackResult {
        if depth > MAX_INCLUDE_DEPTH {
            return Err(format!(
                "#include nesting deeper than {MAX_INCLUDE_DEPTH} (does `{requested}` include itself?)"
            ));
        }
        let base = Path::new(requesting)
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_default();
        let mut candidates = Vec::new();
        if kind == shaderc::IncludeType::Standard {
            candidates.extend(self.include_dirs.iter().map(|d| d.join(requested)));
        }
        candidates.push(base.join(requested));
        let Some(found) = candidates.into_iter().find(|c| c.is_file()) else {
            return Err(format!("cannot find include file `{requested}`"));
        };
        let content = weft_io::read_text(&found, weft_io::read::MAX_TEXT_BYTES)
            .map_err(|e| format!("cannot read `{}`: {}", found.display(), e.reason()))?;
        dependencies.borrow_mut().insert(found.clone());
        Ok(shaderc::ResolvedInclude {
            resolved_name: found.to_string_lossy().into_owned(),
            content,
        })
    }
}

/// Splits shaderc's error text into located diagnostics. Lines look like
/// `path:12: error: 'x' : undeclared identifier`; lines without a location
/// are attributed to the root file.
fn parse_diagnostics(text: &str, root: &Path) -> Vec<ShaderDiagnostic> {
    let mut out = Vec::new();
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if line.ends_with("generated.") {
            continue;
        }
        out.push(
            locate(line)
                .or_else(|| locate_file_level(line))
                .unwrap_or_else(|| ShaderDiagnostic {
                    file: root.to_path_buf(),
                    line: None,
                    message: line.to_string(),
                }),
        );
    }
    if out.is_empty() {
        out.push(ShaderDiagnostic {
            file: root.to_path_buf(),
            line: None,
            message: "compilation failed".into(),
        });
    }
    out
}

/// Finds the first `:<digits>: ` in a line and splits it into file, line and message.
fn locate(line: &str) -> Option<ShaderDiagnostic> {
    for (i, _) in line.match_indices(':') {
        let rest = &line[i + 1..];
        let digits = rest.chars().take_while(char::is_ascii_digit).count();
        if digits == 0 {
            continue;
        }
        let after = &rest[digits..];
        if let Some(message) = after.strip_prefix(": ") {
            let number = rest[..digits].parse().ok()?;
            return Some(ShaderDiagnostic {
                file: PathBuf::from(&line[..i]),
                line: Some(number),
                message: message.to_string(),
            });
        }
    }
    None
}

/// A message about a whole file (`PATH: error: #version ...` for an empty
/// shader), placed at its first line.
fn locate_file_level(line: &str) -> Option<ShaderDiagnostic> {
    ["error:", "warning:"].iter().find_map(|kind| {
        let (file, rest) = line.split_once(&format!(": {kind}"))?;
        Some(ShaderDiagnostic {
            file: PathBuf::from(file),
            line: Some(1),
            message: format!("{kind}{rest}"),
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_level_messages_name_the_file_once_at_line_one() {
        let text = "s/t.frag: error: #version: Desktop shaders for Vulkan SPIR-V require version 140 or higher\n1 error generated.\n";
        let d = parse_diagnostics(text, Path::new("s/t.frag"));
        assert_eq!(
            d.iter().map(ToString::to_string).collect::<Vec<_>>(),
            ["s/t.frag:1: error: #version: Desktop shaders for Vulkan SPIR-V require version 140 or higher"]
        );
    }

    #[test]
    fn locates_compiler_messages() {
        let text = "/a/b.frag:12: error: 'x' : undeclared identifier\n/a/c.glsl:3: error: '' : syntax error\n2 errors generated.\n";
        let d = parse_diagnostics(text, Path::new("/a/b.frag"));
        assert_eq!(d.len(), 2);
        assert_eq!(d[0].file, PathBuf::from("/a/b.frag"));
        assert_eq!(d[0].line, Some(12));
        assert_eq!(d[0].message, "error: 'x' : undeclared identifier");
        assert_eq!(d[1].to_string(), "/a/c.glsl:3: error: '' : syntax error");
    }

    #[test]
    fn rejects_bad_defines() {
        assert_eq!(parse_define("HAS_X").ok(), Some(("HAS_X", None)));
        assert_eq!(parse_define("N=4").ok(), Some(("N", Some("4"))));
        assert!(matches!(parse_define("1X"), Err(ShaderError::Define(_))));
        assert!(matches!(parse_define("A B"), Err(ShaderError::Define(_))));
        assert!(matches!(parse_define(""), Err(ShaderError::Define(_))));
    }
}
