//! The parts of the shader check that do not depend on a pass's kind: the
//! shaders a pass runs as keys ([`PassShaders`], a scene pass's variants),
//! their interface against the graph ([`pass_problems`]), and problems
//! located in the shaders. The check itself, which asks each pass's kind for
//! its shaders, is [`crate::executor::shader_check`].

use crate::bind::{self, FrameValues, ResolvedBinding};
use crate::error::GpuError;
use crate::pipeline::{PipelineCache, ShaderKey};
use crate::reflect::PipelineInterface;
use crate::shader::ShaderStage;
use std::path::Path;
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::schema::{Draw, PassKind};

/// The shader variants a pass runs through the executor's own pipelines.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PassShaders {
    /// Built-in or given vertex shader plus fragment shader, one triangle.
    Fullscreen {
        /// The given vertex shader, or the built-in fullscreen triangle.
        vertex: ShaderKey,
        /// The pass's fragment shader.
        fragment: ShaderKey,
    },
    /// One compute shader.
    Compute(ShaderKey),
}

impl PassShaders {
    /// The stages in pipeline order.
    pub fn keys(&self) -> Vec<&ShaderKey> {
        match self {
            Self::Fullscreen { vertex, fragment } => vec![vertex, fragment],
            Self::Compute(shader) => vec![shader],
        }
    }
}

/// Whether a raster/fullscreen pass draws one fullscreen triangle.
pub fn is_fullscreen(pass: &PlanPass) -> bool {
    pass.kind == PassKind::Fullscreen || pass.draw == Some(Draw::FullscreenTriangle)
}

/// Cross-checks a pass's merged shader interface with the graph: bindings,
/// fragment outputs (for fullscreen passes) and push-constant parameters.
/// Returns the resolved bindings, or every problem found.
pub fn pass_problems(
    plan: &Plan,
    pass: &PlanPass,
    shaders: &PassShaders,
    interface: &PipelineInterface,
) -> Result<Vec<ResolvedBinding>, Vec<String>> {
    let (bindings, mut problems) = match bind::resolve_bindings(plan, pass, interface) {
        Ok(bindings) => (bindings, Vec::new()),
        Err(list) => (Vec::new(), list),
    };
    if matches!(shaders, PassShaders::Fullscreen { .. }) {
        problems.extend(bind::link_problems(interface));
        problems.extend(bind::check_outputs(plan, pass, interface));
    }
    if let Some((block, _)) = &interface.push {
        if let Err(list) = bind::pack_push(block, &pass.params, &FrameValues::default()) {
            problems.extend(list);
        }
    }
    if problems.is_empty() {
        Ok(bindings)
    } else {
        Err(problems)
    }
}

/// Adds where a reflected problem's variable is declared — the first
/// `` `name` `` in the message, looked up in the stages' files (each shader,
/// then its includes; the fragment shader first for a message about a
/// fragment input or output) — so the message names the shader file:line as well as
/// the pass. Compile errors already carry theirs and are returned unchanged.
pub fn with_declaration(cache: &mut PipelineCache, keys: &[ShaderKey], message: String) -> String {
    let about_a_shader_variable = SHADER_VARIABLE_MESSAGES
        .iter()
        .any(|start| message.starts_with(start));
    let name = message.split('`').nth(1).filter(|n| !n.is_empty());
    let Some(name) = name.filter(|_| about_a_shader_variable) else {
        return message;
    };
    // A message about one stage's variable is looked up in that stage first.
    let mut ordered: Vec<&ShaderKey> = keys.iter().collect();
    if message.starts_with("fragment") {
        ordered.sort_by_key(|k| k.stage != ShaderStage::Fragment);
    }
    for key in ordered {
        let Ok(module) = cache.shader(key) else {
            continue;
        };
        let files = std::iter::once(&key.path).chain(
            module
                .compiled
                .dependencies
                .iter()
                .filter(|d| **d != key.path),
        );
        for file in files {
            if let Some(line) = declaration_line(file, name) {
                return format!("{message} (declared at {}:{line})", file.display());
            }
        }
    }
    message
}

/// How the messages about one shader variable (named first, in backticks)
/// begin; others name graph resources or no variable at all.
const SHADER_VARIABLE_MESSAGES: [&str; 4] = [
    "shader binding",
    "fragment input",
    "vertex input",
    "push-constant member",
];

/// The 1-based line of `file` that declares `name`: a `layout(...)` line, or
/// a block or variable declaration, naming it as a whole word.
fn declaration_line(file: &std::path::Path, name: &str) -> Option<usize> {
    let text = weft_io::sources::text_of(file)?;
    let is_word = |line: &str| {
        line.split(|c: char| !(c.is_alphanumeric() || c == '_'))
            .any(|w| w == name)
    };
    text.lines()
        .position(|line| {
            let code = line.split("//").next().unwrap_or_default();
            let declares = ["layout", "uniform", "buffer", " in ", " out "]
                .iter()
                .any(|k| code.contains(k));
            declares && is_word(code)
        })
        .map(|i| i + 1)
}

/// A problem with a pass's shaders.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShaderProblem {
    /// The pass, as named in the graph.
    pub pass: String,
    /// One line; compile errors keep their file:line.
    pub message: String,
}

/// One line per problem a pass's check found: the problems themselves, or a
/// compile failure's diagnostics (each with its file:line), or the error.
pub fn problem_messages(found: Result<Vec<String>, GpuError>) -> Vec<String> {
    match found {
        Ok(list) => list,
        Err(GpuError::Shader(crate::shader::ShaderError::Compile(diagnostics))) => {
            diagnostics.iter().map(ToString::to_string).collect()
        }
        Err(GpuError::Pass { message, .. }) => vec![message],
        Err(e) => vec![e.to_string()],
    }
}

/// The shader variant of a pass's stage with `defines`.
pub(crate) fn stage_key(path: &Path, stage: ShaderStage, defines: &[String]) -> ShaderKey {
    ShaderKey {
        path: path.to_path_buf(),
        stage,
        defines: defines.to_vec(),
    }
}

/// A scene pass's vertex shader (and fragment shader, if it has one) with
/// `defines`; `None` without a vertex shader.
pub fn scene_pass_keys_with(pass: &PlanPass, defines: &[String]) -> Option<Vec<ShaderKey>> {
    let vertex = pass.shaders.vertex.as_deref()?;
    let mut keys = vec![stage_key(vertex, ShaderStage::Vertex, defines)];
    keys.extend(
        pass.shaders
            .fragment
            .as_deref()
            .map(|f| stage_key(f, ShaderStage::Fragment, defines)),
    );
    Some(keys)
}

/// The variants a scene-drawing pass runs, each its vertex shader, then its
/// fragment shader when it has one: one variant, or one per shading model
/// the pass declares defines for when it groups its draws by model.
pub fn scene_pass_variants(pass: &PlanPass) -> Vec<Vec<ShaderKey>> {
    let mut defines = vec![pass.defines.clone()];
    if pass.groups_by_model() {
        let mut models: Vec<&str> = pass.model_defines.iter().map(|(m, _)| m.as_str()).collect();
        models.dedup();
        defines = models.into_iter().map(|m| pass.defines_for(m)).collect();
    }
    defines
        .iter()
        .filter_map(|d| scene_pass_keys_with(pass, d))
        .collect()
}
