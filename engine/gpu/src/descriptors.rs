//! Descriptor sets, safely: set layouts, pools, and one writer, used by the
//! executor for the graph's own sets and by weft-render for the scene's.
//! Handles given to these functions must come from the same device and stay
//! alive while a set refers to them; the owners in this crate and weft-render
//! (caches, frame resources, the GPU scene) keep that contract.

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;

/// Creates a set layout with `bindings`.
pub fn create_set_layout(
    device: &ash::Device,
    bindings: &[vk::DescriptorSetLayoutBinding<'_>],
) -> Result<vk::DescriptorSetLayout, GpuError> {
    let info = vk::DescriptorSetLayoutCreateInfo::default().bindings(bindings);
    unsafe { device.create_descriptor_set_layout(&info, None) }.call("vkCreateDescriptorSetLayout")
}

/// Destroys a set layout no pipeline or pending work uses any more.
pub fn destroy_set_layout(device: &ash::Device, layout: vk::DescriptorSetLayout) {
    unsafe { device.destroy_descriptor_set_layout(layout, None) }
}

/// A descriptor pool, destroyed (with its sets) on drop.
pub struct DescriptorPool<'g> {
    gpu: &'g Gpu,
    pool: vk::DescriptorPool,
}

impl<'g> DescriptorPool<'g> {
    /// A pool for `sets` sets holding at most `counts` descriptors of each type.
    pub fn new(
        gpu: &'g Gpu,
        sets: u32,
        counts: &[(vk::DescriptorType, u32)],
    ) -> Result<Self, GpuError> {
        let sizes: Vec<_> = counts
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|&(ty, n)| vk::DescriptorPoolSize {
                ty,
                descriptor_count: n,
            })
            .collect();
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(sets.max(1))
            .pool_sizes(&sizes);
        let pool = unsafe { gpu.device().create_descriptor_pool(&info, None) }
            .call("vkCreateDescriptorPool")?;
        Ok(Self { gpu, pool })
    }

    /// A new set of `layout`.
    pub fn allocate(&self, layout: vk::DescriptorSetLayout) -> Result<vk::DescriptorSet, GpuError> {
        let layouts = [layout];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        let sets = unsafe { self.gpu.device().allocate_descriptor_sets(&info) }
            .call("vkAllocateDescriptorSets")?;
        sets.into_iter().next().ok_or(GpuError::Vulkan {
            call: "vkAllocateDescriptorSets",
            result: vk::Result::ERROR_OUT_OF_POOL_MEMORY,
        })
    }

    /// Frees every set at once; the device must have finished with them.
    pub fn reset(&self) -> Result<(), GpuError> {
        unsafe {
            self.gpu
                .device()
                .reset_descriptor_pool(self.pool, vk::DescriptorPoolResetFlags::empty())
        }
        .call("vkResetDescriptorPool")
    }
}

impl Drop for DescriptorPool<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_descriptor_pool(self.pool, None) };
    }
}

/// Collects descriptor writes for one set, then writes them in one call.
#[derive(Default)]
pub struct DescriptorWriter {
    images: Vec<(u32, vk::DescriptorType, [vk::DescriptorImageInfo; 1])>,
    buffers: Vec<(u32, vk::DescriptorType, [vk::DescriptorBufferInfo; 1])>,
    texel_buffers: Vec<(u32, [vk::BufferView; 1])>,
    structures: Vec<(u32, [vk::AccelerationStructureKHR; 1])>,
}

impl DescriptorWriter {
    /// An image (sampled, combined with `sampler`, or storage) at `binding`.
    pub fn image(
        &mut self,
        binding: u32,
        ty: vk::DescriptorType,
        sampler: vk::Sampler,
        view: vk::ImageView,
        layout: vk::ImageLayout,
    ) -> &mut Self {
        let info = vk::DescriptorImageInfo {
            sampler,
            image_view: view,
            image_layout: layout,
        };
        self.images.push((binding, ty, [info]));
        self
    }

    /// A whole buffer (uniform or storage) at `binding`.
    pub fn buffer(
        &mut self,
        binding: u32,
        ty: vk::DescriptorType,
        buffer: vk::Buffer,
    ) -> &mut Self {
        let info = vk::DescriptorBufferInfo {
            buffer,
            offset: 0,
            range: vk::WHOLE_SIZE,
        };
        self.buffers.push((binding, ty, [info]));
        self
    }

    /// A uniform texel buffer's `view` at `binding`.
    pub fn texel_buffer(&mut self, binding: u32, view: vk::BufferView) -> &mut Self {
        self.texel_buffers.push((binding, [view]));
        self
    }

    /// A top-level acceleration structure at `binding`, for ray queries.
    pub fn acceleration_structure(
        &mut self,
        binding: u32,
        structure: vk::AccelerationStructureKHR,
    ) -> &mut Self {
        self.structures.push((binding, [structure]));
        self
    }

    /// Writes everything collected into `set`, which no pending work may be using.
    pub fn write(&self, gpu: &Gpu, set: vk::DescriptorSet) {
        let images = self.images.iter().map(|(binding, ty, info)| {
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(*binding)
                .descriptor_type(*ty)
                .image_info(info)
        });
        let buffers = self.buffers.iter().map(|(binding, ty, info)| {
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(*binding)
                .descriptor_type(*ty)
                .buffer_info(info)
        });
        let texel_buffers = self.texel_buffers.iter().map(|(binding, view)| {
            vk::WriteDescriptorSet::default()
                .dst_set(set)
                .dst_binding(*binding)
                .descriptor_type(vk::DescriptorType::UNIFORM_TEXEL_BUFFER)
                .texel_buffer_view(view)
        });
        let mut structures: Vec<_> = self
            .structures
            .iter()
            .map(|(_, handle)| {
                vk::WriteDescriptorSetAccelerationStructureKHR::default()
                    .acceleration_structures(handle)
            })
            .collect();
        let structure_writes =
            self.structures
                .iter()
                .zip(structures.iter_mut())
                .map(|((binding, _), info)| {
                    vk::WriteDescriptorSet::default()
                        .dst_set(set)
                        .dst_binding(*binding)
                        .descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                        .descriptor_count(1)
                        .push_next(info)
                });
        let writes: Vec<_> = images
            .chain(buffers)
            .chain(texel_buffers)
            .chain(structure_writes)
            .collect();
        if !writes.is_empty() {
            unsafe { gpu.device().update_descriptor_sets(&writes, &[]) };
        }
    }
}

/// Writes a pass's graph set (set 0): each resolved binding's image or buffer,
/// images with the sampler `sampler(depth_compare, format)` picks and in the
/// layout `layout` says the image is in during the pass. The executor and
/// weft-render's scene recorder both write graph sets through this.
pub fn write_graph_set(
    gpu: &Gpu,
    set: vk::DescriptorSet,
    bindings: &[crate::bind::ResolvedBinding],
    resources: &crate::resources::FrameResources<'_>,
    sampler: impl Fn(bool, i32) -> vk::Sampler,
    layout: impl Fn(weft_graph::id::ResourceId) -> vk::ImageLayout,
) -> Result<(), GpuError> {
    use crate::resources::GpuResource;
    let mut writer = DescriptorWriter::default();
    for rb in bindings {
        let (binding, ty) = (rb.shader.binding, rb.shader.kind.vk());
        match resources.get(rb.graph.resource) {
            Some(GpuResource::Image(img)) => writer.image(
                binding,
                ty,
                sampler(rb.shader.depth_compare, img.desc.format_raw),
                img.shader_view,
                layout(rb.graph.resource),
            ),
            Some(GpuResource::Buffer(buf)) => writer.buffer(binding, ty, buf.buffer),
            Some(GpuResource::AccelerationStructure) | None => {
                return Err(GpuError::Plan(format!(
                    "resource {} missing",
                    rb.graph.resource
                )))
            }
        };
    }
    writer.write(gpu, set);
    Ok(())
}

/// A descriptor set layout destroyed on drop.
pub struct SetLayout<'g> {
    gpu: &'g Gpu,
    layout: vk::DescriptorSetLayout,
}

impl<'g> SetLayout<'g> {
    /// A layout with `bindings`.
    pub fn new(
        gpu: &'g Gpu,
        bindings: &[vk::DescriptorSetLayoutBinding<'_>],
    ) -> Result<Self, GpuError> {
        Ok(Self {
            gpu,
            layout: create_set_layout(gpu.device(), bindings)?,
        })
    }

    /// The Vulkan handle.
    pub fn handle(&self) -> vk::DescriptorSetLayout {
        self.layout
    }
}

impl Drop for SetLayout<'_> {
    fn drop(&mut self) {
        destroy_set_layout(self.gpu.device(), self.layout);
    }
}
