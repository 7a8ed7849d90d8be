//! Buffers outside a plan's resources (scene data, for one) through the allocator: device-local ones
//! filled once through a staging copy (geometry, draws, materials), and
//! host-visible ones rewritten every frame (camera, animated lights).

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

/// A buffer and its memory, freed on drop.
pub struct Buffer<'g> {
    gpu: &'g Gpu,
    /// The Vulkan buffer, for binding and copies.
    pub buffer: vk::Buffer,
    allocation: Option<Allocation>,
    /// Size in bytes.
    pub size: u64,
}

impl<'g> Buffer<'g> {
    /// A buffer of `size` bytes (at least 16) in `location`.
    pub fn new(
        gpu: &'g Gpu,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self, GpuError> {
        let size = size.max(16);
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let device = gpu.device();
        let buffer = unsafe { device.create_buffer(&info, None) }.call("vkCreateBuffer")?;
        let mut this = Self {
            gpu,
            buffer,
            allocation: None,
            size,
        };
        let requirements = unsafe { device.get_buffer_memory_requirements(buffer) };
        let allocation = gpu
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| GpuError::Allocation {
                what: name.to_string(),
                message: e.to_string(),
            })?;
        unsafe { device.bind_buffer_memory(buffer, allocation.memory(), allocation.offset()) }
            .call("vkBindBufferMemory")?;
        this.allocation = Some(allocation);
        gpu.set_name(buffer, name);
        Ok(this)
    }

    /// A host-visible buffer for data rewritten every frame.
    pub fn host(
        gpu: &'g Gpu,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
    ) -> Result<Self, GpuError> {
        Self::new(gpu, name, size, usage, MemoryLocation::CpuToGpu)
    }

    /// A device-local buffer holding `bytes`, copied through a staging buffer; the copy
    /// is followed by a barrier that makes it visible to every later shader and vertex read.
    pub fn device_local(
        gpu: &'g Gpu,
        name: &str,
        bytes: &[u8],
        usage: vk::BufferUsageFlags,
    ) -> Result<Self, GpuError> {
        let target = Self::new(
            gpu,
            name,
            bytes.len() as u64,
            usage | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        if bytes.is_empty() {
            return Ok(target);
        }
        let mut staging = Self::host(
            gpu,
            &format!("{name} (staging)"),
            bytes.len() as u64,
            vk::BufferUsageFlags::TRANSFER_SRC,
        )?;
        staging.write(bytes)?;
        gpu.one_shot(|cmd| {
            let region = vk::BufferCopy::default().size(bytes.len() as u64);
            let barrier = vk::BufferMemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .dst_access_mask(vk::AccessFlags2::MEMORY_READ)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(target.buffer)
                .offset(0)
                .size(vk::WHOLE_SIZE);
            let barriers = [barrier];
            let dep = vk::DependencyInfo::default().buffer_memory_barriers(&barriers);
            unsafe {
                gpu.device()
                    .cmd_copy_buffer(cmd, staging.buffer, target.buffer, &[region]);
                gpu.device().cmd_pipeline_barrier2(cmd, &dep);
            }
            Ok(())
        })?;
        Ok(target)
    }

    /// Copies `bytes` to the start of a host-visible buffer.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), GpuError> {
        self.write_at(0, bytes)
    }

    /// Copies `bytes` into a host-visible buffer at byte `offset`: a range
    /// update, for data of which only a part changed.
    pub fn write_at(&mut self, offset: usize, bytes: &[u8]) -> Result<(), GpuError> {
        let size = self.size;
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .ok_or_else(|| GpuError::Allocation {
                what: "a scene buffer".into(),
                message: "buffer is not host-visible".into(),
            })?;
        let dst =
            slice
                .get_mut(offset..offset + bytes.len())
                .ok_or_else(|| GpuError::Allocation {
                    what: "a scene buffer".into(),
                    message: format!("{} bytes at {offset} do not fit in {size}", bytes.len()),
                })?;
        dst.copy_from_slice(bytes);
        Ok(())
    }
}

impl Buffer<'_> {
    /// The buffer's device address: it must have been made with
    /// `SHADER_DEVICE_ADDRESS` usage, on a device with `bufferDeviceAddress`
    /// (enabled with ray queries, [`crate::ShaderSupport::ray_query`]).
    pub fn address(&self) -> u64 {
        let info = vk::BufferDeviceAddressInfo::default().buffer(self.buffer);
        unsafe { self.gpu.device().get_buffer_device_address(&info) }
    }

    /// The bytes of a host-visible buffer (a read-back buffer after the
    /// GPU's writes were made visible to the host).
    pub fn mapped(&self) -> Result<&[u8], GpuError> {
        self.allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .ok_or_else(|| GpuError::Allocation {
                what: "a buffer".into(),
                message: "buffer is not host-visible".into(),
            })
    }
}

impl Drop for Buffer<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_buffer(self.buffer, None) };
        if let Some(a) = self.allocation.take() {
            // Freeing only fails for allocations this allocator did not make.
            let _ = self.gpu.allocator().free(a);
        }
    }
}

/// How a [`TexelBuffer`]'s texels are laid out: 32-bit words, read in
/// GLSL through a `usamplerBuffer` (floats with `uintBitsToFloat`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TexelFormat {
    /// Four words a texel (`R32G32B32A32_UINT`): a `uvec4` or `vec4`.
    Words4,
    /// Two words a texel (`R32G32_UINT`): a `uvec2` or `vec2`.
    Words2,
}

impl TexelFormat {
    /// The Vulkan format.
    pub fn vk(self) -> vk::Format {
        match self {
            Self::Words4 => vk::Format::R32G32B32A32_UINT,
            Self::Words2 => vk::Format::R32G32_UINT,
        }
    }

    /// Bytes of one texel.
    pub fn bytes(self) -> u64 {
        match self {
            Self::Words4 => 16,
            Self::Words2 => 8,
        }
    }
}

/// A device-local table that shaders read through a `usamplerBuffer` and
/// `texelFetch`. On lavapipe a texel fetch loads each lane's whole texel
/// with one vector load, where a storage-buffer read loads every component
/// of every lane in a loop with a branch per load (docs/pathtrace.md
/// measures what this buys the ray tracer).
pub struct TexelBuffer<'g> {
    buffer: Buffer<'g>,
    /// The view shaders read the texels through.
    pub view: vk::BufferView,
}

impl<'g> TexelBuffer<'g> {
    /// A texel buffer holding `bytes`, a whole number of `format`'s
    /// texels, refused when the device's texel buffers cannot hold that
    /// many.
    pub fn device_local(
        gpu: &'g Gpu,
        name: &str,
        bytes: &[u8],
        format: TexelFormat,
    ) -> Result<Self, GpuError> {
        texels_within(name, bytes.len(), format, gpu)?;
        let buffer =
            Buffer::device_local(gpu, name, bytes, vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER)?;
        Self::with_view(gpu, buffer, format)
    }

    /// A host-visible texel buffer holding `bytes`, for a table rewritten
    /// while the scene runs ([`write`](Self::write)).
    pub fn host(
        gpu: &'g Gpu,
        name: &str,
        bytes: &[u8],
        format: TexelFormat,
    ) -> Result<Self, GpuError> {
        texels_within(name, bytes.len(), format, gpu)?;
        let mut buffer = Buffer::host(
            gpu,
            name,
            bytes.len() as u64,
            vk::BufferUsageFlags::UNIFORM_TEXEL_BUFFER,
        )?;
        buffer.write(bytes)?;
        Self::with_view(gpu, buffer, format)
    }

    /// Rewrites a host-visible texel buffer from its start.
    pub fn write(&mut self, bytes: &[u8]) -> Result<(), GpuError> {
        self.buffer.write(bytes)
    }

    /// Rewrites part of a host-visible texel buffer, from byte `offset`.
    pub fn write_at(&mut self, offset: usize, bytes: &[u8]) -> Result<(), GpuError> {
        self.buffer.write_at(offset, bytes)
    }

    fn with_view(gpu: &'g Gpu, buffer: Buffer<'g>, format: TexelFormat) -> Result<Self, GpuError> {
        let info = vk::BufferViewCreateInfo::default()
            .buffer(buffer.buffer)
            .format(format.vk())
            .offset(0)
            .range(vk::WHOLE_SIZE);
        let view =
            unsafe { gpu.device().create_buffer_view(&info, None) }.call("vkCreateBufferView")?;
        Ok(Self { buffer, view })
    }
}

impl Drop for TexelBuffer<'_> {
    fn drop(&mut self) {
        unsafe {
            self.buffer
                .gpu
                .device()
                .destroy_buffer_view(self.view, None)
        };
    }
}

/// [`texels_fitting`] under `gpu`'s `maxTexelBufferElements`.
fn texels_within(what: &str, len: usize, format: TexelFormat, gpu: &Gpu) -> Result<u64, GpuError> {
    texels_fitting(what, len, format, gpu.info().max_texel_buffer_elements)
}

/// The texels `len` bytes of `format` make, or the error that names `what`
/// when they are not whole texels or a texel buffer of the device (`limit`
/// texels at most) cannot hold them.
fn texels_fitting(
    what: &str,
    len: usize,
    format: TexelFormat,
    limit: u32,
) -> Result<u64, GpuError> {
    let texels = len as u64 / format.bytes();
    if !(len as u64).is_multiple_of(format.bytes()) {
        return Err(GpuError::Allocation {
            what: what.to_string(),
            message: format!("{len} bytes are not whole {}-byte texels", format.bytes()),
        });
    }
    if texels > u64::from(limit) {
        return Err(GpuError::TooManyTexels {
            what: what.to_string(),
            texels,
            limit,
        });
    }
    Ok(texels)
}

#[cfg(test)]
mod tests {
    use super::{texels_fitting, TexelFormat};

    #[test]
    fn a_table_must_be_whole_texels_within_the_device_limit() {
        assert_eq!(texels_fitting("t", 48, TexelFormat::Words4, 3).unwrap(), 3);
        assert_eq!(texels_fitting("t", 48, TexelFormat::Words2, 6).unwrap(), 6);
        assert_eq!(texels_fitting("t", 0, TexelFormat::Words4, 0).unwrap(), 0);
        assert_eq!(
            texels_fitting("the BVH nodes", 64, TexelFormat::Words4, 3)
                .unwrap_err()
                .to_string(),
            "the BVH nodes needs 4 texels; this device's texel buffers hold at most 3 \
             (maxTexelBufferElements)"
        );
        assert_eq!(
            texels_fitting("uvs", 20, TexelFormat::Words2, 100)
                .unwrap_err()
                .to_string(),
            "memory allocation for uvs failed: 20 bytes are not whole 8-byte texels"
        );
    }
}
