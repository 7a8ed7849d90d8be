//! `VkRenderPass` objects built from the plan's render-pass descriptions
//! (vkCreateRenderPass2), cached by everything that makes two passes
//! compatible, plus framebuffers over a frame's image views.

use crate::convert;
use crate::error::{GpuError, VkCall};
use ash::vk;
use std::collections::HashMap;
use weft_graph::plan::{AttachmentDesc, RenderPassDesc};
use weft_graph::vk::Layout;

/// What identifies a render pass: attachment formats, sample counts, ops and
/// layouts (clear values and sizes are not part of it).
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct RenderPassKey {
    /// (format, samples, load op, store op, initial, subpass and final layout), as Vulkan values.
    attachments: Vec<(i32, u32, i32, i32, Layout, Layout, Layout)>,
    color: Vec<usize>,
    resolve: Vec<Option<usize>>,
    depth: Option<usize>,
}

impl RenderPassKey {
    /// The key of a plan's render pass.
    pub fn of(desc: &RenderPassDesc) -> Self {
        Self {
            attachments: desc
                .attachments
                .iter()
                .map(|a| {
                    (
                        a.format_raw,
                        a.samples,
                        convert::load_op(a.load).as_raw(),
                        convert::store_op(a.store).as_raw(),
                        a.initial_layout,
                        a.layout,
                        a.final_layout,
                    )
                })
                .collect(),
            color: desc.color.clone(),
            resolve: desc.resolve.clone(),
            depth: desc.depth,
        }
    }
}

/// Render passes by key, destroyed with the cache.
#[derive(Default)]
pub struct RenderPassCache {
    passes: HashMap<RenderPassKey, vk::RenderPass>,
}

impl RenderPassCache {
    /// The render pass for a description, created on first use.
    pub fn get(
        &mut self,
        device: &ash::Device,
        desc: &RenderPassDesc,
    ) -> Result<vk::RenderPass, GpuError> {
        let key = RenderPassKey::of(desc);
        if let Some(&pass) = self.passes.get(&key) {
            return Ok(pass);
        }
        let pass = create(device, desc)?;
        self.passes.insert(key, pass);
        Ok(pass)
    }

    /// Number of distinct render passes created.
    pub fn len(&self) -> usize {
        self.passes.len()
    }

    /// Whether no render pass was created yet.
    pub fn is_empty(&self) -> bool {
        self.passes.is_empty()
    }

    /// Destroys every render pass.
    pub fn destroy(&mut self, device: &ash::Device) {
        for (_, pass) in self.passes.drain() {
            unsafe { device.destroy_render_pass(pass, None) };
        }
    }
}

fn attachment(a: &AttachmentDesc) -> vk::AttachmentDescription2<'static> {
    vk::AttachmentDescription2::default()
        .format(vk::Format::from_raw(a.format_raw))
        .samples(convert::samples(a.samples))
        .load_op(convert::load_op(a.load))
        .store_op(convert::store_op(a.store))
        .stencil_load_op(convert::load_op(a.load))
        .stencil_store_op(convert::store_op(a.store))
        .initial_layout(convert::layout(a.initial_layout))
        .final_layout(convert::layout(a.final_layout))
}

fn create(device: &ash::Device, desc: &RenderPassDesc) -> Result<vk::RenderPass, GpuError> {
    let attachments: Vec<_> = desc.attachments.iter().map(attachment).collect();
    let reference = |i: usize| -> Result<vk::AttachmentReference2<'static>, GpuError> {
        let a = desc
            .attachments
            .get(i)
            .ok_or_else(|| GpuError::Plan(format!("render pass attachment {i} does not exist")))?;
        Ok(vk::AttachmentReference2::default()
            .attachment(i as u32)
            .layout(convert::layout(a.layout))
            .aspect_mask(vk::ImageAspectFlags::empty()))
    };
    let color: Vec<_> = desc
        .color
        .iter()
        .map(|&i| reference(i))
        .collect::<Result<_, _>>()?;
    // One entry per colour attachment: the attachment it resolves into, or
    // none (VK_ATTACHMENT_UNUSED).
    let resolve: Vec<_> = desc
        .resolve
        .iter()
        .map(|target| match target {
            Some(i) => reference(*i),
            None => Ok(vk::AttachmentReference2::default()
                .attachment(vk::ATTACHMENT_UNUSED)
                .layout(vk::ImageLayout::UNDEFINED)),
        })
        .collect::<Result<_, _>>()?;
    let depth = desc.depth.map(reference).transpose()?;
    let mut subpass = vk::SubpassDescription2::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&color);
    if desc.resolve.iter().any(Option::is_some) {
        subpass = subpass.resolve_attachments(&resolve);
    }
    if let Some(depth) = &depth {
        subpass = subpass.depth_stencil_attachment(depth);
    }
    let subpasses = [subpass];
    let info = vk::RenderPassCreateInfo2::default()
        .attachments(&attachments)
        .subpasses(&subpasses);
    unsafe { device.create_render_pass2(&info, None) }.call("vkCreateRenderPass2")
}

/// Creates a framebuffer over the given views.
pub fn framebuffer(
    device: &ash::Device,
    pass: vk::RenderPass,
    views: &[vk::ImageView],
    width: u32,
    height: u32,
) -> Result<vk::Framebuffer, GpuError> {
    let info = vk::FramebufferCreateInfo::default()
        .render_pass(pass)
        .attachments(views)
        .width(width)
        .height(height)
        .layers(1);
    unsafe { device.create_framebuffer(&info, None) }.call("vkCreateFramebuffer")
}
