//! Per-pass preparation before recording: pipelines, render passes and
//! framebuffers, push-constant bytes, descriptor sets written with image
//! layouts as the plan's barriers leave them.

use super::{FrameOptions, Prepared, PreparedPlan, Renderer};
use crate::bind::{self, FrameValues};
use crate::context::Gpu;
use crate::descriptors::DescriptorPool;
use crate::draw::SCENE_VARIANTS;
use crate::error::GpuError;
use crate::layouts;
use crate::resources::FrameResources;
use ash::vk;
use weft_graph::id::PassId;
use weft_graph::plan::{Plan, PlanPass, PlanResource, ResourceDesc};
use weft_graph::schema::Draw;

impl<'g> Renderer<'g> {
    /// Prepares every pass of `plan` on `resources` and writes their descriptor sets.
    pub(super) fn prepare_plan(
        &mut self,
        plan: &Plan,
        resources: &mut FrameResources<'g>,
    ) -> Result<PreparedPlan<'g>, GpuError> {
        let mut passes = Vec::with_capacity(plan.passes.len());
        for pass in &plan.passes {
            passes.push(self.prepare_pass(plan, pass, resources)?);
        }
        let pool = descriptor_pool(self.gpu, &passes)?;
        self.write_descriptors(plan, resources, &pool, &mut passes)?;
        Ok(PreparedPlan {
            generation: self.generation,
            resources: resources.id,
            passes,
            _pool: pool,
            scene_pool: scene_pool(self.gpu, plan)?,
        })
    }

    /// This frame's push-constant bytes of a prepared pass for its
    /// `repeat_index`-th dispatch: its parameters and the frame's time,
    /// number and extent.
    pub(super) fn pack_push(
        &self,
        pass: &PlanPass,
        prep: &Prepared,
        options: &FrameOptions,
        repeat_index: u32,
    ) -> Result<Vec<u8>, GpuError> {
        let Some((block, _)) = prep
            .pipeline
            .as_ref()
            .and_then(|p| p.interface.push.as_ref())
        else {
            return Ok(Vec::new());
        };
        let frame = FrameValues {
            time: options.time,
            frame: options.frame,
            extent: [prep.extent.width, prep.extent.height],
            history_frames: options.history_frames,
            plan_frames: options.plan_frames,
            repeat_index,
        };
        bind::pack_push(block, &pass.params, &frame).map_err(|problems| GpuError::Pass {
            pass: pass.name.clone(),
            message: problems.join("; "),
        })
    }

    fn prepare_pass(
        &mut self,
        plan: &Plan,
        pass: &PlanPass,
        resources: &mut FrameResources<'g>,
    ) -> Result<Prepared, GpuError> {
        let checked = self.checked_interface(plan, pass)?;
        let mut prepared = Prepared {
            pipeline: None,
            render_pass: vk::RenderPass::null(),
            framebuffer: vk::Framebuffer::null(),
            extent: vk::Extent2D {
                width: plan.extent.width,
                height: plan.extent.height,
            },
            clears: Vec::new(),
            bindings: Vec::new(),
            push: Vec::new(),
            set: vk::DescriptorSet::null(),
            variants: Vec::new(),
        };
        if let Some((key, bindings)) = checked {
            let scene = self.scene.as_ref();
            prepared.pipeline = Some(self.pipelines.pipeline(self.gpu.device(), &key, scene)?);
            prepared.bindings = bindings;
        }
        if let Some(rp) = &pass.render_pass {
            prepared.render_pass = self.render_passes.get(self.gpu.device(), rp)?;
            prepared.extent = vk::Extent2D {
                width: rp.extent.width,
                height: rp.extent.height,
            };
            let mut views = Vec::with_capacity(rp.attachments.len());
            for a in &rp.attachments {
                views.push(resources.image(a.resource)?.attachment_view);
                prepared
                    .clears
                    .push(clear_value(&plan.resources[a.resource], &a.clear));
            }
            prepared.framebuffer =
                resources.framebuffer(prepared.render_pass, views, prepared.extent)?;
        }
        Ok(prepared)
    }

    /// Writes every pass's descriptor set, with image layouts as the plan's
    /// barriers leave them at that pass.
    fn write_descriptors(
        &self,
        plan: &Plan,
        resources: &FrameResources<'g>,
        pool: &DescriptorPool,
        prepared: &mut [Prepared],
    ) -> Result<(), GpuError> {
        let mut layouts = layouts::frame_start(plan);
        for (index, prep) in prepared.iter_mut().enumerate() {
            layouts::apply_pass(plan, PassId::new(index), &mut layouts);
            let Some(pipeline) = &prep.pipeline else {
                continue;
            };
            let Some(&set_layout) = pipeline.set_layouts.first() else {
                continue;
            };
            prep.set = pool.allocate(set_layout)?;
            crate::descriptors::write_graph_set(
                self.gpu,
                prep.set,
                &prep.bindings,
                resources,
                |compare, format| self.samplers.for_binding(self.gpu, compare, format),
                |r| crate::convert::layout(layouts[r]),
            )?;
        }
        Ok(())
    }
}

/// A pool with room for every prepared pass's descriptor set.
fn descriptor_pool<'g>(
    gpu: &'g Gpu,
    prepared: &[Prepared],
) -> Result<DescriptorPool<'g>, GpuError> {
    let mut counts: Vec<(vk::DescriptorType, u32)> = Vec::new();
    let mut sets = 0;
    for p in prepared.iter().filter(|p| p.pipeline.is_some()) {
        sets += 1;
        for b in &p.bindings {
            let ty = b.shader.kind.vk();
            match counts.iter_mut().find(|(t, _)| *t == ty) {
                Some((_, n)) => *n += b.shader.count,
                None => counts.push((ty, b.shader.count)),
            }
        }
    }
    DescriptorPool::new(gpu, sets, &counts)
}

/// Whether a pass draws scene content through the draw recorder.
fn draws_scene(pass: &PlanPass) -> bool {
    matches!(pass.draw, Some(Draw::Meshes(_) | Draw::LightVolumes(_)))
}

/// A pool with room for the graph sets of [`SCENE_VARIANTS`] pipeline
/// variants of every scene pass (each binding counted for every descriptor
/// type, as arrays of up to 8: the variants' layouts are not known before
/// their shaders are); `None` for a plan without scene passes.
fn scene_pool<'g>(gpu: &'g Gpu, plan: &Plan) -> Result<Option<DescriptorPool<'g>>, GpuError> {
    let scene_passes: Vec<&PlanPass> = plan.passes.iter().filter(|p| draws_scene(p)).collect();
    if scene_passes.is_empty() {
        return Ok(None);
    }
    let sets = SCENE_VARIANTS * scene_passes.len() as u32;
    let bindings: u32 = scene_passes
        .iter()
        .map(|p| p.bindings.len().max(1) as u32)
        .sum();
    let per_type = SCENE_VARIANTS * bindings * 8;
    let counts = [
        vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        vk::DescriptorType::STORAGE_IMAGE,
        vk::DescriptorType::STORAGE_BUFFER,
        vk::DescriptorType::UNIFORM_BUFFER,
    ]
    .map(|ty| (ty, per_type));
    DescriptorPool::new(gpu, sets, &counts).map(Some)
}

fn clear_value(resource: &PlanResource, clear: &[f64]) -> vk::ClearValue {
    let depth = matches!(&resource.desc, ResourceDesc::Image(d) if d.aspect != weft_graph::vk::Aspect::Color);
    if depth {
        vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue {
                depth: clear.first().copied().unwrap_or(0.0) as f32,
                stencil: 0,
            },
        }
    } else {
        let mut c = [0f32; 4];
        for (slot, v) in c.iter_mut().zip(clear) {
            *slot = *v as f32;
        }
        vk::ClearValue {
            color: vk::ClearColorValue { float32: c },
        }
    }
}
