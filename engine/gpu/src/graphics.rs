//! The one graphics-pipeline builder: the executor's fullscreen pipelines and
//! weft-render's scene pipelines are both a vertex shader, an optional
//! fragment shader and a [`GraphicsState`], built here against a render pass
//! with dynamic viewport and scissor.

use crate::error::{GpuError, VkCall};
use crate::shader::CompiledShader;
use crate::state::{blend_state, BlendCode, DepthState};
use ash::vk;

/// Vertex buffer 0's layout; pipelines without one draw from no buffers.
#[derive(Debug, Clone, Copy)]
pub struct VertexInput<'a> {
    /// Bytes per vertex.
    pub stride: u32,
    /// Location, format and offset of each attribute.
    pub attributes: &'a [vk::VertexInputAttributeDescription],
}

/// Fixed-function state of a graphics pipeline.
#[derive(Debug, Clone, Copy)]
pub struct GraphicsState<'a> {
    /// The vertex buffer's layout, if the pipeline reads one.
    pub vertex_input: Option<VertexInput<'a>>,
    /// Culled faces.
    pub cull: vk::CullModeFlags,
    /// Whether fragment depth is clamped to the depth range instead of
    /// triangles clipped at near and far (needs the `depthClamp` feature).
    pub depth_clamp: bool,
    /// Constant and slope-scaled depth bias.
    pub depth_bias: Option<(f32, f32)>,
    /// Samples per pixel of the attachments.
    pub samples: u32,
    /// Depth test and writes.
    pub depth: DepthState,
    /// One per colour attachment.
    pub blends: &'a [BlendCode],
    /// Whether the front face is set per draw (mirrored instances).
    pub dynamic_front_face: bool,
}

/// Builds a graphics pipeline of `vs` and `fs` with `state`, for subpass 0 of
/// `render_pass`. The shader modules live only while the pipeline is built.
pub fn create_graphics_pipeline(
    device: &ash::Device,
    vs: &CompiledShader,
    fs: Option<&CompiledShader>,
    state: &GraphicsState<'_>,
    layout: vk::PipelineLayout,
    render_pass: vk::RenderPass,
) -> Result<vk::Pipeline, GpuError> {
    let mut modules = Vec::new();
    let result = (|| {
        let mut stages = Vec::new();
        for (shader, stage) in [(Some(vs), vk::ShaderStageFlags::VERTEX)]
            .into_iter()
            .chain([(fs, vk::ShaderStageFlags::FRAGMENT)])
        {
            let Some(shader) = shader else { continue };
            let module = shader_module(device, shader)?;
            modules.push(module);
            stages.push(
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(stage)
                    .module(module)
                    .name(c"main"),
            );
        }
        let bindings: Vec<_> = state
            .vertex_input
            .iter()
            .map(|v| vk::VertexInputBindingDescription {
                binding: 0,
                stride: v.stride,
                input_rate: vk::VertexInputRate::VERTEX,
            })
            .collect();
        let attributes = state.vertex_input.map_or(&[][..], |v| v.attributes);
        let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
            .vertex_binding_descriptions(&bindings)
            .vertex_attribute_descriptions(attributes);
        let assembly = vk::PipelineInputAssemblyStateCreateInfo::default()
            .topology(vk::PrimitiveTopology::TRIANGLE_LIST);
        let viewport = vk::PipelineViewportStateCreateInfo::default()
            .viewport_count(1)
            .scissor_count(1);
        let (bias, constant, slope) = match state.depth_bias {
            Some((c, s)) => (true, c, s),
            None => (false, 0.0, 0.0),
        };
        let raster = vk::PipelineRasterizationStateCreateInfo::default()
            .polygon_mode(vk::PolygonMode::FILL)
            .cull_mode(state.cull)
            .depth_clamp_enable(state.depth_clamp)
            .front_face(vk::FrontFace::COUNTER_CLOCKWISE)
            .depth_bias_enable(bias)
            .depth_bias_constant_factor(constant)
            .depth_bias_slope_factor(slope)
            .line_width(1.0);
        let multisample = vk::PipelineMultisampleStateCreateInfo::default()
            .rasterization_samples(crate::convert::samples(state.samples));
        let depth = vk::PipelineDepthStencilStateCreateInfo::default()
            .depth_test_enable(state.depth.test)
            .depth_write_enable(state.depth.write)
            .depth_compare_op(state.depth.compare);
        let attachments: Vec<_> = state.blends.iter().map(|b| blend_state(*b)).collect();
        let blend = vk::PipelineColorBlendStateCreateInfo::default().attachments(&attachments);
        let mut dynamic_states = vec![vk::DynamicState::VIEWPORT, vk::DynamicState::SCISSOR];
        if state.dynamic_front_face {
            dynamic_states.push(vk::DynamicState::FRONT_FACE);
        }
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
            .render_pass(render_pass)
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

/// A pipeline layout over `set_layouts` with `push` ranges.
pub fn create_pipeline_layout(
    device: &ash::Device,
    set_layouts: &[vk::DescriptorSetLayout],
    push: &[vk::PushConstantRange],
) -> Result<vk::PipelineLayout, GpuError> {
    let info = vk::PipelineLayoutCreateInfo::default()
        .set_layouts(set_layouts)
        .push_constant_ranges(push);
    unsafe { device.create_pipeline_layout(&info, None) }.call("vkCreatePipelineLayout")
}

/// Destroys a pipeline, its layout and the set layouts it owns; null handles
/// are skipped. No pending work may use them.
pub fn destroy_pipeline(
    device: &ash::Device,
    pipeline: vk::Pipeline,
    layout: vk::PipelineLayout,
    owned_set_layouts: &[vk::DescriptorSetLayout],
) {
    unsafe {
        device.destroy_pipeline(pipeline, None);
        device.destroy_pipeline_layout(layout, None);
        for &l in owned_set_layouts {
            device.destroy_descriptor_set_layout(l, None);
        }
    }
}

/// A shader module of compiled SPIR-V.
pub(crate) fn shader_module(
    device: &ash::Device,
    shader: &CompiledShader,
) -> Result<vk::ShaderModule, GpuError> {
    let info = vk::ShaderModuleCreateInfo::default().code(&shader.spirv);
    unsafe { device.create_shader_module(&info, None) }.call("vkCreateShaderModule")
}
