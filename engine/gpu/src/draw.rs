//! The hook through which callers record scene draws (meshes, light
//! volumes) inside the render passes the executor begins.

use crate::context::Gpu;
use crate::error::GpuError;
use crate::pipeline::Pipeline;
use crate::resources::FrameResources;
use ash::vk;
use weft_graph::id::{PassId, ResourceId};
use weft_graph::plan::{Plan, PlanPass};

/// What a draw recorder gets for a raster pass that draws scene content: it
/// records draws inside the already begun render pass (viewport and scissor
/// set to `extent`), with pipelines it builds against `render_pass` subpass 0.
pub struct RasterContext<'a> {
    /// The context, for the device and allocator.
    pub gpu: &'a Gpu,
    /// The command buffer being recorded, inside the render pass.
    pub cmd: vk::CommandBuffer,
    /// The plan being executed.
    pub plan: &'a Plan,
    /// Index of the pass in `plan.passes`.
    pub pass_index: PassId,
    /// The render pass the recorder's pipelines must be compatible with (subpass 0);
    /// null for a compute pass, which only gets `bind_scene` calls.
    pub render_pass: vk::RenderPass,
    /// The render area, also set as viewport and scissor.
    pub extent: vk::Extent2D,
    /// The frame's images and buffers, by plan resource index.
    pub resources: &'a FrameResources<'a>,
    /// The linear clamp sampler graph resources are sampled with.
    pub sampler: vk::Sampler,
    /// The nearest clamp sampler, for formats without linear filtering
    /// (`Gpu::linear_filter`), such as depth formats on lavapipe.
    pub nearest_sampler: vk::Sampler,
    /// The depth-compare sampler for `sampler2DShadow` bindings (shadow maps).
    pub compare_sampler: vk::Sampler,
}

impl RasterContext<'_> {
    /// Safe recording into this pass's command buffer.
    pub fn commands(&self) -> crate::commands::Commands<'_> {
        crate::commands::Commands::new(self.gpu.device(), self.cmd)
    }

    /// The pass being recorded.
    pub fn pass(&self) -> &PlanPass {
        &self.plan.passes[self.pass_index]
    }

    /// The layout a graph image is in during this pass, for the recorder's
    /// own descriptors (e.g. a shadow map sampled while drawing meshes).
    pub fn image_layout(&self, resource: ResourceId) -> vk::ImageLayout {
        crate::convert::layout(crate::layouts::layout_at(
            self.plan,
            self.pass_index,
            resource,
        ))
    }
}

/// The descriptor set number reserved for scene data (camera, lights): graph
/// resources are bound in set 0, and a fullscreen pass whose shaders declare
/// set 1 gets it from the draw recorder, so deferred lighting can read the scene
/// (and so can a compute pass, such as tiled light culling).
pub const SCENE_SET: u32 = 1;

/// Records the draws of raster passes whose content comes from outside the
/// graph (scene meshes, light volumes); the render crate implements it.
pub trait DrawRecorder {
    /// Called by the executor once at the start of every frame, before any
    /// pass records; the previous frame has finished on the device, so
    /// per-frame state (descriptor sets, counters) may be recycled.
    fn begin_frame(&mut self) -> Result<(), GpuError> {
        Ok(())
    }

    /// Records the pass's draws into `ctx.cmd`.
    fn record(&mut self, ctx: &RasterContext<'_>) -> Result<(), GpuError>;

    /// Binds scene data at set [`SCENE_SET`] for a fullscreen pass whose
    /// shaders declare it (`pipeline.interface` lists the bindings, and
    /// `pipeline.set_layouts[SCENE_SET]` is the layout to allocate from).
    fn bind_scene(&mut self, ctx: &RasterContext<'_>, pipeline: &Pipeline) -> Result<(), GpuError> {
        let _ = pipeline;
        Err(GpuError::Pass {
            pass: ctx.pass().name.clone(),
            message: format!(
                "its shaders read scene data (set {SCENE_SET}) but no draw recorder supplies it"
            ),
        })
    }
}

/// A recorder for graphs without scene draws: any such pass is an error.
pub struct NoDraws;

impl DrawRecorder for NoDraws {
    fn record(&mut self, ctx: &RasterContext<'_>) -> Result<(), GpuError> {
        Err(GpuError::Pass {
            pass: ctx.pass().name.clone(),
            message: "draws scene content but no draw recorder was given".into(),
        })
    }
}
