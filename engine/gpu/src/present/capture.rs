//! The host-visible buffer a presented image is copied into for a
//! screenshot, and its bytes read back as a [`Readback`].

use super::color_layers;
use crate::buffer::Buffer;
use crate::context::Gpu;
use crate::error::GpuError;
use crate::readback::{self, Readback};
use ash::vk;
use gpu_allocator::MemoryLocation;

/// The name `readback::decode` knows a swapchain format by.
fn format_name(format: vk::Format) -> Option<&'static str> {
    match format {
        vk::Format::B8G8R8A8_SRGB => Some("B8G8R8A8_SRGB"),
        vk::Format::B8G8R8A8_UNORM => Some("B8G8R8A8_UNORM"),
        vk::Format::R8G8B8A8_SRGB => Some("R8G8B8A8_SRGB"),
        vk::Format::R8G8B8A8_UNORM => Some("R8G8B8A8_UNORM"),
        _ => None,
    }
}

/// A host-visible buffer a presented image is copied into.
pub(super) struct CaptureBuffer<'g> {
    gpu: &'g Gpu,
    buffer: Buffer<'g>,
    extent: vk::Extent2D,
}

impl<'g> CaptureBuffer<'g> {
    pub(super) fn new(gpu: &'g Gpu, extent: vk::Extent2D) -> Result<Self, GpuError> {
        let size = u64::from(extent.width) * u64::from(extent.height) * 4;
        let buffer = Buffer::new(
            gpu,
            "the screenshot buffer",
            size,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        Ok(Self {
            gpu,
            buffer,
            extent,
        })
    }

    /// Copies the buffer's extent of `image` (in `TRANSFER_SRC_OPTIMAL`,
    /// from its top-left corner) and makes it visible to the host.
    pub(super) fn record(&self, cmd: vk::CommandBuffer, image: vk::Image) {
        let extent = self.extent;
        let regions = [vk::BufferImageCopy2::default()
            .image_subresource(color_layers())
            .image_extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth: 1,
            })];
        let copy = vk::CopyImageToBufferInfo2::default()
            .src_image(image)
            .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .dst_buffer(self.buffer.buffer)
            .regions(&regions);
        let host = [vk::BufferMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COPY)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::HOST)
            .dst_access_mask(vk::AccessFlags2::HOST_READ)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(self.buffer.buffer)
            .offset(0)
            .size(vk::WHOLE_SIZE)];
        let device = self.gpu.device();
        unsafe {
            device.cmd_copy_image_to_buffer2(cmd, &copy);
            device.cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().buffer_memory_barriers(&host),
            );
        }
    }

    /// The copied pixels as RGBA (after the submission finished).
    pub(super) fn read(&self, format: vk::Format) -> Result<Readback, GpuError> {
        let name = format_name(format).ok_or_else(|| {
            GpuError::Plan(format!("cannot read back swapchain format {format:?}"))
        })?;
        let size = self.extent.width as usize * self.extent.height as usize * 4;
        let bytes = &self.buffer.mapped()?[..size];
        let pixels = readback::decode(name, bytes).map_err(|e| GpuError::Plan(e.to_string()))?;
        Ok(Readback {
            width: self.extent.width,
            height: self.extent.height,
            format: name.to_string(),
            pixels,
        })
    }
}
