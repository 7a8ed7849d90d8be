//! The graphs shipped in `graphs/` run end to end under validation, with the
//! scene draws supplied by a test recorder that paints a constant HDR colour.

use weft_graph::plan::Extent;
use weft_tests as common;

use ash::vk;
use weft_gpu::{DrawRecorder, FrameOptions, GpuError, RasterContext, Renderer};

/// Paints every colour attachment of a scene pass with one colour using
/// `vkCmdClearAttachments` (no pipeline needed); depth-only passes draw nothing.
struct Paint([f32; 4]);

impl DrawRecorder for Paint {
    fn record(&mut self, ctx: &mut RasterContext<'_>) -> Result<(), GpuError> {
        let colors = ctx
            .pass()
            .render_pass
            .as_ref()
            .map_or(0, |rp| rp.color.len());
        let attachments: Vec<vk::ClearAttachment> = (0..colors as u32)
            .map(|i| vk::ClearAttachment {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                color_attachment: i,
                clear_value: vk::ClearValue {
                    color: vk::ClearColorValue { float32: self.0 },
                },
            })
            .collect();
        if attachments.is_empty() {
            return Ok(());
        }
        let rect = vk::ClearRect {
            rect: vk::Rect2D {
                offset: vk::Offset2D::default(),
                extent: ctx.extent,
            },
            base_array_layer: 0,
            layer_count: 1,
        };
        unsafe {
            ctx.gpu
                .device()
                .cmd_clear_attachments(ctx.cmd, &attachments, &[rect])
        };
        Ok(())
    }
}

/// Paints a dim background with one bright square in the middle, so bloom
/// has something to spread.
struct BrightSquare;

impl DrawRecorder for BrightSquare {
    fn record(&mut self, ctx: &mut RasterContext<'_>) -> Result<(), GpuError> {
        let colors = ctx
            .pass()
            .render_pass
            .as_ref()
            .map_or(0, |rp| rp.color.len());
        if colors == 0 {
            return Ok(());
        }
        let clear = |c: [f32; 4]| {
            [vk::ClearAttachment {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                color_attachment: 0,
                clear_value: vk::ClearValue {
                    color: vk::ClearColorValue { float32: c },
                },
            }]
        };
        let rect = |x: u32, y: u32, w: u32, h: u32| {
            [vk::ClearRect {
                rect: vk::Rect2D {
                    offset: vk::Offset2D {
                        x: x as i32,
                        y: y as i32,
                    },
                    extent: vk::Extent2D {
                        width: w,
                        height: h,
                    },
                },
                base_array_layer: 0,
                layer_count: 1,
            }]
        };
        let (w, h) = (ctx.extent.width, ctx.extent.height);
        let device = ctx.gpu.device();
        unsafe {
            device.cmd_clear_attachments(
                ctx.cmd,
                &clear([0.05, 0.05, 0.1, 1.0]),
                &rect(0, 0, w, h),
            );
            device.cmd_clear_attachments(
                ctx.cmd,
                &clear([8.0, 6.0, 2.0, 1.0]),
                &rect(w / 2 - 4, h / 2 - 4, 8, 8),
            );
        }
        Ok(())
    }
}

/// sRGB encoding of a linear value to 8 bits, as an `_SRGB` attachment stores it.
fn srgb8(linear: f64) -> u8 {
    let v = if linear <= 0.0031308 {
        12.92 * linear
    } else {
        1.055 * linear.powf(1.0 / 2.4) - 0.055
    };
    (v * 255.0).round() as u8
}

/// Reinhard tonemapping then sRGB, as `shaders/tonemap.frag` with exposure 1.
fn tonemapped(c: [f64; 3]) -> [u8; 4] {
    let t = |v: f64| srgb8(v / (1.0 + v));
    [t(c[0]), t(c[1]), t(c[2]), 255]
}

/// The hardware's float-to-sRGB conversion may round to the neighbouring
/// 8-bit step (lavapipe gives 187 where the exact value is 187.52), so
/// channels are compared within one step.
fn assert_close(actual: [u8; 4], expected: [u8; 4]) {
    let far = (0..4).any(|c| actual[c].abs_diff(expected[c]) > 1);
    assert!(!far, "{actual:?} is not within 1 of {expected:?}");
}

fn render_forward(features: &[&str]) -> ([u8; 4], Vec<String>) {
    let gpu = common::gpu();
    let extent = Extent {
        width: 32,
        height: 18,
    };
    let plan = common::compile(
        &gpu,
        &common::shipped("forward.ron"),
        extent,
        features,
        Vec::new(),
    );
    let passes = plan.passes.iter().map(|p| p.name.clone()).collect();
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    assert_eq!(renderer.check_shaders(&plan), Vec::new());
    assert_eq!(
        weft_gpu::check_shaders(&plan, Some(&weft_render::scene_interface())).expect("shaderc"),
        Vec::new()
    );
    let report = weft_testkit::render_frames(
        &mut renderer,
        &plan,
        &mut Paint([1.0, 3.0, 0.0, 1.0]),
        2,
        1.0 / 60.0,
        &FrameOptions {
            readback: true,
            ..FrameOptions::default()
        },
    )
    .expect("frames");
    let output = report.output.expect("readback");
    let centre = output.rgba8_at(16, 9);
    for (x, y) in [(0, 0), (31, 17), (5, 12)] {
        assert_eq!(output.rgba8_at(x, y), centre, "pixel ({x}, {y})");
    }
    drop(renderer);
    common::assert_no_validation_messages(gpu);
    (centre, passes)
}

#[test]
fn forward_with_bloom_tonemaps_the_painted_colour() {
    let (pixel, passes) = render_forward(&[]);
    assert_eq!(
        passes,
        vec![
            "forward",
            "bloom_bright",
            "bloom_blur_h",
            "bloom_blur_v",
            "tonemap"
        ]
    );
    // The brightest channel, 3.0, is above the threshold (1.0): the bright pass
    // keeps the colour scaled by (3 - 1) / 3, and blurring a uniform image
    // leaves it as it is, so bloom adds (2/3, 2, 0).
    let bloomed = [1.0 + 2.0 / 3.0, 5.0, 0.0];
    assert_close(pixel, tonemapped(bloomed));
    assert_eq!(tonemapped(bloomed), [207, 235, 0, 255]);
}

#[test]
fn forward_without_bloom_with_prepass_and_shadows() {
    let (pixel, passes) = render_forward(&["!bloom", "depth_prepass", "shadow_casters"]);
    assert_eq!(
        passes,
        vec![
            "shadow_sun",
            "depth_prepass",
            "forward_after_prepass",
            "tonemap"
        ]
    );
    assert_close(pixel, tonemapped([1.0, 3.0, 0.0]));
}

#[test]
fn forward_bloom_matches_its_golden_image() {
    let gpu = common::gpu();
    let extent = Extent {
        width: 64,
        height: 36,
    };
    let plan = common::compile(
        &gpu,
        &common::shipped("forward.ron"),
        extent,
        &[],
        Vec::new(),
    );
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let report = weft_testkit::render_frames(
        &mut renderer,
        &plan,
        &mut BrightSquare,
        1,
        0.0,
        &FrameOptions {
            readback: true,
            ..FrameOptions::default()
        },
    )
    .expect("frame");
    let image = report.output.expect("readback").to_rgba8();
    let golden = common::golden("forward_bloom_64x36.png");
    let tolerance = weft_testkit::Tolerance {
        per_channel: 2,
        mean: 0.5,
    };
    if let Err(e) = weft_testkit::check_golden(&image, &golden, &tolerance) {
        panic!("{e}");
    }
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}
