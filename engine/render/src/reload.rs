//! Hot reload: a render that stays alive across edits. [`LiveRender`] keeps the
//! GPU context, the renderer's caches, the uploaded scene and the plan's images,
//! and applies changed files all-or-nothing in two steps: a [`ReloadJob`] is
//! prepared (loaded and checked, on any thread; see [`crate::prepare`]) without
//! touching anything live, and [`LiveRender::commit`] swaps it in at a frame
//! boundary with only the device work left. A failure leaves the last good
//! version rendering and is reported at file:line.

use crate::error::RenderError;
use crate::frame::{compile_for_scene, load_graph, RenderSettings};
use crate::frame_loop::{FrameLoop, FrameRequest};
use crate::prepare::{
    check_shaders, graph_files, pick_camera, PreparedReload, ReloadBase, ReloadChange, ReloadJob,
    ShaderChecker,
};
use crate::recorder::SceneRecorder;
use crate::reload_error::ReloadError;
use crate::scene_gpu::GpuScene;
use crate::sources::{
    normalize, plan_shader_keys, scene_files, scene_path_files, shader_files, Sources,
};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use weft_gpu::pipeline::PipelineCache;
use weft_gpu::resources::GpuImage;
use weft_gpu::{FrameReport, Gpu, GpuError};
use weft_graph::plan::Plan;
use weft_graph::Prepared;
use weft_scene::SceneUpdater;
use weft_scene::{Camera, Scene};

/// A render kept alive across edits of its graph, shaders and scene.
pub struct LiveRender<'g> {
    frames: FrameLoop<'g>,
    /// Checks reloads prepared on this thread ([`LiveRender::apply`]).
    checker: ShaderChecker,
    gpu: &'g Gpu,
    settings: RenderSettings,
    /// `settings.graph` loaded and resolved: loaded again only when one of
    /// its files or the settings naming it change.
    graph: Arc<Prepared>,
    scene_path: PathBuf,
    scene: Arc<Scene>,
    sources: Sources,
    /// Files changed since the last successful reload; a refused reload keeps
    /// them, so the next attempt still reloads everything that changed.
    pending: BTreeSet<PathBuf>,
    /// Counts commits, so a reload prepared from an older version is refused.
    version: u64,
}

/// What [`LiveRender::commit`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Committed {
    /// The new version is live; these edited files were applied.
    Applied(Vec<PathBuf>),
    /// Nothing: the reload was prepared from a version that is no longer live
    /// (another reload committed meanwhile); prepare it again.
    Stale,
}

impl<'g> LiveRender<'g> {
    /// Loads the scene at `scene_path` and `settings.graph` and compiles the
    /// graph for the scene; the first frame builds the pipelines.
    pub fn new(
        gpu: &'g Gpu,
        scene_path: &Path,
        settings: RenderSettings,
    ) -> Result<Self, ReloadError> {
        let graph = load_graph(&settings).map_err(|e| ReloadError::render(e, &settings.graph))?;
        Self::with_graph(gpu, scene_path, graph, settings)
    }

    /// [`LiveRender::new`] with `settings.graph` already loaded (with
    /// `settings.params`) as `graph`.
    pub fn with_graph(
        gpu: &'g Gpu,
        scene_path: &Path,
        graph: Prepared,
        settings: RenderSettings,
    ) -> Result<Self, ReloadError> {
        let scene = crate::scene_load::load_scene(
            scene_path,
            settings.cache_dir.as_deref(),
            settings.environment.as_deref(),
        )
        .map_err(|e| ReloadError::scene(&e))?;
        pick_camera(&scene, &settings).map_err(|e| ReloadError::render(e, scene_path))?;
        let plan = compile_for_scene(gpu, &scene, &graph, &settings)
            .map_err(|e| ReloadError::render(e, &settings.graph))?;
        let fail = |e: GpuError| ReloadError::gpu(e, &settings.graph);
        let mut cache = PipelineCache::new().map_err(fail)?;
        check_shaders(gpu, &mut cache, &plan, &settings.graph)?;
        let updater = SceneUpdater::live(&scene).map_err(|e| ReloadError::scene(&e))?;
        let mut uploaded = GpuScene::new(gpu, &scene, updater.animates())
            .map_err(|e| ReloadError::render(e, scene_path))?;
        uploaded.cache_bvh_in(settings.cache_dir.clone());
        let sources = Sources {
            graph: graph_files(graph.graph()),
            shaders: shader_files(&mut cache, &plan).map_err(fail)?,
            scene: scene_files(&scene),
        };
        let frames = FrameLoop::new(gpu, Arc::new(plan), (uploaded, updater)).map_err(fail)?;
        Ok(Self {
            frames,
            checker: ShaderChecker::new().map_err(fail)?,
            gpu,
            settings,
            graph: Arc::new(graph),
            scene_path: scene_path.to_path_buf(),
            scene: Arc::new(scene),
            sources,
            pending: BTreeSet::new(),
            version: 0,
        })
    }

    /// The graph that renders now, loaded and resolved.
    pub fn graph(&self) -> &Prepared {
        &self.graph
    }

    /// The files this render depends on, to watch.
    pub fn sources(&self) -> &Sources {
        &self.sources
    }

    /// The plan that renders now.
    pub fn plan(&self) -> &Plan {
        self.frames.plan()
    }

    /// The scene that renders now.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Samples per pixel the last frame's history holds (progressive graphs).
    pub fn samples(&self) -> Option<u64> {
        self.frames.samples()
    }

    /// Draw calls recorded by the last frame.
    pub fn draw_calls(&self) -> u64 {
        self.frames.draw_calls()
    }

    /// Per view, meshes drawn and culled by the last frame.
    pub fn culling(&self) -> &[crate::recorder::ViewCulling] {
        self.frames.culling()
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
        self.frames.output()
    }

    /// Turns the scene's environment map to `rotation_deg` about +y from the
    /// next frame on (the viewer's panel), until the scene reloads.
    pub fn turn_environment(&mut self, rotation_deg: f32) {
        self.frames.turn_environment(rotation_deg);
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
        time: f64,
        frame: u32,
        readback: bool,
    ) -> Result<FrameReport, RenderError> {
        self.frames.draw(&FrameRequest {
            camera,
            time,
            frame,
            timing: self.settings.timing,
            readback,
        })
    }

    /// The scene script's error from `update`, if one failed since the last
    /// call: the frames go on with the lights of the last good step.
    pub fn take_script_error(&mut self) -> Option<weft_scene::SceneError> {
        self.frames.take_script_error()
    }

    fn base(&self) -> ReloadBase {
        ReloadBase {
            version: self.version,
            scene_path: self.scene_path.clone(),
            settings: self.settings.clone(),
            graph: Arc::clone(&self.graph),
            scene: Arc::clone(&self.scene),
            plan: Arc::clone(self.frames.plan()),
            sources: self.sources.clone(),
        }
    }

    /// Records edits to `changed` files (normalized paths; files this render does
    /// not use are ignored) and returns the reload of everything changed since
    /// the last good version, to prepare on any thread and [`commit`](Self::commit).
    pub fn files_job(&mut self, changed: &BTreeSet<PathBuf>) -> ReloadJob {
        let all = self.sources.all();
        self.pending
            .extend(changed.iter().filter(|p| all.contains(*p)).cloned());
        ReloadJob {
            base: self.base(),
            change: ReloadChange::Files(self.pending.clone()),
        }
    }

    /// The reload that switches to other settings (another graph, feature set or size).
    pub fn settings_job(&self, settings: RenderSettings) -> ReloadJob {
        ReloadJob {
            base: self.base(),
            change: ReloadChange::Settings(Box::new(settings)),
        }
    }

    /// Swaps a prepared reload in at a frame boundary: uploads a changed scene,
    /// creates a changed plan's images, drops the pipelines of changed shaders and
    /// hands the caches the shader modules the prepare step compiled, so the next
    /// frame only builds pipelines. Everything that can be wrong with the edited
    /// files was refused by the prepare step; this fails only on device errors,
    /// and then leaves the live version as it was.
    pub fn commit(&mut self, prepared: PreparedReload) -> Result<Committed, ReloadError> {
        if prepared.version != self.version {
            return Ok(Committed::Stale);
        }
        let graph = prepared.settings.graph.clone();
        let fail = |e: GpuError| ReloadError::gpu(e, &graph);
        let new_recorder = match &prepared.scene {
            Some(s) => {
                let updater = SceneUpdater::live(s).map_err(|e| ReloadError::scene(&e))?;
                let mut uploaded = GpuScene::new(self.gpu, s, updater.animates())
                    .map_err(|e| ReloadError::render(e, &self.scene_path))?;
                uploaded.cache_bvh_in(prepared.settings.cache_dir.clone());
                Some((SceneRecorder::new(self.gpu, uploaded), updater))
            }
            None => None,
        };
        let new_resources = match &prepared.plan {
            Some(p) => Some(self.frames.create_resources(p).map_err(fail)?),
            None => None,
        };
        let unwatched = prepared
            .sources
            .shaders
            .iter()
            .filter(|(file, _)| !self.sources.shaders.contains_key(*file))
            .flat_map(|(_, raw)| raw);
        let rebuild: BTreeSet<PathBuf> =
            prepared.shaders.iter().chain(unwatched).cloned().collect();
        if let Some((recorder, updater)) = new_recorder {
            self.frames.swap_scene(recorder, updater);
        }
        for raw in &rebuild {
            self.frames.reload_shader(raw).map_err(fail)?;
        }
        for (key, module) in prepared.modules {
            self.frames.adopt_shader(key, module);
        }
        if let (Some(plan), Some(resources)) = (prepared.plan, new_resources) {
            self.frames.swap_plan(plan, resources);
        }
        if let Some(scene) = prepared.scene {
            self.scene = scene;
        }
        if let Some(graph) = prepared.graph {
            self.graph = graph;
        }
        self.sources = prepared.sources;
        self.settings = prepared.settings;
        for file in &prepared.files {
            self.pending.remove(file);
        }
        self.version += 1;
        Ok(Committed::Applied(prepared.files))
    }

    /// Prepares and commits a job on this thread.
    fn prepare_and_commit(&mut self, job: &ReloadJob) -> Result<Vec<PathBuf>, ReloadError> {
        let prepared = job.prepare(self.gpu, &mut self.checker)?;
        match self.commit(prepared)? {
            Committed::Applied(files) => Ok(files),
            Committed::Stale => Err(ReloadError::new(
                &self.scene_path,
                None,
                "the live version changed while the reload was prepared",
            )),
        }
    }

    /// Switches to other settings (another graph, feature set or size) all-or-nothing:
    /// the new plan and its shaders are built and checked first, and on failure the
    /// live version keeps rendering unchanged. Shader files the live version did not
    /// use are compiled afresh from disk, since no watcher saw their edits.
    pub fn reconfigure(&mut self, settings: RenderSettings) -> Result<(), ReloadError> {
        let job = self.settings_job(settings);
        self.prepare_and_commit(&job).map(|_| ())
    }

    /// Applies edits to `changed` files (normalized paths; files this render does not
    /// use are ignored) on this thread: everything that changed since the last good
    /// version is prepared and checked first; only if all of it succeeds is it
    /// committed. Returns the files reloaded, or why the last good version was kept.
    pub fn apply(&mut self, changed: &BTreeSet<PathBuf>) -> Result<Vec<PathBuf>, ReloadError> {
        let job = self.files_job(changed);
        self.prepare_and_commit(&job)
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
    let mut files = graph_files(&weft_graph::load(&settings.graph));
    files.insert(normalize(&settings.graph));
    files.insert(normalize(&error.file));
    files.extend(scene_path_files(scene_path));
    let Ok(scene) = crate::scene_load::load_scene(
        scene_path,
        settings.cache_dir.as_deref(),
        settings.environment.as_deref(),
    ) else {
        return files;
    };
    files.extend(scene_files(&scene));
    if let Ok(keys) = load_graph(settings)
        .and_then(|graph| compile_for_scene(gpu, &scene, &graph, settings))
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
