//! Runs a compiled `Plan`: prepares pipelines, descriptor sets and push
//! constants for every pass, records the plan's barriers and work into one
//! command buffer (or one per pass when profiling), submits, and reads the
//! output back.

use crate::bind::FrameValues;
use crate::bind::ResolvedBinding;
use crate::check::{self, PassShaders, ShaderProblem};
use crate::context::{Gpu, MemoryReport};
use crate::draw::{DrawRecorder, Variant};
use crate::error::GpuError;
use crate::frame::FramePools;
use crate::pipeline::{Pipeline, PipelineCache, PipelineKey};
use crate::readback::Readback;
use crate::record;
use crate::renderpass::RenderPassCache;
use crate::resources::FrameResources;
use crate::samplers::Samplers;
use crate::scene::{RegisteredScene, SceneInterface, SceneSet};
use crate::scene_check::scene_set_problems;
use crate::sets::SCENE_SET;
use crate::statistics::PassStatistics;
use crate::timing::{PassTiming, TimingMode, TimingSource};
mod kinds;
mod prepare;
mod record_pass;
pub mod shader_check;

use crate::descriptors::DescriptorPool;
use kinds::PassAt;

use ash::vk;
use std::sync::Arc;
use std::time::Instant;
use weft_graph::id::PassId;
use weft_graph::plan::{Plan, PlanPass};

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
    /// For `history_frames` push constants: frames in a row before this one
    /// that drew the same inputs (see [`crate::bind::FrameValues`]).
    pub history_frames: u32,
    /// For `plan_frames` push constants: frames drawn before this one on the
    /// same resources (see [`crate::bind::FrameValues`]).
    pub plan_frames: u32,
}

impl FrameOptions {
    /// The values shaders read as push constants for a pass drawn at
    /// `extent`, in its `repeat_index`-th dispatch.
    fn frame_values(&self, extent: vk::Extent2D, repeat_index: u32) -> FrameValues {
        FrameValues {
            time: self.time,
            frame: self.frame,
            extent: [extent.width, extent.height],
            history_frames: self.history_frames,
            plan_frames: self.plan_frames,
            repeat_index,
        }
    }
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
    /// Device memory of the plan's transient blocks (aliased resources count once).
    pub transient_bytes: u64,
    /// Device memory of resources with their own allocations.
    pub dedicated_bytes: u64,
    /// The allocator's view of all device memory in use.
    pub memory: MemoryReport,
}

impl FrameReport {
    /// The first of `names` that this frame read back: the image an EXR file
    /// gets. A graph may list images it reads back only under some features
    /// (`readback: [(name: "denoised", enabled_if: ["denoise"]), "hdr"]`),
    /// and those the compile left out are skipped.
    pub fn first_read_back(&self, names: &[String]) -> Option<&Readback> {
        names.iter().find_map(|name| {
            self.readbacks
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, image)| image)
        })
    }
}

/// What recording and running a frame gave back.
struct Recorded {
    timings: Vec<PassTiming>,
    statistics: Vec<PassStatistics>,
    /// The output, then the plan's other read-back images.
    images: Vec<Readback>,
    record_ms: f64,
}

/// Everything a pass needs at record time.
pub(crate) struct Prepared {
    pipeline: Option<Arc<Pipeline>>,
    render_pass: vk::RenderPass,
    framebuffer: vk::Framebuffer,
    extent: vk::Extent2D,
    clears: Vec<vk::ClearValue>,
    bindings: Vec<ResolvedBinding>,
    push: Vec<u8>,
    set: vk::DescriptorSet,
    /// A scene pass's pipeline variants, those its draw recorder names,
    /// built before the first frame.
    variants: Vec<Variant>,
}

impl Prepared {
    /// Nothing prepared yet: no pipeline, the plan's extent.
    fn new(plan: &Plan) -> Self {
        Self {
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
            variants: Vec::new(),
        }
    }
}

/// A plan's passes made ready on its resources, once: pipelines, render
/// passes, framebuffers, clear values, resolved bindings and written descriptor
/// sets. Kept by the renderer while the same resources run again and the
/// pipelines it uses stay; a frame then only packs push constants and records.
pub(crate) struct PreparedPlan<'g> {
    /// The renderer's pipeline generation it was built against.
    generation: u64,
    /// The [`FrameResources::id`] it was prepared on.
    resources: u64,
    passes: Vec<Prepared>,
    /// Holds the passes' and the scene variants' descriptor sets.
    _pool: DescriptorPool<'g>,
}

/// Executes plans; owns the render-pass and pipeline caches and the samplers.
pub struct Renderer<'g> {
    gpu: &'g Gpu,
    /// Bumped whenever pipelines may have been replaced, so plans prepared
    /// against the old ones are prepared again.
    generation: u64,
    render_passes: RenderPassCache,
    pipelines: PipelineCache,
    samplers: Samplers,
    /// The scene interface a renderer registered, with its set layouts.
    scene: Option<RegisteredScene<'g>>,
    /// The plan last run, prepared on the resources it ran on; kept while
    /// the same resources run again and the pipelines it uses stay.
    prepared: Option<PreparedPlan<'g>>,
    /// Command buffers, fence, queries and read-back buffers, reused by
    /// every frame (no per-frame Vulkan object creation).
    /// Taken while a frame records, so the frame can borrow the renderer too.
    pools: Option<FramePools<'g>>,
}

impl<'g> Renderer<'g> {
    /// A renderer with empty caches.
    pub fn new(gpu: &'g Gpu) -> Result<Self, GpuError> {
        let pipelines = PipelineCache::new()?;
        let samplers = Samplers::new(gpu)?;
        Ok(Self {
            gpu,
            generation: 0,
            render_passes: RenderPassCache::default(),
            pipelines,
            samplers,
            scene: None,
            prepared: None,
            pools: None,
        })
    }

    /// Registers the scene data a renderer supplies (its sets' bindings and
    /// its vertex layout): every pipeline that reads scene data is then built
    /// against it and every shader checked with it. A renderer registers once;
    /// registering again drops the pipelines built so far.
    pub fn register_scene(&mut self, interface: SceneInterface) -> Result<(), GpuError> {
        let registered = RegisteredScene::new(self.gpu, interface)?;
        if self.scene.is_some() {
            self.gpu.wait_idle()?;
            self.pipelines.destroy(self.gpu.device());
            self.generation += 1;
        }
        self.scene = Some(registered);
        Ok(())
    }

    /// The registered scene interface, if any.
    pub fn scene_interface(&self) -> Option<&SceneInterface> {
        self.scene.as_ref().map(|r| &r.interface)
    }

    /// The context this renderer runs on.
    pub fn gpu(&self) -> &'g Gpu {
        self.gpu
    }

    /// The shader and pipeline cache, for inspection.
    pub fn pipelines(&self) -> &PipelineCache {
        &self.pipelines
    }

    /// Takes a shader variant a hot reload compiled and checked elsewhere
    /// ([`PipelineCache::adopt`]); no pipeline changes, so prepared plans stay.
    pub fn adopt_shader(
        &mut self,
        key: crate::pipeline::ShaderKey,
        module: Arc<crate::pipeline::ShaderModule>,
    ) {
        self.pipelines.adopt(key, module);
    }

    /// Drops every shader and pipeline built from `changed` so the next frame
    /// recompiles them (hot reload); returns how many pipelines were dropped.
    pub fn reload(&mut self, changed: &std::path::Path) -> Result<usize, GpuError> {
        self.gpu.wait_idle()?;
        self.generation += 1;
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
    /// the graph (see `shader_check::check_shaders`); no pipeline is built.
    pub fn check_shaders(&mut self, plan: &Plan) -> Vec<ShaderProblem> {
        let scene = self.scene.as_ref().map(|r| &r.interface);
        shader_check::check_with(&mut self.pipelines, plan, scene)
    }

    /// The pass's pipeline key and resolved bindings, after checking that
    /// its shaders agree with the graph; `None` for passes without shaders of ours.
    fn checked_interface(
        &mut self,
        plan: &Plan,
        pass: &PlanPass,
    ) -> Result<Option<(PipelineKey, Vec<ResolvedBinding>)>, GpuError> {
        let Some(shaders) = shader_check::pass_shaders(pass)? else {
            return Ok(None);
        };
        let interface = self.pipelines.interface(&shaders.keys())?;
        let modules = shaders
            .keys()
            .into_iter()
            .map(|key| self.pipelines.shader(key))
            .collect::<Result<Vec<_>, _>>()?;
        let compiled: Vec<_> = modules.iter().map(|m| &m.compiled).collect();
        let info = self.gpu.info();
        info.shaders.check(&info.name, &pass.name, &compiled)?;
        let mismatch = |problems| GpuError::Mismatch {
            pass: pass.name.clone(),
            problems,
        };
        let bindings = check::pass_problems(plan, pass, &shaders, &interface).map_err(mismatch)?;
        let reads_scene = interface.bindings.keys().any(|(s, _)| *s == SCENE_SET);
        let scene = match self.scene.as_ref().filter(|_| reads_scene) {
            Some(RegisteredScene {
                interface: scene, ..
            }) => {
                let problems = scene_set_problems(scene, &interface, false, pass);
                if !problems.is_empty() {
                    return Err(mismatch(problems));
                }
                let traced = interface.bindings.values().any(|(b, _)| {
                    b.set == SCENE_SET && scene.scene_binding(b.binding).is_some_and(|s| s.tracing)
                });
                Some(if traced {
                    SceneSet::Traced
                } else {
                    SceneSet::Raster
                })
            }
            None => None,
        };
        let key = match shaders {
            PassShaders::Compute(shader) => PipelineKey::Compute { shader, scene },
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
                    scene,
                }
            }
        };
        Ok(Some((key, bindings)))
    }

    /// Builds the plan's pipelines, the scene passes' variants `draws` names
    /// among them, and writes its descriptor sets now rather than in the
    /// first [`execute`](Self::execute), so a caller that times frames
    /// (`--time-limit`) can leave the pipeline builds out.
    pub fn prepare(
        &mut self,
        plan: &Plan,
        resources: &mut FrameResources<'g>,
        draws: &dyn DrawRecorder,
    ) -> Result<(), GpuError> {
        let ready = self.ready_plan(plan, resources, draws)?;
        self.prepared = Some(ready);
        Ok(())
    }

    /// Drops the prepared plan, so the next frame prepares it again: a
    /// caller that hands frames a draw recorder holding another scene calls
    /// it, since the scene passes' variants are the recorder's.
    pub fn forget_prepared(&mut self) {
        self.prepared = None;
    }

    /// The prepared plan kept from the last frame or [`prepare`](Self::prepare),
    /// or a new one when the plan's pipelines or its resources changed since
    /// (or [`forget_prepared`](Self::forget_prepared) was called).
    fn ready_plan(
        &mut self,
        plan: &Plan,
        resources: &mut FrameResources<'g>,
        draws: &dyn DrawRecorder,
    ) -> Result<PreparedPlan<'g>, GpuError> {
        match self.prepared.take() {
            Some(ready)
                if ready.generation == self.generation && ready.resources == resources.id =>
            {
                Ok(ready)
            }
            _ => self.prepare_plan(plan, resources, draws),
        }
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
        let mut ready = self.ready_plan(plan, resources, &*draws)?;
        for (pass, prep) in plan.passes.iter().zip(&mut ready.passes) {
            prep.push = self.pack_push(pass, prep, options, 0)?;
        }
        let readback: Vec<_> = if options.readback {
            std::iter::once(plan.output)
                .chain(plan.readback.iter().copied())
                .collect()
        } else {
            Vec::new()
        };
        let gpu_timing = options.timing == TimingMode::GpuTimestamps;
        let info = self.gpu.info();
        let mut pools = self
            .pools
            .take()
            .map_or_else(|| FramePools::new(self.gpu), Ok)?;
        pools.fit(
            plan,
            (
                gpu_timing && info.timestamps,
                gpu_timing && info.pipeline_statistics,
            ),
            &readback,
        )?;
        let result = self.record_and_submit(
            plan,
            (resources, draws),
            &mut pools,
            &mut ready.passes,
            options,
            started,
        );
        self.pools = Some(pools);
        let Recorded {
            timings,
            statistics,
            images,
            record_ms,
        } = result?;
        let mut images = images.into_iter();
        let output = images.next();
        let readbacks: Vec<(String, Readback)> = plan
            .readback
            .iter()
            .map(|&r| plan.resources[r].name.clone())
            .zip(images)
            .collect();
        self.prepared = Some(ready);
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

    /// Records the frame's passes into `pools`' command buffers, submits and
    /// waits, and reads back the times, statistics and images.
    fn record_and_submit(
        &mut self,
        plan: &Plan,
        (resources, draws): (&mut FrameResources<'g>, &mut dyn DrawRecorder),
        pools: &mut FramePools<'g>,
        prepared: &mut [Prepared],
        options: &FrameOptions,
        started: Instant,
    ) -> Result<Recorded, GpuError> {
        let mut record_ms = started.elapsed().as_secs_f64() * 1e3;
        let mut timings = Vec::new();
        let per_pass = options.timing == TimingMode::CpuPerPass;
        let FramePools {
            commands,
            queries,
            statistics: stats,
            readbacks,
            ..
        } = pools;
        let mut cmd = commands.begin()?;
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
            let at = PassAt {
                plan,
                index: PassId::new(i),
                pass,
            };
            self.record_pass(at, &mut prepared[i], resources, (draws, options), cmd)?;
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
                commands.submit_and_wait(cmd)?;
                draws.submitted();
                timings.push(PassTiming {
                    pass: pass.name.clone(),
                    kind: pass.kind,
                    source: TimingSource::CpuWall,
                    ms: wall.elapsed().as_secs_f64() * 1e3,
                });
                cmd = commands.begin()?;
            }
        }
        let t = Instant::now();
        record::barriers(self.gpu.device(), cmd, &plan.epilogue, resources)?;
        if self.scene.is_some() {
            record::scene_counters_to_host(self.gpu.device(), cmd);
        }
        for rb in readbacks.iter() {
            rb.record(self.gpu, cmd, resources)?;
        }
        record_ms += t.elapsed().as_secs_f64() * 1e3;
        commands.submit_and_wait(cmd)?;
        draws.submitted();
        if let Some(q) = &queries {
            timings = q.timings(self.gpu, plan)?;
        }
        let statistics = match &stats {
            Some(s) => s.read(plan)?,
            None => Vec::new(),
        };
        let images = readbacks
            .iter()
            .map(|rb| rb.read(plan))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Recorded {
            timings,
            statistics,
            images,
            record_ms,
        })
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
