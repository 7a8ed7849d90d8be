//! Runs a compiled `Plan`: prepares pipelines, descriptor sets and push
//! constants for every pass, records the plan's barriers and work into one
//! command buffer (or one per pass when profiling), submits, and reads the
//! output back.

use crate::bind::{self, FrameValues, ResolvedBinding};
use crate::context::{Gpu, MemoryReport};
use crate::error::{GpuError, VkCall};
use crate::pipeline::{Pipeline, PipelineCache, PipelineKey, ShaderKey};
use crate::readback::{self, Readback};
use crate::record;
use crate::renderpass::RenderPassCache;
use crate::resources::{FrameResources, GpuResource};
use crate::shader::ShaderStage;
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;
use std::ffi::CString;
use std::sync::Arc;
use std::time::Instant;
use weft_graph::plan::{Plan, PlanPass, PlanResource, Residency, ResourceDesc};
use weft_graph::schema::{Draw, PassKind};
use weft_graph::vk::Layout;

/// How per-pass times are measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimingMode {
    /// No timing.
    #[default]
    Off,
    /// GPU timestamps around each pass, one submission per frame.
    GpuTimestamps,
    /// CPU wall time of each pass submitted and waited for on its own
    /// (profiling mode: slower frames, but honest figures where timestamps
    /// are not, like compute on lavapipe).
    CpuPerPass,
}

/// What a timing figure measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TimingSource {
    /// Difference of GPU timestamps around the pass.
    GpuTimestamp,
    /// Host wall time from submitting the pass alone to its fence signalling.
    CpuWall,
}

/// The time one pass took.
#[derive(Debug, Clone, PartialEq)]
pub struct PassTiming {
    pub pass: String,
    pub kind: PassKind,
    pub source: TimingSource,
    pub ms: f64,
}

/// Options for one frame.
#[derive(Debug, Clone, Default)]
pub struct FrameOptions {
    pub timing: TimingMode,
    /// Copy the output image back to the CPU.
    pub readback: bool,
    /// Seconds, for `time` push constants.
    pub time: f32,
    /// Frame number, for `frame` push constants.
    pub frame: u32,
}

/// What a frame produced.
#[derive(Debug, Clone, PartialEq)]
pub struct FrameReport {
    pub timings: Vec<PassTiming>,
    pub output: Option<Readback>,
    /// Host time spent preparing and recording commands (excluding GPU waits).
    pub record_ms: f64,
    /// Device memory of the plan's transient blocks (aliased images count once).
    pub transient_bytes: u64,
    /// Device memory of resources with their own allocations.
    pub dedicated_bytes: u64,
    /// The allocator's view of all device memory in use.
    pub memory: MemoryReport,
}

/// What a draw recorder gets for a raster pass that draws scene content: it
/// records draws inside the already begun render pass (viewport and scissor
/// set to `extent`), with pipelines it builds against `render_pass` subpass 0.
pub struct RasterContext<'a> {
    pub gpu: &'a Gpu,
    pub cmd: vk::CommandBuffer,
    pub plan: &'a Plan,
    pub pass_index: usize,
    pub render_pass: vk::RenderPass,
    pub extent: vk::Extent2D,
    pub resources: &'a FrameResources<'a>,
    /// The linear clamp sampler graph resources are sampled with.
    pub sampler: vk::Sampler,
}

impl RasterContext<'_> {
    /// The pass being recorded.
    pub fn pass(&self) -> &PlanPass {
        &self.plan.passes[self.pass_index]
    }
}

/// Records the draws of raster passes whose content comes from outside the
/// graph (scene meshes, light volumes); the render crate implements it.
pub trait DrawRecorder {
    /// Records the pass's draws into `ctx.cmd`.
    fn record(&mut self, ctx: &RasterContext<'_>) -> Result<(), GpuError>;
}

/// A recorder for graphs without scene draws: any such pass is an error.
pub struct NoDraws;

impl DrawRecorder for NoDraws {
    fn record(&mut self, ctx: &RasterContext<'_>) -> Result<(), GpuError> {
        Err(GpuError::Pass {
            pass: ctx.pass().name.clone(),
            message: "draws scene content but no draw recorder was given".into(),
        })
    }
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

/// Executes plans; owns the render-pass and pipeline caches and the sampler.
pub struct Renderer<'g> {
    gpu: &'g Gpu,
    render_passes: RenderPassCache,
    pipelines: PipelineCache,
    sampler: vk::Sampler,
}

impl<'g> Renderer<'g> {
    /// A renderer with empty caches.
    pub fn new(gpu: &'g Gpu) -> Result<Self, GpuError> {
        let pipelines = PipelineCache::new()?;
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::LINEAR)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(vk::LOD_CLAMP_NONE);
        let sampler =
            unsafe { gpu.device().create_sampler(&info, None) }.call("vkCreateSampler")?;
        Ok(Self {
            gpu,
            render_passes: RenderPassCache::default(),
            pipelines,
            sampler,
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
    /// the graph, returning each problem as (pass, message); no pipeline is built.
    pub fn check_shaders(&mut self, plan: &Plan) -> Vec<(String, String)> {
        let mut problems = Vec::new();
        for pass in &plan.passes {
            let list = match self.checked_interface(plan, pass) {
                Ok(_) => continue,
                Err(GpuError::Mismatch { problems, .. }) => problems,
                Err(e) => vec![e.to_string()],
            };
            problems.extend(list.into_iter().map(|m| (pass.name.clone(), m)));
        }
        problems
    }

    /// The pass's pipeline key and shader interface, after checking that the
    /// shaders agree with the graph; `None` for passes without shaders of ours.
    fn checked_interface(
        &mut self,
        plan: &Plan,
        pass: &PlanPass,
    ) -> Result<Option<(PipelineKey, Vec<ResolvedBinding>)>, GpuError> {
        let Some(key) = self.pipeline_key(pass)? else {
            return Ok(None);
        };
        let interface = self.pipelines.interface(&key)?;
        let (bindings, mut problems) = match bind::resolve_bindings(plan, pass, &interface) {
            Ok(bindings) => (bindings, Vec::new()),
            Err(list) => (Vec::new(), list),
        };
        if matches!(key, PipelineKey::Fullscreen { .. }) {
            problems.extend(bind::check_outputs(pass, &interface));
        }
        if let Some((block, _)) = &interface.push {
            if let Err(list) = bind::pack_push(block, &pass.params, &FrameValues::default()) {
                problems.extend(list);
            }
        }
        if !problems.is_empty() {
            return Err(GpuError::Mismatch {
                pass: pass.name.clone(),
                problems,
            });
        }
        Ok(Some((key, bindings)))
    }

    fn pipeline_key(&mut self, pass: &PlanPass) -> Result<Option<PipelineKey>, GpuError> {
        let device = self.gpu.device();
        let missing = |what: &str| GpuError::Pass {
            pass: pass.name.clone(),
            message: format!("needs a {what} shader"),
        };
        let key = |path: &std::path::Path, stage| ShaderKey {
            path: path.to_path_buf(),
            stage,
            defines: pass.defines.clone(),
        };
        let key = match pass.kind {
            PassKind::Compute => {
                let cs = pass
                    .shaders
                    .compute
                    .as_deref()
                    .ok_or_else(|| missing("compute"))?;
                PipelineKey::Compute {
                    shader: key(cs, ShaderStage::Compute),
                }
            }
            PassKind::Fullscreen | PassKind::Raster if is_fullscreen(pass) => {
                let rp = pass.render_pass.as_ref().ok_or_else(|| GpuError::Pass {
                    pass: pass.name.clone(),
                    message: "has no render pass description".into(),
                })?;
                let fs = pass
                    .shaders
                    .fragment
                    .as_deref()
                    .ok_or_else(|| missing("fragment"))?;
                let vertex = match pass.shaders.vertex.as_deref() {
                    Some(vs) => key(vs, ShaderStage::Vertex),
                    None => ShaderKey::fullscreen_vertex(),
                };
                PipelineKey::Fullscreen {
                    vertex,
                    fragment: key(fs, ShaderStage::Fragment),
                    render_pass: self.render_passes.get(device, rp)?,
                    blends: rp
                        .color
                        .iter()
                        .map(|&i| rp.attachments.get(i).and_then(|a| a.blend).into())
                        .collect(),
                    samples: rp.attachments.first().map(|a| a.samples).unwrap_or(1),
                }
            }
            _ => return Ok(None),
        };
        Ok(Some(key))
    }

    /// Creates the plan's resources, runs `frames` frames (numbered from 0,
    /// `time` advancing by `frame_time` seconds) and returns the last frame's
    /// report; what `weft render` needs in one call.
    pub fn render(
        &mut self,
        plan: &Plan,
        draws: &mut dyn DrawRecorder,
        frames: u32,
        frame_time: f32,
        options: &FrameOptions,
    ) -> Result<FrameReport, GpuError> {
        let mut resources = self.create_resources(plan)?;
        let mut last = None;
        for frame in 0..frames.max(1) {
            let options = FrameOptions {
                frame,
                time: options.time + frame as f32 * frame_time,
                readback: options.readback && frame + 1 == frames.max(1),
                timing: options.timing,
            };
            last = Some(self.execute(plan, &mut resources, draws, &options)?);
        }
        last.ok_or_else(|| GpuError::Plan("no frame was rendered".into()))
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
        let mut prepared = Vec::with_capacity(plan.passes.len());
        for pass in &plan.passes {
            prepared.push(self.prepare(plan, pass, resources, options)?);
        }
        let pool = DescriptorPool::new(self.gpu, &prepared)?;
        self.write_descriptors(plan, resources, &pool, &mut prepared)?;
        let readback = if options.readback {
            Some(ReadbackBuffer::new(self.gpu, plan)?)
        } else {
            None
        };
        let queries = if options.timing == TimingMode::GpuTimestamps && self.gpu.info().timestamps {
            Some(QueryPool::new(self.gpu, 2 * plan.passes.len() as u32)?)
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
            self.record_pass(plan, i, pass, &prepared[i], resources, draws, cmd)?;
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
        if let Some(rb) = &readback {
            rb.record(self.gpu, cmd, plan, resources)?;
        }
        record_ms += t.elapsed().as_secs_f64() * 1e3;
        buffers.submit_and_wait(cmd)?;
        if let Some(q) = &queries {
            timings = q.timings(self.gpu, plan)?;
        }
        let output = readback.as_ref().map(|rb| rb.read(plan)).transpose()?;
        drop(buffers);
        drop(pool);
        Ok(FrameReport {
            timings,
            output,
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
        let mut layouts: Vec<Layout> = plan
            .resources
            .iter()
            .map(|r| match r.residency {
                Residency::Transient => Layout::Undefined,
                _ => r.frame_start_layout,
            })
            .collect();
        for (pass, prep) in plan.passes.iter().zip(prepared.iter_mut()) {
            for b in &pass.barriers {
                if let (Some((_, new)), Some(slot)) = (b.layouts, layouts.get_mut(b.resource)) {
                    *slot = new;
                }
            }
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
                            sampler: self.sampler,
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
        index: usize,
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
            PassKind::Copy => record::transfer(device, cmd, plan, pass, resources, false),
            PassKind::Blit => record::transfer(device, cmd, plan, pass, resources, true),
            PassKind::Compute => {
                let dispatch = pass.dispatch.ok_or_else(|| GpuError::Pass {
                    pass: pass.name.clone(),
                    message: "compute pass without a dispatch size".into(),
                })?;
                self.bind(cmd, prep);
                unsafe { device.cmd_dispatch(cmd, dispatch[0], dispatch[1], dispatch[2]) };
                Ok(())
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
                let drawn = if prep.pipeline.is_some() {
                    self.bind(cmd, prep);
                    unsafe { device.cmd_draw(cmd, 3, 1, 0, 0) };
                    Ok(())
                } else {
                    draws.record(&RasterContext {
                        gpu: self.gpu,
                        cmd,
                        plan,
                        pass_index: index,
                        render_pass: prep.render_pass,
                        extent: prep.extent,
                        resources,
                        sampler: self.sampler,
                    })
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
            device.destroy_sampler(self.sampler, None);
        }
        self.pipelines.destroy(device);
        self.render_passes.destroy(device);
    }
}

/// Whether a raster/fullscreen pass draws one fullscreen triangle.
fn is_fullscreen(pass: &PlanPass) -> bool {
    pass.kind == PassKind::Fullscreen || pass.draw == Some(Draw::FullscreenTriangle)
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

/// A debug-utils label around a pass, so validation messages name it.
struct Label(bool);

impl Label {
    fn begin(gpu: &Gpu, cmd: vk::CommandBuffer, name: &str) -> Self {
        let (Some(debug), Ok(name)) = (gpu.debug_utils(), CString::new(name)) else {
            return Self(false);
        };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
        unsafe { debug.cmd_begin_debug_utils_label(cmd, &label) };
        Self(true)
    }

    fn end(self, gpu: &Gpu, cmd: vk::CommandBuffer) {
        if let (true, Some(debug)) = (self.0, gpu.debug_utils()) {
            unsafe { debug.cmd_end_debug_utils_label(cmd) };
        }
    }
}

/// One frame's descriptor pool, sized for every pass's set.
struct DescriptorPool<'g> {
    gpu: &'g Gpu,
    pool: vk::DescriptorPool,
}

impl<'g> DescriptorPool<'g> {
    fn new(gpu: &'g Gpu, prepared: &[Prepared]) -> Result<Self, GpuError> {
        let mut counts: std::collections::HashMap<vk::DescriptorType, u32> = Default::default();
        let mut sets = 0;
        for p in prepared.iter().filter(|p| p.pipeline.is_some()) {
            sets += 1;
            for b in &p.bindings {
                *counts.entry(b.shader.kind.vk()).or_default() += b.shader.count;
            }
        }
        let sizes: Vec<_> = counts
            .into_iter()
            .map(|(ty, n)| vk::DescriptorPoolSize {
                ty,
                descriptor_count: n,
            })
            .collect();
        let info = vk::DescriptorPoolCreateInfo::default()
            .max_sets(sets.max(1))
            .pool_sizes(&sizes);
        let pool = unsafe { gpu.device().create_descriptor_pool(&info, None) }
            .call("vkCreateDescriptorPool")?;
        Ok(Self { gpu, pool })
    }

    fn allocate(
        &self,
        gpu: &Gpu,
        layout: vk::DescriptorSetLayout,
    ) -> Result<vk::DescriptorSet, GpuError> {
        let layouts = [layout];
        let info = vk::DescriptorSetAllocateInfo::default()
            .descriptor_pool(self.pool)
            .set_layouts(&layouts);
        let sets = unsafe { gpu.device().allocate_descriptor_sets(&info) }
            .call("vkAllocateDescriptorSets")?;
        sets.into_iter().next().ok_or(GpuError::Vulkan {
            call: "vkAllocateDescriptorSets",
            result: vk::Result::ERROR_OUT_OF_POOL_MEMORY,
        })
    }
}

impl Drop for DescriptorPool<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_descriptor_pool(self.pool, None) };
    }
}

/// The command buffers of one frame, freed on drop.
struct CommandBuffers<'g> {
    gpu: &'g Gpu,
    buffers: Vec<vk::CommandBuffer>,
}

impl<'g> CommandBuffers<'g> {
    fn new(gpu: &'g Gpu) -> Self {
        Self {
            gpu,
            buffers: Vec::new(),
        }
    }

    fn begin(&mut self) -> Result<vk::CommandBuffer, GpuError> {
        let cmd = self.gpu.allocate_command_buffer()?;
        self.buffers.push(cmd);
        let info = vk::CommandBufferBeginInfo::default()
            .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        unsafe { self.gpu.device().begin_command_buffer(cmd, &info) }
            .call("vkBeginCommandBuffer")?;
        Ok(cmd)
    }

    fn submit_and_wait(&self, cmd: vk::CommandBuffer) -> Result<(), GpuError> {
        unsafe { self.gpu.device().end_command_buffer(cmd) }.call("vkEndCommandBuffer")?;
        self.gpu.submit_and_wait(cmd)
    }
}

impl Drop for CommandBuffers<'_> {
    fn drop(&mut self) {
        if self.buffers.is_empty() {
            return;
        }
        unsafe {
            let _ = self.gpu.device().device_wait_idle();
            self.gpu
                .device()
                .free_command_buffers(self.gpu.command_pool(), &self.buffers);
        }
    }
}

/// Timestamp queries around every pass.
struct QueryPool<'g> {
    gpu: &'g Gpu,
    pool: vk::QueryPool,
    count: u32,
}

impl<'g> QueryPool<'g> {
    fn new(gpu: &'g Gpu, count: u32) -> Result<Self, GpuError> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(count.max(1));
        let pool =
            unsafe { gpu.device().create_query_pool(&info, None) }.call("vkCreateQueryPool")?;
        Ok(Self {
            gpu,
            pool,
            count: count.max(1),
        })
    }

    fn write(&self, gpu: &Gpu, cmd: vk::CommandBuffer, query: u32, stage: vk::PipelineStageFlags2) {
        unsafe {
            gpu.device()
                .cmd_write_timestamp2(cmd, stage, self.pool, query)
        };
    }

    fn timings(&self, gpu: &Gpu, plan: &Plan) -> Result<Vec<PassTiming>, GpuError> {
        let mut ticks = vec![0u64; self.count as usize];
        unsafe {
            gpu.device().get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT,
            )
        }
        .call("vkGetQueryPoolResults")?;
        let period = f64::from(gpu.info().timestamp_period);
        Ok(plan
            .passes
            .iter()
            .enumerate()
            .map(|(i, pass)| PassTiming {
                pass: pass.name.clone(),
                kind: pass.kind,
                source: TimingSource::GpuTimestamp,
                ms: ticks[2 * i + 1].saturating_sub(ticks[2 * i]) as f64 * period / 1e6,
            })
            .collect())
    }
}

impl Drop for QueryPool<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_query_pool(self.pool, None) };
    }
}

/// A host-visible buffer the output image is copied into.
struct ReadbackBuffer<'g> {
    gpu: &'g Gpu,
    buffer: vk::Buffer,
    allocation: Option<Allocation>,
    size: u64,
}

impl<'g> ReadbackBuffer<'g> {
    fn new(gpu: &'g Gpu, plan: &Plan) -> Result<Self, GpuError> {
        let ResourceDesc::Image(desc) = &plan
            .resources
            .get(plan.output)
            .ok_or_else(|| GpuError::Plan("the output resource does not exist".into()))?
            .desc
        else {
            return Err(GpuError::Plan("the output is not an image".into()));
        };
        let texel = readback::texel_bytes(&desc.format).ok_or_else(|| {
            GpuError::Plan(format!(
                "cannot read back an output of format {}",
                desc.format
            ))
        })?;
        let size = u64::from(desc.extent.width) * u64::from(desc.extent.height) * u64::from(texel);
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(vk::BufferUsageFlags::TRANSFER_DST)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        let buffer = unsafe { gpu.device().create_buffer(&info, None) }.call("vkCreateBuffer")?;
        let mut this = Self {
            gpu,
            buffer,
            allocation: None,
            size,
        };
        let requirements = unsafe { gpu.device().get_buffer_memory_requirements(buffer) };
        let allocation = gpu
            .allocator()
            .allocate(&AllocationCreateDesc {
                name: "readback",
                requirements,
                location: MemoryLocation::GpuToCpu,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| GpuError::Allocation {
                what: "the readback buffer".into(),
                message: e.to_string(),
            })?;
        unsafe {
            gpu.device()
                .bind_buffer_memory(buffer, allocation.memory(), allocation.offset())
        }
        .call("vkBindBufferMemory")?;
        this.allocation = Some(allocation);
        Ok(this)
    }

    /// Copies the output (in TRANSFER_SRC_OPTIMAL after the epilogue) into
    /// the buffer and makes the bytes visible to the host.
    fn record(
        &self,
        gpu: &Gpu,
        cmd: vk::CommandBuffer,
        plan: &Plan,
        resources: &FrameResources<'_>,
    ) -> Result<(), GpuError> {
        let img = resources.image(plan.output)?;
        let region = vk::BufferImageCopy2::default()
            .image_subresource(vk::ImageSubresourceLayers {
                aspect_mask: vk::ImageAspectFlags::COLOR,
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            })
            .image_extent(vk::Extent3D {
                width: img.desc.extent.width,
                height: img.desc.extent.height,
                depth: 1,
            });
        let regions = [region];
        let info = vk::CopyImageToBufferInfo2::default()
            .src_image(img.image)
            .src_image_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .dst_buffer(self.buffer)
            .regions(&regions);
        let host = [vk::BufferMemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COPY)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(vk::PipelineStageFlags2::HOST)
            .dst_access_mask(vk::AccessFlags2::HOST_READ)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(self.buffer)
            .offset(0)
            .size(vk::WHOLE_SIZE)];
        unsafe {
            gpu.device().cmd_copy_image_to_buffer2(cmd, &info);
            gpu.device().cmd_pipeline_barrier2(
                cmd,
                &vk::DependencyInfo::default().buffer_memory_barriers(&host),
            );
        }
        Ok(())
    }

    fn read(&self, plan: &Plan) -> Result<Readback, GpuError> {
        let ResourceDesc::Image(desc) = &plan.resources[plan.output].desc else {
            return Err(GpuError::Plan("the output is not an image".into()));
        };
        let bytes = self
            .allocation
            .as_ref()
            .and_then(|a| a.mapped_slice())
            .and_then(|s| s.get(..self.size as usize))
            .ok_or_else(|| GpuError::Allocation {
                what: "the readback buffer".into(),
                message: "memory is not host-mapped".into(),
            })?;
        let pixels =
            readback::decode(&desc.format, bytes).map_err(|e| GpuError::Plan(e.to_string()))?;
        Ok(Readback {
            width: desc.extent.width,
            height: desc.extent.height,
            format: desc.format.clone(),
            pixels,
        })
    }
}

impl Drop for ReadbackBuffer<'_> {
    fn drop(&mut self) {
        unsafe { self.gpu.device().destroy_buffer(self.buffer, None) };
        if let Some(a) = self.allocation.take() {
            // Freeing only fails for allocations this allocator did not make.
            let _ = self.gpu.allocator().free(a);
        }
    }
}
