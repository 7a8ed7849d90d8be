//! A plan's preparation before recording: every pass through its kind
//! ([`super::kinds`]), then one descriptor pool sized from the prepared
//! sets' bindings and every set written with image layouts as the plan's
//! barriers leave them; push-constant bytes per frame.

use super::kinds::{self, PassAt, Preparing};
use super::{FrameOptions, Prepared, PreparedPlan, Renderer};
use crate::bind::{self, ResolvedBinding};
use crate::context::Gpu;
use crate::descriptors::DescriptorPool;
use crate::draw::DrawRecorder;
use crate::error::GpuError;
use crate::layouts;
use crate::resources::FrameResources;
use ash::vk;
use weft_graph::id::PassId;
use weft_graph::plan::{Plan, PlanPass, PlanResource, ResourceDesc};

impl<'g> Renderer<'g> {
    /// Prepares every pass of `plan` on `resources` (scene passes with the
    /// variants `draws` names for them) and writes every descriptor set
    /// from one pool sized from their layouts.
    pub(super) fn prepare_plan(
        &mut self,
        plan: &Plan,
        resources: &mut FrameResources<'g>,
        draws: &dyn DrawRecorder,
    ) -> Result<PreparedPlan<'g>, GpuError> {
        let mut passes = Vec::with_capacity(plan.passes.len());
        for (index, pass) in plan.passes.iter().enumerate() {
            let mut prepared = Prepared::new(plan);
            let mut prep = Preparing {
                at: PassAt {
                    plan,
                    index: PassId::new(index),
                    pass,
                },
                resources,
                draws,
                prepared: &mut prepared,
            };
            kinds::of(pass).prepare(self, &mut prep)?;
            passes.push(prepared);
        }
        let pool = descriptor_pool(self.gpu, &passes)?;
        self.write_descriptors(plan, resources, &pool, &mut passes)?;
        Ok(PreparedPlan {
            generation: self.generation,
            resources: resources.id,
            passes,
            _pool: pool,
        })
    }

    /// Checks the pass's shaders against the graph and builds its own
    /// pipeline (compute and fullscreen passes).
    pub(super) fn prepare_pipeline(
        &mut self,
        plan: &Plan,
        pass: &PlanPass,
        prepared: &mut Prepared,
    ) -> Result<(), GpuError> {
        if let Some((key, bindings)) = self.checked_interface(plan, pass)? {
            let scene = self.scene.as_ref();
            prepared.pipeline = Some(self.pipelines.pipeline(self.gpu.device(), &key, scene)?);
            prepared.bindings = bindings;
        }
        Ok(())
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
        let frame = options.frame_values(prep.extent, repeat_index);
        bind::pack_push(block, &pass.params, &frame).map_err(|problems| GpuError::Pass {
            pass: pass.name.clone(),
            message: problems.join("; "),
        })
    }

    /// Writes every pass's descriptor set and its scene variants' sets 0,
    /// with image layouts as the plan's barriers leave them at that pass.
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
            let write = |set_layout: vk::DescriptorSetLayout, bindings: &[ResolvedBinding]| {
                let set = pool.allocate(set_layout)?;
                crate::descriptors::write_graph_set(
                    self.gpu,
                    set,
                    bindings,
                    resources,
                    |compare, format| self.samplers.for_binding(self.gpu, compare, format),
                    |r| crate::convert::layout(layouts[r]),
                )?;
                Ok::<_, GpuError>(set)
            };
            if let Some(&set_layout) = prep.pipeline.as_ref().and_then(|p| p.set_layouts.first()) {
                prep.set = write(set_layout, &prep.bindings)?;
            }
            for variant in prep.variants.iter_mut().filter(|v| !v.bindings.is_empty()) {
                variant.graph_set = write(variant.pipeline.set_layouts[0], &variant.bindings)?;
            }
        }
        Ok(())
    }
}

/// A pool with room for every prepared pass's descriptor set and its scene
/// variants' sets 0, counted from their resolved bindings.
fn descriptor_pool<'g>(
    gpu: &'g Gpu,
    prepared: &[Prepared],
) -> Result<DescriptorPool<'g>, GpuError> {
    let mut counts: Vec<(vk::DescriptorType, u32)> = Vec::new();
    let mut sets = 0;
    let pass_sets = prepared
        .iter()
        .filter(|p| {
            p.pipeline
                .as_ref()
                .is_some_and(|p| !p.set_layouts.is_empty())
        })
        .map(|p| p.bindings.as_slice());
    let variant_sets = prepared
        .iter()
        .flat_map(|p| &p.variants)
        .filter(|v| !v.bindings.is_empty())
        .map(|v| v.bindings.as_slice());
    for bindings in pass_sets.chain(variant_sets) {
        sets += 1;
        for b in bindings {
            let ty = b.shader.kind.vk();
            match counts.iter_mut().find(|(t, _)| *t == ty) {
                Some((_, n)) => *n += b.shader.count,
                None => counts.push((ty, b.shader.count)),
            }
        }
    }
    DescriptorPool::new(gpu, sets, &counts)
}

/// The clear value of an attachment: depth for a depth image, else colour.
pub(super) fn clear_value(resource: &PlanResource, clear: &[f64]) -> vk::ClearValue {
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
