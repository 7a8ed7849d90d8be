//! How the GPU sees each use a pass makes of a resource: the pipeline
//! stages, the access bits and the image layout the barriers in `state`
//! order it by.

use super::state::{sampled_layout, shader_stages, GpuAccess};
use crate::compile::order::PassUse;
use crate::id::IrPassId;
use crate::resolve::{Ir, IrKind, Usage};
use crate::schema::{LoadDecl, PassKind};
use crate::vk::{Access, Layout, Stage};

/// How the GPU sees a pass's merged use of a resource.
pub(super) fn gpu_access(ir: &Ir, pass: IrPassId, u: &PassUse) -> GpuAccess {
    let p = &ir.passes[pass];
    let aspect = match ir.resources[u.resource].kind {
        IrKind::Image { format, .. } => Some(format.aspect),
        IrKind::AccelerationStructure => return structure_access(p.kind, u),
        // A build's scratch is accessed as the structures are.
        IrKind::Buffer { .. } if p.kind == PassKind::BuildAccelerationStructures => {
            return structure_access(p.kind, u)
        }
        IrKind::Buffer { .. } | IrKind::External => None,
    };
    let mut stage = Stage::empty();
    let mut access = Access::empty();
    let mut layout = Layout::General;
    for &a in &u.accesses {
        let (s, acc, l) = match &p.accesses[a].usage {
            Usage::Sampled => match aspect {
                Some(aspect) => (
                    image_read_stages(p.kind),
                    Access::SHADER_SAMPLED_READ,
                    sampled_layout(aspect),
                ),
                None => (shader_stages(p.kind), Access::UNIFORM_READ, Layout::General),
            },
            Usage::StorageRead => (
                shader_stages(p.kind),
                Access::SHADER_STORAGE_READ,
                Layout::General,
            ),
            Usage::StorageWrite => (
                shader_stages(p.kind),
                Access::SHADER_STORAGE_WRITE,
                Layout::General,
            ),
            Usage::Color { load, .. } => {
                let read = if *load == LoadDecl::Load {
                    Access::COLOR_ATTACHMENT_READ
                } else {
                    Access::empty()
                };
                (
                    Stage::COLOR_ATTACHMENT_OUTPUT,
                    Access::COLOR_ATTACHMENT_WRITE | read,
                    Layout::ColorAttachmentOptimal,
                )
            }
            Usage::Depth {
                read_only: true, ..
            } => (
                Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS,
                Access::DEPTH_STENCIL_ATTACHMENT_READ,
                Layout::DepthStencilReadOnlyOptimal,
            ),
            Usage::Depth { .. } => (
                Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS,
                Access::DEPTH_STENCIL_ATTACHMENT_READ | Access::DEPTH_STENCIL_ATTACHMENT_WRITE,
                Layout::DepthStencilAttachmentOptimal,
            ),
            Usage::TransferSrc => (
                shader_stages(p.kind),
                Access::TRANSFER_READ,
                Layout::TransferSrcOptimal,
            ),
            Usage::TransferDst => (
                shader_stages(p.kind),
                Access::TRANSFER_WRITE,
                Layout::TransferDstOptimal,
            ),
            Usage::IndirectRead => (
                Stage::DRAW_INDIRECT,
                Access::INDIRECT_COMMAND_READ,
                Layout::General,
            ),
        };
        stage |= s;
        access |= acc;
        layout = l;
    }
    if aspect.is_none() {
        layout = Layout::General;
    }
    GpuAccess {
        stage,
        access,
        layout,
        discards: u.discards,
    }
}

/// How the GPU sees a use of the scene's acceleration structures: a build
/// (or refit, which reads what it rewrites) at the build stage, with its
/// scratch buffer (read and written with the same access bits), or ray
/// queries in the shaders of a pass that traces. The structures live in the
/// scene's buffers, so the barriers are memory barriers with no layout.
fn structure_access(kind: PassKind, u: &PassUse) -> GpuAccess {
    let (stage, access) = if kind == PassKind::BuildAccelerationStructures {
        (
            Stage::ACCELERATION_STRUCTURE_BUILD,
            Access::ACCELERATION_STRUCTURE_READ | Access::ACCELERATION_STRUCTURE_WRITE,
        )
    } else {
        (shader_stages(kind), Access::ACCELERATION_STRUCTURE_READ)
    };
    GpuAccess {
        stage,
        access,
        layout: Layout::General,
        discards: u.discards,
    }
}

/// Images are sampled in fragment shaders in raster passes (vertex shaders read buffers).
fn image_read_stages(kind: PassKind) -> Stage {
    match kind {
        PassKind::Raster => Stage::FRAGMENT_SHADER,
        other => shader_stages(other),
    }
}
