//! The frame loop: compile a graph for a scene (its features merged with the
//! graph's defaults and the caller's toggles), upload the scene, and run frames
//! with the camera and lights animated to each frame's time.

use crate::error::RenderError;
use crate::features::scene_features;
use crate::frame_loop::{FrameLoop, FrameRequest};
use crate::providers::trace_backend::{self, RAY_QUERY_FEATURE};
use crate::scene_gpu::{structure_scratch_bytes, GpuScene};
use crate::vocabulary::STRUCTURE_SCRATCH_BYTES;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;
use weft_gpu::{memory_requirements, FrameReport, Gpu, TimingMode};
use weft_graph::plan::{Extent, Plan};
use weft_graph::schema::ParamValue;
use weft_graph::CompileOptions;
use weft_graph::Prepared;
use weft_scene::Scene;

/// What to render.
#[derive(Debug, Clone)]
pub struct RenderSettings {
    /// The graph file.
    pub graph: PathBuf,
    /// Output size in pixels.
    pub extent: Extent,
    /// Frames to run; the last one is reported.
    pub frames: u32,
    /// Seconds at the first frame.
    pub time: f64,
    /// Seconds between frames.
    pub frame_time: f64,
    /// Camera name; the scene's first camera when `None`.
    pub camera: Option<String>,
    /// Toggles as on the command line (`name`, `!name`), applied after scene features.
    pub features: Vec<String>,
    /// How per-pass times are measured.
    pub timing: TimingMode,
    /// Copy the output back.
    pub readback: bool,
    /// Other images to copy back with the output (e.g. `hdr` for EXR files).
    pub extra_readback: Vec<String>,
    /// `extra_readback` names images a user asked for (`--readback`), kept
    /// whatever features the graph reads them back under; otherwise it is
    /// the graph's own list, whose conditional entries the compile filters.
    pub readback_asked: bool,
    /// Values for the graph's top-level parameters, replacing those in the file
    /// (`--param exposure=2`), so a sweep needs no edited copies of the graph.
    pub params: BTreeMap<String, ParamValue>,
    /// For a progressive graph: render until this many samples per pixel,
    /// at a fixed time, instead of `frames` frames.
    pub samples: Option<u64>,
    /// Stop before a frame that would end past this many seconds of
    /// rendering, counted from after the pipelines and the ray tracer's data
    /// are built ([`FrameLoop::prepare`](crate::FrameLoop::prepare)) and
    /// judged by the latest frame after the first (at least one frame is
    /// drawn).
    pub time_limit: Option<f64>,
    /// Where derived scene data is cached between runs (the ray tracer's
    /// BVH); `None` caches nothing.
    pub cache_dir: Option<PathBuf>,
    /// An environment map that replaces the scene's (`--environment`).
    pub environment: Option<PathBuf>,
    /// How passes that trace rays traverse the scene (`--backend`).
    pub trace_backend: crate::providers::trace_backend::TraceBackend,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            graph: PathBuf::from("graphs/forward.ron"),
            extent: Extent {
                width: 1280,
                height: 720,
            },
            frames: 1,
            time: 0.0,
            frame_time: 1.0 / 60.0,
            camera: None,
            features: Vec::new(),
            timing: TimingMode::Off,
            readback: true,
            extra_readback: Vec::new(),
            readback_asked: false,
            params: BTreeMap::new(),
            samples: None,
            time_limit: None,
            cache_dir: None,
            environment: None,
            trace_backend: Default::default(),
        }
    }
}

/// What a render produced.
pub struct Rendered {
    /// The compiled plan that ran.
    pub plan: Plan,
    /// The last frame's report (output, timings, memory).
    pub report: FrameReport,
    /// Name of the camera used.
    pub camera: String,
    /// Draw calls of the last frame.
    pub draw_calls: u64,
    /// Meshes each view of the last frame drew and left out (frustum culling).
    pub culling: Vec<crate::recorder::ViewCulling>,
    /// Host milliseconds per frame spent preparing and recording commands (the
    /// executor's `record_ms`, no GPU wait), one entry per frame.
    pub record_ms: Vec<f64>,
    /// Wall-clock milliseconds per frame from starting to record to the GPU
    /// finishing (and the readback, on the last frame), one entry per frame.
    pub frame_ms: Vec<f64>,
    /// Wall-clock milliseconds before the first frame spent building the
    /// pipelines and, for a graph that traces, the BVH and the ray tracer's
    /// tables ([`FrameLoop::prepare`]); not counted against `time_limit`.
    pub prepare_ms: f64,
    /// Pipelines built before the first frame, every scene-pass variant the
    /// scene needs among them.
    pub pipelines_prepared: usize,
    /// Pipelines after the last frame: the same number, since no frame
    /// builds one.
    pub pipelines_built: usize,
    /// Textures that could not be loaded, meshes skipped.
    pub warnings: Vec<String>,
    /// Samples per pixel the output holds, for a progressive graph.
    pub samples: Option<u64>,
    /// Per-pass times of every frame (empty lists when timing is off), so
    /// callers can take medians over frames.
    pub timings: Vec<Vec<weft_gpu::PassTiming>>,
    /// Rays each tracing pass traced, every frame (empty lists when nothing
    /// traces): the cost model beside the times.
    pub rays: Vec<Vec<crate::PassRays>>,
    /// The plan's summarised views of the last frame (mean, median, p95,
    /// histogram of each per-pixel count or measure), by view name.
    pub views: Vec<(String, crate::ViewSummary)>,
}

/// Where a render stands after a frame, for progress displays.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Frames drawn so far.
    pub frames: u32,
    /// Frames the render will draw (fewer if a time limit stops it).
    pub planned_frames: u32,
    /// Samples per pixel accumulated so far (progressive graphs).
    pub samples: Option<u64>,
    /// Seconds since the first frame started.
    pub elapsed: f64,
}

/// How long the next frame is expected to take, from the frames drawn so far
/// (`frame_ms`): the latest one after the first, which also builds the BVH
/// and uploads the ray tracer's tables and so says nothing about the frames
/// after it; 0 when only the first has been drawn.
fn typical_frame_seconds(frame_ms: &[f64]) -> f64 {
    frame_ms
        .get(1..)
        .and_then(<[f64]>::last)
        .copied()
        .unwrap_or(0.0)
        / 1e3
}

impl Rendered {
    /// Mean of `values` after the first entry (the first frame compiles shaders and
    /// builds pipelines), or the only entry.
    pub fn steady_mean(values: &[f64]) -> f64 {
        let steady = if values.len() > 1 {
            &values[1..]
        } else {
            values
        };
        steady.iter().sum::<f64>() / steady.len().max(1) as f64
    }
}

/// Loads and resolves `settings.graph` with `settings.params`, once: the
/// graph value a render, a live render or a command keeps and compiles as
/// often as it needs.
pub fn load_graph(settings: &RenderSettings) -> Result<Prepared, RenderError> {
    Prepared::load(&settings.graph, settings.params.clone()).map_err(RenderError::Graph)
}

/// Compiles `graph` (loaded from `settings.graph`) for `scene` on `gpu`'s
/// memory requirements, with the scene's features and `settings`' toggles.
pub fn compile_for_scene(
    gpu: &Gpu,
    scene: &Scene,
    graph: &Prepared,
    settings: &RenderSettings,
) -> Result<Plan, RenderError> {
    let loaded = graph.graph();
    let mut requested = scene_features(scene);
    requested.extend(settings.features.iter().cloned());
    // The renderer's to set: on exactly when the plan traces in hardware.
    if settings
        .features
        .iter()
        .any(|f| f.trim().trim_start_matches('!') == RAY_QUERY_FEATURE)
    {
        return Err(RenderError::Graph(vec![weft_graph::Diagnostic::error(
            settings.graph.clone(),
            weft_graph::spans::Pos { line: 1, col: 1 },
            format!(
                "feature `{RAY_QUERY_FEATURE}` is the renderer's: it is on exactly when passes \
                 trace with ray queries"
            ),
        )
        .with_hint(
            "choose the backend with --backend hardware or --backend software",
        )]));
    }
    let memory = memory_requirements(gpu);
    let device = trace_backend::DeviceTracing {
        name: gpu.info().name.clone(),
        ray_query: gpu.info().shaders.ray_query,
        cpu: gpu.info().kind == weft_gpu::DeviceKind::Cpu,
    };
    let names_feature = weft_graph::feature_names(graph.ir()).contains(RAY_QUERY_FEATURE);
    // What a plan that traces in hardware builds its structures in,
    // measured the first time a compile asks for ray queries; a failure to
    // measure is the device's, not the graph's.
    let mut scratch: Option<u64> = None;
    let mut measuring_failed: Option<weft_gpu::GpuError> = None;
    let plan =
        trace_backend::compile_traced(settings.trace_backend, &device, names_feature, |hardware| {
            let mut features = loaded.features(&requested);
            // Whatever the graph's defaults say.
            features.remove(RAY_QUERY_FEATURE);
            if hardware {
                features.insert(RAY_QUERY_FEATURE.to_string());
            }
            let mut scene_values = BTreeMap::new();
            if hardware {
                let bytes = match scratch {
                    Some(bytes) => bytes,
                    None => match structure_scratch_bytes(gpu, scene) {
                        Ok(bytes) => *scratch.insert(bytes),
                        Err(error) => {
                            measuring_failed = Some(error);
                            return Err(Vec::new());
                        }
                    },
                };
                scene_values.insert(STRUCTURE_SCRATCH_BYTES.to_string(), bytes as f64);
            }
            let options = CompileOptions {
                extent: settings.extent,
                features,
                memory: &memory,
                scene_values,
                readback: settings.extra_readback.clone(),
                readback_asked: settings.readback_asked,
            };
            crate::providers::compile(graph, &options)
        })
        .map_err(|d| match measuring_failed.take() {
            Some(error) => RenderError::Gpu(error),
            None => RenderError::Graph(d),
        })?;
    if let Some((image, size)) = weft_gpu::oversized_images(gpu, &plan).into_iter().next() {
        return Err(RenderError::ImageTooLarge {
            image,
            size,
            max: gpu.info().max_image_dimension,
            device: gpu.info().name.clone(),
        });
    }
    if let Some((image, samples)) = weft_gpu::unsupported_sample_counts(gpu, &plan)
        .into_iter()
        .next()
    {
        return Err(RenderError::Graph(vec![unsupported_samples(
            loaded, &image, samples, gpu,
        )]));
    }
    Ok(plan)
}

/// The error at image `image`'s `samples`: a count the device's
/// attachments cannot have, and those they can.
fn unsupported_samples(
    graph: &weft_graph::LoadedGraph,
    image: &str,
    samples: u32,
    gpu: &Gpu,
) -> weft_graph::Diagnostic {
    let declared = graph.resources.iter().find(|r| match &r.item {
        weft_graph::schema::ResourceDecl::Image(i) => i.name == image,
        weft_graph::schema::ResourceDecl::Buffer(_)
        | weft_graph::schema::ResourceDecl::AccelerationStructure(_) => false,
    });
    let (file, pos) = declared.map_or_else(Default::default, |r| {
        graph.locate(
            r.source,
            &[
                weft_graph::spans::Seg::Field("resources"),
                weft_graph::spans::Seg::Index(r.index),
                weft_graph::spans::Seg::Field("samples"),
            ],
        )
    });
    let mask = gpu.info().attachment_sample_counts;
    let offered: Vec<String> = (0..7)
        .map(|bit| 1u32 << bit)
        .filter(|n| mask & n != 0)
        .map(|n| n.to_string())
        .collect();
    weft_graph::Diagnostic::error(
        file,
        pos,
        format!(
            "image \"{image}\" has {samples} samples, which attachments on {} cannot have",
            gpu.info().name
        ),
    )
    .with_hint(format!(
        "use one of {} (framebufferColorSampleCounts and framebufferDepthSampleCounts)",
        offered.join(", ")
    ))
}

/// Renders `scene` through the graph in `settings` (loaded here; callers
/// that keep the graph use [`render_with_progress`]).
pub fn render(
    gpu: &Gpu,
    scene: &Scene,
    settings: &RenderSettings,
) -> Result<Rendered, RenderError> {
    let graph = load_graph(settings)?;
    render_with_progress(gpu, scene, &graph, settings, &mut |_| {})
}

/// Frames to draw: `settings.frames`, or as many as `settings.samples` needs
/// at the plan's samples per frame.
fn planned_frames(plan: &Plan, settings: &RenderSettings) -> Result<u32, RenderError> {
    let Some(samples) = settings.samples else {
        return Ok(settings.frames.max(1));
    };
    let per_frame = plan
        .samples_per_frame
        .ok_or_else(|| RenderError::NotProgressive {
            graph: settings.graph.clone(),
        })?;
    Ok(samples
        .div_ceil(u64::from(per_frame))
        .clamp(1, u64::from(u32::MAX)) as u32)
}

/// [`render`] of a graph already loaded from `settings.graph` (with
/// `settings.params`), calling `progress` after every frame.
pub fn render_with_progress(
    gpu: &Gpu,
    scene: &Scene,
    graph: &Prepared,
    settings: &RenderSettings,
    progress: &mut dyn FnMut(Progress),
) -> Result<Rendered, RenderError> {
    let camera = match &settings.camera {
        Some(name) => scene.camera(name).ok_or_else(|| RenderError::Camera {
            name: name.clone(),
            available: scene
                .cameras
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        })?,
        None => scene.cameras.first().ok_or_else(|| RenderError::Camera {
            name: "(first)".into(),
            available: "none".into(),
        })?,
    };
    let plan = Arc::new(compile_for_scene(gpu, scene, graph, settings)?);
    let count = planned_frames(&plan, settings)?;
    // Accumulating to a sample count keeps the scene still.
    let frame_time = if settings.samples.is_some() {
        0.0
    } else {
        settings.frame_time
    };
    let updater = weft_scene::SceneUpdater::new(scene)?;
    let mut uploaded = GpuScene::new(gpu, scene, updater.animates())?;
    uploaded.cache_bvh_in(settings.cache_dir.clone());
    let mut frames = FrameLoop::new(gpu, Arc::clone(&plan), (uploaded, updater))?;
    // Pipelines and the ray tracer's data are built before the clock starts:
    // `time_limit` counts rendering.
    let preparing = std::time::Instant::now();
    frames.prepare()?;
    let prepare_ms = preparing.elapsed().as_secs_f64() * 1e3;
    let pipelines_prepared = frames.pipeline_count();
    let mut record_ms = Vec::with_capacity(count.min(4096) as usize);
    let mut frame_ms = Vec::with_capacity(count.min(4096) as usize);
    let mut timings = Vec::with_capacity(count.min(4096) as usize);
    let mut rays = Vec::with_capacity(count.min(4096) as usize);
    let mut last = None;
    let start = std::time::Instant::now();
    for frame in 0..count {
        let out_of_time = settings.time_limit.is_some_and(|limit| {
            frame > 0 && start.elapsed().as_secs_f64() + typical_frame_seconds(&frame_ms) > limit
        });
        let final_frame = frame + 1 == count || out_of_time;
        let started = std::time::Instant::now();
        let report = frames.draw(&FrameRequest {
            camera,
            time: settings.time + f64::from(frame) * frame_time,
            frame,
            timing: settings.timing,
            readback: settings.readback && final_frame,
        })?;
        if let Some(error) = frames.take_script_error() {
            return Err(RenderError::Script(error));
        }
        frame_ms.push(started.elapsed().as_secs_f64() * 1e3);
        record_ms.push(report.record_ms);
        timings.push(report.timings.clone());
        rays.push(frames.rays()?);
        last = Some(report);
        progress(Progress {
            frames: frame + 1,
            planned_frames: count,
            samples: frames.samples(),
            elapsed: start.elapsed().as_secs_f64(),
        });
        if final_frame {
            break;
        }
    }
    let samples = frames.samples();
    let report =
        last.ok_or_else(|| RenderError::Gpu(weft_gpu::GpuError::Plan("no frame".into())))?;
    let draw_calls = frames.draw_calls();
    let pipelines_built = frames.pipeline_count();
    let culling = frames.culling().to_vec();
    let warnings = frames.warnings().to_vec();
    drop(frames);
    let plan = Arc::try_unwrap(plan).unwrap_or_else(|shared| (*shared).clone());
    let views = crate::view_summary::plan_views(&plan, &report.readbacks);
    Ok(Rendered {
        views,
        plan,
        report,
        camera: camera.name.clone(),
        draw_calls,
        culling,
        record_ms,
        frame_ms,
        warnings,
        samples,
        timings,
        rays,
        prepare_ms,
        pipelines_prepared,
        pipelines_built,
    })
}

#[cfg(test)]
mod tests {
    use super::typical_frame_seconds;

    #[test]
    fn the_first_frame_is_no_measure_of_the_next() {
        assert_eq!(typical_frame_seconds(&[]), 0.0);
        assert_eq!(typical_frame_seconds(&[600.0]), 0.0);
        assert_eq!(typical_frame_seconds(&[600.0, 20.0]), 0.02);
        assert_eq!(typical_frame_seconds(&[600.0, 20.0, 30.0]), 0.03);
    }
}
