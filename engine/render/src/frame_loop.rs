//! The one frame loop. A [`FrameLoop`] is a committed plan made ready to run:
//! its images and buffers, the scene on the GPU with its recorder, and the
//! executor with its pipeline cache. It is built once, when a plan is
//! committed; a frame then only moves the camera and lights to the frame's
//! time, starts the frame and records. `render`, `render --watch`, `view` and
//! the benchmarks all draw through [`FrameLoop::draw`].

use crate::error::RenderError;
use crate::recorder::SceneRecorder;
use crate::scene_gpu::GpuScene;
use std::sync::Arc;
use weft_gpu::resources::GpuImage;
use weft_gpu::{FrameOptions, FrameReport, FrameResources, Gpu, GpuError, Renderer, TimingMode};
use weft_graph::plan::Plan;
use weft_scene::Camera;

/// A plan ready to run on one device, with the scene it draws.
pub struct FrameLoop<'g> {
    // Field order is drop order: resources and the recorder before the
    // executor whose device objects they were made with.
    resources: FrameResources<'g>,
    recorder: SceneRecorder<'g>,
    renderer: Renderer<'g>,
    plan: Arc<Plan>,
}

/// What one frame is: when, and what to measure and copy back.
#[derive(Debug, Clone, Copy)]
pub struct FrameRequest<'c> {
    /// The camera to look through (animated to `time`).
    pub camera: &'c Camera,
    /// Scene time in seconds.
    pub time: f32,
    /// Frame number.
    pub frame: u32,
    /// How per-pass times are measured.
    pub timing: TimingMode,
    /// Copy the output and the plan's read-back images back.
    pub readback: bool,
}

impl<'g> FrameLoop<'g> {
    /// Creates the plan's resources and the scene's recorder; the first frame
    /// builds the pipelines.
    pub fn new(gpu: &'g Gpu, plan: Arc<Plan>, scene: GpuScene<'g>) -> Result<Self, GpuError> {
        let renderer = Renderer::new(gpu)?;
        let recorder = SceneRecorder::new(gpu, scene)?;
        let resources = renderer.create_resources(&plan)?;
        Ok(Self {
            resources,
            recorder,
            renderer,
            plan,
        })
    }

    /// Draws one frame: the scene moved to the request's time, the plan
    /// recorded and submitted, waited for, read back when asked.
    pub fn draw(&mut self, request: &FrameRequest<'_>) -> Result<FrameReport, RenderError> {
        let extent = [self.plan.extent.width, self.plan.extent.height];
        self.recorder
            .scene
            .update(request.camera, request.time, extent)?;
        self.recorder.set_frame(request.time, request.frame);
        let options = FrameOptions {
            timing: request.timing,
            readback: request.readback,
            time: request.time,
            frame: request.frame,
        };
        self.renderer
            .execute(
                &self.plan,
                &mut self.resources,
                &mut self.recorder,
                &options,
            )
            .map_err(|e| RenderError::at_pass(e, &self.plan))
    }

    /// The plan that runs.
    pub fn plan(&self) -> &Arc<Plan> {
        &self.plan
    }

    /// The plan's output image; after a frame it is in `TRANSFER_SRC_OPTIMAL`.
    pub fn output(&self) -> Result<&GpuImage, GpuError> {
        self.resources.image(self.plan.output)
    }

    /// Draw calls recorded in the last frame.
    pub fn draw_calls(&self) -> u64 {
        self.recorder.draw_calls
    }

    /// Creates a new plan's resources without touching the running one, for a
    /// reload to swap in with [`FrameLoop::swap_plan`] once all of it succeeded.
    pub fn create_resources(&self, plan: &Plan) -> Result<FrameResources<'g>, GpuError> {
        self.renderer.create_resources(plan)
    }

    /// Runs `plan` from the next frame, on `resources` made for it.
    pub fn swap_plan(&mut self, plan: Arc<Plan>, resources: FrameResources<'g>) {
        self.resources = resources;
        self.plan = plan;
    }

    /// Draws another scene from the next frame.
    pub fn swap_scene(&mut self, recorder: SceneRecorder<'g>) {
        self.recorder = recorder;
    }

    /// The executor (its pipeline cache takes reloaded shader modules).
    pub fn renderer(&mut self) -> &mut Renderer<'g> {
        &mut self.renderer
    }

    /// The scene recorder (its pipeline cache takes reloaded shader modules).
    pub fn recorder(&mut self) -> &mut SceneRecorder<'g> {
        &mut self.recorder
    }
}
