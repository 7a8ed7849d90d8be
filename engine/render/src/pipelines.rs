//! Graphics pipelines for scene passes: the pass's shaders (compiled and
//! reflected by the gpu crate's cache), the shared vertex layout, set 0 from
//! reflection (graph resources), set 1 and 2 from the scene, push constants
//! from reflection, and the fixed-function state the plan implies.

use crate::geometry::{VERTEX_ATTRIBUTES, VERTEX_BYTES};
use crate::scene_interface::scene_pass_problems;
use crate::state::{DepthTest, PassState};
use ash::vk;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;
use weft_gpu::pipeline::{blend_state, PipelineCache, ShaderKey, ShaderModule};
use weft_gpu::reflect::PipelineInterface;
use weft_gpu::GpuError;
use weft_gpu::VkCall;
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
    /// Whether the vertex shader reads only the position (location 0): depth-only
    /// passes and light volumes; mesh shading reads normal and UV too.
    pub position_only: bool,
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

fn stage_create_info(
    stage: vk::ShaderStageFlags,
    module: vk::ShaderModule,
) -> vk::PipelineShaderStageCreateInfo<'static> {
    vk::PipelineShaderStageCreateInfo::default()
        .stage(stage)
        .module(module)
        .name(c"main")
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

fn depth_state(test: DepthTest) -> vk::PipelineDepthStencilStateCreateInfo<'static> {
    let (enable, write, op) = match test {
        DepthTest::Off => (false, false, vk::CompareOp::ALWAYS),
        DepthTest::On { compare, write } => (true, write, compare_op(compare)),
    };
    vk::PipelineDepthStencilStateCreateInfo::default()
        .depth_test_enable(enable)
        .depth_write_enable(write)
        .depth_compare_op(op)
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
    /// layouts, once its shaders pass the scene interface check for `pass`.
    pub fn get(
        &mut self,
        device: &ash::Device,
        key: &ScenePipelineKey,
        layouts: [vk::DescriptorSetLayout; 2],
        (plan, pass): (&Plan, &PlanPass),
    ) -> Result<Arc<ScenePipeline>, GpuError> {
        if let Some(p) = self.pipelines.get(key) {
            return Ok(Arc::clone(p));
        }
        let [scene_layout, material_layout] = layouts;
        let vs = self.shaders.shader(&key.vertex)?;
        let fs = key
            .fragment
            .as_ref()
            .map(|k| self.shaders.shader(k))
            .transpose()?;
        let problems =
            scene_pass_problems(plan, pass, &vs.interface, fs.as_ref().map(|f| &f.interface));
        if !problems.is_empty() {
            return Err(GpuError::Pass {
                pass: pass.name.clone(),
                message: problems.join("; "),
            });
        }
        let pipeline = build(
            device,
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
    unsafe {
        device.destroy_pipeline(p.pipeline, None);
        device.destroy_pipeline_layout(p.layout, None);
        device.destroy_descriptor_set_layout(p.graph_layout, None);
    }
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
    let graph_layout = unsafe {
        device.create_descriptor_set_layout(
            &vk::DescriptorSetLayoutCreateInfo::default().bindings(&graph_bindings),
            None,
        )
    }
    .call("vkCreateDescriptorSetLayout")?;
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
    let layout = match unsafe {
        device.create_pipeline_layout(
            &vk::PipelineLayoutCreateInfo::default()
                .set_layouts(&set_layouts)
                .push_constant_ranges(&ranges),
            None,
        )
    } {
        Ok(l) => l,
        Err(result) => {
            unsafe { device.destroy_descriptor_set_layout(graph_layout, None) };
            return Err(GpuError::Vulkan {
                call: "vkCreatePipelineLayout",
                result,
            });
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
    let mut modules = Vec::new();
    let result = (|| {
        let mut stages = Vec::new();
        for (module, stage) in [(Some(vs), vk::ShaderStageFlags::VERTEX)]
            .into_iter()
            .chain([(fs, vk::ShaderStageFlags::FRAGMENT)])
        {
            let Some(module) = module else { continue };
            let info = vk::ShaderModuleCreateInfo::default().code(&module.compiled.spirv);
            let m =
                unsafe { device.create_shader_module(&info, None) }.call("vkCreateShaderModule")?;
            modules.push(m);
            stages.push(stage_create_info(stage, m));
        }
        let bindings = [vk::VertexInputBindingDescription {
            binding: 0,
            stride: VERTEX_BYTES,
            input_rate: vk::VertexInputRate::VERTEX,
        }];
        let mut offset = 0;
        let all = VERTEX_ATTRIBUTES.map(|(location, floats, _)| {
            let attribute = vk::VertexInputAttributeDescription {
                location,
                binding: 0,
                format: match floats {
                    2 => vk::Format::R32G32_SFLOAT,
                    _ => vk::Format::R32G32B32_SFLOAT,
                },
                offset,
            };
            offset += floats * 4;
            attribute
        });
        let attributes = if key.position_only {
            &all[..1]
        } else {
            &all[..]
        };
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&bindings)
            .vertex_attribute_descriptions(attributes);
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let state = &key.state;
        let (bias, constant, slope) = match state.depth_bias {
            Some((c, s)) => (true, f32::from_bits(c), f32::from_bits(s)),
            None => (false, 0.0, 0.0),
        };
        // Every projection flips Y for Vulkan's downward framebuffer Y, which keeps
        // counter-clockwise model triangles counter-clockwise in Vulkan's convention;
        // the front face is dynamic (see `front_face`), this value is a placeholder.
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(match state.cull {
                CullMode::None => vk::CullModeFlags::NONE,
                CullMode::Front => vk::CullModeFlags::FRONT,
                CullMode::Back => vk::CullModeFlags::BACK,
            })
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .depth_bias_enable(bias)
            .depth_bias_constant_factor(constant)
            .depth_bias_slope_factor(slope)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(vk::SampleCountFlags::from_raw(state.samples.max(1)));
        let depth = depth_state(state.depth);
        let attachments: Vec<_> = state.blends.iter().map(|b| blend_state(*b)).collect();
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
        // The front face is set per draw: a mirrored instance (negative
        // determinant) turns its triangles' winding around.
        let dynamic_states = [
            vk::DynamicState::VIEWPORT,
            vk::DynamicState::SCISSOR,
            vk::DynamicState::FRONT_FACE,
        ];
        let dynamic = vk::PipelineDynamicStateCreateInfo::default().dynamic_states(&dynamic_states);
        let info = vk::GraphicsPipelineCreateInfo::default()
            .stages(&stages)
            .vertex_input_state(&vertex_input)
            .input_assembly_state(&assembly)
            .viewport_state(&viewport)
            .rasterization_state(&raster)
            .multisample_state(&multisample)
            .depth_stencil_state(&depth)
            .color_blend_state(&blend)
            .dynamic_state(&dynamic)
            .layout(layout)
            .render_pass(key.render_pass)
            .subpass(0);
        let created =
            unsafe { device.create_graphics_pipelines(vk::PipelineCache::null(), &[info], None) }
                .map_err(|(_, r)| r)
                .call("vkCreateGraphicsPipelines")?;
        created.into_iter().next().ok_or(GpuError::Vulkan {
            call: "vkCreateGraphicsPipelines",
            result: vk::Result::ERROR_UNKNOWN,
        })
    })();
    for m in modules {
        unsafe { device.destroy_shader_module(m, None) };
    }
    result
}
