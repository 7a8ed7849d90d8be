//! Recording one prepared pass: its label and barriers, then its kind's
//! work through the dispatch table ([`super::kinds::of`]).

use super::kinds::{self, PassAt, Recording};
use super::{FrameOptions, Prepared, Renderer};
use crate::draw::DrawRecorder;
use crate::error::GpuError;
use crate::frame::Label;
use crate::record;
use crate::resources::FrameResources;
use ash::vk;
use weft_graph::plan::PlanPass;

impl<'g> Renderer<'g> {
    pub(super) fn record_pass(
        &mut self,
        at: PassAt<'_>,
        prep: &mut Prepared,
        resources: &FrameResources<'g>,
        (draws, options): (&mut dyn DrawRecorder, &FrameOptions),
        cmd: vk::CommandBuffer,
    ) -> Result<(), GpuError> {
        let device = self.gpu.device();
        let frame = options.frame_values(prep.extent, 0);
        let label = Label::begin(self.gpu, cmd, &at.pass.name);
        record::barriers(device, cmd, &at.pass.barriers, resources)?;
        if self.traces(at.pass) {
            record::scene_counter_barrier(device, cmd);
        }
        let mut rec = Recording {
            at,
            prep,
            resources,
            draws,
            options,
            cmd,
            frame,
        };
        let result = kinds::of(at.pass).record(self, &mut rec);
        label.end(self.gpu, cmd);
        result
    }

    /// Whether `pass` traces rays, and so adds to the scene's ray counters.
    pub(super) fn traces(&self, pass: &PlanPass) -> bool {
        self.scene
            .as_ref()
            .is_some_and(|scene| (scene.interface.traces)(pass))
    }

    /// Binds the pass's own pipeline, its descriptor set and push constants.
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
