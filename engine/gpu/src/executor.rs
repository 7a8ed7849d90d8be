//! Runs a compiled `Plan`: prepares pipelines, descriptor sets and push
//! constants for every pass, records the plan's barriers and work into one
//! command buffer (or one per pass when profiling), submits, and reads the
//! output back.

use crate::bind::{self, FrameValues, ResolvedBinding};
use crate::check::{self, PassShaders, ShaderProblem};
use crate::context::{Gpu, MemoryReport};
use crate::download::ReadbackBuffer;
use crate::draw::{DrawRecorder, RasterContext, SCENE_SET};
use crate::error::GpuError;
use crate::frame::{CommandBuffers, DescriptorPool, Label};
use crate::layouts;
use crate::pipeline::{Pipeline, PipelineCache, PipelineKey};
use crate::readback::Readback;
use crate::record;
use crate::renderpass::RenderPassCache;
use crate::resources::{FrameResources, GpuResource};
use crate::samplers::Samplers;
use crate::statistics::{PassStatistics, StatisticsPool};
use crate::timing::{PassTiming, QueryPool, TimingMode, TimingSource};
use ash::vk;
use std::sync::Arc;
use std::time::Instant;
use weft_graph::id::PassId;
use weft_graph::plan::{Plan, PlanPass, PlanResource, ResourceDesc};
use weft_graph::schema::PassKind;

/// Options for one frame.
#[derive(Debug, Clone, Default)]
pub struct FrameOptions {
    /// Whether and how per-pass times are measured.
    pub timing: TimingMode,
    /// Copy the output image back to the CPU.
    pub readback: bool,
    /// Seconds, for `time` push constants.
    pub time: f32,
    /// Frame number, for `frame` push constants.
    pub frame: u32,
}

/// What a frame produced; serialises (without the image) for `--json`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct FrameReport {
    /// Per-pass times, labelled with how they were measured.
    pub timings: Vec<PassTiming>,
    /// Per-pass pipeline statistics, collected with GPU timestamps.
    pub statistics: Vec<PassStatistics>,
    /// The output image, when `readback` was asked for.
    #[serde(skip)]
    pub output: Option<Readback>,
    /// The plan's other images to read back (`Plan::readback`, e.g. the HDR buffer
    /// for EXR output), by name, when `readback` was asked for.
    #[serde(skip)]
    pub readbacks: Vec<(String, Readback)>,
    /// Host time spent preparing and recording commands (excluding GPU waits).
    pub record_ms: f64,
    /// Device memory of the plan's transient blocks (aliased images count once).
    pub transient_bytes: u64,
    /// Device memory of resources with their own allocations.
    pub dedicated_bytes: u64,
    /// The allocator's view of all device memory in use.
    pub memory: MemoryReport,
}

/// Everything a pass needs at record time.
struct Prepared {
    pipeline: Option<Arc<Pipeline>>,
    render_pass: vk::RenderPass,
    framebuffer: vk::Framebuffer,
    extent: vk::Extent2D,
    clears: Vec<vk::ClearValue>,
    bindings: Vec<ResolvedBinding>,
    push: Vec<u8>,
    set: vk::DescriptorSet,
}

/// Executes plans; owns the render-pass and pipeline caches and the samplers.
pub struct Renderer<'g> {
    gpu: &'g Gpu,
    render_passes: RenderPassCache,
    pipelines: PipelineCache,
    samplers: Samplers,
}

impl<'g> Renderer<'g> {
    /// A renderer with empty caches.
    pub fn new(gpu: &'g Gpu) -> Result<Self, GpuError> {
        let pipelines = PipelineCache::new()?;
        let samplers = Samplers::new(gpu)?;
        Ok(Self {
            gpu,
            render_passes: RenderPassCache::default(),
            pipelines,
            samplers,
        })
    }

    /// The context this renderer runs on.
    pub fn gpu(&self) -> &'g Gpu {
        self.gpu
    }

    /// The shader and pipeline cache (for hot reload and inspection).
    pub fn pipelines(&mut self) -> &mut PipelineCache {
        &mut self.pipelines
    }

    /// Drops every shader and pipeline built from `changed` so the next frame
    /// recompiles them (hot reload); returns how many pipelines were dropped.
    pub fn reload(&mut self, changed: &std::path::Path) -> Result<usize, GpuError> {
        self.gpu.wait_idle()?;
        Ok(self.pipelines.invalidate(self.gpu.device(), changed))
    }

    /// Number of distinct render passes created so far.
    pub fn render_pass_count(&self) -> usize {
        self.render_passes.len()
    }

    /// Creates the plan's resources.
    pub fn create_resources(&self, plan: &Plan) -> Result<FrameResources<'g>, GpuError> {
        FrameResources::new(self.gpu, plan)
    }

    /// Compiles and reflects every pass's shaders and cross-checks them with
    /// the graph (see `check::check_shaders`); no pipeline is built.
    pub fn check_shaders(&mut self, plan: &Plan) -> Vec<ShaderProblem> {
        check::check_with(&mut self.pipelines, plan)
    }

    /// The pass's pipeline key and resolved bindings, after checking that
    /// its shaders agree with the graph; `None` for passes without shaders of ours.
    fn checked_interface(
        &mut self,
        plan: &Plan,
        pass: &PlanPass,
    ) -> Result<Option<(PipelineKey, Vec<ResolvedBinding>)>, GpuError> {
        let Some(shaders) = check::pass_shaders(pass)? else {
            return Ok(None);
        };
        let interface = self.pipelines.interface(&shaders.keys())?;
        let bindings =
            check::pass_problems(plan, pass, &shaders, &interface).map_err(|problems| {
                GpuError::Mismatch {
                    pass: pass.name.clone(),
                    problems,
                }
            })?;
        let key = match shaders {
            PassShaders::Compute(shader) => PipelineKey::Compute { shader },
            PassShaders::Fullscreen { vertex, fragment } => {
                let rp = pass.render_pass.as_ref().ok_or_else(|| GpuError::Pass {
                    pass: pass.name.clone(),
                    message: "has no render pass description".into(),
                })?;
                PipelineKey::Fullscreen {
                    vertex,
                    fragment,
                    render_pass: self.render_passes.get(self.gpu.device(), rp)?,
                    blends: rp
                        .color
                        .iter()
                        .map(|&i| rp.attachments.get(i).and_then(|a| a.blend).into())
                        .collect(),
                    samples: rp.attachments.first().map(|a| a.samples).unwrap_or(1),
                }
            }
        };
        Ok(Some((key, bindings)))
    }

    /// Runs one frame of the plan on `resources` (made by `create_resources`
    /// for the same plan); scene draws come from `draws`.
    pub fn execute(
        &mut self,
        plan: &Plan,
        resources: &mut FrameResources<'g>,
        draws: &mut dyn DrawRecorder,
        options: &FrameOptions,
    ) -> Result<FrameReport, GpuError> {
        let started = Instant::now();
        draws.begin_frame()?;
        let mut prepared = Vec::with_capacity(plan.passes.len());
        for pass in &plan.passes {
            prepared.push(self.prepare(plan, pass, resources, options)?);
        }
        let pool = descriptor_pool(self.gpu, &prepared)?;
        self.write_descriptors(plan, resources, &pool, &mut prepared)?;
        let readbacks = if options.readback {
            std::iter::once(plan.output)
                .chain(plan.readback.iter().copied())
                .map(|r| ReadbackBuffer::new(self.gpu, plan, r))
                .collect::<Result<Vec<_>, _>>()?
        } else {
            Vec::new()
        };
        let queries = if options.timing == TimingMode::GpuTimestamps && self.gpu.info().timestamps {
            Some(QueryPool::new(self.gpu, 2 * plan.passes.len() as u32)?)
        } else {
            None
        };
        let stats =
            if options.timing == TimingMode::GpuTimestamps && self.gpu.info().pipeline_statistics {
                Some(StatisticsPool::new(self.gpu, plan.passes.len() as u32)?)
            } else {
                None
            };
        let mut record_ms = started.elapsed().as_secs_f64() * 1e3;
        let mut timings = Vec::new();
        let per_pass = options.timing == TimingMode::CpuPerPass;
        let mut buffers = CommandBuffers::new(self.gpu);
        let mut cmd = buffers.begin()?;
        if let Some(q) = &queries {
            unsafe {
                self.gpu
                    .device()
                    .cmd_reset_query_pool(cmd, q.pool, 0, q.count)
            };
        }
        if let Some(s) = &stats {
            s.reset(cmd);
        }
        for (i, pass) in plan.passes.iter().enumerate() {
            let t = Instant::now();
            if let Some(q) = &queries {
                q.write(
                    self.gpu,
                    cmd,
                    2 * i as u32,
                    vk::PipelineStageFlags2::TOP_OF_PIPE,
                );
            }
            if let Some(s) = &stats {
                s.begin(cmd, i as u32);
            }
            self.record_pass(
                plan,
                PassId::new(i),
                pass,
                &prepared[i],
                resources,
                draws,
                cmd,
            )?;
            if let Some(s) = &stats {
                s.end(cmd, i as u32);
            }
            if let Some(q) = &queries {
                q.write(
                    self.gpu,
                    cmd,
                    2 * i as u32 + 1,
                    vk::PipelineStageFlags2::BOTTOM_OF_PIPE,
                );
            }
            record_ms += t.elapsed().as_secs_f64() * 1e3;
            if per_pass {
                let wall = Instant::now();
                buffers.submit_and_wait(cmd)?;
                timings.push(PassTiming {
                    pass: pass.name.clone(),
                    kind: pass.kind,
                    source: TimingSource::CpuWall,
                    ms: wall.elapsed().as_secs_f64() * 1e3,
                });
                cmd = buffers.begin()?;
            }
        }
        let t = Instant::now();
        record::barriers(self.gpu.device(), cmd, &plan.epilogue, resources)?;
        for rb in &readbacks {
            rb.record(self.gpu, cmd, resources)?;
        }
        record_ms += t.elapsed().as_secs_f64() * 1e3;
        buffers.submit_and_wait(cmd)?;
        if let Some(q) = &queries {
            timings = q.timings(self.gpu, plan)?;
        }
        let statistics = match &stats {
            Some(s) => s.read(plan)?,
            None => Vec::new(),
        };
        let mut images = readbacks
            .iter()
            .map(|rb| rb.read(plan))
            .collect::<Result<Vec<_>, _>>()?
            .into_iter();
        let output = images.next();
        let readbacks: Vec<(String, Readback)> = plan
            .readback
            .iter()
            .map(|&r| plan.resources[r].name.clone())
            .zip(images)
            .collect();
        drop(buffers);
        drop(pool);
        Ok(FrameReport {
            timings,
            statistics,
            output,
            readbacks,
            record_ms,
            transient_bytes: resources.transient_bytes,
            dedicated_bytes: resources.dedicated_bytes,
            memory: self.gpu.memory_report(),
        })
    }

    fn prepare(
        &mut self,
        plan: &Plan,
        pass: &PlanPass,
        resources: &mut FrameResources<'g>,
        options: &FrameOptions,
    ) -> Result<Prepared, GpuError> {
        let fail = |problems: Vec<String>| GpuError::Pass {
            pass: pass.name.clone(),
            message: problems.join("; "),
        };
        let checked = self.checked_interface(plan, pass)?;
        let mut prepared = Prepared {
            pipeline: None,
            render_pass: vk::RenderPass::null(),
            framebuffer: vk::Framebuffer::null(),
            extent: vk::Extent2D {
                width: plan.extent.width,
                height: plan.extent.height,
            },
            clears: Vec::new(),
            bindings: Vec::new(),
            push: Vec::new(),
            set: vk::DescriptorSet::null(),
        };
        if let Some((key, bindings)) = checked {
            prepared.pipeline = Some(self.pipelines.pipeline(self.gpu.device(), &key)?);
            prepared.bindings = bindings;
        }
        if let Some(rp) = &pass.render_pass {
            prepared.render_pass = self.render_passes.get(self.gpu.device(), rp)?;
            prepared.extent = vk::Extent2D {
                width: rp.extent.width,
                height: rp.extent.height,
            };
            let mut views = Vec::with_capacity(rp.attachments.len());
            for a in &rp.attachments {
                views.push(resources.image(a.resource)?.attachment_view);
                prepared
                    .clears
                    .push(clear_value(&plan.resources[a.resource], &a.clear));
            }
            prepared.framebuffer =
                resources.framebuffer(prepared.render_pass, views, prepared.extent)?;
        }
        if let Some(p) = &prepared.pipeline {
            if let Some((block, _)) = &p.interface.push {
                let frame = FrameValues {
                    time: options.time,
                    frame: options.frame,
                    extent: [prepared.extent.width, prepared.extent.height],
                };
                prepared.push = bind::pack_push(block, &pass.params, &frame).map_err(fail)?;
            }
        }
        Ok(prepared)
    }

    /// Writes every pass's descriptor set, with image layouts as the plan's
    /// barriers leave them at that pass.
    fn write_descriptors(
        &self,
        plan: &Plan,
        resources: &FrameResources<'g>,
        pool: &DescriptorPool,
        prepared: &mut [Prepared],
    ) -> Result<(), GpuError> {
        let mut layouts = layouts::frame_start(plan);
        for (index, prep) in prepared.iter_mut().enumerate() {
            layouts::apply_pass(plan, PassId::new(index), &mut layouts);
            let Some(pipeline) = &prep.pipeline else {
                continue;
            };
            let Some(&set_layout) = pipeline.set_layouts.first() else {
                continue;
            };
            prep.set = pool.allocate(self.gpu, set_layout)?;
            let mut image_infos = Vec::new();
            let mut buffer_infos = Vec::new();
            for rb in &prep.bindings {
                match resources.get(rb.graph.resource) {
                    Some(GpuResource::Image(img)) => image_infos.push((
                        rb,
                        [vk::DescriptorImageInfo {
                            sampler: self.samplers.for_binding(
                                self.gpu,
                                rb.shader.depth_compare,
                                img.desc.format_raw,
                            ),
                            image_view: img.shader_view,
                            image_layout: crate::convert::layout(layouts[rb.graph.resource]),
                        }],
                    )),
                    Some(GpuResource::Buffer(buf)) => buffer_infos.push((
                        rb,
                        [vk::DescriptorBufferInfo {
                            buffer: buf.buffer,
                            offset: 0,
                            range: vk::WHOLE_SIZE,
                        }],
                    )),
                    None => {
                        return Err(GpuError::Plan(format!(
                            "resource {} missing",
                            rb.graph.resource
                        )))
                    }
                }
            }
            let mut writes = Vec::new();
            for (rb, info) in &image_infos {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(prep.set)
                        .dst_binding(rb.shader.binding)
                        .descriptor_type(rb.shader.kind.vk())
                        .image_info(info),
                );
            }
            for (rb, info) in &buffer_infos {
                writes.push(
                    vk::WriteDescriptorSet::default()
                        .dst_set(prep.set)
                        .dst_binding(rb.shader.binding)
                        .descriptor_type(rb.shader.kind.vk())
                        .buffer_info(info),
                );
            }
            unsafe { self.gpu.device().update_descriptor_sets(&writes, &[]) };
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn record_pass(
        &self,
        plan: &Plan,
        index: PassId,
        pass: &PlanPass,
        prep: &Prepared,
        resources: &FrameResources<'g>,
        draws: &mut dyn DrawRecorder,
        cmd: vk::CommandBuffer,
    ) -> Result<(), GpuError> {
        let device = self.gpu.device();
        let label = Label::begin(self.gpu, cmd, &pass.name);
        record::barriers(device, cmd, &pass.barriers, resources)?;
        let result = match pass.kind {
            PassKind::Copy => record::transfer(self.gpu, cmd, plan, pass, resources, false),
            PassKind::Blit => record::transfer(self.gpu, cmd, plan, pass, resources, true),
            PassKind::Compute => {
                let dispatch = pass.dispatch.ok_or_else(|| GpuError::Pass {
                    pass: pass.name.clone(),
                    message: "compute pass without a dispatch size".into(),
                })?;
                self.bind(cmd, prep);
                // A compute pass that reads scene data (tiled light culling reads the
                // camera and the lights) gets set 1 from the draw recorder, as a
                // fullscreen pass does; there is no render pass around it.
                let scene = prep
                    .pipeline
                    .as_ref()
                    .filter(|p| p.interface.bindings.keys().any(|(s, _)| *s == SCENE_SET));
                let bound = match scene {
                    Some(p) => draws.bind_scene(
                        &RasterContext {
                            gpu: self.gpu,
                            cmd,
                            plan,
                            pass_index: index,
                            render_pass: vk::RenderPass::null(),
                            extent: prep.extent,
                            resources,
                            sampler: self.samplers.linear,
                            nearest_sampler: self.samplers.nearest,
                            compare_sampler: self.samplers.compare,
                        },
                        p,
                    ),
                    None => Ok(()),
                };
                bound.map(|()| unsafe {
                    device.cmd_dispatch(cmd, dispatch[0], dispatch[1], dispatch[2])
                })
            }
            PassKind::Fullscreen | PassKind::Raster => {
                let area = vk::Rect2D {
                    offset: vk::Offset2D::default(),
                    extent: prep.extent,
                };
                let begin = vk::RenderPassBeginInfo::default()
                    .render_pass(prep.render_pass)
                    .framebuffer(prep.framebuffer)
                    .render_area(area)
                    .clear_values(&prep.clears);
                let subpass = vk::SubpassBeginInfo::default().contents(vk::SubpassContents::INLINE);
                unsafe {
                    device.cmd_begin_render_pass2(cmd, &begin, &subpass);
                    device.cmd_set_viewport(
                        cmd,
                        0,
                        &[vk::Viewport {
                            x: 0.0,
                            y: 0.0,
                            width: prep.extent.width as f32,
                            height: prep.extent.height as f32,
                            min_depth: 0.0,
                            max_depth: 1.0,
                        }],
                    );
                    device.cmd_set_scissor(cmd, 0, &[area]);
                }
                let ctx = RasterContext {
                    gpu: self.gpu,
                    cmd,
                    plan,
                    pass_index: index,
                    render_pass: prep.render_pass,
                    extent: prep.extent,
                    resources,
                    sampler: self.samplers.linear,
                    nearest_sampler: self.samplers.nearest,
                    compare_sampler: self.samplers.compare,
                };
                let drawn = match &prep.pipeline {
                    Some(p) => {
                        self.bind(cmd, prep);
                        let scene = p.interface.bindings.keys().any(|(s, _)| *s == SCENE_SET);
                        let bound = if scene {
                            draws.bind_scene(&ctx, p)
                        } else {
                            Ok(())
                        };
                        bound.map(|()| unsafe { device.cmd_draw(cmd, 3, 1, 0, 0) })
                    }
                    None => draws.record(&ctx),
                };
                unsafe { device.cmd_end_render_pass2(cmd, &vk::SubpassEndInfo::default()) };
                drawn
            }
        };
        label.end(self.gpu, cmd);
        result
    }

    fn bind(&self, cmd: vk::CommandBuffer, prep: &Prepared) {
        let Some(p) = &prep.pipeline else {
            return;
        };
        let device = self.gpu.device();
        unsafe {
            device.cmd_bind_pipeline(cmd, p.bind_point, p.pipeline);
            if prep.set != vk::DescriptorSet::null() {
                device.cmd_bind_descriptor_sets(cmd, p.bind_point, p.layout, 0, &[prep.set], &[]);
            }
            if let Some((_, stages)) = &p.interface.push {
                device.cmd_push_constants(cmd, p.layout, *stages, 0, &prep.push);
            }
        }
    }
}

impl Drop for Renderer<'_> {
    fn drop(&mut self) {
        let device = self.gpu.device();
        unsafe {
            let _ = device.device_wait_idle();
        }
        self.samplers.destroy(self.gpu);
        self.pipelines.destroy(device);
        self.render_passes.destroy(device);
    }
}

/// A pool with room for every prepared pass's descriptor set.
fn descriptor_pool<'g>(
    gpu: &'g Gpu,
    prepared: &[Prepared],
) -> Result<DescriptorPool<'g>, GpuError> {
    let mut counts: Vec<(vk::DescriptorType, u32)> = Vec::new();
    let mut sets = 0;
    for p in prepared.iter().filter(|p| p.pipeline.is_some()) {
        sets += 1;
        for b in &p.bindings {
            let ty = b.shader.kind.vk();
            match counts.iter_mut().find(|(t, _)| *t == ty) {
                Some((_, n)) => *n += b.shader.count,
                None => counts.push((ty, b.shader.count)),
            }
        }
    }
    DescriptorPool::new(gpu, sets, &counts)
}

fn clear_value(resource: &PlanResource, clear: &[f64]) -> vk::ClearValue {
    let depth = matches!(&resource.desc, ResourceDesc::Image(d) if d.aspect != weft_graph::vk::Aspect::Color);
    if depth {
        vk::ClearValue {
            depth_stencil: vk::ClearDepthStencilValue {
                depth: clear.first().copied().unwrap_or(0.0) as f32,
                stencil: 0,
            },
        }
    } else {
        let mut c = [0f32; 4];
        for (slot, v) in c.iter_mut().zip(clear) {
            *slot = *v as f32;
        }
        vk::ClearValue {
            color: vk::ClearColorValue { float32: c },
        }
    }
}
