//! Recording one prepared pass: its barriers, then a copy, a dispatch, a
//! fullscreen triangle or the draw recorder's scene draws inside its render pass.

use super::{FrameOptions, Prepared, Renderer};
use crate::bind::{FrameValues, REPEAT_INDEX};
use crate::descriptors::DescriptorPool;
use crate::draw::{DrawRecorder, RasterContext, ScenePass};
use crate::error::GpuError;
use crate::frame::Label;
use crate::record;
use crate::resources::FrameResources;
use crate::sets::SCENE_SET;
use ash::vk;
use weft_graph::id::PassId;
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::resolve::INDIRECT_RECORD_BYTES;
use weft_graph::schema::PassKind;

impl<'g> Renderer<'g> {
    pub(super) fn record_pass(
        &mut self,
        (plan, index, pass): (&Plan, PassId, &PlanPass),
        (prep, scene_pool): (&mut Prepared, Option<&DescriptorPool<'g>>),
        resources: &FrameResources<'g>,
        (draws, options): (&mut dyn DrawRecorder, &FrameOptions),
        cmd: vk::CommandBuffer,
    ) -> Result<(), GpuError> {
        let gpu = self.gpu;
        let device = gpu.device();
        let frame = FrameValues {
            time: options.time,
            frame: options.frame,
            extent: [prep.extent.width, prep.extent.height],
            history_frames: options.history_frames,
            plan_frames: options.plan_frames,
            repeat_index: 0,
        };
        let label = Label::begin(self.gpu, cmd, &pass.name);
        record::barriers(device, cmd, &pass.barriers, resources)?;
        if self.traces(pass) {
            record::scene_counter_barrier(device, cmd);
        }
        let result = match pass.kind {
            PassKind::Copy => record::transfer(self.gpu, cmd, plan, pass, resources, false),
            PassKind::Blit => record::transfer(self.gpu, cmd, plan, pass, resources, true),
            PassKind::Compute => {
                let dispatch = dispatch_source(pass, resources)?;
                self.bind(cmd, prep);
                // A compute pass that reads scene data (tiled light culling reads the
                // camera and the lights) gets set 1 from the draw recorder, as a
                // fullscreen pass does; there is no render pass around it.
                let scene = prep
                    .pipeline
                    .as_ref()
                    .filter(|p| p.interface.bindings.keys().any(|(s, _)| *s == SCENE_SET));
                let bound = match scene {
                    Some(p) => draws.bind_scene(
                        &RasterContext {
                            gpu,
                            cmd,
                            plan,
                            pass_index: index,
                            render_pass: vk::RenderPass::null(),
                            extent: prep.extent,
                            resources,
                            frame,
                            scene: None,
                        },
                        p,
                    ),
                    None => Ok(()),
                };
                bound.and_then(|()| self.dispatch(cmd, pass, prep, (resources, options), dispatch))
            }
            PassKind::Fullscreen | PassKind::Raster => {
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
                let pipeline = prep.pipeline.clone();
                if pipeline.is_some() {
                    self.bind(cmd, prep);
                }
                let scene = match (&pipeline, &self.scene) {
                    (None, Some(scene)) => Some(ScenePass {
                        pipelines: &mut self.pipelines,
                        scene,
                        samplers: &self.samplers,
                        variants: &mut prep.variants,
                        pool: scene_pool,
                    }),
                    _ => None,
                };
                let mut ctx = RasterContext {
                    gpu,
                    cmd,
                    plan,
                    pass_index: index,
                    render_pass: prep.render_pass,
                    extent: prep.extent,
                    resources,
                    frame,
                    scene,
                };
                let drawn = match &pipeline {
                    Some(p) => {
                        let scene = p.interface.bindings.keys().any(|(s, _)| *s == SCENE_SET);
                        let bound = if scene {
                            draws.bind_scene(&ctx, p)
                        } else {
                            Ok(())
                        };
                        bound.map(|()| unsafe { device.cmd_draw(cmd, 3, 1, 0, 0) })
                    }
                    None => draws.record(&mut ctx),
                };
                unsafe { device.cmd_end_render_pass2(cmd, &vk::SubpassEndInfo::default()) };
                drawn
            }
        };
        label.end(self.gpu, cmd);
        result
    }

    /// A compute pass's dispatches: one, or `repeat` in a row with the pass's
    /// repeat barriers between them and, where the shader reads it, each
    /// one's `repeat_index` pushed (the other push constants stay bound).
    fn dispatch(
        &self,
        cmd: vk::CommandBuffer,
        pass: &PlanPass,
        prep: &Prepared,
        (resources, options): (&FrameResources<'g>, &FrameOptions),
        groups: DispatchSource,
    ) -> Result<(), GpuError> {
        let device = self.gpu.device();
        for repeat_index in 0..pass.repeat.max(1) {
            if repeat_index > 0 {
                record::barriers(device, cmd, &pass.repeat_barriers, resources)?;
                if self.traces(pass) {
                    record::scene_counter_barrier(device, cmd);
                }
                if let Some((p, (_, stages))) = prep
                    .pipeline
                    .as_ref()
                    .and_then(|p| p.interface.push.as_ref().map(|push| (p, push)))
                    .filter(|(_, (block, _))| block.members.iter().any(|m| m.name == REPEAT_INDEX))
                {
                    let push = self.pack_push(pass, prep, options, repeat_index)?;
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

    /// Whether `pass` traces rays, and so adds to the scene's ray counters.
    fn traces(&self, pass: &PlanPass) -> bool {
        self.scene
            .as_ref()
            .is_some_and(|scene| (scene.interface.traces)(pass))
    }

    pub(super) fn bind(&self, cmd: vk::CommandBuffer, prep: &Prepared) {
        let Some(p) = &prep.pipeline else {
            return;
        };
        let device = self.gpu.device();
        unsafe {
            device.cmd_bind_pipeline(cmd, p.bind_point, p.pipeline);
            if prep.set != vk::DescriptorSet::null() {
                device.cmd_bind_descriptor_sets(cmd, p.bind_point, p.layout, 0, &[prep.set], &[]);
            }
            if let Some((_, stages)) = &p.interface.push {
                device.cmd_push_constants(cmd, p.layout, *stages, 0, &prep.push);
            }
        }
    }
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
