//! One module per kind of pass the executor runs, each implementing
//! [`PassKindOps`]: what it prepares before the first frame and what it
//! records after the pass's barriers. [`of`] is the one table the executor
//! dispatches through; a new kind is a module here and a row there.

mod acceleration;
mod compute;
mod fullscreen;
mod scene_raster;
mod transfer;

use super::{FrameOptions, Prepared, Renderer};
use crate::bind::FrameValues;
use crate::check::{is_fullscreen, PassShaders};
use crate::draw::{DrawRecorder, RasterContext};
use crate::error::GpuError;
use crate::resources::FrameResources;
use ash::vk;
use weft_graph::id::PassId;
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::schema::PassKind;

/// How one kind of pass is made ready and recorded.
pub(super) trait PassKindOps: Sync {
    /// Makes the pass ready: its checked pipeline, render pass and
    /// framebuffer, the scene variants its draw recorder names; descriptor
    /// sets are written afterwards, once the plan's pool is sized. Nothing
    /// by default (copies and blits).
    fn prepare<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        prep: &mut Preparing<'_, 'g>,
    ) -> Result<(), GpuError> {
        let _ = (renderer, prep);
        Ok(())
    }

    /// The shaders the executor builds the pass's pipeline from, which
    /// `weft graph check --shaders` checks; `None` where there are none
    /// (copies, blits, builds) or the draw recorder supplies them (scene
    /// draws).
    fn shaders(&self, pass: &PlanPass) -> Result<Option<PassShaders>, GpuError> {
        let _ = pass;
        Ok(None)
    }

    /// Records the pass's work into `rec.cmd`; its barriers are recorded.
    fn record<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        rec: &mut Recording<'_, 'g>,
    ) -> Result<(), GpuError>;
}

/// A pass and the plan it belongs to.
#[derive(Clone, Copy)]
pub(super) struct PassAt<'a> {
    pub(super) plan: &'a Plan,
    pub(super) index: PassId,
    pub(super) pass: &'a PlanPass,
}

/// Everything a pass is prepared with.
pub(super) struct Preparing<'a, 'g> {
    pub(super) at: PassAt<'a>,
    pub(super) resources: &'a mut FrameResources<'g>,
    pub(super) draws: &'a dyn DrawRecorder,
    pub(super) prepared: &'a mut Prepared,
}

/// Everything a pass records with.
pub(super) struct Recording<'a, 'g> {
    pub(super) at: PassAt<'a>,
    pub(super) prep: &'a mut Prepared,
    pub(super) resources: &'a FrameResources<'g>,
    pub(super) draws: &'a mut dyn DrawRecorder,
    pub(super) options: &'a FrameOptions,
    pub(super) cmd: vk::CommandBuffer,
    pub(super) frame: FrameValues,
}

/// The operations of `pass`'s kind: the executor's one dispatch table.
pub(super) fn of(pass: &PlanPass) -> &'static dyn PassKindOps {
    match pass.kind {
        PassKind::Copy => &transfer::COPY,
        PassKind::Blit => &transfer::BLIT,
        PassKind::Compute => &compute::Compute,
        PassKind::Fullscreen => &fullscreen::Fullscreen,
        PassKind::Raster if is_fullscreen(pass) => &fullscreen::Fullscreen,
        PassKind::Raster => &scene_raster::SceneRaster,
        PassKind::BuildAccelerationStructures => &acceleration::BuildStructures,
    }
}

/// The error of a pass that lacks the `what` shader its kind runs.
fn missing_shader(pass: &PlanPass, what: &str) -> GpuError {
    GpuError::Pass {
        pass: pass.name.clone(),
        message: format!("needs a {what} shader"),
    }
}

/// Gets the pass's render pass from the cache and its framebuffer on
/// `resources`, with the attachments' clear values.
fn prepare_render_pass<'g>(
    renderer: &mut Renderer<'g>,
    prep: &mut Preparing<'_, 'g>,
) -> Result<(), GpuError> {
    let Preparing {
        at,
        resources,
        prepared,
        ..
    } = prep;
    let Some(rp) = &at.pass.render_pass else {
        return Err(GpuError::Pass {
            pass: at.pass.name.clone(),
            message: "has no render pass description".into(),
        });
    };
    prepared.render_pass = renderer.render_passes.get(renderer.gpu.device(), rp)?;
    prepared.extent = vk::Extent2D {
        width: rp.extent.width,
        height: rp.extent.height,
    };
    let mut views = Vec::with_capacity(rp.attachments.len());
    for a in &rp.attachments {
        views.push(resources.image(a.resource)?.attachment_view);
        prepared.clears.push(super::prepare::clear_value(
            &at.plan.resources[a.resource],
            &a.clear,
        ));
    }
    prepared.framebuffer = resources.framebuffer(prepared.render_pass, views, prepared.extent)?;
    Ok(())
}

/// Begins the pass's render pass, with the viewport and scissor set to its
/// whole area.
fn begin_render_pass(device: &ash::Device, cmd: vk::CommandBuffer, prep: &Prepared) {
    let area = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent: prep.extent,
    };
    let begin = vk::RenderPassBeginInfo::default()
        .render_pass(prep.render_pass)
        .framebuffer(prep.framebuffer)
        .render_area(area)
        .clear_values(&prep.clears);
    let subpass = vk::SubpassBeginInfo::default().contents(vk::SubpassContents::INLINE);
    unsafe {
        device.cmd_begin_render_pass2(cmd, &begin, &subpass);
        device.cmd_set_viewport(
            cmd,
            0,
            &[vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: prep.extent.width as f32,
                height: prep.extent.height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            }],
        );
        device.cmd_set_scissor(cmd, 0, &[area]);
    }
}

/// Ends the render pass [`begin_render_pass`] began.
fn end_render_pass(device: &ash::Device, cmd: vk::CommandBuffer) {
    unsafe { device.cmd_end_render_pass2(cmd, &vk::SubpassEndInfo::default()) };
}

/// What a draw recorder gets for a pass: scene binding for a compute or
/// fullscreen pass, draws for a scene pass. Takes the recording's fields
/// apart from its draw recorder, which the caller lends the result to.
fn raster_context<'a>(
    renderer: &'a Renderer<'_>,
    (at, prep, resources): (PassAt<'a>, &'a Prepared, &'a FrameResources<'_>),
    (cmd, frame): (vk::CommandBuffer, FrameValues),
    render_pass: vk::RenderPass,
) -> RasterContext<'a> {
    RasterContext {
        gpu: renderer.gpu,
        cmd,
        plan: at.plan,
        pass_index: at.index,
        render_pass,
        extent: prep.extent,
        resources,
        frame,
        scene: renderer.scene.as_ref(),
        variants: &prep.variants,
    }
}
