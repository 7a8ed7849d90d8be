//! The narrow seam through which a renderer records scene draws (meshes,
//! light volumes) inside the render passes the executor begins. The executor
//! prepares every pass, scene passes included: their pipelines come from its
//! one cache, built against the registered scene interface, with set 0 and
//! push constants bound by [`RasterContext::bind_variant`]. A draw recorder
//! only binds the scene's sets and issues draws.

use crate::bind::{pack_push, resolve_bindings, FrameValues};
use crate::check::scene_pass_keys_with;
use crate::context::Gpu;
use crate::descriptors::{write_graph_set, DescriptorPool};
use crate::error::GpuError;
use crate::pipeline::{Pipeline, PipelineCache, PipelineKey, ShaderKey};
use crate::resources::FrameResources;
use crate::samplers::Samplers;
use crate::scene::RegisteredScene;
use crate::scene_check::{scene_pass_problems, with_per_draw};
use crate::sets::SCENE_SET;
use crate::state::{pass_state, PassState};
use ash::vk;
use std::sync::Arc;
use weft_graph::id::{PassId, ResourceId};
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::schema::ParamValue;

/// Pipeline variants one scene pass may use in a prepared plan: two shading
/// models, each opaque and blended.
pub const SCENE_VARIANTS: u32 = 4;

/// A scene pass's pipeline variant made ready for one prepared plan: its
/// pipeline and its set 0, written once.
pub(crate) struct Variant {
    key: PipelineKey,
    pipeline: Arc<Pipeline>,
    graph_set: vk::DescriptorSet,
}

/// What the executor lends a scene pass for building and binding its variants.
pub(crate) struct ScenePass<'a> {
    pub(crate) pipelines: &'a mut PipelineCache,
    pub(crate) scene: &'a RegisteredScene<'a>,
    pub(crate) samplers: &'a Samplers,
    pub(crate) variants: &'a mut Vec<Variant>,
    pub(crate) pool: Option<&'a DescriptorPool<'a>>,
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
    pub(crate) scene: Option<ScenePass<'a>>,
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
    /// reads, written once per prepared plan) and the push constants. Built,
    /// after the scene interface check, on first use.
    pub fn bind_variant(
        &mut self,
        defines: &[String],
        state: &PassState,
    ) -> Result<Arc<Pipeline>, GpuError> {
        let keys = scene_pass_keys_with(self.pass(), defines)
            .ok_or_else(|| self.fail("needs a vertex shader"))?;
        let key = PipelineKey::Scene {
            vertex: keys[0].clone(),
            fragment: keys.get(1).cloned(),
            render_pass: self.render_pass,
            state: state.clone(),
        };
        let (gpu, plan, pass, resources) = (self.gpu, self.plan, self.pass_index, self.resources);
        let Some(scene) = self.scene.as_mut() else {
            return Err(self.fail("draws scene content but no scene interface is registered"));
        };
        let index = match scene.variants.iter().position(|v| v.key == key) {
            Some(index) => index,
            None => {
                let variant = scene.prepare_variant((gpu, plan, pass, resources), key, &keys)?;
                scene.variants.push(variant);
                scene.variants.len() - 1
            }
        };
        let variant = &scene.variants[index];
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
            .as_ref()
            .ok_or_else(|| self.fail("no scene interface is registered"))?;
        let mut params = with_per_draw(&scene.scene.interface, self.pass());
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

impl ScenePass<'_> {
    /// Checks the variant's shaders against the graph and the scene
    /// interface, builds its pipeline and writes its set 0.
    fn prepare_variant(
        &mut self,
        (gpu, plan, pass_index, resources): (&Gpu, &Plan, PassId, &FrameResources<'_>),
        key: PipelineKey,
        keys: &[ShaderKey],
    ) -> Result<Variant, GpuError> {
        let pass = &plan.passes[pass_index];
        let fail = |message: String| GpuError::Pass {
            pass: pass.name.clone(),
            message,
        };
        let depth_clamp = matches!(&key, PipelineKey::Scene { state, .. } if state.depth_clamp);
        if depth_clamp && !gpu.info().depth_clamp {
            return Err(fail(
                "`raster.depth_clamp` needs the device feature depthClamp, which this device lacks"
                    .into(),
            ));
        }
        let modules = keys
            .iter()
            .map(|k| self.pipelines.shader(k))
            .collect::<Result<Vec<_>, _>>()?;
        let compiled: Vec<_> = modules.iter().map(|m| &m.compiled).collect();
        let info = gpu.info();
        info.shaders.check(&info.name, &pass.name, &compiled)?;
        let problems = scene_pass_problems(
            &self.scene.interface,
            plan,
            pass,
            &modules[0].interface,
            modules.get(1).map(|m| &m.interface),
        );
        if !problems.is_empty() {
            return Err(fail(problems.join("; ")));
        }
        let pipeline = self
            .pipelines
            .pipeline(gpu.device(), &key, Some(self.scene))?;
        let mut graph_only = pipeline.interface.clone();
        graph_only.bindings.retain(|(set, _), _| *set == 0);
        let mut graph_set = vk::DescriptorSet::null();
        if !graph_only.bindings.is_empty() {
            let resolved = resolve_bindings(plan, pass, &graph_only).map_err(|problems| {
                GpuError::Mismatch {
                    pass: pass.name.clone(),
                    problems,
                }
            })?;
            let pool = self
                .pool
                .ok_or_else(|| fail("no descriptor pool for scene passes".into()))?;
            graph_set = pool.allocate(pipeline.set_layouts[0]).map_err(|e| {
                fail(format!(
                    "its graph set for one more pipeline variant could not be allocated ({e}); a prepared plan holds {} per scene pass",
                    SCENE_VARIANTS
                ))
            })?;
            let samplers = self.samplers;
            write_graph_set(
                gpu,
                graph_set,
                &resolved,
                resources,
                |compare, format| samplers.for_binding(gpu, compare, format),
                |r| crate::convert::layout(crate::layouts::layout_at(plan, pass_index, r)),
            )?;
        }
        Ok(Variant {
            key,
            pipeline,
            graph_set,
        })
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

    /// Records the pass's draws into `ctx.cmd`, binding pipelines with
    /// [`RasterContext::bind_variant`].
    fn record(&mut self, ctx: &mut RasterContext<'_>) -> Result<(), GpuError>;

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
