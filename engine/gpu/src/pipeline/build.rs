//! Building the cache's pipelines: layouts (set 0 from reflection, the scene
//! sets registered), then fullscreen, compute and scene pipelines.

use super::{Pipeline, ShaderModule};
use crate::error::{GpuError, VkCall};
use crate::graphics::{GraphicsState, VertexInput};
use crate::reflect::{PipelineInterface, ShaderInterface};
use crate::scene::{RegisteredScene, SceneLayouts, SceneSet};

use crate::sets::{MATERIAL_SET, SCENE_SET};
use crate::state::{BlendCode, PassState};
use ash::vk;
use std::collections::BTreeSet;
use std::path::PathBuf;

pub(super) fn destroy_pipeline(device: &ash::Device, p: &Pipeline) {
    crate::graphics::destroy_pipeline(device, p.pipeline, p.layout, &p.owned_layouts);
}

/// The scene layouts a pipeline's sets 1 (of kind `SceneSet`) and, for
/// scene pipelines, 2 come from.
struct SharedSets<'a, 'g> {
    layouts: &'a SceneLayouts<'g>,
    scene: SceneSet,
    material: bool,
}

impl<'a, 'g> SharedSets<'a, 'g> {
    /// Set 1 of kind `scene` shared, for a fullscreen or compute pipeline.
    fn scene_only((layouts, scene): (&'a SceneLayouts<'g>, SceneSet)) -> Self {
        Self {
            layouts,
            scene,
            material: false,
        }
    }

    fn layout(&self, set: u32) -> Option<vk::DescriptorSetLayout> {
        match set {
            SCENE_SET => Some(self.layouts.scene(self.scene)),
            MATERIAL_SET if self.material => Some(self.layouts.material.handle()),
            _ => None,
        }
    }
}

/// Descriptor set layouts (`sets` at least) and the pipeline layout for a
/// merged interface: shared scene layouts where given, the rest created
/// from reflection; returns them with the created ones.
fn build_layout(
    device: &ash::Device,
    interface: &PipelineInterface,
    sets: u32,
    shared: Option<&SharedSets<'_, '_>>,
) -> Result<
    (
        Vec<vk::DescriptorSetLayout>,
        Vec<vk::DescriptorSetLayout>,
        vk::PipelineLayout,
    ),
    GpuError,
> {
    let mut set_layouts = Vec::new();
    let mut owned = Vec::new();
    let result = (|| {
        for set in 0..interface.set_count().max(sets) {
            match shared.and_then(|s| s.layout(set)) {
                Some(layout) => set_layouts.push(layout),
                None => {
                    let bindings = interface.set_layout_bindings(set);
                    let layout = crate::descriptors::create_set_layout(device, &bindings)?;
                    owned.push(layout);
                    set_layouts.push(layout);
                }
            }
        }
        let ranges = interface.push_constant_ranges();
        crate::graphics::create_pipeline_layout(device, &set_layouts, &ranges)
    })();
    match result {
        Ok(layout) => Ok((set_layouts, owned, layout)),
        Err(e) => {
            for l in owned {
                crate::descriptors::destroy_set_layout(device, l);
            }
            Err(e)
        }
    }
}

pub(super) fn merged(modules: &[&ShaderModule]) -> Result<PipelineInterface, GpuError> {
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

/// A pipeline of `modules` with its layout, before the Vulkan pipeline is made.
fn with_layout(
    device: &ash::Device,
    modules: &[&ShaderModule],
    bind_point: vk::PipelineBindPoint,
    sets: u32,
    shared: Option<SharedSets<'_, '_>>,
) -> Result<Pipeline, GpuError> {
    let interface = merged(modules)?;
    let (set_layouts, owned_layouts, layout) =
        build_layout(device, &interface, sets, shared.as_ref())?;
    Ok(Pipeline {
        pipeline: vk::Pipeline::null(),
        layout,
        set_layouts,
        owned_layouts,
        scene_set: shared.map(|s| s.scene),
        interface,
        bind_point,
        dependencies: dependencies(modules),
        shaders: modules.iter().map(|m| m.compiled.path.clone()).collect(),
    })
}

/// Fills in `pipeline`'s Vulkan pipeline from `made`, or destroys its layout.
fn finish(
    device: &ash::Device,
    mut pipeline: Pipeline,
    made: Result<vk::Pipeline, GpuError>,
) -> Result<Pipeline, GpuError> {
    match made {
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

/// A fullscreen-triangle pipeline for `(render pass, blends, samples)`.
pub(super) fn build_graphics(
    device: &ash::Device,
    vs: &ShaderModule,
    fs: &ShaderModule,
    (render_pass, blends, samples): (vk::RenderPass, &[BlendCode], u32),
    scene: Option<(&SceneLayouts<'_>, SceneSet)>,
) -> Result<Pipeline, GpuError> {
    let shared = scene.map(SharedSets::scene_only);
    let pipeline = with_layout(
        device,
        &[vs, fs],
        vk::PipelineBindPoint::GRAPHICS,
        0,
        shared,
    )?;
    let state = GraphicsState {
        vertex_input: None,
        cull: vk::CullModeFlags::NONE,
        depth_clamp: false,
        depth_bias: None,
        samples,
        depth: crate::state::DepthState::OFF,
        blends,
        dynamic_front_face: false,
    };
    let made = crate::graphics::create_graphics_pipeline(
        device,
        &vs.compiled,
        Some(&fs.compiled),
        &state,
        pipeline.layout,
        render_pass,
    );
    finish(device, pipeline, made)
}

/// A pipeline drawing from the scene's vertex buffer with `state`: sets 1
/// and 2 the scene's, whatever the shaders declare of them; set 1 with the
/// ray tracer's bindings when the shaders read them (a pass that declares
/// `RayTracing`, checked before this is built).
pub(super) fn build_scene(
    device: &ash::Device,
    (vs, fs): (&ShaderModule, Option<&ShaderModule>),
    (render_pass, state): (vk::RenderPass, &PassState),
    scene: &RegisteredScene<'_>,
) -> Result<Pipeline, GpuError> {
    let layouts = &scene.layouts;
    let mut modules = vec![vs];
    modules.extend(fs);
    let reads_tracing = modules.iter().any(|m| {
        m.interface.bindings.iter().any(|b| {
            b.set == SCENE_SET
                && scene
                    .interface
                    .scene_binding(b.binding)
                    .is_some_and(|s| s.tracing)
        })
    });
    let shared = SharedSets {
        layouts,
        scene: if reads_tracing {
            SceneSet::Traced
        } else {
            SceneSet::Raster
        },
        material: true,
    };
    let pipeline = with_layout(
        device,
        &modules,
        vk::PipelineBindPoint::GRAPHICS,
        MATERIAL_SET + 1,
        Some(shared),
    )?;
    // The attributes the vertex shader reads (a subset of the vertex, which
    // the shader check guarantees): unread ones would only draw warnings.
    let attributes: Vec<vk::VertexInputAttributeDescription> = scene
        .interface
        .vertex_attributes
        .iter()
        .filter(|a| vs.interface.inputs.iter().any(|i| i.location == a.location))
        .map(|a| vk::VertexInputAttributeDescription {
            location: a.location,
            binding: 0,
            format: a.format.vk(),
            offset: a.offset,
        })
        .collect();
    // Every projection flips Y for Vulkan's downward framebuffer Y, which keeps
    // counter-clockwise model triangles counter-clockwise in Vulkan's convention;
    // the front face is set per draw, since a mirrored instance (negative
    // determinant) turns its triangles' winding around (`state::front_face`).
    let graphics = GraphicsState {
        vertex_input: Some(VertexInput {
            stride: scene.interface.vertex_stride,
            attributes: &attributes,
        }),
        cull: state.cull_flags(),
        depth_clamp: state.depth_clamp,
        depth_bias: state.depth_bias(),
        samples: state.samples,
        depth: state.depth.vk(),
        blends: &state.blends,
        dynamic_front_face: true,
    };
    let made = crate::graphics::create_graphics_pipeline(
        device,
        &vs.compiled,
        fs.map(|f| &f.compiled),
        &graphics,
        pipeline.layout,
        render_pass,
    );
    finish(device, pipeline, made)
}

/// A compute pipeline of `cs`.
pub(super) fn build_compute(
    device: &ash::Device,
    cs: &ShaderModule,
    scene: Option<(&SceneLayouts<'_>, SceneSet)>,
) -> Result<Pipeline, GpuError> {
    let shared = scene.map(SharedSets::scene_only);
    let pipeline = with_layout(device, &[cs], vk::PipelineBindPoint::COMPUTE, 0, shared)?;
    let made = crate::graphics::shader_module(device, &cs.compiled).and_then(|m| {
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(m)
            .name(c"main");
        let info = vk::ComputePipelineCreateInfo::default()
            .stage(stage)
            .layout(pipeline.layout);
        let r =
            unsafe { device.create_compute_pipelines(vk::PipelineCache::null(), &[info], None) }
                .map_err(|(_, r)| r)
                .call("vkCreateComputePipelines");
        unsafe { device.destroy_shader_module(m, None) };
        r.and_then(|v| {
            v.into_iter().next().ok_or(GpuError::Vulkan {
                call: "vkCreateComputePipelines",
                result: vk::Result::ERROR_UNKNOWN,
            })
        })
    });
    finish(device, pipeline, made)
}
