//! Rays per pass (engine/render/src/providers/ray_counts.rs), the cost model
//! `weft compare` shows beside each pass's time: every BVH walk a tracing
//! pass makes adds one to its pass's counter. Counts whose value follows from
//! the graph are checked exactly, and a path tracer's counts, fixed by its
//! seed, do not depend on how the frame is submitted.

use weft_gpu::TimingMode;
use weft_render::{PassRays, RenderSettings};
use weft_tests::render::square_settings;

const SIZE: u32 = 16;
const PIXELS: u64 = (SIZE * SIZE) as u64;

/// The rays of every frame of a validated render of the Cornell box.
fn rays(settings: RenderSettings) -> Vec<Vec<PassRays>> {
    let scene = weft_tests::render::root().join("scenes/cornell.scene");
    let (rendered, _) = weft_tests::render::render_hdr_validated(&scene, settings);
    rendered.rays
}

fn of(frame: &[PassRays], pass: &str) -> u64 {
    frame
        .iter()
        .find(|r| r.pass == pass)
        .unwrap_or_else(|| panic!("no count for {pass} in {frame:?}"))
        .rays
}

#[test]
fn camera_rays_are_one_per_sample_and_guides_one_per_pixel() {
    let mut settings = square_settings(
        "pathtrace.ron",
        SIZE,
        None,
        &[("max_depth", 1.0), ("samples_per_frame", 3.0)],
        &[],
    );
    settings.frames = 2;
    let frames = rays(settings);
    assert_eq!(frames.len(), 2);
    for frame in &frames {
        // max_depth 1: the camera ray only, three samples a pixel, every frame.
        assert_eq!(of(frame, "trace"), 3 * PIXELS);
    }
    let mut settings = square_settings("pathtrace_denoised.ron", SIZE, None, &[], &[]);
    settings.frames = 2;
    let frames = rays(settings);
    assert_eq!(of(&frames[1], "guides"), PIXELS);
    assert!(of(&frames[1], "trace") > 2 * PIXELS, "{frames:?}");
}

#[test]
fn a_pass_whose_tracing_feature_is_off_traces_nothing() {
    let mut settings = square_settings("forward.ron", SIZE, None, &[], &["!bloom"]);
    settings.frames = 1;
    let frames = rays(settings);
    // The forward pass declares `RayTracing` for its `rt_shadows` feature.
    assert_eq!(of(&frames[0], "forward"), 0);
    settings = square_settings("forward.ron", SIZE, None, &[], &["!bloom", "rt_shadows"]);
    let frames = rays(settings);
    assert!(of(&frames[0], "forward") > 0, "{frames:?}");
}

#[test]
fn ambient_occlusion_traces_its_rays_for_every_covered_pixel() {
    let ao = |rays: f64| {
        let mut settings = square_settings(
            "deferred.ron",
            SIZE,
            None,
            &[("rt_ao.rays", rays)],
            &["!bloom", "rt_ao"],
        );
        settings.frames = 1;
        of(&self::rays(settings)[0], "rt_ao")
    };
    let one = ao(1.0);
    // Pixels that see past the box trace none.
    assert!(one > 0 && one < PIXELS, "{one}");
    assert_eq!(ao(8.0), 8 * one);
}

#[test]
fn counts_are_the_same_with_each_pass_submitted_alone() {
    let settings = |timing| RenderSettings {
        timing,
        frames: 2,
        ..square_settings("pathtrace.ron", SIZE, None, &[("max_depth", 4.0)], &[])
    };
    let together = rays(settings(TimingMode::Off));
    let alone = rays(settings(TimingMode::CpuPerPass));
    assert_eq!(together, alone);
    // Two frames with different samples trace different paths.
    assert_ne!(together[0], together[1]);
}
