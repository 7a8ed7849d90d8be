//! The one shader and pipeline cache: GLSL compiled once per (file, stage,
//! defines), pipeline layouts derived from reflection (the scene sets from the
//! registered scene interface), graphics pipelines for fullscreen and scene
//! passes and compute pipelines, all dropped when a file they depend on changes.

mod build;

use build::{build_compute, build_graphics, build_scene, destroy_pipeline, merged};

use crate::error::GpuError;
use crate::reflect::{PipelineInterface, ShaderInterface};
use crate::scene::{RegisteredScene, SceneSet};
use crate::shader::{CompiledShader, ShaderCompiler, ShaderStage};
use crate::state::{BlendCode, PassState};
use ash::vk;
use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Source of the built-in fullscreen-triangle vertex shader.
const FULLSCREEN_VERT: &str = include_str!("../fullscreen.vert");
/// Name under which the built-in vertex shader is cached and reported.
const FULLSCREEN_NAME: &str = "<weft>/fullscreen.vert";

/// Identifies one compiled shader variant.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ShaderKey {
    /// The GLSL file (or the built-in shader's name).
    pub path: PathBuf,
    /// The stage it is compiled for.
    pub stage: ShaderStage,
    /// Preprocessor defines selecting the variant.
    pub defines: Vec<String>,
}

impl ShaderKey {
    /// The built-in fullscreen vertex shader.
    pub fn fullscreen_vertex() -> Self {
        Self {
            path: PathBuf::from(FULLSCREEN_NAME),
            stage: ShaderStage::Vertex,
            defines: Vec::new(),
        }
    }
}

/// A compiled shader with its reflected interface.
#[derive(Debug)]
pub struct ShaderModule {
    /// The SPIR-V and the files it was built from.
    pub compiled: CompiledShader,
    /// Its reflected bindings, push constants and outputs.
    pub interface: ShaderInterface,
}

/// Identifies a pipeline.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum PipelineKey {
    /// A fullscreen-triangle graphics pipeline.
    Fullscreen {
        /// Vertex shader variant.
        vertex: ShaderKey,
        /// Fragment shader variant.
        fragment: ShaderKey,
        /// The render pass it is built against.
        render_pass: vk::RenderPass,
        /// Blend mode per colour attachment, as `BlendCode`s.
        blends: Vec<BlendCode>,
        /// Rasterisation samples of the attachments.
        samples: u32,
        /// The layout of set 1 when the shaders read scene data.
        scene: Option<SceneSet>,
    },
    /// A compute pipeline.
    Compute {
        /// Compute shader variant.
        shader: ShaderKey,
        /// The layout of set 1 when the shader reads scene data.
        scene: Option<SceneSet>,
    },
    /// A pipeline that draws scene meshes or light volumes from the shared
    /// vertex buffer: set 0 from reflection (graph resources), sets 1 and 2
    /// the scene's (raster bindings, a material's textures).
    Scene {
        /// The vertex shader variant.
        vertex: ShaderKey,
        /// The fragment shader variant; `None` for depth-only passes.
        fragment: Option<ShaderKey>,
        /// The render pass it must be compatible with.
        render_pass: vk::RenderPass,
        /// Depth, culling, blending and bias.
        state: PassState,
    },
}

/// A pipeline with its layout and the interface it was built from.
#[derive(Debug)]
pub struct Pipeline {
    /// The pipeline object.
    pub pipeline: vk::Pipeline,
    /// Its layout (descriptor sets and push constants).
    pub layout: vk::PipelineLayout,
    /// One descriptor set layout per set number the shaders use; the scene
    /// sets' are the registered ones ([`SceneLayouts`]).
    pub set_layouts: Vec<vk::DescriptorSetLayout>,
    /// The layouts this pipeline created (set 0, and any set built from
    /// reflection), destroyed with it.
    owned_layouts: Vec<vk::DescriptorSetLayout>,
    /// Which layout of set 1 it was built with, when it reads scene data.
    pub scene_set: Option<SceneSet>,
    /// The merged interface the layout was built from.
    pub interface: PipelineInterface,
    /// Graphics or compute.
    pub bind_point: vk::PipelineBindPoint,
    /// Every file the pipeline's shaders were built from.
    pub dependencies: BTreeSet<PathBuf>,
    /// The shader files, for messages.
    pub shaders: Vec<PathBuf>,
}

/// Compiled shaders and pipelines, owned by the executor.
pub struct PipelineCache {
    compiler: ShaderCompiler,
    shaders: HashMap<ShaderKey, Arc<ShaderModule>>,
    pipelines: HashMap<PipelineKey, Arc<Pipeline>>,
}

impl PipelineCache {
    /// An empty cache with a shader compiler.
    pub fn new() -> Result<Self, GpuError> {
        Ok(Self {
            compiler: ShaderCompiler::new(Vec::new())?,
            shaders: HashMap::new(),
            pipelines: HashMap::new(),
        })
    }

    /// Number of pipelines built.
    pub fn pipeline_count(&self) -> usize {
        self.pipelines.len()
    }

    /// The shader variant, compiled and reflected on first use.
    pub fn shader(&mut self, key: &ShaderKey) -> Result<Arc<ShaderModule>, GpuError> {
        if let Some(m) = self.shaders.get(key) {
            return Ok(Arc::clone(m));
        }
        let compiled = if key.path == Path::new(FULLSCREEN_NAME) {
            self.compiler
                .compile_source(FULLSCREEN_VERT, &key.path, key.stage, &key.defines)?
        } else {
            self.compiler
                .compile_file(&key.path, key.stage, &key.defines)?
        };
        let interface = ShaderInterface::reflect(&compiled)?;
        let module = Arc::new(ShaderModule {
            compiled,
            interface,
        });
        self.shaders.insert(key.clone(), Arc::clone(&module));
        Ok(module)
    }

    /// Takes a shader variant compiled elsewhere (a hot reload's check, on
    /// another thread) so it is not compiled again here; a variant already
    /// cached is kept, since pipelines may have been built from it.
    pub fn adopt(&mut self, key: ShaderKey, module: Arc<ShaderModule>) {
        self.shaders.entry(key).or_insert(module);
    }

    /// The merged interface of shader stages, compiling and reflecting them
    /// if needed but creating no Vulkan objects.
    pub fn interface(&mut self, keys: &[&ShaderKey]) -> Result<PipelineInterface, GpuError> {
        let mut modules = Vec::with_capacity(keys.len());
        for key in keys {
            modules.push(self.shader(key)?);
        }
        let refs: Vec<&ShaderModule> = modules.iter().map(|m| &**m).collect();
        merged(&refs)
    }

    /// A cached pipeline, if built.
    pub fn get(&self, key: &PipelineKey) -> Option<Arc<Pipeline>> {
        self.pipelines.get(key).cloned()
    }

    /// Builds (or returns) the pipeline for a key; pipelines that read scene
    /// data are built against `scene`'s layouts.
    pub fn pipeline(
        &mut self,
        device: &ash::Device,
        key: &PipelineKey,
        scene: Option<&RegisteredScene<'_>>,
    ) -> Result<Arc<Pipeline>, GpuError> {
        if let Some(p) = self.pipelines.get(key) {
            return Ok(Arc::clone(p));
        }
        let registered = || {
            scene.ok_or_else(|| {
                GpuError::Plan(
                    "a pipeline reads scene data, but no scene interface is registered".into(),
                )
            })
        };
        let scene_layouts = |set: Option<SceneSet>| {
            set.map(|set| registered().map(|r| (&r.layouts, set)))
                .transpose()
        };
        let pipeline = match key {
            PipelineKey::Fullscreen {
                vertex,
                fragment,
                render_pass,
                blends,
                samples,
                scene: set,
            } => {
                let vs = self.shader(vertex)?;
                let fs = self.shader(fragment)?;
                let target = (*render_pass, blends.as_slice(), *samples);
                build_graphics(device, &vs, &fs, target, scene_layouts(*set)?)?
            }
            PipelineKey::Compute { shader, scene: set } => {
                let cs = self.shader(shader)?;
                build_compute(device, &cs, scene_layouts(*set)?)?
            }
            PipelineKey::Scene {
                vertex,
                fragment,
                render_pass,
                state,
            } => {
                let registered = registered()?;
                let vs = self.shader(vertex)?;
                let fs = fragment.as_ref().map(|f| self.shader(f)).transpose()?;
                build_scene(
                    device,
                    (&vs, fs.as_deref()),
                    (*render_pass, state),
                    registered,
                )?
            }
        };
        let pipeline = Arc::new(pipeline);
        self.pipelines.insert(key.clone(), Arc::clone(&pipeline));
        Ok(pipeline)
    }

    /// Forgets every shader and pipeline built from `file` (hot reload); the
    /// caller must make sure the device no longer uses them.
    pub fn invalidate(&mut self, device: &ash::Device, file: &Path) -> usize {
        self.shaders
            .retain(|_, m| !m.compiled.dependencies.contains(file));
        let stale: Vec<PipelineKey> = self
            .pipelines
            .iter()
            .filter(|(_, p)| p.dependencies.contains(file))
            .map(|(k, _)| k.clone())
            .collect();
        for key in &stale {
            if let Some(p) = self.pipelines.remove(key) {
                destroy_pipeline(device, &p);
            }
        }
        stale.len()
    }

    /// Destroys every pipeline.
    pub fn destroy(&mut self, device: &ash::Device) {
        for (_, p) in self.pipelines.drain() {
            destroy_pipeline(device, &p);
        }
        self.shaders.clear();
    }
}
