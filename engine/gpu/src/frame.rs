//! Objects that live for one frame: debug labels, the descriptor pool and
//! the command buffers, each released on drop.

use crate::context::Gpu;
use crate::error::{GpuError, VkCall};
use ash::vk;
use std::ffi::CString;

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

/// The command buffers of one frame, freed on drop.
pub(crate) struct CommandBuffers<'g> {
    gpu: &'g Gpu,
    buffers: Vec<vk::CommandBuffer>,
}

impl<'g> CommandBuffers<'g> {
    pub(crate) fn new(gpu: &'g Gpu) -> Self {
        Self {
            gpu,
            buffers: Vec::new(),
        }
    }

    pub(crate) fn begin(&mut self) -> Result<vk::CommandBuffer, GpuError> {
        let cmd = self.gpu.allocate_command_buffer()?;
        self.buffers.push(cmd);
        let info = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        unsafe { self.gpu.device().begin_command_buffer(cmd, &info) }
            .call("vkBeginCommandBuffer")?;
        Ok(cmd)
    }

    pub(crate) fn submit_and_wait(&self, cmd: vk::CommandBuffer) -> Result<(), GpuError> {
        unsafe { self.gpu.device().end_command_buffer(cmd) }.call("vkEndCommandBuffer")?;
        self.gpu.submit_and_wait(cmd)
    }
}

impl Drop for CommandBuffers<'_> {
    fn drop(&mut self) {
        if self.buffers.is_empty() {
            return;
        }
        unsafe {
            let _ = self.gpu.device().device_wait_idle();
            self.gpu
                .device()
                .free_command_buffers(self.gpu.command_pool(), &self.buffers);
        }
    }
}
