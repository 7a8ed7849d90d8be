//! Errors of the render crate: what can fail turning a scene and a graph into frames.

use std::path::PathBuf;
use weft_gpu::{GpuError, ShaderDiagnostic, ShaderError};
use weft_graph::Diagnostic;

/// Anything that can go wrong uploading a scene or rendering it through a graph.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A Vulkan call, shader or plan problem from the executor.
    #[error(transparent)]
    Gpu(#[from] GpuError),
    /// The graph failed to load or compile; every diagnostic, one per line.
    #[error("{}", .0.iter().map(ToString::to_string).collect::<Vec<_>>().join("\n"))]
    Graph(Vec<weft_graph::Diagnostic>),
    /// A sample count was asked of a graph that does not accumulate.
    #[error("{}: --spp needs a progressive graph (one that declares `progressive: (samples_per_frame: ...)`, such as graphs/pathtrace.ron)", graph.display())]
    NotProgressive {
        /// The graph file.
        graph: PathBuf,
    },
    /// No scene camera has the requested name.
    #[error("no camera named \"{name}\"; the scene has: {available}")]
    Camera {
        /// The name asked for.
        name: String,
        /// The scene's camera names, comma-separated.
        available: String,
    },
    /// A texture could not be read or decoded (the material falls back to white).
    #[error("{}: {message}", path.display())]
    Texture {
        /// The file, or the embedded image's id.
        path: PathBuf,
        /// What the decoder said.
        message: String,
    },
    /// A pass failed while a frame was prepared or recorded; located at the
    /// pass's declaration in its graph file.
    #[error("{}:{}: {error}", at.file.display(), at.pos)]
    AtPass {
        /// Where the pass is declared.
        at: weft_graph::plan::Location,
        /// What went wrong (not a `source`: the message already includes it).
        error: GpuError,
    },
    /// The scene has more of something than the GPU layouts can index.
    #[error("scene too large: {0}")]
    TooLarge(String),
    /// The scene's script failed (at load or in `update`), located in the script.
    #[error(transparent)]
    Script(#[from] weft_scene::SceneError),
    /// The plan has an image larger than the device can create.
    #[error("image `{image}` would be {}x{}; {device} allows at most {max} texels per side (maxImageDimension2D): render smaller or lower the graph parameter that sizes it", size[0], size[1])]
    ImageTooLarge {
        /// The graph's resource name.
        image: String,
        /// Its width and height for this render.
        size: [u32; 2],
        /// The device's limit.
        max: u32,
        /// The device's name.
        device: String,
    },
}

impl RenderError {
    /// The located problems behind this error, as weft's one diagnostic type:
    /// the graph's diagnostics, a shader compiler's, or the pass a frame failed
    /// in. Empty when the error names no file.
    pub fn diagnostics(&self) -> Vec<Diagnostic> {
        match self {
            Self::Graph(diagnostics) => diagnostics.clone(),
            Self::Gpu(GpuError::Shader(ShaderError::Compile(list))) => {
                list.iter().map(ShaderDiagnostic::diagnostic).collect()
            }
            Self::AtPass { at, error } => {
                vec![Diagnostic::error(&at.file, at.pos, error.to_string())]
            }
            Self::Texture { path, message } => vec![Diagnostic::in_file(path, None, message)],
            Self::Script(error) => vec![error.diagnostic()],
            Self::NotProgressive { graph } => vec![Diagnostic::in_file(
                graph,
                None,
                "--spp needs a progressive graph",
            )
            .with_hint(
                "declare `progressive: (samples_per_frame: ...)`, as graphs/pathtrace.ron does",
            )],
            Self::Gpu(_) | Self::Camera { .. } | Self::TooLarge(_) | Self::ImageTooLarge { .. } => {
                Vec::new()
            }
        }
    }

    /// `error` located at the declaration of the pass it names, when it names
    /// one of `plan`'s passes.
    pub fn at_pass(error: GpuError, plan: &weft_graph::Plan) -> Self {
        let name = match &error {
            GpuError::Pass { pass, .. } | GpuError::Mismatch { pass, .. } => pass,
            _ => return Self::Gpu(error),
        };
        match plan.passes.iter().find(|p| p.name == *name) {
            Some(pass) => Self::AtPass {
                at: pass.declared_at.clone(),
                error,
            },
            None => Self::Gpu(error),
        }
    }
}
