//! Recording of the plan's own commands: barriers exactly as the plan lists
//! them, copies and blits, and the readback copy.

use crate::context::Gpu;
use crate::convert;
use crate::error::GpuError;
use crate::resources::{full_range, FrameResources, GpuResource};
use ash::vk;
use weft_graph::plan::{Barrier, Plan, PlanPass};
use weft_graph::vk::{Aspect, Layout};

/// The shader stages that may add to a scene counter (set 1 storage the
/// shaders write, such as the per-pass ray counters).
const COUNTING_STAGES: vk::PipelineStageFlags2 = vk::PipelineStageFlags2::from_raw(
    vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw()
        | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw(),
);

/// Orders a pass that adds to the scene's counters (a pass that traces)
/// after every earlier shader's additions; the plan's barriers cover only
/// graph resources, and the counters are the scene's.
pub fn scene_counter_barrier(device: &ash::Device, cmd: vk::CommandBuffer) {
    let barrier = [vk::MemoryBarrier2::default()
        .src_stage_mask(COUNTING_STAGES)
        .src_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE)
        .dst_stage_mask(COUNTING_STAGES)
        .dst_access_mask(
            vk::AccessFlags2::SHADER_STORAGE_READ | vk::AccessFlags2::SHADER_STORAGE_WRITE,
        )];
    let dep = vk::DependencyInfo::default().memory_barriers(&barrier);
    unsafe { device.cmd_pipeline_barrier2(cmd, &dep) };
}

/// Makes the frame's counter additions visible to the host, which reads
/// them once the frame's fence has signalled.
pub fn scene_counters_to_host(device: &ash::Device, cmd: vk::CommandBuffer) {
    let barrier = [vk::MemoryBarrier2::default()
        .src_stage_mask(COUNTING_STAGES)
        .src_access_mask(vk::AccessFlags2::SHADER_STORAGE_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::HOST)
        .dst_access_mask(vk::AccessFlags2::HOST_READ)];
    let dep = vk::DependencyInfo::default().memory_barriers(&barrier);
    unsafe { device.cmd_pipeline_barrier2(cmd, &dep) };
}

/// Records one `vkCmdPipelineBarrier2` with the given barriers (nothing when empty).
///
/// Transient images and buffers share memory, and a barrier that hands
/// memory over carries the previous occupant's stages and accesses, which
/// a buffer or image barrier's access scope (limited to that resource)
/// would not formally name. So a buffer's barrier is a global memory
/// barrier, and an image's first barrier (from `UNDEFINED`, after accesses)
/// comes with one: both at least as strong as the barriers they stand for.
pub fn barriers(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    list: &[Barrier],
    resources: &FrameResources<'_>,
) -> Result<(), GpuError> {
    if list.is_empty() {
        return Ok(());
    }
    let global = |b: &Barrier| {
        vk::MemoryBarrier2::default()
            .src_stage_mask(convert::stage(b.src_stage))
            .src_access_mask(convert::access(b.src_access))
            .dst_stage_mask(convert::stage(b.dst_stage))
            .dst_access_mask(convert::access(b.dst_access))
    };
    let mut images = Vec::new();
    let mut memory = Vec::new();
    for b in list {
        match resources.get(b.resource) {
            Some(GpuResource::Image(img)) => {
                let (old, new) = b.layouts.ok_or_else(|| {
                    GpuError::Plan(format!(
                        "image barrier on resource {} has no layouts",
                        b.resource
                    ))
                })?;
                if old == Layout::Undefined && !b.src_access.is_empty() {
                    memory.push(global(b));
                }
                images.push(
                    vk::ImageMemoryBarrier2::default()
                        .src_stage_mask(convert::stage(b.src_stage))
                        .src_access_mask(convert::access(b.src_access))
                        .dst_stage_mask(convert::stage(b.dst_stage))
                        .dst_access_mask(convert::access(b.dst_access))
                        .old_layout(convert::layout(old))
                        .new_layout(convert::layout(new))
                        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                        .image(img.image)
                        .subresource_range(full_range(&img.desc)),
                );
            }
            // The scene's structures live in its buffers: a memory barrier.
            Some(GpuResource::Buffer(_) | GpuResource::AccelerationStructure) => {
                memory.push(global(b))
            }
            None => {
                return Err(GpuError::Plan(format!(
                    "barrier on resource {} which does not exist",
                    b.resource
                )))
            }
        }
    }
    let dep = vk::DependencyInfo::default()
        .memory_barriers(&memory)
        .image_memory_barriers(&images);
    unsafe { device.cmd_pipeline_barrier2(cmd, &dep) };
    Ok(())
}

fn layers(aspect: vk::ImageAspectFlags, mip: u32, layers: u32) -> vk::ImageSubresourceLayers {
    vk::ImageSubresourceLayers {
        aspect_mask: aspect,
        mip_level: mip,
        base_array_layer: 0,
        layer_count: layers,
    }
}

fn corner(w: u32, h: u32) -> vk::Offset3D {
    vk::Offset3D {
        x: w as i32,
        y: h as i32,
        z: 1,
    }
}

/// Records a copy or blit pass: source in TRANSFER_SRC_OPTIMAL, destination in
/// TRANSFER_DST_OPTIMAL, as the plan's barriers left them.
pub fn transfer(
    gpu: &Gpu,
    cmd: vk::CommandBuffer,
    plan: &Plan,
    pass: &PlanPass,
    resources: &FrameResources<'_>,
    blit: bool,
) -> Result<(), GpuError> {
    let (src, dst) = pass.transfer.ok_or_else(|| GpuError::Pass {
        pass: pass.name.clone(),
        message: "copy/blit pass without a source and destination".into(),
    })?;
    let device = gpu.device();
    let fail = |message: String| GpuError::Pass {
        pass: pass.name.clone(),
        message,
    };
    match (resources.get(src), resources.get(dst)) {
        (Some(GpuResource::Image(s)), Some(GpuResource::Image(d))) => {
            let aspect = convert::full_aspect(s.desc.aspect);
            let layer_count = s.desc.layers.min(d.desc.layers);
            if blit {
                let filter =
                    if s.desc.aspect == Aspect::Color && gpu.linear_filter(s.desc.format_raw) {
                        vk::Filter::LINEAR
                    } else {
                        vk::Filter::NEAREST
                    };
                let region = vk::ImageBlit2::default()
                    .src_subresource(layers(aspect, 0, layer_count))
                    .src_offsets([
                        vk::Offset3D::default(),
                        corner(s.desc.extent.width, s.desc.extent.height),
                    ])
                    .dst_subresource(layers(aspect, 0, layer_count))
                    .dst_offsets([
                        vk::Offset3D::default(),
                        corner(d.desc.extent.width, d.desc.extent.height),
                    ]);
                let regions = [region];
                let info = vk::BlitImageInfo2::default()
                    .src_image(s.image)
                    .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                    .dst_image(d.image)
                    .dst_image_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                    .regions(&regions)
                    .filter(filter);
                unsafe { device.cmd_blit_image2(cmd, &info) };
            } else {
                if s.desc.extent != d.desc.extent {
                    return Err(fail(format!(
                        "copy from `{}` to `{}` needs equal sizes",
                        plan.resources[src].name, plan.resources[dst].name
                    )));
                }
                let regions: Vec<_> = (0..s.desc.mips.min(d.desc.mips))
                    .map(|mip| {
                        vk::ImageCopy2::default()
                            .src_subresource(layers(aspect, mip, layer_count))
                            .dst_subresource(layers(aspect, mip, layer_count))
                            .extent(vk::Extent3D {
                                width: (s.desc.extent.width >> mip).max(1),
                                height: (s.desc.extent.height >> mip).max(1),
                                depth: 1,
                            })
                    })
                    .collect();
                let info = vk::CopyImageInfo2::default()
                    .src_image(s.image)
                    .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
                    .dst_image(d.image)
                    .dst_image_layout(vk::ImageLayout::TRANSFER_DST_OPTIMAL)
                    .regions(&regions);
                unsafe { device.cmd_copy_image2(cmd, &info) };
            }
            Ok(())
        }
        (Some(GpuResource::Buffer(s)), Some(GpuResource::Buffer(d))) if !blit => {
            let regions = [vk::BufferCopy2::default().size(s.desc.size.min(d.desc.size))];
            let info = vk::CopyBufferInfo2::default()
                .src_buffer(s.buffer)
                .dst_buffer(d.buffer)
                .regions(&regions);
            unsafe { device.cmd_copy_buffer2(cmd, &info) };
            Ok(())
        }
        _ => Err(fail(format!(
            "cannot {} `{}` to `{}`",
            if blit { "blit" } else { "copy" },
            plan.resources
                .get(src)
                .map(|r| r.name.as_str())
                .unwrap_or("?"),
            plan.resources
                .get(dst)
                .map(|r| r.name.as_str())
                .unwrap_or("?")
        ))),
    }
}
