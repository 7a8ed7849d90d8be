//! Renders a graph headless and prints per-pass times (GPU timestamps and
//! CPU wall time per pass), host recording cost and device memory. Scene
//! passes are painted with one colour, so the figures are the graph's own
//! passes (post-processing, compute, copies).
//!
//! `cargo run --release -p weft-gpu --example frame_timings -- [GRAPH] [WxH] [FRAMES]`

use ash::vk;
use std::path::PathBuf;
use std::time::Instant;
use weft_gpu::{
    format_timings, memory_requirements, DrawRecorder, FrameOptions, Gpu, GpuError, GpuOptions,
    RasterContext, Renderer, TimingMode,
};
use weft_graph::plan::Extent;
use weft_graph::CompileOptions;

/// Clears every colour attachment of scene passes to a constant HDR colour.
struct Paint;

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
                    color: vk::ClearColorValue {
                        float32: [1.0, 3.0, 0.5, 1.0],
                    },
                },
            })
            .collect();
        if !attachments.is_empty() {
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
        }
        Ok(())
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let graph = PathBuf::from(args.next().unwrap_or_else(|| "graphs/forward.ron".into()));
    let size = args.next().unwrap_or_else(|| "1920x1080".into());
    let frames: u32 = args.next().map(|f| f.parse()).transpose()?.unwrap_or(10);
    let (w, h) = size.split_once('x').ok_or("size must be WxH")?;
    let extent = Extent {
        width: w.parse()?,
        height: h.parse()?,
    };

    let gpu = Gpu::new(&GpuOptions::default())?;
    println!("device: {} ({:?})", gpu.info().name, gpu.info().kind);
    let loaded = weft_graph::load(&graph);
    let memory = memory_requirements(&gpu);
    let options = CompileOptions {
        extent,
        features: loaded.features::<&str>(&[]),
        memory: &memory,
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&loaded, &options).map_err(|d| format!("{d:?}"))?;
    let mut renderer = Renderer::new(&gpu)?;
    let mut resources = renderer.create_resources(&plan)?;

    let mut frame = |timing| {
        renderer.execute(
            &plan,
            &mut resources,
            &mut Paint,
            &FrameOptions {
                timing,
                ..FrameOptions::default()
            },
        )
    };
    frame(TimingMode::Off)?;
    let start = Instant::now();
    let mut record_ms = 0.0;
    for _ in 0..frames {
        record_ms += frame(TimingMode::Off)?.record_ms;
    }
    let frame_ms = start.elapsed().as_secs_f64() * 1e3 / f64::from(frames.max(1));
    let gpu_report = frame(TimingMode::GpuTimestamps)?;
    let cpu_report = frame(TimingMode::CpuPerPass)?;

    println!(
        "{} at {}x{}: {:.2} ms per frame over {} frames (submit and wait), host recording {:.3} ms per frame",
        plan.name,
        extent.width,
        extent.height,
        frame_ms,
        frames,
        record_ms / f64::from(frames.max(1))
    );
    println!("\n{}", format_timings(&gpu_report.timings));
    for s in &gpu_report.statistics {
        println!(
            "{:<14} primitives {:>8}  vertices {:>8}  fragments {:>10}  compute {:>8}",
            s.pass,
            s.input_primitives,
            s.vertex_invocations,
            s.fragment_invocations,
            s.compute_invocations
        );
    }
    println!();
    println!("{}", format_timings(&cpu_report.timings));
    println!(
        "device memory: transient blocks {} bytes (plan: {} aliased, {} unaliased), dedicated {} bytes, allocator total {} bytes",
        cpu_report.transient_bytes,
        plan.memory.transient_bytes,
        plan.memory.transient_bytes_unaliased,
        cpu_report.dedicated_bytes,
        cpu_report.memory.allocated_bytes
    );
    Ok(())
}
