//! Helpers only tests use, kept out of the engine's public APIs: golden-image
//! comparison, the CPU mirror of tiled light culling, running a plan for
//! several frames, and scratch folders removed at exit.

pub mod brdf;
pub mod golden;
pub mod light_scene;
pub mod raytrace;
pub mod scratch;
pub mod tiles;

pub use golden::{check_golden, Comparison, GoldenError, Tolerance};

use weft_gpu::{DrawRecorder, FrameOptions, FrameReport, GpuError, Renderer};
use weft_graph::Plan;

/// One frame of `plan` with its output and read-back images copied back and
/// no scene draws (graphs of fullscreen, compute and transfer passes).
pub fn one_frame(renderer: &mut Renderer<'_>, plan: &Plan) -> Result<FrameReport, GpuError> {
    let options = FrameOptions {
        readback: true,
        ..FrameOptions::default()
    };
    render_frames(renderer, plan, &mut weft_gpu::NoDraws, 1, 0.0, &options)
}

/// Creates the plan's resources, runs `frames` frames (numbered from 0,
/// `time` advancing by `frame_time` seconds) and returns the last frame's
/// report, read back when `options.readback` asks for it.
pub fn render_frames(
    renderer: &mut Renderer<'_>,
    plan: &Plan,
    draws: &mut dyn DrawRecorder,
    frames: u32,
    frame_time: f32,
    options: &FrameOptions,
) -> Result<FrameReport, GpuError> {
    let mut resources = renderer.create_resources(plan)?;
    let mut last = None;
    for frame in 0..frames.max(1) {
        let options = FrameOptions {
            frame,
            time: options.time + frame as f32 * frame_time,
            readback: options.readback && frame + 1 == frames.max(1),
            timing: options.timing,
            history_frames: options.history_frames + frame,
            plan_frames: options.plan_frames + frame,
        };
        last = Some(renderer.execute(plan, &mut resources, draws, &options)?);
    }
    last.ok_or_else(|| GpuError::Plan("no frame was rendered".into()))
}
