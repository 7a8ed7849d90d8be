//! Copies and blits between graph images and buffers: no pipeline, no
//! descriptor set, only the transfer command.

use super::{PassKindOps, Recording};
use crate::error::GpuError;
use crate::executor::Renderer;
use crate::record;

/// A copy (`filtered: false`) or a blit (a scaled, filtered copy).
pub(super) struct Transfer {
    filtered: bool,
}

/// Copies one image or buffer to another of the same size.
pub(super) const COPY: Transfer = Transfer { filtered: false };
/// Blits one image to another.
pub(super) const BLIT: Transfer = Transfer { filtered: true };

impl PassKindOps for Transfer {
    fn record<'g>(
        &self,
        renderer: &mut Renderer<'g>,
        rec: &mut Recording<'_, 'g>,
    ) -> Result<(), GpuError> {
        let at = rec.at;
        record::transfer(
            renderer.gpu,
            rec.cmd,
            at.plan,
            at.pass,
            rec.resources,
            self.filtered,
        )
    }
}
