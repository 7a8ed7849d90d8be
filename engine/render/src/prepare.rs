//! The half of a hot reload that needs no frame boundary: reading, parsing and
//! validating the scene and graph, compiling the plan, and compiling, reflecting
//! and checking every shader it runs. It touches nothing live and owns what it
//! reads, so it can run on a worker thread while frames keep coming; the device
//! work is left to [`crate::LiveRender::commit`].

use crate::frame::{compile_for_scene, load_graph, RenderSettings};
use crate::reload_error::ReloadError;
use crate::sources::{normalize, plan_shader_keys, scene_files, shader_files, Sources};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use weft_gpu::pipeline::{PipelineCache, ShaderKey, ShaderModule};
use weft_gpu::{Gpu, GpuError};
use weft_graph::plan::Plan;
use weft_graph::Prepared;
use weft_scene::{Camera, Scene};

/// The live version a reload starts from, owned (scene and plan shared) so a
/// worker thread can take it while the live version keeps rendering.
#[derive(Debug, Clone)]
pub struct ReloadBase {
    /// Which commit of the live render this is; a prepared reload applies only
    /// to the version it was prepared from.
    pub(crate) version: u64,
    pub(crate) scene_path: PathBuf,
    pub(crate) settings: RenderSettings,
    /// The live graph, loaded from `settings.graph`.
    pub(crate) graph: Arc<Prepared>,
    pub(crate) scene: Arc<Scene>,
    pub(crate) plan: Arc<Plan>,
    pub(crate) sources: Sources,
}

/// What a reload changes.
#[derive(Debug, Clone)]
pub enum ReloadChange {
    /// Files edited since the last good version (normalized, all watched).
    Files(BTreeSet<PathBuf>),
    /// Other settings (graph, features, size) for the same scene.
    Settings(Box<RenderSettings>),
}

/// One reload to prepare: where it starts and what changes.
#[derive(Debug, Clone)]
pub struct ReloadJob {
    /// The live version it starts from.
    pub base: ReloadBase,
    /// What changes.
    pub change: ReloadChange,
}

/// A new version, loaded and checked, waiting for a frame boundary.
#[derive(Debug)]
pub struct PreparedReload {
    pub(crate) version: u64,
    pub(crate) settings: RenderSettings,
    /// The graph loaded again, when its files or the settings naming it changed.
    pub(crate) graph: Option<Arc<Prepared>>,
    /// The reloaded scene, when it changed.
    pub(crate) scene: Option<Arc<Scene>>,
    /// The recompiled plan, when the scene, graph or settings changed.
    pub(crate) plan: Option<Arc<Plan>>,
    pub(crate) sources: Sources,
    /// Shader files (as the caches spell them) whose pipelines must be rebuilt.
    pub(crate) shaders: BTreeSet<PathBuf>,
    /// The edited files this reload applies.
    pub(crate) files: Vec<PathBuf>,
    /// Every shader variant the new version runs, compiled and checked, for
    /// the live caches to adopt instead of compiling them again.
    pub(crate) modules: Vec<(ShaderKey, Arc<ShaderModule>)>,
}

impl PreparedReload {
    /// The edited files this reload applies.
    pub fn files(&self) -> &[PathBuf] {
        &self.files
    }
}

/// Shaders compiled from disk to check a candidate; it builds no pipelines.
/// Modules of files that stopped being watched may be stale (no watcher saw
/// their edits), so it starts afresh whenever the watched shader files change.
pub struct ShaderChecker {
    cache: PipelineCache,
    watched: BTreeMap<PathBuf, BTreeSet<PathBuf>>,
}

impl ShaderChecker {
    /// An empty checker with its own shader compiler.
    pub fn new() -> Result<Self, GpuError> {
        Ok(Self {
            cache: PipelineCache::new()?,
            watched: BTreeMap::new(),
        })
    }

    /// Starts afresh unless it was last in step with exactly `sources`' shaders.
    fn sync(&mut self, sources: &Sources) -> Result<(), GpuError> {
        if self.watched != sources.shaders {
            self.cache = PipelineCache::new()?;
            self.watched = sources.shaders.clone();
        }
        Ok(())
    }
}

/// The camera the settings name, or the scene's first.
pub(crate) fn pick_camera<'s>(
    scene: &'s Scene,
    settings: &RenderSettings,
) -> Result<&'s Camera, crate::RenderError> {
    match &settings.camera {
        Some(name) => scene
            .camera(name)
            .ok_or_else(|| crate::RenderError::Camera {
                name: name.clone(),
                available: scene
                    .cameras
                    .iter()
                    .map(|c| c.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            }),
        None => scene
            .cameras
            .first()
            .ok_or_else(|| crate::RenderError::Camera {
                name: "(first)".into(),
                available: "none".into(),
            }),
    }
}

/// Compiles and checks every shader the plan runs (and its agreement with the
/// graph) through `checker`, without building pipelines.
pub(crate) fn check_shaders(
    gpu: &Gpu,
    checker: &mut PipelineCache,
    plan: &Plan,
    graph: &Path,
) -> Result<(), ReloadError> {
    let keys = plan_shader_keys(plan).map_err(|e| ReloadError::gpu(e, graph))?;
    let device = gpu.info();
    for key in &keys {
        let module = checker
            .shader(key)
            .map_err(|e| ReloadError::gpu(e, &key.path))?;
        if let Some(refusal) = device.shaders.refusal(&device.name, &module.compiled) {
            return Err(ReloadError::new(
                &crate::sources::normalize(&key.path),
                None,
                &refusal,
            ));
        }
    }
    let scene = crate::bindings::scene_interface();
    let problems = weft_gpu::executor::shader_check::check_with(checker, plan, Some(&scene));
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

/// The checked modules of every shader variant `plan` runs (cached by
/// `check_shaders`, so nothing is compiled again).
fn plan_modules(
    cache: &mut PipelineCache,
    plan: &Plan,
    graph: &Path,
) -> Result<Vec<(ShaderKey, Arc<ShaderModule>)>, ReloadError> {
    let keys = plan_shader_keys(plan).map_err(|e| ReloadError::gpu(e, graph))?;
    keys.into_iter()
        .map(|key| {
            let module = cache
                .shader(&key)
                .map_err(|e| ReloadError::gpu(e, &key.path))?;
            Ok((key, module))
        })
        .collect()
}

/// A loaded graph's file and its includes, normalized.
pub(crate) fn graph_files(graph: &weft_graph::LoadedGraph) -> BTreeSet<PathBuf> {
    graph.files().iter().map(|p| normalize(p)).collect()
}

impl ReloadJob {
    /// Loads and checks everything the new version needs; `gpu` is only asked
    /// for image memory requirements (no queue, no command buffer, no object is
    /// created), so this may run on any thread.
    pub fn prepare(
        &self,
        gpu: &Gpu,
        checker: &mut ShaderChecker,
    ) -> Result<PreparedReload, ReloadError> {
        match &self.change {
            ReloadChange::Files(changed) => prepare_files(gpu, checker, &self.base, changed),
            ReloadChange::Settings(settings) => prepare_settings(gpu, &self.base, settings),
        }
    }
}

fn prepare_files(
    gpu: &Gpu,
    checker: &mut ShaderChecker,
    base: &ReloadBase,
    changed: &BTreeSet<PathBuf>,
) -> Result<PreparedReload, ReloadError> {
    let graph = &base.settings.graph;
    checker
        .sync(&base.sources)
        .map_err(|e| ReloadError::gpu(e, graph))?;
    let scene_changed = changed.iter().any(|p| base.sources.scene.contains(p));
    let graph_changed = changed.iter().any(|p| base.sources.graph.contains(p));
    let shaders: BTreeSet<PathBuf> = changed
        .iter()
        .filter_map(|p| base.sources.shaders.get(p))
        .flatten()
        .cloned()
        .collect();
    for raw in &shaders {
        checker.cache.invalidate(gpu.device(), raw);
    }
    let new_scene = if scene_changed {
        let loaded = crate::scene_load::load_scene(
            &base.scene_path,
            base.settings.cache_dir.as_deref(),
            base.settings.environment.as_deref(),
        )
        .map_err(|e| ReloadError::scene(&e))?;
        Some(Arc::new(loaded))
    } else {
        None
    };
    let scene = new_scene.as_deref().unwrap_or(&base.scene);
    pick_camera(scene, &base.settings).map_err(|e| ReloadError::render(e, &base.scene_path))?;
    let new_graph = if graph_changed {
        let loaded = load_graph(&base.settings).map_err(|e| ReloadError::render(e, graph))?;
        Some(Arc::new(loaded))
    } else {
        None
    };
    let new_plan = if scene_changed || graph_changed {
        let value = new_graph.as_deref().unwrap_or(&base.graph);
        let plan = compile_for_scene(gpu, scene, value, &base.settings)
            .map_err(|e| ReloadError::render(e, graph))?;
        Some(Arc::new(plan))
    } else {
        None
    };
    let plan = new_plan.as_deref().unwrap_or(&base.plan);
    check_shaders(gpu, &mut checker.cache, plan, graph)?;
    let sources = Sources {
        graph: if graph_changed {
            graph_files(new_graph.as_deref().unwrap_or(&base.graph).graph())
        } else {
            base.sources.graph.clone()
        },
        shaders: shader_files(&mut checker.cache, plan).map_err(|e| ReloadError::gpu(e, graph))?,
        scene: match &new_scene {
            Some(s) => scene_files(s),
            None => base.sources.scene.clone(),
        },
    };
    checker.watched = sources.shaders.clone();
    let modules = plan_modules(&mut checker.cache, plan, graph)?;
    Ok(PreparedReload {
        version: base.version,
        settings: base.settings.clone(),
        graph: new_graph,
        scene: new_scene,
        plan: new_plan,
        sources,
        shaders,
        files: changed.iter().cloned().collect(),
        modules,
    })
}

/// Other settings are checked with shaders compiled afresh from disk: files the
/// live version did not use were not watched, so no cache of them is trusted.
fn prepare_settings(
    gpu: &Gpu,
    base: &ReloadBase,
    settings: &RenderSettings,
) -> Result<PreparedReload, ReloadError> {
    let graph = &settings.graph;
    // Another environment map (the viewer's picker) is a scene loaded again.
    let new_scene = if settings.environment != base.settings.environment {
        let loaded = crate::scene_load::load_scene(
            &base.scene_path,
            settings.cache_dir.as_deref(),
            settings.environment.as_deref(),
        )
        .map_err(|e| ReloadError::scene(&e))?;
        Some(Arc::new(loaded))
    } else {
        None
    };
    let scene = new_scene.as_deref().unwrap_or(&base.scene);
    pick_camera(scene, settings).map_err(|e| ReloadError::render(e, &base.scene_path))?;
    // The same graph file with the same parameters is the live graph value
    // (its edits arrive as file changes); another is loaded.
    let same_graph =
        settings.graph == base.settings.graph && settings.params == base.settings.params;
    let new_graph = if same_graph {
        None
    } else {
        let loaded = load_graph(settings).map_err(|e| ReloadError::render(e, graph))?;
        Some(Arc::new(loaded))
    };
    let value = new_graph.as_deref().unwrap_or(&base.graph);
    let plan = compile_for_scene(gpu, scene, value, settings)
        .map_err(|e| ReloadError::render(e, graph))?;
    let fail = |e: GpuError| ReloadError::gpu(e, graph);
    let mut cache = PipelineCache::new().map_err(fail)?;
    check_shaders(gpu, &mut cache, &plan, graph)?;
    let sources = Sources {
        graph: graph_files(value.graph()),
        shaders: shader_files(&mut cache, &plan).map_err(fail)?,
        scene: new_scene
            .as_deref()
            .map_or_else(|| base.sources.scene.clone(), scene_files),
    };
    let modules = plan_modules(&mut cache, &plan, graph)?;
    Ok(PreparedReload {
        version: base.version,
        settings: settings.clone(),
        graph: new_graph,
        scene: new_scene,
        plan: Some(Arc::new(plan)),
        sources,
        shaders: BTreeSet::new(),
        files: Vec::new(),
        modules,
    })
}
