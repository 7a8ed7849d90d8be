//! The samplers graph images are read through: linear clamp-to-edge, nearest
//! for formats the device cannot filter linearly (depth on lavapipe), and a
//! depth-compare sampler for `sampler2DShadow` bindings (shadow maps).

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;

/// Linear and nearest clamp-to-edge samplers, and the shadow-map compare sampler.
pub struct Samplers {
    /// Linear filtering, linear mips.
    pub linear: vk::Sampler,
    /// Nearest filtering, for formats without linear filtering.
    pub nearest: vk::Sampler,
    /// Depth comparison `reference <= stored` (forward-Z shadow maps cleared to 1)
    /// with linear filtering, so one lookup is the hardware's 2x2 percentage-closer
    /// filter; clamp to an opaque white border, so lookups outside the map are lit.
    pub compare: vk::Sampler,
}

/// The shadow-map sampler: compare-enabled, bilinear, white border. Linear
/// filtering of a compare sampler filters the comparison results, which Vulkan
/// allows for depth formats without `SAMPLED_IMAGE_FILTER_LINEAR` (VUID-04553
/// concerns samplers with comparison off).
fn create_compare(gpu: &Gpu) -> Result<vk::Sampler, GpuError> {
    let border = vk::SamplerAddressMode::CLAMP_TO_BORDER;
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(vk::Filter::LINEAR)
        .min_filter(vk::Filter::LINEAR)
        .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
        .address_mode_u(border)
        .address_mode_v(border)
        .address_mode_w(border)
        .border_color(vk::BorderColor::FLOAT_OPAQUE_WHITE)
        .compare_enable(true)
        .compare_op(vk::CompareOp::LESS_OR_EQUAL)
        .max_lod(0.0);
    unsafe { gpu.device().create_sampler(&info, None) }.call("vkCreateSampler")
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
    /// Creates the three samplers.
    pub fn new(gpu: &Gpu) -> Result<Self, GpuError> {
        let linear = create(gpu, vk::Filter::LINEAR, vk::SamplerMipmapMode::LINEAR)?;
        let nearest = match create(gpu, vk::Filter::NEAREST, vk::SamplerMipmapMode::NEAREST) {
            Ok(n) => n,
            Err(e) => {
                unsafe { gpu.device().destroy_sampler(linear, None) };
                return Err(e);
            }
        };
        match create_compare(gpu) {
            Ok(compare) => Ok(Self {
                linear,
                nearest,
                compare,
            }),
            Err(e) => {
                unsafe {
                    gpu.device().destroy_sampler(linear, None);
                    gpu.device().destroy_sampler(nearest, None);
                }
                Err(e)
            }
        }
    }

    /// The sampler for a shader binding reading an image of `format_raw`: the
    /// compare sampler for `sampler2DShadow`, else by the format's filtering.
    pub fn for_binding(&self, gpu: &Gpu, depth_compare: bool, format_raw: i32) -> vk::Sampler {
        if depth_compare {
            self.compare
        } else {
            self.for_format(gpu, format_raw)
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

    /// Destroys the samplers.
    pub fn destroy(&self, gpu: &Gpu) {
        unsafe {
            gpu.device().destroy_sampler(self.linear, None);
            gpu.device().destroy_sampler(self.nearest, None);
            gpu.device().destroy_sampler(self.compare, None);
        }
    }
}

/// A sampler destroyed on drop, for samplers outside the three above (a scene's
/// material textures, which repeat).
pub struct Sampler<'g> {
    gpu: &'g Gpu,
    sampler: vk::Sampler,
}

impl<'g> Sampler<'g> {
    /// Linear filtering and mips, repeating in every direction: material textures.
    pub fn linear_repeat(gpu: &'g Gpu) -> Result<Self, GpuError> {
        let repeat = vk::SamplerAddressMode::REPEAT;
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::LINEAR)
            .address_mode_u(repeat)
            .address_mode_v(repeat)
            .address_mode_w(repeat)
            .max_lod(vk::LOD_CLAMP_NONE);
        let sampler =
            unsafe { gpu.device().create_sampler(&info, None) }.call("vkCreateSampler")?;
        Ok(Self { gpu, sampler })
    }

    /// The Vulkan handle.
    pub fn handle(&self) -> vk::Sampler {
        self.sampler
    }
}

impl Drop for Sampler<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_sampler(self.sampler, None) };
    }
}
