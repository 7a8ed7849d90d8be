//! The samplers graph images are read through: linear clamp-to-edge, and
//! nearest for formats the device cannot filter linearly (depth on lavapipe).

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;

/// Linear and nearest clamp-to-edge samplers.
pub struct Samplers {
    /// Linear filtering, linear mips.
    pub linear: vk::Sampler,
    /// Nearest filtering, for formats without linear filtering.
    pub nearest: vk::Sampler,
}

fn create(
    gpu: &Gpu,
    filter: vk::Filter,
    mip: vk::SamplerMipmapMode,
) -> Result<vk::Sampler, GpuError> {
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(filter)
        .min_filter(filter)
        .mipmap_mode(mip)
        .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
        .max_lod(vk::LOD_CLAMP_NONE);
    unsafe { gpu.device().create_sampler(&info, None) }.call("vkCreateSampler")
}

impl Samplers {
    /// Creates both samplers.
    pub fn new(gpu: &Gpu) -> Result<Self, GpuError> {
        let linear = create(gpu, vk::Filter::LINEAR, vk::SamplerMipmapMode::LINEAR)?;
        match create(gpu, vk::Filter::NEAREST, vk::SamplerMipmapMode::NEAREST) {
            Ok(nearest) => Ok(Self { linear, nearest }),
            Err(e) => {
                unsafe { gpu.device().destroy_sampler(linear, None) };
                Err(e)
            }
        }
    }

    /// The linear sampler where the format supports linear filtering, else nearest.
    pub fn for_format(&self, gpu: &Gpu, format_raw: i32) -> vk::Sampler {
        if gpu.linear_filter(format_raw) {
            self.linear
        } else {
            self.nearest
        }
    }

    /// Destroys both samplers.
    pub fn destroy(&self, gpu: &Gpu) {
        unsafe {
            gpu.device().destroy_sampler(self.linear, None);
            gpu.device().destroy_sampler(self.nearest, None);
        }
    }
}
