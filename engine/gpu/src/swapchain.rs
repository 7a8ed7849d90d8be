//! A window's surface and swapchain: created from raw window handles, sized to
//! the window, and recreated when the window changes size or the swapchain goes
//! out of date. The choices (format, present mode, extent, image count) are pure
//! functions so they are tested without a display.

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};

/// A surface and the swapchain presenting to it.
pub struct Swapchain<'g> {
    gpu: &'g Gpu,
    surface_fns: ash::khr::surface::Instance,
    surface: vk::SurfaceKHR,
    fns: ash::khr::swapchain::Device,
    swapchain: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    format: vk::SurfaceFormatKHR,
    extent: vk::Extent2D,
}

impl<'g> Swapchain<'g> {
    /// Creates a surface for the window and a swapchain of `size` (the window's
    /// inner size in pixels; the surface's own extent wins where it has one).
    ///
    /// # Safety
    /// The handles must name a live window on the display `gpu` was made for
    /// ([`Gpu::for_display`]), and the window must outlive the swapchain.
    pub unsafe fn new(
        gpu: &'g Gpu,
        display: RawDisplayHandle,
        window: RawWindowHandle,
        size: [u32; 2],
    ) -> Result<Self, GpuError> {
        if !gpu.can_present() {
            return Err(GpuError::Plan(
                "this context was made without presentation (use Gpu::for_display)".into(),
            ));
        }
        let surface = unsafe {
            ash_window::create_surface(gpu.entry(), gpu.instance(), display, window, None)
        }
        .call("vkCreateSurfaceKHR")?;
        let surface_fns = ash::khr::surface::Instance::new(gpu.entry(), gpu.instance());
        let fns = ash::khr::swapchain::Device::new(gpu.instance(), gpu.device());
        let mut this = Self {
            gpu,
            surface_fns,
            surface,
            fns,
            swapchain: vk::SwapchainKHR::null(),
            images: Vec::new(),
            format: vk::SurfaceFormatKHR::default(),
            extent: vk::Extent2D::default(),
        };
        let supported = unsafe {
            this.surface_fns.get_physical_device_surface_support(
                gpu.physical_device(),
                gpu.queue_family(),
                surface,
            )
        }
        .call("vkGetPhysicalDeviceSurfaceSupportKHR")?;
        if !supported {
            return Err(GpuError::Plan(
                "the device's queue cannot present to this window".into(),
            ));
        }
        this.recreate(size)?;
        Ok(this)
    }

    /// Rebuilds the swapchain for a window of `size` pixels, after waiting for
    /// the device to finish with the old one.
    pub fn recreate(&mut self, size: [u32; 2]) -> Result<(), GpuError> {
        self.gpu.wait_idle()?;
        let physical = self.gpu.physical_device();
        let caps = unsafe {
            self.surface_fns
                .get_physical_device_surface_capabilities(physical, self.surface)
        }
        .call("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let formats = unsafe {
            self.surface_fns
                .get_physical_device_surface_formats(physical, self.surface)
        }
        .call("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        let modes = unsafe {
            self.surface_fns
                .get_physical_device_surface_present_modes(physical, self.surface)
        }
        .call("vkGetPhysicalDeviceSurfacePresentModesKHR")?;
        let format = choose_format(&formats)
            .ok_or(GpuError::Plan("the surface offers no image format".into()))?;
        let extent = choose_extent(&caps, size);
        // Colour attachment: an overlay (the viewer's panel) draws over the blit.
        let usage = vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC
            | vk::ImageUsageFlags::COLOR_ATTACHMENT;
        if !caps.supported_usage_flags.contains(usage) {
            return Err(GpuError::Plan(format!(
                "swapchain images cannot be blitted to, drawn to and copied from (usage {:?})",
                caps.supported_usage_flags
            )));
        }
        let old = self.swapchain;
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(self.surface)
            .min_image_count(image_count(&caps))
            .image_format(format.format)
            .image_color_space(format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(choose_alpha(caps.supported_composite_alpha))
            .present_mode(choose_present_mode(&modes))
            .clipped(true)
            .old_swapchain(old);
        let swapchain =
            unsafe { self.fns.create_swapchain(&info, None) }.call("vkCreateSwapchainKHR")?;
        if old != vk::SwapchainKHR::null() {
            unsafe { self.fns.destroy_swapchain(old, None) };
        }
        self.swapchain = swapchain;
        self.images =
            unsafe { self.fns.get_swapchain_images(swapchain) }.call("vkGetSwapchainImagesKHR")?;
        self.format = format;
        self.extent = extent;
        for (i, &image) in self.images.iter().enumerate() {
            self.gpu.set_name(image, &format!("swapchain image {i}"));
        }
        Ok(())
    }

    /// The swapchain handle.
    pub fn handle(&self) -> vk::SwapchainKHR {
        self.swapchain
    }

    /// The swapchain functions (acquire, present).
    pub fn fns(&self) -> &ash::khr::swapchain::Device {
        &self.fns
    }

    /// The images presented, by the index acquire returns.
    pub fn images(&self) -> &[vk::Image] {
        &self.images
    }

    /// Pixel format and colour space of the images.
    pub fn format(&self) -> vk::SurfaceFormatKHR {
        self.format
    }

    /// Size of the images in pixels.
    pub fn extent(&self) -> vk::Extent2D {
        self.extent
    }
}

impl Drop for Swapchain<'_> {
    fn drop(&mut self) {
        unsafe {
            let _ = self.gpu.device().device_wait_idle();
            if self.swapchain != vk::SwapchainKHR::null() {
                self.fns.destroy_swapchain(self.swapchain, None);
            }
            self.surface_fns.destroy_surface(self.surface, None);
        }
    }
}

/// An 8-bit sRGB format when offered (the graphs' outputs are sRGB-encoded, so a
/// blit copies them unchanged), else 8-bit UNORM, else the first.
pub fn choose_format(formats: &[vk::SurfaceFormatKHR]) -> Option<vk::SurfaceFormatKHR> {
    let preferred = [
        vk::Format::B8G8R8A8_SRGB,
        vk::Format::R8G8B8A8_SRGB,
        vk::Format::B8G8R8A8_UNORM,
        vk::Format::R8G8B8A8_UNORM,
    ];
    preferred
        .iter()
        .find_map(|&want| {
            formats
                .iter()
                .copied()
                .find(|f| f.format == want && f.color_space == vk::ColorSpaceKHR::SRGB_NONLINEAR)
        })
        .or_else(|| formats.first().copied())
}

/// Mailbox when offered (no tearing, no waiting for vertical blank, so frame
/// times measure rendering), else FIFO, which every implementation has.
pub fn choose_present_mode(modes: &[vk::PresentModeKHR]) -> vk::PresentModeKHR {
    if modes.contains(&vk::PresentModeKHR::MAILBOX) {
        vk::PresentModeKHR::MAILBOX
    } else {
        vk::PresentModeKHR::FIFO
    }
}

/// The surface's extent where it dictates one, else the window size clamped to
/// what the surface allows (and at least one pixel).
pub fn choose_extent(caps: &vk::SurfaceCapabilitiesKHR, size: [u32; 2]) -> vk::Extent2D {
    if caps.current_extent.width != u32::MAX {
        return caps.current_extent;
    }
    let clamp = |v: u32, lo: u32, hi: u32| v.clamp(lo.max(1), hi.max(lo).max(1));
    vk::Extent2D {
        width: clamp(
            size[0],
            caps.min_image_extent.width,
            caps.max_image_extent.width,
        ),
        height: clamp(
            size[1],
            caps.min_image_extent.height,
            caps.max_image_extent.height,
        ),
    }
}

/// One more image than the minimum, so acquiring does not wait for the
/// presentation engine, within the maximum (0 means none).
pub fn image_count(caps: &vk::SurfaceCapabilitiesKHR) -> u32 {
    let wanted = caps.min_image_count + 1;
    if caps.max_image_count == 0 {
        wanted
    } else {
        wanted.min(caps.max_image_count)
    }
}

/// Opaque composition when offered; otherwise the first mode offered.
fn choose_alpha(supported: vk::CompositeAlphaFlagsKHR) -> vk::CompositeAlphaFlagsKHR {
    [
        vk::CompositeAlphaFlagsKHR::OPAQUE,
        vk::CompositeAlphaFlagsKHR::INHERIT,
        vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
        vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
    ]
    .into_iter()
    .find(|&a| supported.contains(a))
    .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn format(format: vk::Format) -> vk::SurfaceFormatKHR {
        vk::SurfaceFormatKHR {
            format,
            color_space: vk::ColorSpaceKHR::SRGB_NONLINEAR,
        }
    }

    #[test]
    fn formats_prefer_srgb_then_unorm_then_the_first() {
        let offered = [
            format(vk::Format::A2B10G10R10_UNORM_PACK32),
            format(vk::Format::B8G8R8A8_UNORM),
            format(vk::Format::B8G8R8A8_SRGB),
        ];
        assert_eq!(
            choose_format(&offered).map(|f| f.format),
            Some(vk::Format::B8G8R8A8_SRGB)
        );
        assert_eq!(
            choose_format(&offered[..2]).map(|f| f.format),
            Some(vk::Format::B8G8R8A8_UNORM)
        );
        assert_eq!(
            choose_format(&offered[..1]).map(|f| f.format),
            Some(vk::Format::A2B10G10R10_UNORM_PACK32)
        );
        assert_eq!(choose_format(&[]), None);
    }

    #[test]
    fn present_mode_is_mailbox_when_offered_else_fifo() {
        use vk::PresentModeKHR as M;
        assert_eq!(
            choose_present_mode(&[M::IMMEDIATE, M::MAILBOX, M::FIFO]),
            M::MAILBOX
        );
        assert_eq!(choose_present_mode(&[M::IMMEDIATE, M::FIFO]), M::FIFO);
    }

    #[test]
    fn extent_follows_the_surface_or_clamps_the_window() {
        let mut caps = vk::SurfaceCapabilitiesKHR {
            current_extent: vk::Extent2D {
                width: 640,
                height: 480,
            },
            min_image_extent: vk::Extent2D {
                width: 1,
                height: 1,
            },
            max_image_extent: vk::Extent2D {
                width: 4096,
                height: 2048,
            },
            ..Default::default()
        };
        assert_eq!(
            choose_extent(&caps, [100, 100]),
            vk::Extent2D {
                width: 640,
                height: 480
            }
        );
        caps.current_extent = vk::Extent2D {
            width: u32::MAX,
            height: u32::MAX,
        };
        assert_eq!(
            choose_extent(&caps, [5000, 0]),
            vk::Extent2D {
                width: 4096,
                height: 1
            }
        );
    }

    #[test]
    fn image_count_is_one_over_the_minimum_within_the_maximum() {
        let caps = |min, max| vk::SurfaceCapabilitiesKHR {
            min_image_count: min,
            max_image_count: max,
            ..Default::default()
        };
        assert_eq!(image_count(&caps(2, 0)), 3);
        assert_eq!(image_count(&caps(2, 8)), 3);
        assert_eq!(image_count(&caps(3, 3)), 3);
    }
}
