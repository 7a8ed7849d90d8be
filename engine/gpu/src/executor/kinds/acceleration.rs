//! Builds of the scene's acceleration structures: no pipeline and no
//! descriptor set; the draw recorder, which holds the scene, records the
//! build or refit ([`crate::draw::DrawRecorder::build_structures`]) in the
//! pass's scratch buffer (`PlanPass::scratch`, transient memory of the
//! plan's). The plan's barriers order it after the last frame's ray queries
//! and before this frame's.

use super::{PassKindOps, Recording};
use crate::acceleration::ScratchSpan;
use crate::error::GpuError;
use crate::executor::Renderer;
use ash::vk;

/// A `BuildAccelerationStructures` pass.
pub(super) struct BuildStructures;

impl PassKindOps for BuildStructures {
    fn record<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        rec: &mut Recording<'_, 'g>,
    ) -> Result<(), GpuError> {
        let pass = rec.at.pass;
        let id = pass.scratch.ok_or_else(|| GpuError::Pass {
            pass: pass.name.clone(),
            message: "builds acceleration structures without a scratch buffer".into(),
        })?;
        let scratch = rec.resources.buffer(id)?;
        let info = vk::BufferDeviceAddressInfo::default().buffer(scratch.buffer);
        let gpu = renderer.gpu();
        let address = unsafe { gpu.device().get_buffer_device_address(&info) };
        let span = ScratchSpan::within(gpu, address, scratch.desc.size);
        rec.draws.build_structures(pass, rec.cmd, span)
    }
}
