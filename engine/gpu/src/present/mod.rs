//! Putting a rendered image on screen: acquire a swapchain image, blit the
//! graph's output into it (scaled when the sizes differ), let an [`Overlay`]
//! draw over it (the viewer's panel), optionally copy the result back
//! (screenshots of exactly what was shown, with or without the overlay), and
//! present it.
//!
//! Synchronization: acquire signals a semaphore that the blit waits for at the
//! blit stage; the blit signals a per-swapchain-image semaphore that presenting
//! waits for (a per-image semaphore is never signalled again while a present
//! may still wait on it); a fence per frame slot bounds the frames in flight.
//! Before returning, the submission is waited for, because the executor writes
//! the output image again next frame and runs one frame at a time itself.

mod capture;

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use crate::readback::Readback;
use crate::swapchain::Swapchain;
use ash::vk;
use capture::CaptureBuffer;

/// Frame slots: acquire semaphores, fences and command buffers cycle through them.
const FRAMES_IN_FLIGHT: usize = 2;

/// Where the first write to an acquired swapchain image waits for it: the
/// transfer stages (the clear beside a docked panel, the blit).
const ACQUIRE_WAIT: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::ALL_TRANSFER;

/// The image to show: the graph's output, in `TRANSFER_SRC_OPTIMAL` with blit
/// reads made visible (what the plan's epilogue leaves it in).
#[derive(Debug, Clone, Copy)]
pub struct PresentSource {
    /// The image.
    pub image: vk::Image,
    /// Its size in pixels.
    pub extent: vk::Extent2D,
    /// Its format, to know whether it can be filtered when scaled.
    pub format: vk::Format,
    /// The part of the window it fills, from the top-left corner (the
    /// whole window, or what a panel docked on the right leaves); the rest
    /// is cleared for the overlay to draw on.
    pub area: vk::Extent2D,
}

/// Something drawn over the presented image before it is shown (the viewer's
/// panel), in the presenter's command buffer: [`Overlay::record`] finds the
/// swapchain image in `COLOR_ATTACHMENT_OPTIMAL` with the blit's writes
/// visible to colour-attachment reads and writes, and leaves it in that layout
/// with its own writes made at the colour-attachment-output stage.
pub trait Overlay {
    /// Records the overlay's drawing into `cmd`.
    fn record(&mut self, cmd: vk::CommandBuffer, target: &OverlayTarget) -> Result<(), GpuError>;
}

/// The swapchain image an [`Overlay`] draws on.
#[derive(Debug, Clone, Copy)]
pub struct OverlayTarget {
    /// The image.
    pub image: vk::Image,
    /// Its index in the swapchain (stable until the swapchain is recreated,
    /// which also changes `image`).
    pub index: usize,
    /// Its size in pixels.
    pub extent: vk::Extent2D,
    /// Its format.
    pub format: vk::Format,
}

/// Whether a presented frame is also copied back, and at which point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Capture {
    /// Not copied.
    No,
    /// The graph's image as blitted, before any overlay.
    Image,
    /// What the window shows, overlay included.
    WithOverlay,
}

/// What presenting a frame did.
#[derive(Debug)]
pub enum Presented {
    /// Shown; with the swapchain image's pixels when a capture was asked for.
    Shown(Option<Readback>),
    /// The swapchain no longer matched the window; it was recreated at the
    /// window's size and nothing was shown (render again).
    Recreated,
}

/// Presents images to one window.
pub struct Presenter<'g> {
    gpu: &'g Gpu,
    swapchain: Swapchain<'g>,
    acquired: Vec<vk::Semaphore>,
    rendered: Vec<vk::Semaphore>,
    fences: Vec<vk::Fence>,
    commands: Vec<vk::CommandBuffer>,
    slot: usize,
}

impl<'g> Presenter<'g> {
    /// Takes over a swapchain and creates the per-frame objects.
    pub fn new(gpu: &'g Gpu, swapchain: Swapchain<'g>) -> Result<Self, GpuError> {
        let mut this = Self {
            gpu,
            swapchain,
            acquired: Vec::new(),
            rendered: Vec::new(),
            fences: Vec::new(),
            commands: Vec::new(),
            slot: 0,
        };
        for _ in 0..FRAMES_IN_FLIGHT {
            this.acquired.push(semaphore(gpu)?);
            let signalled = vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
            this.fences.push(
                unsafe { gpu.device().create_fence(&signalled, None) }.call("vkCreateFence")?,
            );
            this.commands.push(gpu.allocate_command_buffer()?);
        }
        this.make_image_semaphores()?;
        Ok(this)
    }

    /// The swapchain's current size.
    pub fn extent(&self) -> vk::Extent2D {
        self.swapchain.extent()
    }

    /// The swapchain's image format.
    pub fn format(&self) -> vk::Format {
        self.swapchain.format().format
    }

    /// Rebuilds the swapchain for a window of `size` pixels (after a resize).
    pub fn resize(&mut self, size: [u32; 2]) -> Result<(), GpuError> {
        self.swapchain.recreate(size)?;
        self.make_image_semaphores()
    }

    /// One semaphore per swapchain image, made afresh (the device is idle
    /// whenever this runs, so none is in use).
    fn make_image_semaphores(&mut self) -> Result<(), GpuError> {
        self.gpu.wait_idle()?;
        for s in self.rendered.drain(..) {
            unsafe { self.gpu.device().destroy_semaphore(s, None) };
        }
        for _ in self.swapchain.images() {
            self.rendered.push(semaphore(self.gpu)?);
        }
        Ok(())
    }

    /// Shows `source` in the window (scaled to the swapchain's size) with
    /// `overlay` drawn over it. With `capture`, the swapchain image is also
    /// copied back. `size` is the window's size, used if the swapchain must be
    /// recreated.
    pub fn present(
        &mut self,
        source: PresentSource,
        capture: Capture,
        size: [u32; 2],
        overlay: Option<&mut dyn Overlay>,
    ) -> Result<Presented, GpuError> {
        let device = self.gpu.device();
        let slot = self.slot;
        let fence = self.fences[slot];
        unsafe { device.wait_for_fences(&[fence], true, u64::MAX) }.call("vkWaitForFences")?;
        let acquired = unsafe {
            self.swapchain.fns().acquire_next_image(
                self.swapchain.handle(),
                u64::MAX,
                self.acquired[slot],
                vk::Fence::null(),
            )
        };
        let index = match acquired {
            Ok((index, _suboptimal)) => index,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.resize(size)?;
                return Ok(Presented::Recreated);
            }
            Err(result) => {
                return Err(GpuError::Vulkan {
                    call: "vkAcquireNextImageKHR",
                    result,
                })
            }
        };
        let target = self.swapchain.images()[index as usize];
        let extent = self.swapchain.extent();
        let area = vk::Extent2D {
            width: source.area.width.clamp(1, extent.width),
            height: source.area.height.clamp(1, extent.height),
        };
        // The graph's image alone is its area; with the overlay, the window.
        let captured = if capture == Capture::Image {
            area
        } else {
            extent
        };
        let capture_buffer = match capture {
            Capture::No => None,
            Capture::Image | Capture::WithOverlay => Some(CaptureBuffer::new(self.gpu, captured)?),
        };
        let cmd = self.commands[slot];
        unsafe {
            device.reset_fences(&[fence]).call("vkResetFences")?;
            device
                .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
                .call("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            device
                .begin_command_buffer(cmd, &begin)
                .call("vkBeginCommandBuffer")?;
        }
        let filter = if source.extent == area || !self.gpu.linear_filter(source.format.as_raw()) {
            vk::Filter::NEAREST
        } else {
            vk::Filter::LINEAR
        };
        let mut state = self.record_blit(cmd, source, target, (extent, area), filter);
        let copy = |state: &mut TargetState| {
            if let Some(buffer) = capture_buffer.as_ref() {
                state.transition(
                    self.gpu,
                    cmd,
                    vk::PipelineStageFlags2::COPY,
                    vk::AccessFlags2::TRANSFER_READ,
                    vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                );
                buffer.record(cmd, target);
                state.access = vk::AccessFlags2::NONE;
            }
        };
        if capture == Capture::Image || overlay.is_none() {
            copy(&mut state);
        }
        if let Some(overlay) = overlay {
            state.transition(
                self.gpu,
                cmd,
                vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
                vk::AccessFlags2::COLOR_ATTACHMENT_READ | vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
                vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
            );
            state.access = vk::AccessFlags2::COLOR_ATTACHMENT_WRITE;
            let drawn = overlay.record(
                cmd,
                &OverlayTarget {
                    image: target,
                    index: index as usize,
                    extent,
                    format: self.swapchain.format().format,
                },
            );
            if let Err(err) = drawn {
                unsafe { device.end_command_buffer(cmd) }.call("vkEndCommandBuffer")?;
                return Err(err);
            }
            if capture == Capture::WithOverlay {
                copy(&mut state);
            }
        }
        state.transition(
            self.gpu,
            cmd,
            vk::PipelineStageFlags2::NONE,
            vk::AccessFlags2::NONE,
            vk::ImageLayout::PRESENT_SRC_KHR,
        );
        unsafe { device.end_command_buffer(cmd) }.call("vkEndCommandBuffer")?;
        let waits = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.acquired[slot])
            .stage_mask(ACQUIRE_WAIT)];
        let signals = [vk::SemaphoreSubmitInfo::default()
            .semaphore(self.rendered[index as usize])
            .stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)];
        let buffers = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = vk::SubmitInfo2::default()
            .wait_semaphore_infos(&waits)
            .command_buffer_infos(&buffers)
            .signal_semaphore_infos(&signals);
        unsafe { device.queue_submit2(self.gpu.queue(), &[submit], fence) }
            .call("vkQueueSubmit2")?;
        let wait = [self.rendered[index as usize]];
        let swapchains = [self.swapchain.handle()];
        let indices = [index];
        let info = vk::PresentInfoKHR::default()
            .wait_semaphores(&wait)
            .swapchains(&swapchains)
            .image_indices(&indices);
        let shown = unsafe { self.swapchain.fns().queue_present(self.gpu.queue(), &info) };
        self.slot = (slot + 1) % FRAMES_IN_FLIGHT;
        unsafe { device.wait_for_fences(&[fence], true, u64::MAX) }.call("vkWaitForFences")?;
        let pixels = match capture_buffer {
            Some(buffer) => Some(buffer.read(self.swapchain.format().format)?),
            None => None,
        };
        match shown {
            Ok(false) => Ok(Presented::Shown(pixels)),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => {
                self.resize(size)?;
                Ok(Presented::Shown(pixels))
            }
            Err(result) => Err(GpuError::Vulkan {
                call: "vkQueuePresentKHR",
                result,
            }),
        }
    }

    /// Records the blit of `source` into `area` of `target` (whose size is
    /// `extent`; the rest cleared first when `area` is smaller), leaving
    /// `target` in `TRANSFER_DST_OPTIMAL`; returns that state for the next
    /// transition.
    fn record_blit(
        &self,
        cmd: vk::CommandBuffer,
        source: PresentSource,
        target: vk::Image,
        (extent, area): (vk::Extent2D, vk::Extent2D),
        filter: vk::Filter,
    ) -> TargetState {
        let device = self.gpu.device();
        // The clear and the blit are transfer stages, after the acquire
        // semaphore's wait ([`ACQUIRE_WAIT`]).
        let mut state = TargetState {
            image: target,
            stage: ACQUIRE_WAIT,
            access: vk::AccessFlags2::NONE,
            layout: vk::ImageLayout::UNDEFINED,
        };
        state.transition(
            self.gpu,
            cmd,
            ACQUIRE_WAIT,
            vk::AccessFlags2::TRANSFER_WRITE,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
        );
        if area != extent {
            // The panel's background where the image does not reach.
            let clear = vk::ClearColorValue {
                float32: [0.106, 0.106, 0.106, 1.0],
            };
            let ranges = [vk::ImageSubresourceRange::default()
                .aspect_mask(vk::ImageAspectFlags::COLOR)
                .level_count(1)
                .layer_count(1)];
            unsafe {
                device.cmd_clear_color_image(
                    cmd,
                    target,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &clear,
                    &ranges,
                );
            }
            state.transition(
                self.gpu,
                cmd,
                vk::PipelineStageFlags2::BLIT,
                vk::AccessFlags2::TRANSFER_WRITE,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            );
        }
        let region = vk::ImageBlit2::default()
            .src_subresource(color_layers())
            .src_offsets([vk::Offset3D::default(), corner(source.extent)])
            .dst_subresource(color_layers())
            .dst_offsets([vk::Offset3D::default(), corner(area)]);
        let regions = [region];
        let blit = vk::BlitImageInfo2::default()
            .src_image(source.image)
            .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .dst_image(target)
            .dst_image_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
            .regions(&regions)
            .filter(filter);
        unsafe { device.cmd_blit_image2(cmd, &blit) };
        state
    }
}

/// Where the swapchain image stands within one frame's commands: the stage
/// and access of its last use, and its layout.
struct TargetState {
    image: vk::Image,
    stage: vk::PipelineStageFlags2,
    access: vk::AccessFlags2,
    layout: vk::ImageLayout,
}

impl TargetState {
    /// Records a barrier from the last use to one at `stage` with `access` in
    /// `layout`, and makes that the last use.
    fn transition(
        &mut self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        stage: vk::PipelineStageFlags2,
        access: vk::AccessFlags2,
        layout: vk::ImageLayout,
    ) {
        let barrier = image_barrier(self.image)
            .src_stage_mask(self.stage)
            .src_access_mask(self.access)
            .dst_stage_mask(stage)
            .dst_access_mask(access)
            .old_layout(self.layout)
            .new_layout(layout);
        unsafe {
            gpu.device().cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().image_memory_barriers(&[barrier]),
            );
        }
        self.stage = stage;
        self.access = access;
        self.layout = layout;
    }
}

impl Drop for Presenter<'_> {
    fn drop(&mut self) {
        let device = self.gpu.device();
        unsafe {
            let _ = device.device_wait_idle();
            for &s in self.acquired.iter().chain(&self.rendered) {
                device.destroy_semaphore(s, None);
            }
            for &f in &self.fences {
                device.destroy_fence(f, None);
            }
            device.free_command_buffers(self.gpu.command_pool(), &self.commands);
        }
    }
}

fn semaphore(gpu: &Gpu) -> Result<vk::Semaphore, GpuError> {
    unsafe {
        gpu.device()
            .create_semaphore(&vk::SemaphoreCreateInfo::default(), None)
    }
    .call("vkCreateSemaphore")
}

pub(super) fn color_layers() -> vk::ImageSubresourceLayers {
    vk::ImageSubresourceLayers {
        aspect_mask: vk::ImageAspectFlags::COLOR,
        mip_level: 0,
        base_array_layer: 0,
        layer_count: 1,
    }
}

fn corner(extent: vk::Extent2D) -> vk::Offset3D {
    vk::Offset3D {
        x: extent.width as i32,
        y: extent.height as i32,
        z: 1,
    }
}

fn image_barrier(image: vk::Image) -> vk::ImageMemoryBarrier2<'static> {
    vk::ImageMemoryBarrier2::default()
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(SWAPCHAIN_RANGE)
}

/// A swapchain image's one mip and layer, colour aspect.
pub const SWAPCHAIN_RANGE: vk::ImageSubresourceRange = vk::ImageSubresourceRange {
    aspect_mask: vk::ImageAspectFlags::COLOR,
    base_mip_level: 0,
    level_count: 1,
    base_array_layer: 0,
    layer_count: 1,
};
