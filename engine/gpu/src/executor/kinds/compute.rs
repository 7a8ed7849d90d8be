//! Compute passes: a checked pipeline, scene data bound when the shader
//! reads it (tiled light culling reads the camera and the lights), and one
//! dispatch or `repeat` of them with the pass's repeat barriers between.

use super::{PassKindOps, Preparing, Recording};
use crate::bind::REPEAT_INDEX;
use crate::check::{stage_key, PassShaders};
use crate::error::GpuError;
use crate::executor::Renderer;
use crate::record;
use crate::resources::FrameResources;
use crate::sets::SCENE_SET;
use crate::shader::ShaderStage;
use ash::vk;
use weft_graph::plan::PlanPass;
use weft_graph::resolve::INDIRECT_RECORD_BYTES;

/// The compute kind.
pub(super) struct Compute;

impl PassKindOps for Compute {
    fn shaders(&self, pass: &PlanPass) -> Result<Option<PassShaders>, GpuError> {
        let compute = pass.shaders.compute.as_deref();
        let compute = compute.ok_or_else(|| super::missing_shader(pass, "compute"))?;
        Ok(Some(PassShaders::Compute(stage_key(
            compute,
            ShaderStage::Compute,
            &pass.defines,
        ))))
    }

    fn prepare<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        prep: &mut Preparing<'_, 'g>,
    ) -> Result<(), GpuError> {
        renderer.prepare_pipeline(prep.at.plan, prep.at.pass, prep.prepared)
    }

    fn record<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        rec: &mut Recording<'_, 'g>,
    ) -> Result<(), GpuError> {
        let dispatch = dispatch_source(rec.at.pass, rec.resources)?;
        renderer.bind(rec.cmd, rec.prep);
        // Scene data comes from the draw recorder, as for a fullscreen pass;
        // there is no render pass around it.
        let reads_scene = rec
            .prep
            .pipeline
            .clone()
            .filter(|p| p.interface.bindings.keys().any(|(s, _)| *s == SCENE_SET));
        if let Some(p) = reads_scene {
            let ctx = super::raster_context(
                renderer,
                (rec.at, &*rec.prep, rec.resources),
                (rec.cmd, rec.frame),
                vk::RenderPass::null(),
            );
            rec.draws.bind_scene(&ctx, &p)?;
        }
        dispatch_all(renderer, rec, dispatch)
    }
}

/// The pass's dispatches: one, or `repeat` in a row with the pass's repeat
/// barriers between them and, where the shader reads it, each one's
/// `repeat_index` pushed (the other push constants stay bound).
fn dispatch_all(
    renderer: &Renderer<'_>,
    rec: &Recording<'_, '_>,
    groups: DispatchSource,
) -> Result<(), GpuError> {
    let device = renderer.gpu.device();
    let (pass, prep, cmd) = (rec.at.pass, &*rec.prep, rec.cmd);
    for repeat_index in 0..pass.repeat.max(1) {
        if repeat_index > 0 {
            record::barriers(device, cmd, &pass.repeat_barriers, rec.resources)?;
            if renderer.traces(pass) {
                record::scene_counter_barrier(device, cmd);
            }
            if let Some((p, (_, stages))) = prep
                .pipeline
                .as_ref()
                .and_then(|p| p.interface.push.as_ref().map(|push| (p, push)))
                .filter(|(_, (block, _))| block.members.iter().any(|m| m.name == REPEAT_INDEX))
            {
                let push = renderer.pack_push(pass, prep, rec.options, repeat_index)?;
                unsafe { device.cmd_push_constants(cmd, p.layout, *stages, 0, &push) };
            }
        }
        match groups {
            DispatchSource::Groups([x, y, z]) => unsafe { device.cmd_dispatch(cmd, x, y, z) },
            DispatchSource::Indirect(buffer, stride) => unsafe {
                device.cmd_dispatch_indirect(cmd, buffer, u64::from(repeat_index * stride))
            },
        }
    }
    Ok(())
}

/// Where a compute pass's work-group counts come from.
#[derive(Clone, Copy)]
enum DispatchSource {
    /// Known when the plan was compiled.
    Groups([u32; 3]),
    /// Read by the GPU from a buffer: the `k`-th dispatch at byte `k × stride`.
    Indirect(vk::Buffer, u32),
}

/// A compute pass's dispatch, with an indirect one's every record checked to
/// lie inside its buffer (Vulkan leaves reading past the end undefined).
fn dispatch_source(
    pass: &PlanPass,
    resources: &FrameResources,
) -> Result<DispatchSource, GpuError> {
    let fail = |message: String| GpuError::Pass {
        pass: pass.name.clone(),
        message,
    };
    match (pass.dispatch, pass.indirect) {
        (Some(groups), _) => Ok(DispatchSource::Groups(groups)),
        (None, Some(indirect)) => {
            let buffer = resources.buffer(indirect.buffer)?;
            let end = u64::from(pass.repeat.max(1) - 1) * u64::from(indirect.stride)
                + u64::from(INDIRECT_RECORD_BYTES);
            if end > buffer.desc.size {
                return Err(fail(format!(
                    "its {} indirect dispatch(es) read up to byte {end} of a {}-byte buffer",
                    pass.repeat.max(1),
                    buffer.desc.size
                )));
            }
            Ok(DispatchSource::Indirect(buffer.buffer, indirect.stride))
        }
        (None, None) => Err(fail("compute pass without a dispatch size".into())),
    }
}
