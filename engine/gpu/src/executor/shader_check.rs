//! The one shader check, as `weft graph check --shaders`, a hot reload and
//! the executor before it builds a pipeline run it, with no device: each
//! pass's shaders, chosen by its kind ([`pass_shaders`], through the
//! executor's table of pass kinds), compiled, reflected and compared with
//! the graph and, where given, the scene interface.

use super::kinds;
use crate::check::{
    pass_problems, problem_messages, scene_pass_variants, with_declaration, PassShaders,
    ShaderProblem,
};
use crate::error::GpuError;
use crate::pipeline::{PipelineCache, ShaderKey};
use crate::scene::SceneInterface;
use crate::scene_check::{scene_pass_problems, scene_set_problems};
use weft_graph::plan::{Plan, PlanPass};

/// The shaders the executor builds `pass`'s pipeline from, as its kind
/// says; `None` for copies, blits, builds and scene draws (whose shaders a
/// draw recorder chooses: [`crate::check::scene_pass_variants`]).
pub fn pass_shaders(pass: &PlanPass) -> Result<Option<PassShaders>, GpuError> {
    kinds::of(pass).shaders(pass)
}

/// Compiles and reflects every pass's shaders and checks them against the
/// graph (and, with `scene`, against the scene data a renderer supplies), with
/// no Vulkan device; every problem is returned.
pub fn check_shaders(
    plan: &Plan,
    scene: Option<&SceneInterface>,
) -> Result<Vec<ShaderProblem>, GpuError> {
    let mut cache = PipelineCache::new()?;
    Ok(check_with(&mut cache, plan, scene))
}

/// `check_shaders` with a given cache (the executor's): the one shader check.
/// Fullscreen and compute passes are checked against the graph and, where
/// they read scene data, the scene sets; scene-drawing passes (with `scene`)
/// in every variant they run. Each problem names its pass, once.
pub fn check_with(
    cache: &mut PipelineCache,
    plan: &Plan,
    scene: Option<&SceneInterface>,
) -> Vec<ShaderProblem> {
    let mut problems = Vec::new();
    for pass in &plan.passes {
        for problem in check_pass(cache, plan, pass, scene) {
            if !problems.contains(&problem) {
                problems.push(problem);
            }
        }
    }
    problems
}

/// [`check_with`] for one pass of `plan`.
pub fn check_pass(
    cache: &mut PipelineCache,
    plan: &Plan,
    pass: &PlanPass,
    scene: Option<&SceneInterface>,
) -> Vec<ShaderProblem> {
    let found = match pass_shaders(pass) {
        Ok(Some(shaders)) => own_pass_problems(cache, plan, pass, &shaders, scene),
        Ok(None) => match scene {
            Some(scene) => scene_pass_shader_problems(cache, scene, plan, pass),
            None => Ok(Vec::new()),
        },
        Err(e) => Err(e),
    };
    problem_messages(found)
        .into_iter()
        .map(|message| ShaderProblem {
            pass: pass.name.clone(),
            message,
        })
        .collect()
}

/// A fullscreen or compute pass's problems, located in its shaders.
fn own_pass_problems(
    cache: &mut PipelineCache,
    plan: &Plan,
    pass: &PlanPass,
    shaders: &PassShaders,
    scene: Option<&SceneInterface>,
) -> Result<Vec<String>, GpuError> {
    let interface = cache.interface(&shaders.keys())?;
    let keys: Vec<ShaderKey> = shaders.keys().into_iter().cloned().collect();
    let mut found = pass_problems(plan, pass, shaders, &interface)
        .err()
        .unwrap_or_default();
    if let Some(scene) = scene {
        found.extend(scene_set_problems(scene, &interface, false, pass));
    }
    Ok(found
        .into_iter()
        .map(|m| with_declaration(cache, &keys, m))
        .collect())
}

/// A scene-drawing pass's shaders, in every variant it runs, compiled through
/// `cache` and checked against the scene interface.
fn scene_pass_shader_problems(
    cache: &mut PipelineCache,
    scene: &SceneInterface,
    plan: &Plan,
    pass: &PlanPass,
) -> Result<Vec<String>, GpuError> {
    if pass.draw.is_none() {
        return Ok(Vec::new());
    }
    if pass.shaders.vertex.is_none() {
        return Ok(vec!["needs a vertex shader".into()]);
    }
    let mut found = Vec::new();
    for keys in scene_pass_variants(pass) {
        let vs = cache.shader(&keys[0])?;
        let fs = keys.get(1).map(|k| cache.shader(k)).transpose()?;
        let problems = scene_pass_problems(
            scene,
            plan,
            pass,
            &vs.interface,
            fs.as_ref().map(|f| &f.interface),
        );
        for m in problems {
            let located = with_declaration(cache, &keys, m);
            if !found.contains(&located) {
                found.push(located);
            }
        }
    }
    Ok(found)
}
