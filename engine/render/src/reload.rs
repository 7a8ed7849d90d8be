//! Hot reload: a render that stays alive across edits. [`LiveRender`] keeps the
//! GPU context, the renderer's caches, the uploaded scene and the plan's images,
//! and applies changed files all-or-nothing: the new scene, plan and shaders are
//! loaded and checked before anything live is touched, and only then swapped in.
//! A failure leaves the last good version rendering and is reported at file:line.

use crate::error::RenderError;
use crate::frame::{compile_for_scene, RenderSettings};
use crate::recorder::SceneRecorder;
use crate::scene_gpu::GpuScene;
use crate::sources::{
    normalize, plan_shader_keys, scene_files, scene_path_files, shader_files, Sources,
};
use std::collections::BTreeSet;
use std::fmt;
use std::path::{Path, PathBuf};
use weft_gpu::pipeline::PipelineCache;
use weft_gpu::resources::GpuImage;
use weft_gpu::{FrameOptions, FrameReport, FrameResources, Gpu, GpuError, Renderer, ShaderError};
use weft_graph::plan::Plan;
use weft_scene::{Camera, Scene, SceneError};

/// Why a reload was refused, located at the file and line to fix.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub struct ReloadError {
    /// The file with the problem.
    pub file: PathBuf,
    /// Its 1-based line, when known.
    pub line: Option<u32>,
    /// What is wrong, on one line.
    pub message: String,
}

impl fmt::Display for ReloadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{line}: {}", self.file.display(), self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

impl ReloadError {
    fn new(file: &Path, line: Option<u32>, message: &str) -> Self {
        Self {
            file: file.to_path_buf(),
            line,
            message: message
                .lines()
                .next()
                .map(|l| l.strip_prefix("error: ").unwrap_or(l).trim())
                .unwrap_or_default()
                .to_string(),
        }
    }

    fn scene(err: &SceneError) -> Self {
        let at = err.location();
        let line = at.line.and_then(|l| u32::try_from(l).ok());
        Self::new(&at.file, line, &err.message())
    }

    /// Locates a render error; errors that name no file are put on `fallback`.
    fn render(err: RenderError, fallback: &Path) -> Self {
        match err {
            RenderError::Graph(diagnostics) => diagnostics
                .iter()
                .find(|d| d.is_error())
                .or(diagnostics.first())
                .map(|d| Self::new(&d.file, Some(d.pos.line), &d.message))
                .unwrap_or_else(|| Self::new(fallback, None, "the graph did not compile")),
            RenderError::Gpu(err) => Self::gpu(err, fallback),
            other => Self::new(fallback, None, &other.to_string()),
        }
    }

    fn gpu(err: GpuError, fallback: &Path) -> Self {
        match err {
            GpuError::Shader(ShaderError::Compile(diagnostics)) => diagnostics
                .iter()
                .find(|d| d.message.starts_with("error"))
                .or(diagnostics.first())
                .map(|d| Self::new(&d.file, d.line, &d.message))
                .unwrap_or_else(|| Self::new(fallback, None, "shader compilation failed")),
            other => Self::new(fallback, None, &other.to_string()),
        }
    }
}

/// A render kept alive across edits of its graph, shaders and scene.
pub struct LiveRender<'g> {
    resources: FrameResources<'g>,
    recorder: SceneRecorder<'g>,
    renderer: Renderer<'g>,
    /// Shaders compiled from disk to check a candidate before it goes live; it
    /// builds no pipelines, so invalidating it never touches the device.
    checker: PipelineCache,
    gpu: &'g Gpu,
    settings: RenderSettings,
    scene_path: PathBuf,
    scene: Scene,
    plan: Plan,
    sources: Sources,
    /// Files changed since the last successful reload; a refused reload keeps
    /// them, so the next attempt still reloads everything that changed.
    pending: BTreeSet<PathBuf>,
}

/// The camera the settings name, or the scene's first.
fn pick_camera<'s>(scene: &'s Scene, settings: &RenderSettings) -> Result<&'s Camera, RenderError> {
    match &settings.camera {
        Some(name) => scene.camera(name).ok_or_else(|| RenderError::Camera {
            name: name.clone(),
            available: scene
                .cameras
                .iter()
                .map(|c| c.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        }),
        None => scene.cameras.first().ok_or_else(|| RenderError::Camera {
            name: "(first)".into(),
            available: "none".into(),
        }),
    }
}

/// Compiles and checks every shader the plan runs (and its agreement with the
/// graph) through `checker`, without building pipelines.
fn check_shaders(
    checker: &mut PipelineCache,
    plan: &Plan,
    graph: &Path,
) -> Result<(), ReloadError> {
    let keys = plan_shader_keys(plan).map_err(|e| ReloadError::gpu(e, graph))?;
    for key in &keys {
        checker
            .shader(key)
            .map_err(|e| ReloadError::gpu(e, &key.path))?;
    }
    let problems = weft_gpu::check::check_with(checker, plan);
    match problems.first() {
        None => Ok(()),
        Some(problem) => {
            let at = plan
                .passes
                .iter()
                .find(|p| p.name == problem.pass)
                .map(|p| (p.declared_at.file.clone(), Some(p.declared_at.pos.line)))
                .unwrap_or_else(|| (graph.to_path_buf(), None));
            Err(ReloadError::new(
                &at.0,
                at.1,
                &format!("pass `{}`: {}", problem.pass, problem.message),
            ))
        }
    }
}

impl<'g> LiveRender<'g> {
    /// Loads the scene at `scene_path` and compiles `settings.graph` for it; the
    /// first frame builds the pipelines.
    pub fn new(
        gpu: &'g Gpu,
        scene_path: &Path,
        settings: RenderSettings,
    ) -> Result<Self, ReloadError> {
        let scene = weft_scene::load_scene(scene_path).map_err(|e| ReloadError::scene(&e))?;
        pick_camera(&scene, &settings).map_err(|e| ReloadError::render(e, scene_path))?;
        let plan = compile_for_scene(gpu, &scene, &settings)
            .map_err(|e| ReloadError::render(e, &settings.graph))?;
        let mut checker = PipelineCache::new().map_err(|e| ReloadError::gpu(e, &settings.graph))?;
        check_shaders(&mut checker, &plan, &settings.graph)?;
        let fail = |e: GpuError| ReloadError::gpu(e, &settings.graph);
        let renderer = Renderer::new(gpu).map_err(fail)?;
        let uploaded =
            GpuScene::new(gpu, &scene).map_err(|e| ReloadError::render(e, scene_path))?;
        let recorder = SceneRecorder::new(gpu, uploaded).map_err(fail)?;
        let resources = renderer.create_resources(&plan).map_err(fail)?;
        let sources = Sources {
            graph: graph_files(&settings.graph),
            shaders: shader_files(&mut checker, &plan).map_err(fail)?,
            scene: scene_files(&scene),
        };
        Ok(Self {
            resources,
            recorder,
            renderer,
            checker,
            gpu,
            settings,
            scene_path: scene_path.to_path_buf(),
            scene,
            plan,
            sources,
            pending: BTreeSet::new(),
        })
    }

    /// The files this render depends on, to watch.
    pub fn sources(&self) -> &Sources {
        &self.sources
    }

    /// The plan that renders now.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The scene that renders now.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The settings the live version was built with.
    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// The camera the settings name (or the scene's first).
    pub fn camera(&self) -> Result<&Camera, RenderError> {
        pick_camera(&self.scene, &self.settings)
    }

    /// The live plan's output image; after a frame it is in
    /// `TRANSFER_SRC_OPTIMAL`, ready to be presented or copied.
    pub fn output(&self) -> Result<&GpuImage, GpuError> {
        self.resources.image(self.plan.output)
    }

    /// Renders one frame of the live version at the settings' time, reading the
    /// output (and the settings' extra images) back.
    pub fn frame(&mut self) -> Result<FrameReport, RenderError> {
        let camera = pick_camera(&self.scene, &self.settings)?.clone();
        self.draw(&camera, self.settings.time, 0, true)
    }

    /// Renders frame number `frame` of the live version seen from `camera` at
    /// `time` seconds (a viewer's own camera), reading the output back only
    /// when asked.
    pub fn draw(
        &mut self,
        camera: &Camera,
        time: f32,
        frame: u32,
        readback: bool,
    ) -> Result<FrameReport, RenderError> {
        let extent = [self.settings.extent.width, self.settings.extent.height];
        self.recorder.scene.update(camera, time, extent)?;
        self.recorder.set_frame(time, frame);
        let options = FrameOptions {
            timing: self.settings.timing,
            readback,
            time,
            frame,
        };
        Ok(self.renderer.execute(
            &self.plan,
            &mut self.resources,
            &mut self.recorder,
            &options,
        )?)
    }

    /// Switches to other settings (another graph, feature set or size) all-or-nothing:
    /// the new plan and its shaders are built and checked first, and on failure the
    /// live version keeps rendering unchanged. Shader files the live version did not
    /// use are compiled afresh from disk, since no watcher saw their edits.
    pub fn reconfigure(&mut self, settings: RenderSettings) -> Result<(), ReloadError> {
        let graph = settings.graph.clone();
        pick_camera(&self.scene, &settings)
            .map_err(|e| ReloadError::render(e, &self.scene_path))?;
        let plan = compile_for_scene(self.gpu, &self.scene, &settings)
            .map_err(|e| ReloadError::render(e, &graph))?;
        let fail = |e: GpuError| ReloadError::gpu(e, &graph);
        let mut checker = PipelineCache::new().map_err(fail)?;
        check_shaders(&mut checker, &plan, &graph)?;
        let shaders = shader_files(&mut checker, &plan).map_err(fail)?;
        let resources = self.renderer.create_resources(&plan).map_err(fail)?;
        let unwatched: Vec<&PathBuf> = shaders
            .iter()
            .filter(|(file, _)| !self.sources.shaders.contains_key(*file))
            .flat_map(|(_, raw)| raw)
            .collect();
        for raw in unwatched {
            self.renderer.reload(raw).map_err(fail)?;
            self.recorder.reload(raw).map_err(fail)?;
        }
        self.sources = Sources {
            graph: graph_files(&graph),
            shaders,
            scene: self.sources.scene.clone(),
        };
        self.checker = checker;
        self.resources = resources;
        self.plan = plan;
        self.settings = settings;
        Ok(())
    }

    /// Applies edits to `changed` files (normalized paths; files this render does not
    /// use are ignored). Everything that changed since the last good version is
    /// reloaded and checked first; only if all of it succeeds is it swapped in.
    /// Returns the files reloaded, or why the last good version was kept.
    pub fn apply(&mut self, changed: &BTreeSet<PathBuf>) -> Result<Vec<PathBuf>, ReloadError> {
        let all = self.sources.all();
        self.pending
            .extend(changed.iter().filter(|p| all.contains(*p)).cloned());
        let pending = self.pending.clone();
        let scene_changed = pending.iter().any(|p| self.sources.scene.contains(p));
        let graph_changed = pending.iter().any(|p| self.sources.graph.contains(p));
        let shaders: BTreeSet<PathBuf> = pending
            .iter()
            .filter_map(|p| self.sources.shaders.get(p))
            .flatten()
            .cloned()
            .collect();
        let graph = self.settings.graph.clone();
        let device = self.gpu.device();
        for raw in &shaders {
            self.checker.invalidate(device, raw);
        }
        let new_scene = if scene_changed {
            Some(weft_scene::load_scene(&self.scene_path).map_err(|e| ReloadError::scene(&e))?)
        } else {
            None
        };
        let scene = new_scene.as_ref().unwrap_or(&self.scene);
        pick_camera(scene, &self.settings).map_err(|e| ReloadError::render(e, &self.scene_path))?;
        let new_plan = if scene_changed || graph_changed {
            Some(
                compile_for_scene(self.gpu, scene, &self.settings)
                    .map_err(|e| ReloadError::render(e, &graph))?,
            )
        } else {
            None
        };
        let plan = new_plan.as_ref().unwrap_or(&self.plan);
        check_shaders(&mut self.checker, plan, &graph)?;
        let fail = |e: GpuError| ReloadError::gpu(e, &graph);
        let sources = Sources {
            graph: if graph_changed {
                graph_files(&graph)
            } else {
                self.sources.graph.clone()
            },
            shaders: shader_files(&mut self.checker, plan).map_err(fail)?,
            scene: match &new_scene {
                Some(s) => scene_files(s),
                None => self.sources.scene.clone(),
            },
        };
        let new_recorder = match &new_scene {
            Some(s) => {
                let uploaded = GpuScene::new(self.gpu, s)
                    .map_err(|e| ReloadError::render(e, &self.scene_path))?;
                Some(SceneRecorder::new(self.gpu, uploaded).map_err(fail)?)
            }
            None => None,
        };
        let new_resources = match &new_plan {
            Some(p) => Some(self.renderer.create_resources(p).map_err(fail)?),
            None => None,
        };
        for raw in &shaders {
            self.renderer.reload(raw).map_err(fail)?;
            self.recorder.reload(raw).map_err(fail)?;
        }
        if let Some(recorder) = new_recorder {
            self.recorder = recorder;
        }
        if let (Some(plan), Some(resources)) = (new_plan, new_resources) {
            self.resources = resources;
            self.plan = plan;
        }
        if let Some(scene) = new_scene {
            self.scene = scene;
        }
        self.sources = sources;
        self.pending.clear();
        Ok(pending.into_iter().collect())
    }
}

/// The files a render that failed to start reads, as far as they can be found
/// (the graph and its includes, the scene and its includes and models, the shader
/// files of the plan when it compiles, and the file the error is in), so a watcher
/// can wait for the fix.
pub fn startup_files(
    gpu: &Gpu,
    scene_path: &Path,
    settings: &RenderSettings,
    error: &ReloadError,
) -> BTreeSet<PathBuf> {
    let mut files = graph_files(&settings.graph);
    files.insert(normalize(&error.file));
    files.extend(scene_path_files(scene_path));
    let Ok(scene) = weft_scene::load_scene(scene_path) else {
        return files;
    };
    files.extend(scene_files(&scene));
    if let Ok(keys) = compile_for_scene(gpu, &scene, settings)
        .map_err(|e| e.to_string())
        .and_then(|plan| plan_shader_keys(&plan).map_err(|e| e.to_string()))
    {
        files.extend(
            keys.iter()
                .filter(|k| k.path.is_file())
                .map(|k| normalize(&k.path)),
        );
    }
    files
}

/// The graph file and its includes, normalized.
fn graph_files(graph: &Path) -> BTreeSet<PathBuf> {
    let mut files: BTreeSet<PathBuf> = weft_graph::load(graph)
        .files()
        .iter()
        .map(|p| normalize(p))
        .collect();
    files.insert(normalize(graph));
    files
}
