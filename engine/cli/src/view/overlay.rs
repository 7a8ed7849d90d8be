//! The viewer's panel on screen: egui fed with the window's events
//! (egui-winit) and drawn by egui-ash-renderer in a render pass of its own over
//! the presented image, as the presenter's [`Overlay`] — after the graph's
//! output is blitted, so it is never part of the graph or its timings.

use anyhow::{anyhow, Context, Result};
use ash::vk;
use egui_ash_renderer::allocator::DefaultAllocator;
use egui_ash_renderer::{Options, RenderMode, Renderer};
use weft_gpu::{Gpu, GpuError, Overlay, OverlayTarget, VkCall};
use winit::event::WindowEvent;
use winit::window::Window;

/// A swapchain image's view and framebuffer for the overlay's render pass.
struct Target {
    image: vk::Image,
    extent: vk::Extent2D,
    view: vk::ImageView,
    framebuffer: vk::Framebuffer,
}

/// egui on Vulkan over the presented image.
pub struct EguiOverlay<'g> {
    gpu: &'g Gpu,
    ctx: egui::Context,
    state: egui_winit::State,
    renderer: Renderer<DefaultAllocator>,
    format: vk::Format,
    render_pass: vk::RenderPass,
    /// Texture uploads run on a pool of the overlay's own.
    pool: vk::CommandPool,
    targets: Vec<Option<Target>>,
    /// The last run's shapes, drawn by the next [`Overlay::record`].
    primitives: Vec<egui::ClippedPrimitive>,
    pixels_per_point: f32,
    /// Textures egui no longer uses, freed once the frame drawn with them is done.
    to_free: Vec<egui::TextureId>,
    /// Events given by a script (`--ui`), added to the next run's input.
    injected: Vec<egui::Event>,
}

impl<'g> EguiOverlay<'g> {
    /// Sets egui up for `window`, drawing onto swapchain images of `format`.
    pub fn new(gpu: &'g Gpu, window: &Window, format: vk::Format) -> Result<Self> {
        let ctx = egui::Context::default();
        // A click is a press and a release without moving away, however
        // long the frames between them take: egui measures a press in frame
        // times, and at 1-2 s a frame (a large image on a CPU device) its
        // default 0.8 s would turn every click into a long press, lost.
        ctx.options_mut(|o| o.input_options.max_click_duration = f64::INFINITY);
        let state = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        let render_pass = render_pass(gpu, format)?;
        let renderer = Renderer::with_default_allocator(
            gpu.instance(),
            gpu.physical_device(),
            gpu.device().clone(),
            RenderMode::RenderPass(render_pass),
            Options {
                in_flight_frames: 1,
                srgb_framebuffer: is_srgb(format),
                ..Options::default()
            },
        )
        .map_err(|e| anyhow!("setting up the panel's renderer: {e}"))?;
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(gpu.queue_family())
            .flags(vk::CommandPoolCreateFlags::TRANSIENT);
        let pool = unsafe { gpu.device().create_command_pool(&pool_info, None) }
            .call("vkCreateCommandPool")?;
        Ok(Self {
            gpu,
            ctx,
            state,
            renderer,
            format,
            render_pass,
            pool,
            targets: Vec::new(),
            primitives: Vec::new(),
            pixels_per_point: 1.0,
            to_free: Vec::new(),
            injected: Vec::new(),
        })
    }

    /// Passes a window event to egui; true when egui used it (a click on
    /// the panel, typing into a field), so the viewer should not act on it.
    pub fn on_window_event(&mut self, window: &Window, event: &WindowEvent) -> bool {
        self.state.on_window_event(window, event).consumed
    }

    /// Window pixels per egui point, as the last run laid the UI out.
    pub fn pixels_per_point(&self) -> f32 {
        self.pixels_per_point
    }

    /// The egui context (to load textures the UI shows).
    pub fn context(&self) -> &egui::Context {
        &self.ctx
    }

    /// Whether the pointer is over the panel or dragging one of its widgets.
    pub fn wants_pointer(&self) -> bool {
        self.ctx.egui_wants_pointer_input() || self.ctx.is_pointer_over_egui()
    }

    /// Whether a panel field has the keyboard.
    pub fn wants_keyboard(&self) -> bool {
        self.ctx.egui_wants_keyboard_input()
    }

    /// Queues events for the next run, as if they came from the window.
    pub fn inject(&mut self, events: impl IntoIterator<Item = egui::Event>) {
        self.injected.extend(events);
    }

    /// Runs the UI for this frame and uploads what it needs; the shapes are
    /// drawn by the next [`Overlay::record`]. `ui` returns what it wants done.
    pub fn run<T>(&mut self, window: &Window, mut ui: impl FnMut(&mut egui::Ui) -> T) -> Result<T> {
        let mut input = self.state.take_egui_input(window);
        input.events.append(&mut self.injected);
        let mut result = None;
        let mut output = self.ctx.run_ui(input, |root| result = Some(ui(root)));
        self.state
            .handle_platform_output(window, output.platform_output);
        self.pixels_per_point = output.pixels_per_point;
        self.primitives = self.ctx.tessellate(output.shapes, output.pixels_per_point);
        // Every delta is taken here (egui checks none is dropped unapplied).
        let set: Vec<_> = output.textures_delta.set.drain().collect();
        self.to_free.extend(output.textures_delta.free.drain());
        for (id, deltas) in set {
            for delta in &deltas {
                self.renderer
                    .set_texture(self.gpu.queue(), self.pool, id, delta)
                    .map_err(|e| anyhow!("uploading a panel texture: {e}"))?;
            }
        }
        result.context("the panel's UI did not run")
    }

    /// Frees the textures the last frame stopped using (after it was presented).
    pub fn after_present(&mut self) -> Result<()> {
        for id in self.to_free.drain(..) {
            self.renderer
                .free_texture(id)
                .map_err(|e| anyhow!("freeing a panel texture: {e}"))?;
        }
        Ok(())
    }

    /// Nothing to draw this frame: the next present shows no overlay.
    pub fn clear(&mut self) {
        self.primitives.clear();
    }

    /// The view and framebuffer for `target`, made (again) when the
    /// swapchain image or its size changed. Every earlier frame has finished
    /// (the presenter waits for each), so replaced ones can go at once.
    fn framebuffer(&mut self, target: &OverlayTarget) -> Result<vk::Framebuffer, GpuError> {
        if target.format != self.format {
            self.destroy_targets();
            let pass = render_pass(self.gpu, target.format)?;
            unsafe {
                self.gpu
                    .device()
                    .destroy_render_pass(self.render_pass, None)
            };
            self.render_pass = pass;
            self.format = target.format;
            self.renderer
                .set_render_mode(RenderMode::RenderPass(pass))
                .map_err(|e| GpuError::Plan(format!("the panel's pipeline: {e}")))?;
        }
        if self.targets.len() <= target.index {
            self.targets.resize_with(target.index + 1, || None);
        }
        let slot = &mut self.targets[target.index];
        match slot {
            Some(t) if t.image == target.image && t.extent == target.extent => Ok(t.framebuffer),
            _ => {
                if let Some(old) = slot.take() {
                    destroy_target(self.gpu, old);
                }
                let made = make_target(self.gpu, self.render_pass, target)?;
                let framebuffer = made.framebuffer;
                *slot = Some(made);
                Ok(framebuffer)
            }
        }
    }

    fn destroy_targets(&mut self) {
        for target in self.targets.drain(..).flatten() {
            destroy_target(self.gpu, target);
        }
    }
}

impl Overlay for EguiOverlay<'_> {
    fn record(&mut self, cmd: vk::CommandBuffer, target: &OverlayTarget) -> Result<(), GpuError> {
        if self.primitives.is_empty() {
            return Ok(());
        }
        let framebuffer = self.framebuffer(target)?;
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(self.render_pass)
            .framebuffer(framebuffer)
            .render_area(vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: target.extent,
            });
        let device = self.gpu.device();
        unsafe { device.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE) };
        let drawn = self
            .renderer
            .cmd_draw(cmd, target.extent, self.pixels_per_point, &self.primitives)
            .map_err(|e| GpuError::Plan(format!("drawing the panel: {e}")));
        unsafe { device.cmd_end_render_pass(cmd) };
        drawn
    }
}

impl Drop for EguiOverlay<'_> {
    fn drop(&mut self) {
        let _ = self.gpu.wait_idle();
        self.destroy_targets();
        unsafe {
            self.gpu
                .device()
                .destroy_render_pass(self.render_pass, None);
            self.gpu.device().destroy_command_pool(self.pool, None);
        }
    }
}

fn is_srgb(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::B8G8R8A8_SRGB | vk::Format::R8G8B8A8_SRGB | vk::Format::A8B8G8R8_SRGB_PACK32
    )
}

/// One subpass drawing over what the image holds: loaded and stored in
/// `COLOR_ATTACHMENT_OPTIMAL` (the presenter transitions around it).
fn render_pass(gpu: &Gpu, format: vk::Format) -> Result<vk::RenderPass, GpuError> {
    let attachments = [vk::AttachmentDescription::default()
        .format(format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::LOAD)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
        .final_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
    let colour = [vk::AttachmentReference::default()
        .attachment(0)
        .layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)];
    let subpasses = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&colour)];
    let stage = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT;
    let access = vk::AccessFlags::COLOR_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_WRITE;
    let dependencies = [
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(stage)
            .dst_stage_mask(stage)
            .src_access_mask(access)
            .dst_access_mask(access),
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(stage)
            .dst_stage_mask(stage)
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_access_mask(access),
    ];
    let info = vk::RenderPassCreateInfo::default()
        .attachments(&attachments)
        .subpasses(&subpasses)
        .dependencies(&dependencies);
    let pass =
        unsafe { gpu.device().create_render_pass(&info, None) }.call("vkCreateRenderPass")?;
    gpu.set_name(pass, "panel overlay");
    Ok(pass)
}

fn make_target(
    gpu: &Gpu,
    render_pass: vk::RenderPass,
    target: &OverlayTarget,
) -> Result<Target, GpuError> {
    let view_info = vk::ImageViewCreateInfo::default()
        .image(target.image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(target.format)
        .subresource_range(weft_gpu::present::SWAPCHAIN_RANGE);
    let view =
        unsafe { gpu.device().create_image_view(&view_info, None) }.call("vkCreateImageView")?;
    let views = [view];
    let info = vk::FramebufferCreateInfo::default()
        .render_pass(render_pass)
        .attachments(&views)
        .width(target.extent.width)
        .height(target.extent.height)
        .layers(1);
    let framebuffer = match unsafe { gpu.device().create_framebuffer(&info, None) } {
        Ok(f) => f,
        Err(result) => {
            unsafe { gpu.device().destroy_image_view(view, None) };
            return Err(GpuError::Vulkan {
                call: "vkCreateFramebuffer",
                result,
            });
        }
    };
    Ok(Target {
        image: target.image,
        extent: target.extent,
        view,
        framebuffer,
    })
}

fn destroy_target(gpu: &Gpu, target: Target) {
    unsafe {
        gpu.device().destroy_framebuffer(target.framebuffer, None);
        gpu.device().destroy_image_view(target.view, None);
    }
}
