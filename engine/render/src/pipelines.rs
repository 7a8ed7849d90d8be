//! Graphics pipelines for scene passes: the pass's shaders (compiled and
//! reflected by the gpu crate's cache), the shared vertex layout, set 0 from
//! reflection (graph resources), set 1 and 2 from the scene, push constants
//! from reflection, and the fixed-function state the plan implies.

use crate::geometry::{VertexFormat, VERTEX_ATTRIBUTES, VERTEX_BYTES};
use crate::scene_interface::scene_pass_problems;
use crate::state::{DepthTest, PassState};
use ash::vk;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use weft_gpu::descriptors::{create_set_layout, destroy_set_layout};
use weft_gpu::graphics::{
    create_graphics_pipeline, create_pipeline_layout, destroy_pipeline, DepthState, GraphicsState,
    VertexInput,
};
use weft_gpu::pipeline::{PipelineCache, ShaderKey, ShaderModule};
use weft_gpu::reflect::PipelineInterface;
use weft_gpu::{Gpu, GpuError};
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::schema::{CompareOp, CullMode};

/// Set number of a material's texture.
pub const MATERIAL_SET: u32 = 2;

/// Identifies a scene pipeline.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct ScenePipelineKey {
    /// The vertex shader variant.
    pub vertex: ShaderKey,
    /// The fragment shader variant; `None` for depth-only passes.
    pub fragment: Option<ShaderKey>,
    /// The render pass it must be compatible with.
    pub render_pass: vk::RenderPass,
    /// Depth, culling, blending and bias.
    pub state: PassState,
}

/// A built scene pipeline.
pub struct ScenePipeline {
    /// The graphics pipeline.
    pub pipeline: vk::Pipeline,
    /// Its layout: graph set, scene set, material set and push constants.
    pub layout: vk::PipelineLayout,
    /// Set 0: the graph resources the pass samples (may be empty).
    pub graph_layout: vk::DescriptorSetLayout,
    /// The merged shader interface, for binding graph resources and push constants.
    pub interface: PipelineInterface,
}

/// Scene pipelines by key, with the shader cache they are built from.
pub struct ScenePipelines {
    shaders: PipelineCache,
    pipelines: HashMap<ScenePipelineKey, Arc<ScenePipeline>>,
}

/// The front face of a draw: counter-clockwise model triangles, turned around
/// by a mirroring (negative-determinant) model matrix.
pub fn front_face(mirrored: bool) -> vk::FrontFace {
    if mirrored {
        vk::FrontFace::CLOCKWISE
    } else {
        vk::FrontFace::COUNTER_CLOCKWISE
    }
}

fn depth_state(test: DepthTest) -> DepthState {
    match test {
        DepthTest::Off => DepthState::OFF,
        DepthTest::On { compare, write } => DepthState {
            test: true,
            write,
            compare: compare_op(compare),
        },
    }
}

fn compare_op(compare: CompareOp) -> vk::CompareOp {
    match compare {
        CompareOp::Never => vk::CompareOp::NEVER,
        CompareOp::Less => vk::CompareOp::LESS,
        CompareOp::Equal => vk::CompareOp::EQUAL,
        CompareOp::LessOrEqual => vk::CompareOp::LESS_OR_EQUAL,
        CompareOp::Greater => vk::CompareOp::GREATER,
        CompareOp::NotEqual => vk::CompareOp::NOT_EQUAL,
        CompareOp::GreaterOrEqual => vk::CompareOp::GREATER_OR_EQUAL,
        CompareOp::Always => vk::CompareOp::ALWAYS,
    }
}

impl ScenePipelines {
    /// An empty cache.
    pub fn new() -> Result<Self, GpuError> {
        Ok(Self {
            shaders: PipelineCache::new()?,
            pipelines: HashMap::new(),
        })
    }

    /// The pipeline for `key`, built on first use against the scene's set
    /// layouts, once its shaders pass the scene interface check for `pass` and
    /// the device has the fixed-function features its state asks for.
    pub fn get(
        &mut self,
        gpu: &Gpu,
        key: &ScenePipelineKey,
        layouts: [vk::DescriptorSetLayout; 2],
        (plan, pass): (&Plan, &PlanPass),
    ) -> Result<Arc<ScenePipeline>, GpuError> {
        if let Some(p) = self.pipelines.get(key) {
            return Ok(Arc::clone(p));
        }
        if key.state.depth_clamp && !gpu.info().depth_clamp {
            return Err(GpuError::Pass {
                pass: pass.name.clone(),
                message: "`raster.depth_clamp` needs the device feature depthClamp, which this device lacks".into(),
            });
        }
        let [scene_layout, material_layout] = layouts;
        let vs = self.shaders.shader(&key.vertex)?;
        let fs = key
            .fragment
            .as_ref()
            .map(|k| self.shaders.shader(k))
            .transpose()?;
        let info = gpu.info();
        let compiled: Vec<_> = std::iter::once(&vs)
            .chain(&fs)
            .map(|m| &m.compiled)
            .collect();
        info.shaders.check(&info.name, &pass.name, &compiled)?;
        let problems =
            scene_pass_problems(plan, pass, &vs.interface, fs.as_ref().map(|f| &f.interface));
        if !problems.is_empty() {
            return Err(GpuError::Pass {
                pass: pass.name.clone(),
                message: problems.join("; "),
            });
        }
        let pipeline = build(
            gpu.device(),
            key,
            &vs,
            fs.as_deref(),
            scene_layout,
            material_layout,
        )?;
        let pipeline = Arc::new(pipeline);
        self.pipelines.insert(key.clone(), Arc::clone(&pipeline));
        Ok(pipeline)
    }

    /// Takes a shader variant compiled elsewhere (see `PipelineCache::adopt`).
    pub fn adopt(&mut self, key: ShaderKey, module: Arc<ShaderModule>) {
        self.shaders.adopt(key, module);
    }

    /// Forgets every shader and pipeline built from `file` (hot reload) so the next
    /// frame rebuilds them; the caller must make sure the device no longer uses them.
    /// Returns how many pipelines were dropped.
    pub fn invalidate(&mut self, device: &ash::Device, file: &Path) -> usize {
        let shaders = &mut self.shaders;
        let mut uses = |key: &ShaderKey| {
            shaders
                .shader(key)
                .map_or(true, |m| m.compiled.dependencies.contains(file))
        };
        let stale: Vec<ScenePipelineKey> = self
            .pipelines
            .keys()
            .filter(|k| uses(&k.vertex) || k.fragment.as_ref().is_some_and(&mut uses))
            .cloned()
            .collect();
        for key in &stale {
            if let Some(p) = self.pipelines.remove(key) {
                destroy(device, &p);
            }
        }
        self.shaders.invalidate(device, file);
        stale.len()
    }

    /// Destroys every pipeline.
    pub fn destroy(&mut self, device: &ash::Device) {
        for (_, p) in self.pipelines.drain() {
            destroy(device, &p);
        }
    }
}

fn destroy(device: &ash::Device, p: &ScenePipeline) {
    destroy_pipeline(device, p.pipeline, p.layout, &[p.graph_layout]);
}

fn reflect_error(key: &ScenePipelineKey, message: String) -> GpuError {
    GpuError::Shader(weft_gpu::ShaderError::Reflect {
        path: key.vertex.path.clone(),
        message,
    })
}

fn build(
    device: &ash::Device,
    key: &ScenePipelineKey,
    vs: &ShaderModule,
    fs: Option<&ShaderModule>,
    scene_layout: vk::DescriptorSetLayout,
    material_layout: vk::DescriptorSetLayout,
) -> Result<ScenePipeline, GpuError> {
    let mut stages = vec![&vs.interface];
    stages.extend(fs.map(|f| &f.interface));
    let interface = PipelineInterface::merge(&stages).map_err(|m| reflect_error(key, m))?;
    let graph_bindings: Vec<_> = interface
        .bindings
        .iter()
        .filter(|((s, _), _)| *s == 0)
        .map(|(_, (b, stages))| {
            vk::DescriptorSetLayoutBinding::default()
                .binding(b.binding)
                .descriptor_type(b.kind.vk())
                .descriptor_count(b.count)
                .stage_flags(*stages)
        })
        .collect();
    let graph_layout = create_set_layout(device, &graph_bindings)?;
    let set_layouts = [graph_layout, scene_layout, material_layout];
    let ranges: Vec<_> = interface
        .push
        .iter()
        .map(|(block, stages)| {
            vk::PushConstantRange::default()
                .stage_flags(*stages)
                .offset(0)
                .size(block.size)
        })
        .collect();
    let layout = match create_pipeline_layout(device, &set_layouts, &ranges) {
        Ok(l) => l,
        Err(e) => {
            destroy_set_layout(device, graph_layout);
            return Err(e);
        }
    };
    let mut pipeline = ScenePipeline {
        pipeline: vk::Pipeline::null(),
        layout,
        graph_layout,
        interface,
    };
    match create_pipeline(device, key, vs, fs, layout) {
        Ok(p) => {
            pipeline.pipeline = p;
            Ok(pipeline)
        }
        Err(e) => {
            destroy(device, &pipeline);
            Err(e)
        }
    }
}

fn create_pipeline(
    device: &ash::Device,
    key: &ScenePipelineKey,
    vs: &ShaderModule,
    fs: Option<&ShaderModule>,
    layout: vk::PipelineLayout,
) -> Result<vk::Pipeline, GpuError> {
    let all = VERTEX_ATTRIBUTES.map(|a| vk::VertexInputAttributeDescription {
        location: a.location,
        binding: 0,
        format: match a.format {
            VertexFormat::Float3 => vk::Format::R32G32B32_SFLOAT,
            VertexFormat::Uint => vk::Format::R32_UINT,
            VertexFormat::Unorm16x2 => vk::Format::R16G16_UNORM,
        },
        offset: a.offset,
    });
    // The attributes the vertex shader reads (a subset of the vertex, which
    // the shader check guarantees): unread ones would only draw warnings.
    let attributes: Vec<vk::VertexInputAttributeDescription> = all
        .into_iter()
        .filter(|a| vs.interface.inputs.iter().any(|i| i.location == a.location))
        .collect();
    let state = &key.state;
    // Every projection flips Y for Vulkan's downward framebuffer Y, which keeps
    // counter-clockwise model triangles counter-clockwise in Vulkan's convention;
    // the front face is set per draw, since a mirrored instance (negative
    // determinant) turns its triangles' winding around (see `front_face`).
    let graphics = GraphicsState {
        vertex_input: Some(VertexInput {
            stride: VERTEX_BYTES,
            attributes: &attributes,
        }),
        cull: match state.cull {
            CullMode::None => vk::CullModeFlags::NONE,
            CullMode::Front => vk::CullModeFlags::FRONT,
            CullMode::Back => vk::CullModeFlags::BACK,
        },
        depth_clamp: state.depth_clamp,
        depth_bias: state
            .depth_bias
            .map(|(c, s)| (f32::from_bits(c), f32::from_bits(s))),
        samples: state.samples,
        depth: depth_state(state.depth),
        blends: &state.blends,
        dynamic_front_face: true,
    };
    create_graphics_pipeline(
        device,
        &vs.compiled,
        fs.map(|f| &f.compiled),
        &graphics,
        layout,
        key.render_pass,
    )
}
