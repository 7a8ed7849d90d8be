//! Conversions from the plan's Vulkan-valued plain data to `ash` types.

use ash::vk;
use weft_graph::plan::{LoadOp, StoreOp};
use weft_graph::vk::{Access, Aspect, Layout, Stage};

/// Synchronization2 stage mask.
pub fn stage(s: Stage) -> vk::PipelineStageFlags2 {
    vk::PipelineStageFlags2::from_raw(s.bits())
}

/// Synchronization2 access mask.
pub fn access(a: Access) -> vk::AccessFlags2 {
    vk::AccessFlags2::from_raw(a.bits())
}

/// Image layout.
pub fn layout(l: Layout) -> vk::ImageLayout {
    vk::ImageLayout::from_raw(l.raw())
}

/// Aspect mask covering the whole image (barriers, attachments).
pub fn full_aspect(a: Aspect) -> vk::ImageAspectFlags {
    match a {
        Aspect::Color => vk::ImageAspectFlags::COLOR,
        Aspect::Depth => vk::ImageAspectFlags::DEPTH,
        Aspect::DepthStencil => vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL,
    }
}

/// Aspect mask a shader samples or stores through (one aspect only).
pub fn shader_aspect(a: Aspect) -> vk::ImageAspectFlags {
    match a {
        Aspect::Color => vk::ImageAspectFlags::COLOR,
        Aspect::Depth | Aspect::DepthStencil => vk::ImageAspectFlags::DEPTH,
    }
}

/// Attachment load op.
pub fn load_op(op: LoadOp) -> vk::AttachmentLoadOp {
    match op {
        LoadOp::Load => vk::AttachmentLoadOp::LOAD,
        LoadOp::Clear => vk::AttachmentLoadOp::CLEAR,
        LoadOp::DontCare => vk::AttachmentLoadOp::DONT_CARE,
    }
}

/// Attachment store op (`NONE` is core in Vulkan 1.3).
pub fn store_op(op: StoreOp) -> vk::AttachmentStoreOp {
    match op {
        StoreOp::Store => vk::AttachmentStoreOp::STORE,
        StoreOp::DontCare => vk::AttachmentStoreOp::DONT_CARE,
        StoreOp::None => vk::AttachmentStoreOp::NONE,
    }
}

/// Sample count flag for a count of 1, 2, 4, ... samples.
pub fn samples(n: u32) -> vk::SampleCountFlags {
    vk::SampleCountFlags::from_raw(n.max(1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_match_vulkan() {
        assert_eq!(stage(Stage::COPY), vk::PipelineStageFlags2::COPY);
        assert_eq!(
            stage(Stage::COLOR_ATTACHMENT_OUTPUT),
            vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT
        );
        assert_eq!(
            access(Access::SHADER_STORAGE_WRITE),
            vk::AccessFlags2::SHADER_STORAGE_WRITE
        );
        assert_eq!(
            layout(Layout::DepthStencilReadOnlyOptimal),
            vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL
        );
        assert_eq!(samples(4), vk::SampleCountFlags::TYPE_4);
    }
}
