//! The images and buffers of a plan. Transient images and buffers are bound at
//! the plan's offsets inside one allocation per memory block, so aliasing is real;
//! history and output resources get their own memory and are put in their
//! frame-start layout once, at creation.

use crate::context::Gpu;
use crate::convert;
use crate::error::{GpuError, VkCall};
use crate::renderpass;
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::collections::HashMap;
use weft_graph::id::ResourceId;
use weft_graph::plan::{BufferDesc, ImageDesc, Plan, PlanResource, Residency, ResourceDesc};
use weft_graph::vk::{Aspect, Layout};
use weft_graph::MemoryRequirements;

/// A created image with the views passes need.
#[derive(Debug)]
pub struct GpuImage {
    /// The image.
    pub image: vk::Image,
    /// View over every aspect, for attachments.
    pub attachment_view: vk::ImageView,
    /// Single-aspect view for sampling and storage (the same handle for colour).
    pub shader_view: vk::ImageView,
    /// What it was created from.
    pub desc: ImageDesc,
}

/// A created buffer.
#[derive(Debug)]
pub struct GpuBuffer {
    /// The buffer.
    pub buffer: vk::Buffer,
    /// What it was created from.
    pub desc: BufferDesc,
}

/// One plan resource on the device.
#[derive(Debug)]
pub enum GpuResource {
    /// An image resource.
    Image(GpuImage),
    /// A buffer resource.
    Buffer(GpuBuffer),
    /// The scene's acceleration structures: nothing of the plan's own, only
    /// a resource its barriers name (as memory barriers).
    AccelerationStructure,
}

/// The device objects for one plan, destroyed on drop.
pub struct FrameResources<'g> {
    gpu: &'g Gpu,
    resources: Vec<GpuResource>,
    /// Own allocations of non-aliased resources, and one per transient block.
    allocations: Vec<Allocation>,
    /// Framebuffers over these resources' views, by render pass and views.
    framebuffers: HashMap<(vk::RenderPass, Vec<vk::ImageView>), vk::Framebuffer>,
    /// Bytes of the shared transient blocks (aliased resources count once).
    pub transient_bytes: u64,
    /// Bytes of resources with memory of their own (history and output
    /// images and buffers).
    pub dedicated_bytes: u64,
    /// Tells these resources apart from any others made in this process,
    /// so the executor knows what a prepared plan was prepared on.
    pub(crate) id: u64,
}

/// The next [`FrameResources::id`].
static NEXT_RESOURCES_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

/// The memory requirements the device reports for an image, without creating
/// it (maintenance4); pass this to the graph compiler so placements are exact.
pub fn image_requirements(gpu: &Gpu, desc: &ImageDesc) -> MemoryRequirements {
    let info = image_info(desc, false);
    let query = vk::DeviceImageMemoryRequirements::default().create_info(&info);
    let mut out = vk::MemoryRequirements2::default();
    unsafe {
        gpu.device()
            .get_device_image_memory_requirements(&query, &mut out)
    };
    MemoryRequirements {
        size: out.memory_requirements.size,
        alignment: out.memory_requirements.alignment,
    }
}

/// The memory requirements the device reports for a plan's buffer, without
/// creating it (maintenance4), rounded out to `bufferImageGranularity` at
/// both ends: a transient buffer shares its allocation with images, and
/// none may share a page of that size with one.
pub fn buffer_requirements(gpu: &Gpu, desc: &BufferDesc) -> MemoryRequirements {
    let info = vk::BufferCreateInfo::default()
        .size(desc.size.max(1))
        .usage(vk::BufferUsageFlags::from_raw(desc.usage.bits()))
        .sharing_mode(vk::SharingMode::EXCLUSIVE);
    let query = vk::DeviceBufferMemoryRequirements::default().create_info(&info);
    let mut out = vk::MemoryRequirements2::default();
    unsafe {
        gpu.device()
            .get_device_buffer_memory_requirements(&query, &mut out)
    };
    let page = gpu.info().buffer_image_granularity.max(1);
    let alignment = out.memory_requirements.alignment.max(page);
    MemoryRequirements {
        size: out.memory_requirements.size.next_multiple_of(alignment),
        alignment,
    }
}

/// The device's requirements as the closure
/// `weft_graph::CompileOptions::memory` takes: [`image_requirements`] and
/// [`buffer_requirements`]. An image larger than the device allows is not
/// asked of the device (that would be invalid usage) but estimated;
/// [`oversized_images`] then refuses the plan.
pub fn memory_requirements(gpu: &Gpu) -> impl Fn(&ResourceDesc) -> MemoryRequirements + '_ {
    move |desc| match desc {
        ResourceDesc::Image(image) if fits(gpu, image) => image_requirements(gpu, image),
        ResourceDesc::Buffer(buffer) => buffer_requirements(gpu, buffer),
        other => weft_graph::estimate_requirements(other),
    }
}

fn fits(gpu: &Gpu, desc: &ImageDesc) -> bool {
    let max = gpu.info().max_image_dimension;
    desc.extent.width <= max && desc.extent.height <= max
}

/// The plan's images wider or taller than the device's
/// `maxImageDimension2D`: their names and extents.
pub fn oversized_images(gpu: &Gpu, plan: &Plan) -> Vec<(String, [u32; 2])> {
    plan.resources
        .iter()
        .filter_map(|r| match &r.desc {
            ResourceDesc::Image(desc) if !fits(gpu, desc) => {
                Some((r.name.clone(), [desc.extent.width, desc.extent.height]))
            }
            _ => None,
        })
        .collect()
}

/// The plan's images with a sample count the device's attachments cannot
/// have (`DeviceInfo::attachment_sample_counts`): their names and counts.
pub fn unsupported_sample_counts(gpu: &Gpu, plan: &Plan) -> Vec<(String, u32)> {
    let mask = gpu.info().attachment_sample_counts;
    plan.resources
        .iter()
        .filter_map(|r| match &r.desc {
            ResourceDesc::Image(desc) if desc.samples > 1 && mask & desc.samples == 0 => {
                Some((r.name.clone(), desc.samples))
            }
            _ => None,
        })
        .collect()
}

fn image_info(desc: &ImageDesc, output: bool) -> vk::ImageCreateInfo<'static> {
    let mut usage = vk::ImageUsageFlags::from_raw(desc.usage.bits());
    if output {
        usage |= vk::ImageUsageFlags::TRANSFER_SRC;
    }
    vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(vk::Format::from_raw(desc.format_raw))
        .extent(vk::Extent3D {
            width: desc.extent.width,
            height: desc.extent.height,
            depth: 1,
        })
        .mip_levels(desc.mips.max(1))
        .array_layers(desc.layers.max(1))
        .samples(convert::samples(desc.samples))
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(usage)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
}

impl<'g> FrameResources<'g> {
    /// Creates every resource of the plan and binds its memory.
    pub fn new(gpu: &'g Gpu, plan: &Plan) -> Result<Self, GpuError> {
        let mut this = Self {
            gpu,
            resources: Vec::with_capacity(plan.resources.len()),
            allocations: Vec::new(),
            framebuffers: HashMap::new(),
            transient_bytes: 0,
            dedicated_bytes: 0,
            id: NEXT_RESOURCES_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
        };
        for r in &plan.resources {
            let created = match &r.desc {
                ResourceDesc::Image(desc) => this.create_image(r, desc)?,
                ResourceDesc::Buffer(desc) => this.create_buffer(r, desc)?,
                ResourceDesc::AccelerationStructure => GpuResource::AccelerationStructure,
            };
            this.resources.push(created);
        }
        this.bind_memory(plan)?;
        for (r, created) in plan.resources.iter().zip(&mut this.resources) {
            if let GpuResource::Image(img) = created {
                let (attachment, shader) = create_views(gpu, img.image, &img.desc)?;
                img.attachment_view = attachment;
                img.shader_view = shader;
                gpu.set_name(img.image, &r.name);
            }
        }
        this.initial_layouts(plan)?;
        Ok(this)
    }

    /// A plan resource's GPU object.
    pub fn get(&self, id: ResourceId) -> Option<&GpuResource> {
        self.resources.get(id.index())
    }

    /// A plan image, or an error naming what was expected.
    pub fn image(&self, id: ResourceId) -> Result<&GpuImage, GpuError> {
        match self.get(id) {
            Some(GpuResource::Image(i)) => Ok(i),
            _ => Err(GpuError::Plan(format!("resource {id} is not an image"))),
        }
    }

    /// A plan buffer, or an error naming what was expected.
    pub fn buffer(&self, id: ResourceId) -> Result<&GpuBuffer, GpuError> {
        match self.get(id) {
            Some(GpuResource::Buffer(b)) => Ok(b),
            _ => Err(GpuError::Plan(format!("resource {id} is not a buffer"))),
        }
    }

    /// The framebuffer of a render pass over these views, created on first use.
    pub fn framebuffer(
        &mut self,
        pass: vk::RenderPass,
        views: Vec<vk::ImageView>,
        extent: vk::Extent2D,
    ) -> Result<vk::Framebuffer, GpuError> {
        let key = (pass, views);
        if let Some(&fb) = self.framebuffers.get(&key) {
            return Ok(fb);
        }
        let fb =
            renderpass::framebuffer(self.gpu.device(), pass, &key.1, extent.width, extent.height)?;
        self.framebuffers.insert(key, fb);
        Ok(fb)
    }

    fn create_image(&self, r: &PlanResource, desc: &ImageDesc) -> Result<GpuResource, GpuError> {
        let info = image_info(desc, r.residency == Residency::Output);
        let image = unsafe { self.gpu.device().create_image(&info, None) }.call("vkCreateImage")?;
        Ok(GpuResource::Image(GpuImage {
            image,
            attachment_view: vk::ImageView::null(),
            shader_view: vk::ImageView::null(),
            desc: desc.clone(),
        }))
    }

    fn create_buffer(&self, r: &PlanResource, desc: &BufferDesc) -> Result<GpuResource, GpuError> {
        let info = vk::BufferCreateInfo::default()
            .size(desc.size.max(1))
            .usage(vk::BufferUsageFlags::from_raw(desc.usage.bits()))
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let buffer =
            unsafe { self.gpu.device().create_buffer(&info, None) }.call("vkCreateBuffer")?;
        self.gpu.set_name(buffer, &r.name);
        Ok(GpuResource::Buffer(GpuBuffer {
            buffer,
            desc: desc.clone(),
        }))
    }

    fn requirements(&self, index: usize) -> vk::MemoryRequirements {
        let device = self.gpu.device();
        unsafe {
            match &self.resources[index] {
                GpuResource::Image(i) => device.get_image_memory_requirements(i.image),
                GpuResource::Buffer(b) => device.get_buffer_memory_requirements(b.buffer),
                GpuResource::AccelerationStructure => vk::MemoryRequirements::default(),
            }
        }
    }

    fn allocate(
        &mut self,
        name: &str,
        requirements: vk::MemoryRequirements,
        scheme: AllocationScheme,
    ) -> Result<usize, GpuError> {
        let allocation = self
            .gpu
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: scheme,
            })
            .map_err(|e| GpuError::Allocation {
                what: name.to_string(),
                message: e.to_string(),
            })?;
        match scheme {
            AllocationScheme::GpuAllocatorManaged => self.transient_bytes += requirements.size,
            _ => self.dedicated_bytes += requirements.size,
        }
        self.allocations.push(allocation);
        Ok(self.allocations.len() - 1)
    }

    fn bind(&self, index: usize, allocation: usize, offset: u64) -> Result<(), GpuError> {
        let a = &self.allocations[allocation];
        let (memory, base) = (unsafe { a.memory() }, a.offset());
        let device = self.gpu.device();
        unsafe {
            match &self.resources[index] {
                GpuResource::Image(i) => device
                    .bind_image_memory(i.image, memory, base + offset)
                    .call("vkBindImageMemory"),
                GpuResource::Buffer(b) => device
                    .bind_buffer_memory(b.buffer, memory, base + offset)
                    .call("vkBindBufferMemory"),
                GpuResource::AccelerationStructure => Ok(()),
            }
        }
    }

    /// One allocation per memory block (sized by the plan, of a memory type every
    /// image and buffer placed in it accepts), resources bound at their
    /// placements; the rest get their own memory. Vulkan does not promise that
    /// buffers and optimally tiled images share a memory type; a device where
    /// they share none is refused here with the block named.
    fn bind_memory(&mut self, plan: &Plan) -> Result<(), GpuError> {
        for (b, block) in plan.memory.blocks.iter().enumerate() {
            let mut type_bits = u32::MAX;
            let mut members = Vec::new();
            for (i, r) in plan.resources.iter().enumerate() {
                let Some(p) = r.placement.filter(|p| p.block == b) else {
                    continue;
                };
                let req = self.requirements(i);
                if req.size > p.size
                    || p.offset % req.alignment.max(1) != 0
                    || p.offset + p.size > block.size
                {
                    return Err(GpuError::Plan(format!(
                        "`{}` needs {} bytes aligned to {} but is placed at {}+{} in block {b} of {} bytes; compile with the device's memory requirements",
                        r.name, req.size, req.alignment, p.offset, p.size, block.size
                    )));
                }
                type_bits &= req.memory_type_bits;
                members.push((i, p.offset));
            }
            if members.is_empty() {
                continue;
            }
            if type_bits == 0 {
                return Err(GpuError::Plan(format!(
                    "the resources of memory block {b} have no memory type in common"
                )));
            }
            let requirements = vk::MemoryRequirements {
                size: block.size,
                alignment: block.alignment.max(1),
                memory_type_bits: type_bits,
            };
            let allocation = self.allocate(
                &format!("transient block {b}"),
                requirements,
                AllocationScheme::GpuAllocatorManaged,
            )?;
            for (i, offset) in members {
                self.bind(i, allocation, offset)?;
            }
        }
        for (i, r) in plan.resources.iter().enumerate() {
            if r.placement.is_some() {
                continue;
            }
            let scheme = match &self.resources[i] {
                GpuResource::Image(img) => AllocationScheme::DedicatedImage(img.image),
                GpuResource::Buffer(buf) => AllocationScheme::DedicatedBuffer(buf.buffer),
                GpuResource::AccelerationStructure => continue,
            };
            let allocation = self.allocate(&r.name, self.requirements(i), scheme)?;
            self.bind(i, allocation, 0)?;
        }
        Ok(())
    }

    /// Puts persistent images in the layout a frame expects them in.
    fn initial_layouts(&self, plan: &Plan) -> Result<(), GpuError> {
        let mut barriers = Vec::new();
        for (r, created) in plan.resources.iter().zip(&self.resources) {
            let GpuResource::Image(img) = created else {
                continue;
            };
            if r.residency == Residency::Transient || r.frame_start_layout == Layout::Undefined {
                continue;
            }
            barriers.push(
                vk::ImageMemoryBarrier2::default()
                    .src_stage_mask(vk::PipelineStageFlags2::NONE)
                    .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                    .dst_access_mask(vk::AccessFlags2::MEMORY_READ | vk::AccessFlags2::MEMORY_WRITE)
                    .old_layout(vk::ImageLayout::UNDEFINED)
                    .new_layout(convert::layout(r.frame_start_layout))
                    .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                    .image(img.image)
                    .subresource_range(full_range(&img.desc)),
            );
        }
        if barriers.is_empty() {
            return Ok(());
        }
        self.gpu.one_shot(|cmd| {
            let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
            unsafe { self.gpu.device().cmd_pipeline_barrier2(cmd, &dep) };
            Ok(())
        })
    }
}

/// Every mip and layer of an image, all aspects.
pub fn full_range(desc: &ImageDesc) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: convert::full_aspect(desc.aspect),
        base_mip_level: 0,
        level_count: vk::REMAINING_MIP_LEVELS,
        base_array_layer: 0,
        layer_count: vk::REMAINING_ARRAY_LAYERS,
    }
}

fn create_views(
    gpu: &Gpu,
    image: vk::Image,
    desc: &ImageDesc,
) -> Result<(vk::ImageView, vk::ImageView), GpuError> {
    let view_type = if desc.layers > 1 {
        vk::ImageViewType::TYPE_2D_ARRAY
    } else {
        vk::ImageViewType::TYPE_2D
    };
    let make = |aspect: vk::ImageAspectFlags| {
        let info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(view_type)
            .format(vk::Format::from_raw(desc.format_raw))
            .subresource_range(vk::ImageSubresourceRange {
                aspect_mask: aspect,
                ..full_range(desc)
            });
        unsafe { gpu.device().create_image_view(&info, None) }.call("vkCreateImageView")
    };
    let attachment = make(convert::full_aspect(desc.aspect))?;
    if desc.aspect == Aspect::DepthStencil {
        match make(convert::shader_aspect(desc.aspect)) {
            Ok(shader) => Ok((attachment, shader)),
            Err(e) => {
                unsafe { gpu.device().destroy_image_view(attachment, None) };
                Err(e)
            }
        }
    } else {
        Ok((attachment, attachment))
    }
}

impl Drop for FrameResources<'_> {
    fn drop(&mut self) {
        let device = self.gpu.device();
        unsafe {
            let _ = device.device_wait_idle();
            for (_, fb) in self.framebuffers.drain() {
                device.destroy_framebuffer(fb, None);
            }
            for r in &self.resources {
                match r {
                    GpuResource::Image(i) => {
                        if i.shader_view != i.attachment_view {
                            device.destroy_image_view(i.shader_view, None);
                        }
                        device.destroy_image_view(i.attachment_view, None);
                        device.destroy_image(i.image, None);
                    }
                    GpuResource::Buffer(b) => device.destroy_buffer(b.buffer, None),
                    GpuResource::AccelerationStructure => {}
                }
            }
        }
        let mut allocator = self.gpu.allocator();
        for a in self.allocations.drain(..) {
            // Freeing only fails for allocations this allocator did not make.
            let _ = allocator.free(a);
        }
    }
}
