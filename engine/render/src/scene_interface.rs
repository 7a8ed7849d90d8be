//! What the engine hands scene shaders — set 1 (scene buffers), set 2 (a
//! material's textures), the vertex layout — and the check that a pass's
//! shaders ask for exactly that. `weft graph check --shaders`, a hot reload and
//! pipeline creation all run it, so a shader that declares the materials at
//! binding 19 is refused with its pass's location instead of reading an
//! unbound descriptor on the GPU.

use crate::geometry::{VertexFormat, VERTEX_ATTRIBUTES};
use crate::pipelines::MATERIAL_SET;
use crate::providers::SHADOW_VIEW;
use crate::scene_gpu::{
    is_trace_texture, MATERIAL_SET_BINDINGS, SCENE_SET_BINDINGS, TRACE_SET_BINDINGS,
};
use crate::sources::scene_pass_variants;
use weft_gpu::bind::{
    check_outputs, link_problems, pack_push, resolve_bindings, shape_name, FrameValues,
};
use weft_gpu::check::{problem_messages, with_declaration};
use weft_gpu::pipeline::{PipelineCache, ShaderKey};
use weft_gpu::reflect::{DescriptorKind, PipelineInterface, ScalarKind, ShaderInterface};
use weft_gpu::{GpuError, ShaderProblem, SCENE_SET};
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::schema::{Draw, ParamValue};

/// Whether a scene pass reads only vertex positions (depth-only passes and
/// light volumes); mesh shading reads normals and UVs too.
pub fn position_only(pass: &PlanPass) -> bool {
    matches!(pass.draw, Some(Draw::LightVolumes(_))) || pass.shaders.fragment.is_none()
}

/// Problems with the scene sets (1, and 2 where `materials` allows it) that
/// a pass's merged interface declares: every binding must be one the engine
/// writes, with the descriptor type it writes (material textures as float 2D
/// `sampler2D`s). The ray tracer's bindings are fed only to passes that
/// declare `derive: [RayTracing()]` (`tracing`).
pub fn scene_set_problems(
    interface: &PipelineInterface,
    materials: bool,
    tracing: bool,
) -> Vec<String> {
    let mut problems = Vec::new();
    let scene: Vec<(u32, DescriptorKind, &str)> = SCENE_SET_BINDINGS
        .iter()
        .chain(TRACE_SET_BINDINGS.iter().filter(|_| tracing))
        .copied()
        .collect();
    for (shader, _) in interface.bindings.values() {
        if shader.set == SCENE_SET
            && !tracing
            && TRACE_SET_BINDINGS
                .iter()
                .any(|(b, _, _)| *b == shader.binding)
        {
            problems.push(format!(
                "shader binding `{}` (set {} binding {}) is ray-tracing scene data, which the engine feeds only to passes that declare `derive: [RayTracing()]`",
                shader.name, shader.set, shader.binding
            ));
            continue;
        }
        let table: &[(u32, DescriptorKind, &str)] = match shader.set {
            SCENE_SET => &scene,
            MATERIAL_SET if materials => &MATERIAL_SET_BINDINGS,
            _ => continue,
        };
        match table.iter().find(|(b, _, _)| *b == shader.binding) {
            Some((_, kind, what)) if *kind == shader.kind => {
                let arrayed = shader.set == SCENE_SET && is_trace_texture(shader.binding);
                let right_shape = shader.image.is_none_or(|i| {
                    i.scalar == Some(ScalarKind::Float)
                        && i.two_d
                        && i.arrayed == arrayed
                        && !i.multisampled
                });
                if !right_shape || shader.depth_compare {
                    let (glsl, shape) = if arrayed {
                        ("sampler2DArray", "an array of 2D colour textures")
                    } else {
                        ("sampler2D", "a 2D colour texture")
                    };
                    problems.push(format!(
                        "shader binding `{}` (set {} binding {}) must be a {glsl}: the engine binds {what} there, {shape}",
                        shader.name, shader.set, shader.binding
                    ));
                }
            }
            Some((_, kind, what)) => problems.push(format!(
                "shader binding `{}` (set {} binding {}) is a {:?}, but the engine binds {what} there as a {kind:?}",
                shader.name, shader.set, shader.binding, shader.kind
            )),
            None => problems.push(format!(
                "shader binding `{}` (set {} binding {}) is not scene data the engine binds; set {} has {}",
                shader.name,
                shader.set,
                shader.binding,
                shader.set,
                slot_list(table.iter().map(|(b, _, what)| (*b, *what)))
            )),
        }
    }
    problems
}

/// Numbered slots as `0: what, 1: what`, for messages listing what the
/// engine supplies.
fn slot_list<'a>(slots: impl Iterator<Item = (u32, &'a str)>) -> String {
    slots
        .map(|(n, what)| format!("{n}: {what}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// The shader input type a vertex attribute's format gives.
fn shader_shape(format: VertexFormat) -> (ScalarKind, u32) {
    match format {
        VertexFormat::Float3 => (ScalarKind::Float, 3),
        VertexFormat::Uint => (ScalarKind::Uint, 1),
        VertexFormat::Unorm16x2 => (ScalarKind::Float, 2),
    }
}

/// Vertex attributes the shader reads that the scene's vertex buffer does
/// not supply, or supplies with another type.
fn vertex_input_problems(vs: &ShaderInterface, position_only: bool) -> Vec<String> {
    let supplied = if position_only {
        &VERTEX_ATTRIBUTES[..1]
    } else {
        &VERTEX_ATTRIBUTES[..]
    };
    vs.inputs
        .iter()
        .filter_map(|input| {
            let found = supplied.iter().find(|a| a.location == input.location);
            match (found, input.shape) {
                (Some(a), Some((kind, m)))
                    if kind == shader_shape(a.format).0 && m <= shader_shape(a.format).1 =>
                {
                    None
                }
                (Some(a), _) => Some(format!(
                    "vertex input `{}` at location {} is {}, but the scene supplies the {} as {}",
                    input.name,
                    a.location,
                    shape_name(input.shape),
                    a.what,
                    shape_name(Some(shader_shape(a.format)))
                )),
                (None, _) => Some(format!(
                    "vertex input `{}` at location {} is not supplied; this pass's vertices have {}",
                    input.name,
                    input.location,
                    slot_list(supplied.iter().map(|a| (a.location, a.what)))
                )),
            }
        })
        .collect()
}

/// Every problem with a scene-drawing pass's shaders: graph bindings (set 0),
/// scene sets, vertex inputs, vertex outputs against fragment inputs,
/// fragment outputs against the attachments, push constants against params.
pub fn scene_pass_problems(
    plan: &Plan,
    pass: &PlanPass,
    vs: &ShaderInterface,
    fs: Option<&ShaderInterface>,
) -> Vec<String> {
    let mut stages = vec![vs];
    stages.extend(fs);
    let merged = match PipelineInterface::merge(&stages) {
        Ok(m) => m,
        Err(message) => return vec![message],
    };
    let mut graph_only = merged.clone();
    graph_only.bindings.retain(|(set, _), _| *set == 0);
    let mut problems = resolve_bindings(plan, pass, &graph_only)
        .err()
        .unwrap_or_default();
    problems.extend(
        merged
            .bindings
            .values()
            .filter(|(b, _)| b.set > MATERIAL_SET)
            .map(|(b, _)| {
                format!(
                    "shader binding `{}` is in set {}; scene shaders use sets 0 (graph), {SCENE_SET} (scene) and {MATERIAL_SET} (material)",
                    b.name, b.set
                )
            }),
    );
    problems.extend(scene_set_problems(&merged, true, false));
    problems.extend(vertex_input_problems(vs, position_only(pass)));
    if fs.is_some() {
        problems.extend(link_problems(&merged));
        problems.extend(check_outputs(plan, pass, &merged));
    }
    if let Some((block, _)) = &merged.push {
        let mut params = pass.params.clone();
        if crate::providers::supplied(pass, SHADOW_VIEW) {
            params.insert(SHADOW_VIEW.to_string(), ParamValue::Number(0.0));
        }
        if let Err(list) = pack_push(block, &params, &FrameValues::default()) {
            problems.extend(list);
        }
    }
    problems
}

/// Compiles, reflects and checks every shader a plan runs — the executor's
/// fullscreen and compute passes through `weft_gpu::check`, scene-drawing
/// passes here — and every pass's scene sets; each problem names its pass.
pub fn check_plan_shaders(cache: &mut PipelineCache, plan: &Plan) -> Vec<ShaderProblem> {
    let mut problems = weft_gpu::check::check_with(cache, plan);
    for pass in &plan.passes {
        let found = match weft_gpu::check::pass_shaders(pass) {
            Ok(Some(shaders)) => {
                let keys: Vec<ShaderKey> = shaders.keys().into_iter().cloned().collect();
                cache.interface(&shaders.keys()).map(|merged| {
                    scene_set_problems(&merged, false, crate::providers::traces(pass))
                        .into_iter()
                        .map(|m| with_declaration(cache, &keys, m))
                        .collect()
                })
            }
            Ok(None) => scene_pass_shaders(cache, plan, pass),
            Err(_) => continue, // reported by `check_with`
        };
        let messages = problem_messages(found);
        for message in messages {
            let problem = ShaderProblem {
                pass: pass.name.clone(),
                message,
            };
            if !problems.contains(&problem) {
                problems.push(problem);
            }
        }
    }
    problems
}

/// A scene-drawing pass's shaders compiled through `cache` and checked.
fn scene_pass_shaders(
    cache: &mut PipelineCache,
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
        let problems =
            scene_pass_problems(plan, pass, &vs.interface, fs.as_ref().map(|f| &f.interface));
        for m in problems {
            let located = with_declaration(cache, &keys, m);
            if !found.contains(&located) {
                found.push(located);
            }
        }
    }
    Ok(found)
}
