//! Material textures: decoded on the CPU, uploaded once to sRGB images through a
//! staging buffer and left in `SHADER_READ_ONLY_OPTIMAL`; a 1x1 white texture
//! stands in for materials without one (and for files that cannot be read).

use crate::buffer::Buffer;
use crate::error::RenderError;
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use weft_gpu::{Gpu, GpuError};
use weft_scene::material::TextureSource;

/// Decoded RGBA8 pixels, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Pixels {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Four bytes per texel, rows top to bottom.
    pub rgba: Vec<u8>,
}

impl Pixels {
    /// One white texel.
    pub fn white() -> Self {
        Self {
            width: 1,
            height: 1,
            rgba: vec![255; 4],
        }
    }
}

/// Decodes a texture's image file or embedded bytes.
pub fn decode(source: &TextureSource) -> Result<Pixels, RenderError> {
    let (path, result) = match source {
        TextureSource::File(path) => (path.clone(), image::open(path)),
        TextureSource::Embedded { id, bytes, .. } => (id.into(), image::load_from_memory(bytes)),
    };
    let img = result
        .map_err(|e| RenderError::Texture {
            path,
            message: e.to_string(),
        })?
        .to_rgba8();
    Ok(Pixels {
        width: img.width(),
        height: img.height(),
        rgba: img.into_raw(),
    })
}

/// A sampled image on the device, destroyed on drop.
pub struct Texture<'g> {
    gpu: &'g Gpu,
    /// The image.
    pub image: vk::Image,
    /// A 2D colour view for sampling.
    pub view: vk::ImageView,
    allocation: Option<Allocation>,
}

fn vk_err(call: &'static str) -> impl Fn(vk::Result) -> GpuError {
    move |result| GpuError::Vulkan { call, result }
}

impl<'g> Texture<'g> {
    /// Uploads `pixels` as an `R8G8B8A8_SRGB` image ready for sampling in fragment shaders.
    pub fn upload(gpu: &'g Gpu, name: &str, pixels: &Pixels) -> Result<Self, GpuError> {
        let device = gpu.device();
        let format = vk::Format::R8G8B8A8_SRGB;
        let extent = vk::Extent3D {
            width: pixels.width.max(1),
            height: pixels.height.max(1),
            depth: 1,
        };
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(extent)
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let image = unsafe { device.create_image(&info, None) }.map_err(vk_err("vkCreateImage"))?;
        let mut this = Self {
            gpu,
            image,
            view: vk::ImageView::null(),
            allocation: None,
        };
        let requirements = unsafe { device.get_image_memory_requirements(image) };
        let allocation = gpu
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| GpuError::Allocation {
                what: name.to_string(),
                message: e.to_string(),
            })?;
        unsafe { device.bind_image_memory(image, allocation.memory(), allocation.offset()) }
            .map_err(vk_err("vkBindImageMemory"))?;
        this.allocation = Some(allocation);
        gpu.set_name(image, name);
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(range);
        this.view = unsafe { device.create_image_view(&view_info, None) }
            .map_err(vk_err("vkCreateImageView"))?;
        let mut staging = Buffer::host(
            gpu,
            &format!("{name} (staging)"),
            pixels.rgba.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
        )?;
        staging.write(&pixels.rgba)?;
        gpu.one_shot(|cmd| {
            let to_dst = vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::NONE)
                .dst_stage_mask(vk::PipelineStageFlags2::COPY)
                .dst_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .old_layout(vk::ImageLayout::UNDEFINED)
                .new_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image)
                .subresource_range(range);
            let to_read = vk::ImageMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::FRAGMENT_SHADER)
                .dst_access_mask(vk::AccessFlags2::SHADER_SAMPLED_READ)
                .old_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                .new_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(image)
                .subresource_range(range);
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(extent);
            let first = [to_dst];
            let second = [to_read];
            unsafe {
                device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&first),
                );
                device.cmd_copy_buffer_to_image(
                    cmd,
                    staging.buffer,
                    image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &[region],
                );
                device.cmd_pipeline_barrier2(
                    cmd,
                    &vk::DependencyInfo::default().image_memory_barriers(&second),
                );
            }
            Ok(())
        })?;
        Ok(this)
    }
}

impl Drop for Texture<'_> {
    fn drop(&mut self) {
        let device = self.gpu.device();
        unsafe {
            if self.view != vk::ImageView::null() {
                device.destroy_image_view(self.view, None);
            }
            device.destroy_image(self.image, None);
        }
        if let Some(a) = self.allocation.take() {
            // Freeing only fails for allocations this allocator did not make.
            let _ = self.gpu.allocator().free(a);
        }
    }
}
