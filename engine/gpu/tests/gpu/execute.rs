//! Runs compiled graphs on the device under validation and synchronization
//! validation and checks the exact pixels.

use crate::common;

use weft_gpu::{FrameOptions, NoDraws, Renderer, Severity, TimingMode, TimingSource};

/// Expected pixel of the `mixed` fixture at (x, y): red from the pattern,
/// green from the inverted pattern, blue from the parameter via the buffer.
fn mixed_pixel(x: u32, y: u32) -> [u8; 4] {
    [(x * 32) as u8, (255 - y * 32) as u8, 51, 255]
}

#[test]
fn fullscreen_compute_blit_graph_renders_exact_pixels() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("mixed.ron"), 8, 8);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let report = weft_testkit::one_frame(&mut renderer, &plan).expect("frame");
    let output = report.output.as_ref().expect("readback");
    assert_eq!((output.width, output.height), (8, 8));
    for y in 0..8 {
        for x in 0..8 {
            assert_eq!(output.rgba8_at(x, y), mixed_pixel(x, y), "pixel ({x}, {y})");
        }
    }
    assert_eq!(report.transient_bytes, plan.memory.transient_bytes);
    let json = serde_json::to_value(&report).expect("serialises");
    let keys: Vec<&str> = json
        .as_object()
        .expect("object")
        .keys()
        .map(String::as_str)
        .collect();
    assert_eq!(
        keys,
        vec![
            "dedicated_bytes",
            "memory",
            "record_ms",
            "statistics",
            "timings",
            "transient_bytes"
        ]
    );
    assert_eq!(json["transient_bytes"], plan.memory.transient_bytes);
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}

#[test]
fn dropping_a_barrier_is_reported_as_a_hazard() {
    let gpu = common::gpu();
    let mut plan = common::compile(&gpu, &common::graph("mixed.ron"), 8, 8);
    let stats = plan.resource("stats").expect("stats buffer");
    let combine = plan
        .passes
        .iter_mut()
        .find(|p| p.name == "combine")
        .expect("combine pass");
    let before = combine.barriers.len();
    combine.barriers.retain(|b| b.resource != stats);
    assert_eq!(combine.barriers.len(), before - 1);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let mut resources = renderer.create_resources(&plan).expect("resources");
    renderer
        .execute(
            &plan,
            &mut resources,
            &mut NoDraws,
            &FrameOptions::default(),
        )
        .expect("frame records and runs");
    let errors = gpu.validation().of(Severity::Error);
    let ids: Vec<&str> = errors.iter().map(|m| m.id.as_str()).collect();
    assert_eq!(ids, vec!["SYNC-HAZARD-READ-AFTER-WRITE"], "{errors:#?}");
    let text = &errors[0].text;
    assert!(text.contains("name = stats"), "{text}");
    assert!(
        text.contains("usage: SYNC_FRAGMENT_SHADER_UNIFORM_READ, prior_usage: SYNC_COMPUTE_SHADER_SHADER_STORAGE_WRITE"),
        "{text}"
    );
}

#[test]
fn renders_several_frames_with_cached_pipelines_and_timings() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("mixed.ron"), 8, 8);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let mut resources = renderer.create_resources(&plan).expect("resources");
    for (frame, timing) in [
        TimingMode::GpuTimestamps,
        TimingMode::CpuPerPass,
        TimingMode::Off,
    ]
    .into_iter()
    .enumerate()
    {
        let report = renderer
            .execute(
                &plan,
                &mut resources,
                &mut NoDraws,
                &FrameOptions {
                    timing,
                    readback: true,
                    frame: frame as u32,
                    ..FrameOptions::default()
                },
            )
            .expect("frame");
        assert_eq!(
            report.output.expect("readback").rgba8_at(3, 5),
            mixed_pixel(3, 5)
        );
        let names: Vec<&str> = report.timings.iter().map(|t| t.pass.as_str()).collect();
        match timing {
            TimingMode::Off => assert!(names.is_empty()),
            _ => assert_eq!(names, vec!["fill", "shrink", "invert", "combine"]),
        }
        if timing == TimingMode::GpuTimestamps {
            // Counts the API defines exactly (fragment and clipping counts
            // depend on the rasteriser): (primitives, vertices, compute invocations).
            let counts: Vec<(&str, u64, u64, u64)> = report
                .statistics
                .iter()
                .map(|s| {
                    (
                        s.pass.as_str(),
                        s.input_primitives,
                        s.vertex_invocations,
                        s.compute_invocations,
                    )
                })
                .collect();
            assert_eq!(
                counts,
                vec![
                    ("fill", 1, 3, 0),
                    ("shrink", 0, 0, 0),
                    ("invert", 0, 0, 64),
                    ("combine", 1, 3, 0)
                ]
            );
        } else {
            assert!(report.statistics.is_empty());
        }
        let expected_source = match timing {
            TimingMode::CpuPerPass => Some(TimingSource::CpuWall),
            TimingMode::GpuTimestamps => Some(TimingSource::GpuTimestamp),
            TimingMode::Off => None,
        };
        assert!(report
            .timings
            .iter()
            .all(|t| Some(t.source) == expected_source && t.ms >= 0.0));
    }
    assert_eq!(renderer.pipelines().pipeline_count(), 3);
    assert_eq!(renderer.render_pass_count(), 2);
    assert_eq!(renderer.check_shaders(&plan), Vec::new());
    drop(resources);
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}

#[test]
fn history_images_carry_values_across_frames() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("history.ron"), 8, 8);
    let order: Vec<&str> = plan.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(order, vec!["show", "accumulate"]);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let mut resources = renderer.create_resources(&plan).expect("resources");
    let mut shown = Vec::new();
    for frame in 0..4 {
        let report = renderer
            .execute(
                &plan,
                &mut resources,
                &mut NoDraws,
                &FrameOptions {
                    readback: true,
                    frame,
                    ..FrameOptions::default()
                },
            )
            .expect("frame");
        shown.push(report.output.expect("readback").rgba8_at(7, 7));
    }
    // `show` runs first and sees the previous frame's accumulation.
    assert_eq!(
        shown[1..],
        [[16, 0, 0, 255], [32, 0, 0, 255], [48, 0, 0, 255]]
    );
    drop(resources);
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}

#[test]
fn transient_images_and_buffers_share_memory_as_planned() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("mixed.ron"), 8, 8);
    let placement = |name: &str| {
        plan.resources[plan.resource(name).expect("resource")]
            .placement
            .expect("placed")
    };
    let (pattern, inverted) = (placement("pattern"), placement("inverted"));
    assert_eq!(
        (pattern.block, pattern.offset),
        (inverted.block, inverted.offset)
    );
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let mut resources = renderer.create_resources(&plan).expect("resources");
    let report = renderer
        .execute(
            &plan,
            &mut resources,
            &mut NoDraws,
            &FrameOptions::default(),
        )
        .expect("frame");
    let placed: u64 = plan
        .resources
        .iter()
        .filter(|r| r.placement.is_some())
        .map(|r| r.placement.map_or(0, |p| p.size))
        .sum();
    assert_eq!(placed, plan.memory.transient_bytes_unaliased);
    // The buffer, alive with `inverted`, takes the rest of what the pattern
    // is done with.
    let stats = placement("stats");
    assert_eq!(stats.block, pattern.block);
    assert!(stats.offset >= inverted.offset + inverted.size);
    assert!(stats.offset + stats.size <= pattern.offset + pattern.size);
    assert_eq!(
        plan.memory.transient_bytes,
        plan.memory.transient_bytes_unaliased - inverted.size - stats.size
    );
    assert_eq!(report.transient_bytes, plan.memory.transient_bytes);
    assert_eq!(
        report.memory.allocated_bytes,
        report.transient_bytes + report.dedicated_bytes
    );
    drop(resources);
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}

#[test]
fn depth_attachments_clear_and_are_sampled() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("depth.ron"), 4, 4);
    let report = common::render_readback(&gpu, &plan, 1);
    let output = report.output.expect("readback");
    // Depth cleared to 0.25 and never written: 0.25 * 255 = 63.75.
    assert_eq!(output.rgba8_at(2, 1), [64, 0, 0, 255]);
    common::assert_no_validation_messages(gpu);
}

#[test]
fn image_and_buffer_copies_carry_data_between_passes() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("copies.ron"), 8, 8);
    let report = common::render_readback(&gpu, &plan, 2);
    let output = report.output.expect("readback");
    for (x, y) in [(0, 0), (3, 6), (7, 7)] {
        let expected = [(x / 2 * 32) as u8, (y / 2 * 32) as u8, 153, 255];
        assert_eq!(output.rgba8_at(x, y), expected, "pixel ({x}, {y})");
    }
    common::assert_no_validation_messages(gpu);
}

#[test]
fn a_pass_without_bindings_renders_its_parameter() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("solid.ron"), 3, 2);
    let report = common::render_readback(&gpu, &plan, 1);
    let output = report.output.expect("readback");
    assert_eq!(output.format, "B8G8R8A8_UNORM");
    // 0.2, 0.4, 0.6 of 255, read back from BGRA and swizzled to RGBA.
    assert_eq!(output.rgba8_at(2, 1), [51, 102, 153, 255]);
    common::assert_no_validation_messages(gpu);
}
