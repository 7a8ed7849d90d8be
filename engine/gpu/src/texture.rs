//! Sampled textures outside a plan's resources (a scene's materials): RGBA8
//! pixels uploaded once through a staging buffer (colour as sRGB, data such as
//! metallic-roughness as UNORM), mipmapped by blits and left in
//! `SHADER_READ_ONLY_OPTIMAL`; [`Rgba8Image::white`] stands in for a missing one.
//! [`Texture::upload_layers`] makes a 2D array of equally sized layers (the
//! path tracer's textures, one array per size class).

use crate::buffer::Buffer;
use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

/// Decoded RGBA8 pixels, top row first.
#[derive(Debug, Clone, PartialEq)]
pub struct Rgba8Image {
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Four bytes per texel, rows top to bottom.
    pub rgba: Vec<u8>,
}

impl Rgba8Image {
    /// One white texel.
    pub fn white() -> Self {
        Self {
            width: 1,
            height: 1,
            rgba: vec![255; 4],
        }
    }
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

impl<'g> Texture<'g> {
    /// Uploads `pixels` as an `R8G8B8A8_SRGB` image (colour, `srgb`) or
    /// `R8G8B8A8_UNORM` (data) with a full mip chain (made by linear blits, where
    /// the format can be filtered) ready for sampling in fragment and compute
    /// shaders, viewed as a plain 2D image.
    pub fn upload(
        gpu: &'g Gpu,
        name: &str,
        pixels: &Rgba8Image,
        srgb: bool,
    ) -> Result<Self, GpuError> {
        Self::create(gpu, name, std::slice::from_ref(pixels), srgb, true)
    }

    /// Uploads equally sized `layers` as one 2D array image (viewed as
    /// `sampler2DArray`), sRGB or UNORM as [`Texture::upload`], without mips.
    pub fn upload_layers(
        gpu: &'g Gpu,
        name: &str,
        layers: &[Rgba8Image],
        srgb: bool,
    ) -> Result<Self, GpuError> {
        let first = layers
            .first()
            .ok_or_else(|| GpuError::Plan(format!("texture array {name}: no layers to upload")))?;
        if let Some(odd) = layers
            .iter()
            .find(|l| (l.width, l.height) != (first.width, first.height))
        {
            return Err(GpuError::Plan(format!(
                "texture array {name}: a {}x{} layer among {}x{} ones",
                odd.width, odd.height, first.width, first.height
            )));
        }
        Self::create(gpu, name, layers, srgb, false)
    }

    fn create(
        gpu: &'g Gpu,
        name: &str,
        layers: &[Rgba8Image],
        srgb: bool,
        single: bool,
    ) -> Result<Self, GpuError> {
        let device = gpu.device();
        let pixels = &layers[0];
        let layer_count = layers.len() as u32;
        let format = if srgb {
            vk::Format::R8G8B8A8_SRGB
        } else {
            vk::Format::R8G8B8A8_UNORM
        };
        let extent = vk::Extent3D {
            width: pixels.width.max(1),
            height: pixels.height.max(1),
            depth: 1,
        };
        let max = gpu.info().max_image_dimension;
        if extent.width > max || extent.height > max {
            // Drivers may crash on such an image rather than refuse it.
            return Err(GpuError::Plan(format!(
                "texture {name} is {}x{}; the device allows at most {max} texels per side (maxImageDimension2D)",
                extent.width, extent.height
            )));
        }
        let levels = if single && gpu.linear_filter(format.as_raw()) {
            mip_levels(extent.width, extent.height)
        } else {
            1
        };
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(extent)
            .mip_levels(levels)
            .array_layers(layer_count)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(
                vk::ImageUsageFlags::SAMPLED
                    | vk::ImageUsageFlags::TRANSFER_DST
                    | vk::ImageUsageFlags::TRANSFER_SRC,
            )
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let image = unsafe { device.create_image(&info, None) }.call("vkCreateImage")?;
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
            .call("vkBindImageMemory")?;
        this.allocation = Some(allocation);
        gpu.set_name(image, name);
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: levels,
            base_array_layer: 0,
            layer_count,
        };
        let view_info = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(if single {
                vk::ImageViewType::TYPE_2D
            } else {
                vk::ImageViewType::TYPE_2D_ARRAY
            })
            .format(format)
            .subresource_range(range);
        this.view =
            unsafe { device.create_image_view(&view_info, None) }.call("vkCreateImageView")?;
        let bytes: Vec<u8> = layers.iter().flat_map(|l| l.rgba.iter().copied()).collect();
        let mut staging = Buffer::host(
            gpu,
            &format!("{name} (staging)"),
            bytes.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
        )?;
        staging.write(&bytes)?;
        let shape = Shape {
            extent,
            levels,
            layers: layer_count,
        };
        gpu.one_shot(|cmd| {
            record_upload(device, cmd, staging.buffer, image, shape);
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

/// Levels of a full mip chain for a `width` x `height` image.
pub fn mip_levels(width: u32, height: u32) -> u32 {
    32 - width.max(height).max(1).leading_zeros()
}

/// An image's size, mip levels and array layers.
#[derive(Clone, Copy)]
struct Shape {
    extent: vk::Extent3D,
    levels: u32,
    layers: u32,
}

fn level_barrier(
    image: vk::Image,
    (level, layers): (u32, u32),
    (src_stage, src_access, old): (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout),
    (dst_stage, dst_access, new): (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout),
) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(old)
        .new_layout(new)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: level,
            level_count: 1,
            base_array_layer: 0,
            layer_count: layers,
        })
}

fn barrier(device: &ash::Device, cmd: vk::CommandBuffer, barriers: &[vk::ImageMemoryBarrier2]) {
    let dep = vk::DependencyInfo::default().image_memory_barriers(barriers);
    unsafe { device.cmd_pipeline_barrier2(cmd, &dep) };
}

/// Copies the staging buffer into level 0 of every layer, blits each level
/// from the one above, and leaves every level in `SHADER_READ_ONLY_OPTIMAL` for
/// fragment and compute shaders.
fn record_upload(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    staging: vk::Buffer,
    image: vk::Image,
    shape: Shape,
) {
    let Shape {
        extent,
        levels,
        layers: layer_count,
    } = shape;
    let none = (
        vk::PipelineStageFlags2::NONE,
        vk::AccessFlags2::NONE,
        vk::ImageLayout::UNDEFINED,
    );
    let written = (
        vk::PipelineStageFlags2::TRANSFER,
        vk::AccessFlags2::TRANSFER_WRITE,
        vk::ImageLayout::TRANSFER_DST_OPTIMAL,
    );
    let source = (
        vk::PipelineStageFlags2::TRANSFER,
        vk::AccessFlags2::TRANSFER_READ,
        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    );
    let sampled = (
        vk::PipelineStageFlags2::FRAGMENT_SHADER | vk::PipelineStageFlags2::COMPUTE_SHADER,
        vk::AccessFlags2::SHADER_SAMPLED_READ,
        vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    );
    let to_dst: Vec<_> = (0..levels)
        .map(|l| level_barrier(image, (l, layer_count), none, written))
        .collect();
    barrier(device, cmd, &to_dst);
    let layers = |level| vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: level,
        base_array_layer: 0,
        layer_count,
    };
    let region = vk::BufferImageCopy::default()
        .image_subresource(layers(0))
        .image_extent(extent);
    unsafe {
        device.cmd_copy_buffer_to_image(
            cmd,
            staging,
            image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        );
    }
    let size = |level: u32| {
        [
            (extent.width >> level).max(1) as i32,
            (extent.height >> level).max(1) as i32,
        ]
    };
    for level in 1..levels {
        barrier(
            device,
            cmd,
            &[level_barrier(
                image,
                (level - 1, layer_count),
                written,
                source,
            )],
        );
        let [sw, sh] = size(level - 1);
        let [dw, dh] = size(level);
        let blit = vk::ImageBlit::default()
            .src_subresource(layers(level - 1))
            .src_offsets([vk::Offset3D::default(), vk::Offset3D { x: sw, y: sh, z: 1 }])
            .dst_subresource(layers(level))
            .dst_offsets([vk::Offset3D::default(), vk::Offset3D { x: dw, y: dh, z: 1 }]);
        unsafe {
            device.cmd_blit_image(
                cmd,
                image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[blit],
                vk::Filter::LINEAR,
            );
        }
        barrier(
            device,
            cmd,
            &[level_barrier(
                image,
                (level - 1, layer_count),
                source,
                sampled,
            )],
        );
    }
    barrier(
        device,
        cmd,
        &[level_barrier(
            image,
            (levels - 1, layer_count),
            written,
            sampled,
        )],
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mip_chain_goes_down_to_one_texel() {
        assert_eq!(mip_levels(1, 1), 1);
        assert_eq!(mip_levels(256, 256), 9);
        assert_eq!(mip_levels(300, 20), 9);
        assert_eq!(mip_levels(2, 1), 2);
    }
}
