//! Every file a live render was built from, so hot reload knows what to watch
//! and what a change touches: the graph and its includes, each shader with its
//! `#include`s, and the scene with its includes, models and what they read.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use weft_gpu::pipeline::{PipelineCache, ShaderKey};
use weft_gpu::GpuError;
use weft_graph::plan::{Plan, PlanPass};
use weft_scene::Scene;

/// How deep scene `include`s are followed (the loader's own limit).
const MAX_SCENE_INCLUDE_DEPTH: usize = 32;

/// How deep shader `#include`s are followed by [`graph_source_files`].
const MAX_SHADER_INCLUDE_DEPTH: usize = 32;

/// The files behind a live render, as absolute paths (canonical where they exist),
/// grouped by what a change to them means.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Sources {
    /// The graph file and its includes: a change recompiles the plan.
    pub graph: BTreeSet<PathBuf>,
    /// Each shader file and `#include` the plan uses, mapped to the spellings the
    /// shader caches recorded it under: a change drops what was built from it.
    pub shaders: BTreeMap<PathBuf, BTreeSet<PathBuf>>,
    /// The scene file, its includes, models, material libraries and textures: a
    /// change reloads and re-uploads the scene.
    pub scene: BTreeSet<PathBuf>,
}

impl Sources {
    /// Every file, for the watcher.
    pub fn all(&self) -> BTreeSet<PathBuf> {
        self.graph
            .iter()
            .chain(self.shaders.keys())
            .chain(&self.scene)
            .cloned()
            .collect()
    }
}

/// `path` made absolute and canonical, or just absolute when it does not exist
/// (a file being replaced by rename); events name files this way.
pub fn normalize(path: &Path) -> PathBuf {
    path.canonicalize()
        .or_else(|_| std::path::absolute(path))
        .unwrap_or_else(|_| path.to_path_buf())
}

/// The shader variants the plan's passes run: fullscreen and compute passes as
/// the executor builds them, scene passes as the scene recorder does.
pub fn plan_shader_keys(plan: &Plan) -> Result<Vec<ShaderKey>, GpuError> {
    let mut keys = Vec::new();
    for pass in &plan.passes {
        if let Some(shaders) = weft_gpu::executor::shader_check::pass_shaders(pass)? {
            keys.extend(shaders.keys().into_iter().cloned());
            continue;
        }
        keys.extend(scene_pass_keys(pass));
    }
    Ok(keys)
}

/// Every shader variant a scene-drawing pass runs
/// ([`weft_gpu::check::scene_pass_variants`]).
pub fn scene_pass_keys(pass: &PlanPass) -> Vec<ShaderKey> {
    weft_gpu::check::scene_pass_variants(pass)
        .into_iter()
        .flatten()
        .collect()
}

/// Every file the plan's shaders depend on, by normalized path, compiled through
/// `cache` (already cached variants cost nothing).
pub fn shader_files(
    cache: &mut PipelineCache,
    plan: &Plan,
) -> Result<BTreeMap<PathBuf, BTreeSet<PathBuf>>, GpuError> {
    let mut files: BTreeMap<PathBuf, BTreeSet<PathBuf>> = BTreeMap::new();
    for key in plan_shader_keys(plan)? {
        let module = cache.shader(&key)?;
        for dep in &module.compiled.dependencies {
            if dep.is_file() {
                files.entry(normalize(dep)).or_default().insert(dep.clone());
            }
        }
    }
    Ok(files)
}

/// Every file a graph is built from, found without compiling it: its graph
/// files, every pass's shaders whatever the features, and the files they
/// `#include`, read from their `#include "FILE"` lines (relative to the
/// including file, as the compiler resolves them). For what must notice an
/// edit to any of them (a resumed sweep).
pub fn graph_source_files(graph: &weft_graph::Prepared) -> BTreeSet<PathBuf> {
    let mut files: BTreeSet<PathBuf> = graph.graph().files().iter().map(|f| normalize(f)).collect();
    for pass in graph.ir().passes.iter() {
        let stages = [
            &pass.shaders.vertex,
            &pass.shaders.fragment,
            &pass.shaders.compute,
        ];
        for shader in stages.into_iter().flatten() {
            shader_includes(shader, 0, &mut files);
        }
    }
    files
}

/// Adds the shader `path` and, recursively, the files its `#include` lines name.
fn shader_includes(path: &Path, depth: usize, files: &mut BTreeSet<PathBuf>) {
    if !files.insert(normalize(path)) || depth >= MAX_SHADER_INCLUDE_DEPTH {
        return;
    }
    let Ok(text) = std::fs::read_to_string(path) else {
        return;
    };
    let base = path.parent().unwrap_or(Path::new(""));
    for line in text.lines() {
        let included = line
            .trim()
            .strip_prefix("#include")
            .map(str::trim)
            .and_then(|rest| rest.strip_prefix('"'))
            .and_then(|rest| rest.split_once('"'))
            .map(|(name, _)| name);
        if let Some(name) = included {
            shader_includes(&base.join(name), depth + 1, files);
        }
    }
}

/// The files a loaded scene was read from. The scene loader does not record its
/// `include`s, so they are found again by reading each `include "FILE"` line;
/// models list what they read themselves (`Model::sources`).
pub fn scene_files(scene: &Scene) -> BTreeSet<PathBuf> {
    let mut files = BTreeSet::new();
    scene_includes(&scene.path, 0, &mut files);
    if let Some(script) = &scene.script {
        files.insert(normalize(&script.path));
        files.extend(script.imports.iter().map(|p| normalize(p)));
    }
    for model in &scene.models {
        files.insert(normalize(&model.path));
        files.extend(model.sources.iter().map(|p| normalize(p)));
    }
    if let Some(environment) = &scene.environment {
        files.insert(normalize(&environment.file));
    }
    files
}

/// The scene file and the files its `include` lines name, recursively, for a scene
/// that may not load.
pub fn scene_path_files(path: &Path) -> BTreeSet<PathBuf> {
    let mut files = BTreeSet::new();
    scene_includes(path, 0, &mut files);
    files
}

/// Adds `path` and, recursively, the files its `include` lines name, and
/// the script a `script` line names. A `.rhai` scene is a file of its own.
fn scene_includes(path: &Path, depth: usize, files: &mut BTreeSet<PathBuf>) {
    if path.extension().is_some_and(|e| e == "rhai") {
        files.insert(normalize(path));
        return;
    }
    if !files.insert(normalize(path)) || depth >= MAX_SCENE_INCLUDE_DEPTH {
        return;
    }
    let asked_at = weft_scene::Location::file(path);
    let Ok(text) =
        weft_scene::source::read_text(path, &asked_at, weft_scene::source::MAX_SCENE_BYTES)
    else {
        return;
    };
    let base = path.parent().unwrap_or(Path::new(""));
    for line in text.lines() {
        let line = line.trim();
        let Some(rest) = line
            .strip_prefix("include")
            .or_else(|| line.strip_prefix("script"))
        else {
            continue;
        };
        let name = rest.trim();
        if let Some(name) = name.strip_prefix('"').and_then(|n| n.strip_suffix('"')) {
            scene_includes(&base.join(name.replace('\\', "/")), depth + 1, files);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A shipped graph's files: the graph and the fragments it includes,
    /// their passes' shaders, and those shaders' includes two levels down
    /// (gi.comp includes pathtrace/next_event.glsl; include/trace.glsl
    /// includes bindings.glsl), whatever the features (gi is off by default).
    #[test]
    fn a_graph_is_built_from_its_files_shaders_and_their_includes() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
        let graph =
            weft_graph::Prepared::load(&root.join("graphs/deferred.ron"), Default::default())
                .expect("graphs/deferred.ron loads");
        let files = graph_source_files(&graph);
        for expected in [
            "graphs/deferred.ron",
            "graphs/gi.ron",
            "graphs/scene_shading.ron",
            "shaders/gi.comp",
            "shaders/pathtrace/next_event.glsl",
            "shaders/include/trace.glsl",
            "shaders/include/bindings.glsl",
        ] {
            assert!(
                files.contains(&normalize(&root.join(expected))),
                "{expected} in {files:#?}"
            );
        }
        assert!(files.iter().all(|f| f.is_file()), "{files:#?}");
    }

    #[test]
    fn follows_scene_includes() {
        let dir = std::env::temp_dir().join(format!("weft-sources-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).expect("temp dir");
        std::fs::write(
            dir.join("a.scene"),
            "# include \"ignored.scene\"\ninclude \"sub/b.scene\"\n",
        )
        .expect("write a");
        std::fs::write(dir.join("sub/b.scene"), "include \"../a.scene\"\n").expect("write b");
        let mut files = BTreeSet::new();
        scene_includes(&dir.join("a.scene"), 0, &mut files);
        let expected: BTreeSet<PathBuf> = [dir.join("a.scene"), dir.join("sub/b.scene")]
            .iter()
            .map(|p| normalize(p))
            .collect();
        assert_eq!(files, expected);
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
