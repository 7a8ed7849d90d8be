//! Safe recording into a command buffer the executor has begun. The handles
//! passed in come from this crate's caches and resources, which keep them alive
//! until the frame has finished; that is the contract under which these calls
//! are sound, and it is kept in one place here rather than at every call site.

use ash::vk;

/// A command buffer in the recording state, with the device that records into it.
#[derive(Clone, Copy)]
pub struct Commands<'a> {
    device: &'a ash::Device,
    cmd: vk::CommandBuffer,
}

impl<'a> Commands<'a> {
    /// Records into `cmd`, which must be in the recording state.
    pub fn new(device: &'a ash::Device, cmd: vk::CommandBuffer) -> Self {
        Self { device, cmd }
    }

    /// Binds a pipeline.
    pub fn bind_pipeline(&self, point: vk::PipelineBindPoint, pipeline: vk::Pipeline) {
        unsafe { self.device.cmd_bind_pipeline(self.cmd, point, pipeline) }
    }

    /// Binds descriptor sets from `first_set` on.
    pub fn bind_sets(
        &self,
        point: vk::PipelineBindPoint,
        layout: vk::PipelineLayout,
        first_set: u32,
        sets: &[vk::DescriptorSet],
    ) {
        unsafe {
            self.device
                .cmd_bind_descriptor_sets(self.cmd, point, layout, first_set, sets, &[])
        }
    }

    /// Sets push constants from offset 0.
    pub fn push_constants(
        &self,
        layout: vk::PipelineLayout,
        stages: vk::ShaderStageFlags,
        bytes: &[u8],
    ) {
        unsafe {
            self.device
                .cmd_push_constants(self.cmd, layout, stages, 0, bytes)
        }
    }

    /// Binds vertex buffer 0 and a 32-bit index buffer, both from offset 0.
    pub fn bind_geometry(&self, vertices: vk::Buffer, indices: vk::Buffer) {
        unsafe {
            self.device
                .cmd_bind_vertex_buffers(self.cmd, 0, &[vertices], &[0]);
            self.device
                .cmd_bind_index_buffer(self.cmd, indices, 0, vk::IndexType::UINT32);
        }
    }

    /// Sets the dynamic front face.
    pub fn set_front_face(&self, face: vk::FrontFace) {
        unsafe { self.device.cmd_set_front_face(self.cmd, face) }
    }

    /// Sets the dynamic viewport (depth range 0..1) and a scissor over the same area.
    pub fn set_viewport_and_scissor(&self, area: vk::Rect2D) {
        let viewport = vk::Viewport {
            x: area.offset.x as f32,
            y: area.offset.y as f32,
            width: area.extent.width as f32,
            height: area.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        unsafe {
            self.device.cmd_set_viewport(self.cmd, 0, &[viewport]);
            self.device.cmd_set_scissor(self.cmd, 0, &[area]);
        }
    }

    /// Sets the current subpass's depth attachment to `depth` inside `area`,
    /// within a render pass (`vkCmdClearAttachments`).
    pub fn clear_depth(&self, area: vk::Rect2D, depth: f32) {
        let attachment = vk::ClearAttachment {
            aspect_mask: vk::ImageAspectFlags::DEPTH,
            color_attachment: 0,
            clear_value: vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue { depth, stencil: 0 },
            },
        };
        let rect = vk::ClearRect {
            rect: area,
            base_array_layer: 0,
            layer_count: 1,
        };
        unsafe {
            self.device
                .cmd_clear_attachments(self.cmd, &[attachment], &[rect])
        }
    }

    /// An indexed draw of one instance, `first_instance` passed through.
    pub fn draw_indexed(
        &self,
        index_count: u32,
        first_index: u32,
        vertex_offset: i32,
        first_instance: u32,
    ) {
        self.draw_indexed_instanced(index_count, 1, first_index, vertex_offset, first_instance)
    }

    /// An indexed draw of `instances` instances.
    pub fn draw_indexed_instanced(
        &self,
        index_count: u32,
        instances: u32,
        first_index: u32,
        vertex_offset: i32,
        first_instance: u32,
    ) {
        unsafe {
            self.device.cmd_draw_indexed(
                self.cmd,
                index_count,
                instances,
                first_index,
                vertex_offset,
                first_instance,
            )
        }
    }
}
