//! What frames record with: debug labels around passes, and the pools every
//! frame reuses (command buffers, fence, queries, read-back buffers).

use crate::context::Gpu;
use crate::download::ReadbackBuffer;
use crate::error::{GpuError, VkCall};
use crate::statistics::StatisticsPool;
use crate::timing::QueryPool;
use ash::vk;
use std::ffi::CString;
use weft_graph::id::ResourceId;
use weft_graph::plan::Plan;

/// A debug-utils label around a pass, so validation messages name it.
pub(crate) struct Label(bool);

impl Label {
    pub(crate) fn begin(gpu: &Gpu, cmd: vk::CommandBuffer, name: &str) -> Self {
        let (Some(debug), Ok(name)) = (gpu.debug_utils(), CString::new(name)) else {
            return Self(false);
        };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
        unsafe { debug.cmd_begin_debug_utils_label(cmd, &label) };
        Self(true)
    }

    pub(crate) fn end(self, gpu: &Gpu, cmd: vk::CommandBuffer) {
        if let (true, Some(debug)) = (self.0, gpu.debug_utils()) {
            unsafe { debug.cmd_end_debug_utils_label(cmd) };
        }
    }
}

/// What every frame records into and reads back through, made once and
/// reused while it fits: command buffers and a fence ([`Commands`]), the
/// timestamp and statistics query pools, and the read-back buffers. Frames
/// are recorded, submitted and waited for one at a time, so nothing here is
/// in use when the next frame starts.
pub(crate) struct FramePools<'g> {
    gpu: &'g Gpu,
    pub(crate) commands: Commands<'g>,
    pub(crate) queries: Option<QueryPool<'g>>,
    pub(crate) statistics: Option<StatisticsPool<'g>>,
    pub(crate) readbacks: Vec<ReadbackBuffer<'g>>,
}

impl<'g> FramePools<'g> {
    pub(crate) fn new(gpu: &'g Gpu) -> Result<Self, GpuError> {
        Ok(Self {
            gpu,
            commands: Commands::new(gpu)?,
            queries: None,
            statistics: None,
            readbacks: Vec::new(),
        })
    }

    /// Makes the pools fit a frame of `plan`: `timestamps` and `statistics`
    /// queries when asked for, and read-back buffers for `readback` (the
    /// images, in order). Pools that already fit are kept; the command
    /// buffers start over.
    pub(crate) fn fit(
        &mut self,
        plan: &Plan,
        (timestamps, statistics): (bool, bool),
        readback: &[ResourceId],
    ) -> Result<(), GpuError> {
        self.commands.used = 0;
        let passes = plan.passes.len() as u32;
        if !timestamps {
            self.queries = None;
        } else if self
            .queries
            .as_ref()
            .is_none_or(|q| q.count != (2 * passes).max(1))
        {
            self.queries = Some(QueryPool::new(self.gpu, 2 * passes)?);
        }
        if !statistics {
            self.statistics = None;
        } else if self
            .statistics
            .as_ref()
            .is_none_or(|s| s.count() != passes.max(1))
        {
            self.statistics = Some(StatisticsPool::new(self.gpu, passes)?);
        }
        let fits = self.readbacks.len() == readback.len()
            && self
                .readbacks
                .iter()
                .zip(readback)
                .all(|(buffer, &r)| buffer.fits(plan, r));
        if !fits {
            self.readbacks = readback
                .iter()
                .map(|&r| ReadbackBuffer::new(self.gpu, plan, r))
                .collect::<Result<_, _>>()?;
        }
        Ok(())
    }
}

/// Primary command buffers, begun again frame after frame (the pool resets
/// them), and the fence their submissions are waited on.
pub(crate) struct Commands<'g> {
    gpu: &'g Gpu,
    buffers: Vec<vk::CommandBuffer>,
    /// Command buffers begun this frame.
    used: usize,
    fence: vk::Fence,
}

impl<'g> Commands<'g> {
    fn new(gpu: &'g Gpu) -> Result<Self, GpuError> {
        let fence = unsafe {
            gpu.device()
                .create_fence(&vk::FenceCreateInfo::default(), None)
        }
        .call("vkCreateFence")?;
        Ok(Self {
            gpu,
            buffers: Vec::new(),
            used: 0,
            fence,
        })
    }

    /// Begins the frame's next command buffer.
    pub(crate) fn begin(&mut self) -> Result<vk::CommandBuffer, GpuError> {
        if self.used == self.buffers.len() {
            self.buffers.push(self.gpu.allocate_command_buffer()?);
        }
        let cmd = self.buffers[self.used];
        self.used += 1;
        // Explicitly, so a buffer a failed frame left recording starts clean.
        unsafe {
            self.gpu
                .device()
                .reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty())
        }
        .call("vkResetCommandBuffer")?;
        let info = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        unsafe { self.gpu.device().begin_command_buffer(cmd, &info) }
            .call("vkBeginCommandBuffer")?;
        Ok(cmd)
    }

    /// Ends `cmd`, submits it and waits for it.
    pub(crate) fn submit_and_wait(&self, cmd: vk::CommandBuffer) -> Result<(), GpuError> {
        unsafe { self.gpu.device().end_command_buffer(cmd) }.call("vkEndCommandBuffer")?;
        self.gpu.submit_and_wait_on(cmd, self.fence)
    }
}

impl Drop for Commands<'_> {
    fn drop(&mut self) {
        let device = self.gpu.device();
        unsafe {
            let _ = device.device_wait_idle();
            if !self.buffers.is_empty() {
                device.free_command_buffers(self.gpu.command_pool(), &self.buffers);
            }
            device.destroy_fence(self.fence, None);
        }
    }
}
