//! Builds of the scene's acceleration structures: no pipeline and no
//! descriptor set; the draw recorder, which holds the scene, records the
//! build or refit ([`crate::draw::DrawRecorder::build_structures`]). The
//! plan's barriers order it after the last frame's ray queries and before
//! this frame's.

use super::{PassKindOps, Recording};
use crate::error::GpuError;
use crate::executor::Renderer;

/// A `BuildAccelerationStructures` pass.
pub(super) struct BuildStructures;

impl PassKindOps for BuildStructures {
    fn record<'g>(
        &self,
        _renderer: &mut Renderer<'g>,
        rec: &mut Recording<'_, 'g>,
    ) -> Result<(), GpuError> {
        rec.draws.build_structures(rec.at.pass, rec.cmd)
    }
}
