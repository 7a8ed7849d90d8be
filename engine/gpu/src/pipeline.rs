//! Shader and pipeline caches: GLSL compiled once per (file, stage, defines),
//! pipeline layouts derived from reflection, graphics pipelines for fullscreen
//! passes and compute pipelines, all dropped when a file they depend on changes.

use crate::error::{GpuError, VkCall};
use crate::reflect::{PipelineInterface, ShaderInterface};
use crate::shader::{CompiledShader, ShaderCompiler, ShaderStage};
use ash::vk;
use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use weft_graph::schema::Blend;

/// Source of the built-in fullscreen-triangle vertex shader.
const FULLSCREEN_VERT: &str = include_str!("fullscreen.vert");
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
    },
    /// A compute pipeline.
    Compute {
        /// Compute shader variant.
        shader: ShaderKey,
    },
}

/// A colour attachment's blend mode as a hashable key part.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BlendCode {
    /// No blending: the output replaces the attachment.
    Off,
    /// dst + src.
    Additive,
    /// Source-over with source alpha.
    Alpha,
}

impl From<Option<Blend>> for BlendCode {
    fn from(b: Option<Blend>) -> Self {
        match b {
            None => Self::Off,
            Some(Blend::Additive) => Self::Additive,
            Some(Blend::Alpha) => Self::Alpha,
        }
    }
}

/// A pipeline with its layout and the interface it was built from.
#[derive(Debug)]
pub struct Pipeline {
    /// The pipeline object.
    pub pipeline: vk::Pipeline,
    /// Its layout (descriptor sets and push constants).
    pub layout: vk::PipelineLayout,
    /// One descriptor set layout per set number the shaders use.
    pub set_layouts: Vec<vk::DescriptorSetLayout>,
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

    /// Builds (or returns) the pipeline for a key.
    pub fn pipeline(
        &mut self,
        device: &ash::Device,
        key: &PipelineKey,
    ) -> Result<Arc<Pipeline>, GpuError> {
        if let Some(p) = self.pipelines.get(key) {
            return Ok(Arc::clone(p));
        }
        let pipeline = match key {
            PipelineKey::Fullscreen {
                vertex,
                fragment,
                render_pass,
                blends,
                samples,
            } => {
                let vs = self.shader(vertex)?;
                let fs = self.shader(fragment)?;
                build_graphics(device, &vs, &fs, *render_pass, blends, *samples)?
            }
            PipelineKey::Compute { shader } => {
                let cs = self.shader(shader)?;
                build_compute(device, &cs)?
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

fn destroy_pipeline(device: &ash::Device, p: &Pipeline) {
    crate::graphics::destroy_pipeline(device, p.pipeline, p.layout, &p.set_layouts);
}

/// Descriptor set layouts and the pipeline layout for a merged interface.
fn build_layout(
    device: &ash::Device,
    interface: &PipelineInterface,
) -> Result<(Vec<vk::DescriptorSetLayout>, vk::PipelineLayout), GpuError> {
    let mut set_layouts = Vec::new();
    let result = (|| {
        for set in 0..interface.set_count() {
            let bindings = interface.set_layout_bindings(set);
            set_layouts.push(crate::descriptors::create_set_layout(device, &bindings)?);
        }
        let ranges = interface.push_constant_ranges();
        crate::graphics::create_pipeline_layout(device, &set_layouts, &ranges)
    })();
    match result {
        Ok(layout) => Ok((set_layouts, layout)),
        Err(e) => {
            for l in set_layouts {
                crate::descriptors::destroy_set_layout(device, l);
            }
            Err(e)
        }
    }
}

fn merged(modules: &[&ShaderModule]) -> Result<PipelineInterface, GpuError> {
    let ifaces: Vec<&ShaderInterface> = modules.iter().map(|m| &m.interface).collect();
    PipelineInterface::merge(&ifaces).map_err(|message| {
        GpuError::Shader(crate::shader::ShaderError::Reflect {
            path: modules
                .last()
                .map(|m| m.compiled.path.clone())
                .unwrap_or_default(),
            message,
        })
    })
}

fn dependencies(modules: &[&ShaderModule]) -> BTreeSet<PathBuf> {
    modules
        .iter()
        .flat_map(|m| m.compiled.dependencies.iter().cloned())
        .collect()
}

/// The colour-blend state of a blend mode, shared by the executor's pipelines and
/// the render crate's scene pipelines.
pub fn blend_state(blend: BlendCode) -> vk::PipelineColorBlendAttachmentState {
    let state = vk::PipelineColorBlendAttachmentState::default()
        .color_write_mask(vk::ColorComponentFlags::RGBA);
    match blend {
        BlendCode::Off => state,
        BlendCode::Additive => state
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::ONE)
            .dst_color_blend_factor(vk::BlendFactor::ONE)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE)
            .alpha_blend_op(vk::BlendOp::ADD),
        BlendCode::Alpha => state
            .blend_enable(true)
            .src_color_blend_factor(vk::BlendFactor::SRC_ALPHA)
            .dst_color_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .color_blend_op(vk::BlendOp::ADD)
            .src_alpha_blend_factor(vk::BlendFactor::ONE)
            .dst_alpha_blend_factor(vk::BlendFactor::ONE_MINUS_SRC_ALPHA)
            .alpha_blend_op(vk::BlendOp::ADD),
    }
}

fn build_graphics(
    device: &ash::Device,
    vs: &ShaderModule,
    fs: &ShaderModule,
    render_pass: vk::RenderPass,
    blends: &[BlendCode],
    samples: u32,
) -> Result<Pipeline, GpuError> {
    let interface = merged(&[vs, fs])?;
    let (set_layouts, layout) = build_layout(device, &interface)?;
    let mut pipeline = Pipeline {
        pipeline: vk::Pipeline::null(),
        layout,
        set_layouts,
        interface,
        bind_point: vk::PipelineBindPoint::GRAPHICS,
        dependencies: dependencies(&[vs, fs]),
        shaders: vec![vs.compiled.path.clone(), fs.compiled.path.clone()],
    };
    let state = crate::graphics::GraphicsState {
        vertex_input: None,
        cull: vk::CullModeFlags::NONE,
        depth_clamp: false,
        depth_bias: None,
        samples,
        depth: crate::graphics::DepthState::OFF,
        blends,
        dynamic_front_face: false,
    };
    match crate::graphics::create_graphics_pipeline(
        device,
        &vs.compiled,
        Some(&fs.compiled),
        &state,
        layout,
        render_pass,
    ) {
        Ok(p) => {
            pipeline.pipeline = p;
            Ok(pipeline)
        }
        Err(e) => {
            destroy_pipeline(device, &pipeline);
            Err(e)
        }
    }
}

fn build_compute(device: &ash::Device, cs: &ShaderModule) -> Result<Pipeline, GpuError> {
    let interface = merged(&[cs])?;
    let (set_layouts, layout) = build_layout(device, &interface)?;
    let mut pipeline = Pipeline {
        pipeline: vk::Pipeline::null(),
        layout,
        set_layouts,
        interface,
        bind_point: vk::PipelineBindPoint::COMPUTE,
        dependencies: dependencies(&[cs]),
        shaders: vec![cs.compiled.path.clone()],
    };
    let result = crate::graphics::shader_module(device, &cs.compiled).and_then(|m| {
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(m)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(layout);
        let r =
            unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) }
                .map_err(|(_, r)| r)
                .call("vkCreateComputePipelines");
        unsafe { device.destroy_shader_module(m, None) };
        r
    });
    match result.map(|v| v.into_iter().next()) {
        Ok(Some(p)) => {
            pipeline.pipeline = p;
            Ok(pipeline)
        }
        Ok(None) => {
            destroy_pipeline(device, &pipeline);
            Err(GpuError::Vulkan {
                call: "vkCreateComputePipelines",
                result: vk::Result::ERROR_UNKNOWN,
            })
        }
        Err(e) => {
            destroy_pipeline(device, &pipeline);
            Err(e)
        }
    }
}
