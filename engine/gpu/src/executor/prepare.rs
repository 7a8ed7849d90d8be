//! Per-pass preparation before recording: pipelines, render passes and
//! framebuffers, push-constant bytes, descriptor sets written with image
//! layouts as the plan's barriers leave them.

use super::{FrameOptions, Prepared, PreparedPlan, Renderer};
use crate::bind::{self, FrameValues};
use crate::context::Gpu;
use crate::descriptors::DescriptorPool;
use crate::error::GpuError;
use crate::layouts;
use crate::resources::FrameResources;
use ash::vk;
use weft_graph::id::PassId;
use weft_graph::plan::{Plan, PlanPass, PlanResource, ResourceDesc};

impl<'g> Renderer<'g> {
    /// Prepares every pass of `plan` on `resources` and writes their descriptor sets.
    pub(super) fn prepare_plan(
        &mut self,
        plan: &Plan,
        resources: &mut FrameResources<'g>,
    ) -> Result<PreparedPlan<'g>, GpuError> {
        let mut passes = Vec::with_capacity(plan.passes.len());
        for pass in &plan.passes {
            passes.push(self.prepare(plan, pass, resources)?);
        }
        let pool = descriptor_pool(self.gpu, &passes)?;
        self.write_descriptors(plan, resources, &pool, &mut passes)?;
        Ok(PreparedPlan {
            generation: self.generation,
            passes,
            _pool: pool,
        })
    }

    /// This frame's push-constant bytes of a prepared pass: its parameters and
    /// the frame's time, number and extent.
    pub(super) fn pack_push(
        &self,
        pass: &PlanPass,
        prep: &Prepared,
        options: &FrameOptions,
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
        };
        bind::pack_push(block, &pass.params, &frame).map_err(|problems| GpuError::Pass {
            pass: pass.name.clone(),
            message: problems.join("; "),
        })
    }

    fn prepare(
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
        };
        if let Some((key, bindings)) = checked {
            prepared.pipeline = Some(self.pipelines.pipeline(self.gpu.device(), &key)?);
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
