//! Copies the output image into host-visible memory after the epilogue and
//! decodes it.

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use crate::readback::{self, Readback};
use crate::resources::FrameResources;
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use weft_graph::id::ResourceId;
use weft_graph::plan::{Plan, ResourceDesc};

/// A host-visible buffer the output image is copied into.
pub(crate) struct ReadbackBuffer<'g> {
    gpu: &'g Gpu,
    /// The image copied: the output or one of `Plan::readback`.
    resource: ResourceId,
    buffer: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
}

impl<'g> ReadbackBuffer<'g> {
    /// The bytes `resource` of `plan` takes when read back.
    fn bytes(plan: &Plan, resource: ResourceId) -> Result<u64, GpuError> {
        let ResourceDesc::Image(desc) = &plan
            .resources
            .get(resource)
            .ok_or_else(|| GpuError::Plan("the image to read back does not exist".into()))?
            .desc
        else {
            return Err(GpuError::Plan("only images can be read back".into()));
        };
        let texel = readback::texel_bytes(&desc.format).ok_or_else(|| {
            GpuError::Plan(format!(
                "cannot read back \"{}\" of format {}",
                plan.resources[resource].name, desc.format
            ))
        })?;
        Ok(u64::from(desc.extent.width) * u64::from(desc.extent.height) * u64::from(texel))
    }

    pub(crate) fn new(gpu: &'g Gpu, plan: &Plan, resource: ResourceId) -> Result<Self, GpuError> {
        let size = Self::bytes(plan, resource)?;
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(vk::BufferUsageFlags::TRANSFER_DST)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let buffer = unsafe { gpu.device().create_buffer(&info, None) }.call("vkCreateBuffer")?;
        let mut this = Self {
            gpu,
            resource,
            buffer,
            allocation: None,
            size,
        };
        let requirements = unsafe { gpu.device().get_buffer_memory_requirements(buffer) };
        let allocation = gpu
            .allocator()
            .allocate(&AllocationCreateDesc {
                name: "readback",
                requirements,
                location: MemoryLocation::GpuToCpu,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| GpuError::Allocation {
                what: "the readback buffer".into(),
                message: e.to_string(),
            })?;
        unsafe {
            gpu.device()
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())
        }
        .call("vkBindBufferMemory")?;
        this.allocation = Some(allocation);
        Ok(this)
    }

    /// Copies the image (in TRANSFER_SRC_OPTIMAL after the epilogue) into
    /// the buffer and makes the bytes visible to the host.
    /// Whether this buffer can take `resource` of `plan`: the same image,
    /// of the same size in bytes.
    pub(crate) fn fits(&self, plan: &Plan, resource: ResourceId) -> bool {
        self.resource == resource
            && Self::bytes(plan, resource).is_ok_and(|bytes| bytes == self.size)
    }

    pub(crate) fn record(
        &self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        resources: &FrameResources<'_>,
    ) -> Result<(), GpuError> {
        let img = resources.image(self.resource)?;
        let region = vk::BufferImageCopy2::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D {
                width: img.desc.extent.width,
                height: img.desc.extent.height,
                depth: 1,
            });
        let regions = [region];
        let info = vk::CopyImageToBufferInfo2::default()
            .src_image(img.image)
            .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .dst_buffer(self.buffer)
            .regions(&regions);
        let host = [vk::BufferMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COPY)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::HOST)
            .dst_access_mask(vk::AccessFlags2::HOST_READ)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(self.buffer)
            .offset(0)
            .size(vk::WHOLE_SIZE)];
        unsafe {
            gpu.device().cmd_copy_image_to_buffer2(cmd, &info);
            gpu.device().cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().buffer_memory_barriers(&host),
            );
        }
        Ok(())
    }

    pub(crate) fn read(&self, plan: &Plan) -> Result<Readback, GpuError> {
        let ResourceDesc::Image(desc) = &plan.resources[self.resource].desc else {
            return Err(GpuError::Plan("only images can be read back".into()));
        };
        let bytes = self
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .and_then(|s| s.get(..self.size as usize))
            .ok_or_else(|| GpuError::Allocation {
                what: "the readback buffer".into(),
                message: "memory is not host-mapped".into(),
            })?;
        let pixels =
            readback::decode(&desc.format, bytes).map_err(|e| GpuError::Plan(e.to_string()))?;
        Ok(Readback {
            width: desc.extent.width,
            height: desc.extent.height,
            format: desc.format.clone(),
            pixels,
        })
    }
}

impl Drop for ReadbackBuffer<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_buffer(self.buffer, None) };
        if let Some(a) = self.allocation.take() {
            // Freeing only fails for allocations this allocator did not make.
            let _ = self.gpu.allocator().free(a);
        }
    }
}
