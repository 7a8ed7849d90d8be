//! The narrow seam through which a renderer records scene draws (meshes,
//! light volumes) inside the render passes the executor begins. The executor
//! prepares every pass before its first frame, scene passes included: the
//! draw recorder names the pipeline variants each scene pass binds
//! ([`DrawRecorder::variants`]), and the executor builds them from its one
//! cache against the registered scene interface and writes their set 0. At
//! record time [`RasterContext::bind_variant`] only binds; a recorder only
//! binds the scene's sets and issues draws.

use crate::bind::{pack_push, FrameValues, ResolvedBinding};
use crate::check::scene_pass_keys_with;
use crate::context::Gpu;
use crate::error::GpuError;
use crate::pipeline::{Pipeline, PipelineKey, ShaderKey};
use crate::resources::FrameResources;
use crate::scene::RegisteredScene;
use crate::scene_check::with_per_draw;
use crate::sets::SCENE_SET;
use crate::state::{pass_state, PassState};
use ash::vk;
use std::sync::Arc;
use weft_graph::id::{PassId, ResourceId};
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::schema::ParamValue;

/// One pipeline variant a scene pass binds: its shaders compiled with
/// `defines`, drawn with `state` (the pass's own, or one derived from it
/// such as blended transparency).
#[derive(Debug, Clone, PartialEq)]
pub struct SceneVariant {
    /// The shader defines (the pass's, or those for one shading model).
    pub defines: Vec<String>,
    /// The fixed-function state.
    pub state: PassState,
}

impl SceneVariant {
    /// The pipeline key and the shaders of this variant of `pass` in
    /// `render_pass`; `None` when the pass has no vertex shader.
    pub(crate) fn key(
        &self,
        pass: &PlanPass,
        render_pass: vk::RenderPass,
    ) -> Option<(PipelineKey, Vec<ShaderKey>)> {
        let keys = scene_pass_keys_with(pass, &self.defines)?;
        let key = PipelineKey::Scene {
            vertex: keys[0].clone(),
            fragment: keys.get(1).cloned(),
            render_pass,
            state: self.state.clone(),
        };
        Some((key, keys))
    }
}

/// A scene pass's pipeline variant made ready for one prepared plan: its
/// pipeline, the graph resources its set 0 reads, and that set once written.
pub(crate) struct Variant {
    pub(crate) key: PipelineKey,
    pub(crate) pipeline: Arc<Pipeline>,
    pub(crate) bindings: Vec<ResolvedBinding>,
    pub(crate) graph_set: vk::DescriptorSet,
}

/// What a draw recorder gets for a pass that draws scene content: it
/// records draws inside the already begun render pass (viewport and scissor
/// set to `extent`), binding pipelines through [`RasterContext::bind_variant`].
pub struct RasterContext<'a> {
    /// The context, for the device and allocator.
    pub gpu: &'a Gpu,
    /// The command buffer being recorded, inside the render pass.
    pub cmd: vk::CommandBuffer,
    /// The plan being executed.
    pub plan: &'a Plan,
    /// Index of the pass in `plan.passes`.
    pub pass_index: PassId,
    /// The render pass the pass's pipelines are built against (subpass 0);
    /// null for a compute pass, which only gets `bind_scene` calls.
    pub render_pass: vk::RenderPass,
    /// The render area, also set as viewport and scissor.
    pub extent: vk::Extent2D,
    /// The frame's images and buffers, by plan resource index.
    pub resources: &'a FrameResources<'a>,
    /// The frame's `time`, `frame`, `extent` and `history_frames` for push constants.
    pub frame: FrameValues,
    /// The registered scene interface, for the per-draw parameters.
    pub(crate) scene: Option<&'a RegisteredScene<'a>>,
    /// The pass's variants, prepared with the plan.
    pub(crate) variants: &'a [Variant],
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

    /// The layout a graph image is in during this pass.
    pub fn image_layout(&self, resource: ResourceId) -> vk::ImageLayout {
        crate::convert::layout(crate::layouts::layout_at(
            self.plan,
            self.pass_index,
            resource,
        ))
    }

    /// The fixed-function state the graph declares for this pass.
    pub fn pass_state(&self) -> PassState {
        pass_state(self.pass())
    }

    fn fail(&self, message: impl Into<String>) -> GpuError {
        GpuError::Pass {
            pass: self.pass().name.clone(),
            message: message.into(),
        }
    }

    /// Binds a variant of the pass's pipeline: its shaders compiled with
    /// `defines`, drawn with `state` (the pass's own, or one derived from it
    /// such as blended transparency), with set 0 (the graph resources it
    /// reads, written once per prepared plan) and the push constants. The
    /// variant must be one the recorder's [`DrawRecorder::variants`] named,
    /// so it was built and checked before the first frame.
    pub fn bind_variant(
        &mut self,
        defines: &[String],
        state: &PassState,
    ) -> Result<Arc<Pipeline>, GpuError> {
        let wanted = SceneVariant {
            defines: defines.to_vec(),
            state: state.clone(),
        };
        let (key, _) = wanted
            .key(self.pass(), self.render_pass)
            .ok_or_else(|| self.fail("needs a vertex shader"))?;
        let Some(variant) = self.variants.iter().find(|v| v.key == key) else {
            return Err(self.fail(format!(
                "binds a pipeline variant (defines [{}]) its draw recorder did not name in `DrawRecorder::variants`, so none was prepared",
                defines.join(", ")
            )));
        };
        let (pipeline, graph_set) = (Arc::clone(&variant.pipeline), variant.graph_set);
        let commands = self.commands();
        commands.bind_pipeline(vk::PipelineBindPoint::GRAPHICS, pipeline.pipeline);
        if graph_set != vk::DescriptorSet::null() {
            commands.bind_sets(
                vk::PipelineBindPoint::GRAPHICS,
                pipeline.layout,
                0,
                &[graph_set],
            );
        }
        self.push_constants(&pipeline, &[])?;
        Ok(pipeline)
    }

    /// Pushes the pass's constants for `pipeline` (bound by `bind_variant`):
    /// its parameters, with `overrides` of the ones set per draw (a shadow
    /// view's index), and the frame's values.
    pub fn push_constants(
        &self,
        pipeline: &Pipeline,
        overrides: &[(&str, f64)],
    ) -> Result<(), GpuError> {
        let Some((block, stages)) = &pipeline.interface.push else {
            return Ok(());
        };
        let scene = self
            .scene
            .ok_or_else(|| self.fail("no scene interface is registered"))?;
        let mut params = with_per_draw(&scene.interface, self.pass());
        for (name, value) in overrides {
            params.insert(name.to_string(), ParamValue::Number(*value));
        }
        let bytes = pack_push(block, &params, &self.frame)
            .map_err(|problems| self.fail(problems.join("; ")))?;
        self.commands()
            .push_constants(pipeline.layout, *stages, &bytes);
        Ok(())
    }
}

/// Records the draws of raster passes whose content comes from outside the
/// graph (scene meshes, light volumes); the render crate implements it.
pub trait DrawRecorder {
    /// Called by the executor once at the start of every frame, before any
    /// pass records; the previous frame has finished on the device, so
    /// per-frame state (counters) may be recycled.
    fn begin_frame(&mut self) -> Result<(), GpuError> {
        Ok(())
    }

    /// Called by the executor after each submission of the frame's commands
    /// (one at the end, or one per pass when timing passes on the CPU):
    /// what was recorded so far will run, so state that records work once
    /// (an acceleration structure's build) may count it done.
    fn submitted(&mut self) {}

    /// The pipeline variants `pass` (a scene pass) binds through
    /// [`RasterContext::bind_variant`] with the recorder's scene; the
    /// executor builds each, and writes its set 0, when it prepares the
    /// plan, before the first frame. The list must stay the same while the
    /// plan is kept: a recorder with another scene is handed over with
    /// [`crate::Renderer::forget_prepared`]. None by default: a recorder
    /// that draws without the executor's pipelines (clears) needs none.
    fn variants(&self, pass: &PlanPass) -> Vec<SceneVariant> {
        let _ = pass;
        Vec::new()
    }

    /// Records the pass's draws into `ctx.cmd`, binding pipelines with
    /// [`RasterContext::bind_variant`].
    fn record(&mut self, ctx: &mut RasterContext<'_>) -> Result<(), GpuError>;

    /// Records into `cmd` what the scene's acceleration structures need
    /// before this frame's ray queries: their first build, or a refit of
    /// the top level to placements that moved since, or nothing. The
    /// executor runs it for a `BuildAccelerationStructures` pass, after
    /// the barriers the plan orders it by (the last frame's traces) and
    /// before those that order the traces after it, building in `scratch`,
    /// the pass's scratch buffer.
    fn build_structures(
        &mut self,
        pass: &PlanPass,
        cmd: vk::CommandBuffer,
        scratch: crate::acceleration::ScratchSpan,
    ) -> Result<(), GpuError> {
        let _ = (cmd, scratch);
        Err(GpuError::Pass {
            pass: pass.name.clone(),
            message: "builds acceleration structures, but no draw recorder holds a scene with them"
                .into(),
        })
    }

    /// Binds scene data at set [`SCENE_SET`] for a fullscreen or compute
    /// pass whose shaders declare it; `pipeline.scene_set` says which layout
    /// of the set it was built with.
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
    fn record(&mut self, ctx: &mut RasterContext<'_>) -> Result<(), GpuError> {
        Err(GpuError::Pass {
            pass: ctx.pass().name.clone(),
            message: "draws scene content but no draw recorder was given".into(),
        })
    }
}
