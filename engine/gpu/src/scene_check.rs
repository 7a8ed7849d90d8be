//! The check that a pass's shaders ask for exactly the scene data the
//! registered [`SceneInterface`] supplies: `weft graph check --shaders`, a hot
//! reload and pipeline creation all run it, so a shader that declares the
//! materials at binding 19 is refused with its pass's location instead of
//! reading an unbound descriptor on the GPU.

use crate::bind::FrameValues;
use crate::bind::{check_outputs, link_problems, pack_push, resolve_bindings, shape_name};
use crate::reflect::{DescriptorKind, PipelineInterface, ScalarKind, ShaderInterface};
use crate::scene::{SceneBinding, SceneInterface, VertexFormat};
use crate::sets::{MATERIAL_SET, SCENE_SET};
use weft_graph::plan::{Plan, PlanPass};
use weft_graph::schema::ParamValue;

/// Problems with the scene sets (1, and 2 where `materials` allows it) that
/// a pass's merged interface declares: every binding must be one the engine
/// writes, with the descriptor type it writes (material textures as float 2D
/// `sampler2D`s). The tracing-only bindings are fed only to passes that
/// trace rays (the scene's `traces`), and the acceleration structure only to
/// those that read one the plan builds (`structure`), so the build is
/// ordered before their ray queries.
pub fn scene_set_problems(
    scene: &SceneInterface,
    interface: &PipelineInterface,
    materials: bool,
    pass: &PlanPass,
) -> Vec<String> {
    let tracing = (scene.traces)(pass);
    let mut problems = Vec::new();
    for (shader, _) in interface.bindings.values() {
        let table: Vec<&SceneBinding> = match shader.set {
            SCENE_SET => scene
                .scene_set
                .iter()
                .filter(|b| tracing || !b.tracing)
                .collect(),
            MATERIAL_SET if materials => scene.material_set.iter().collect(),
            _ => continue,
        };
        let tracing_only = scene
            .scene_binding(shader.binding)
            .is_some_and(|b| b.tracing);
        if shader.set == SCENE_SET && !tracing && tracing_only {
            problems.push(format!(
                "shader binding `{}` (set {} binding {}) is ray-tracing scene data, which the engine feeds only to passes that declare `derive: [RayTracing()]`",
                shader.name, shader.set, shader.binding
            ));
            continue;
        }
        if shader.set == SCENE_SET
            && shader.kind == DescriptorKind::AccelerationStructure
            && pass.structure.is_none()
        {
            problems.push(format!(
                "shader binding `{}` (set {} binding {}) is the scene's acceleration structure, \
                 which a pass traces against only when it reads one the plan builds: add \
                 `(name: \"scene_structures\", enabled_if: [\"ray_queries\"])` to its \
                 `storage_read` and include graphs/acceleration.ron",
                shader.name, shader.set, shader.binding
            ));
            continue;
        }
        match table.iter().find(|b| b.binding == shader.binding) {
            Some(b) if b.kind == shader.kind => {
                let right_shape = shader.image.is_none_or(|i| {
                    i.scalar == Some(ScalarKind::Float)
                        && i.two_d
                        && i.arrayed == b.arrayed
                        && !i.multisampled
                });
                if !right_shape || shader.depth_compare {
                    let (glsl, shape) = if b.arrayed {
                        ("sampler2DArray", "an array of 2D colour textures")
                    } else {
                        ("sampler2D", "a 2D colour texture")
                    };
                    problems.push(format!(
                        "shader binding `{}` (set {} binding {}) must be a {glsl}: the engine binds {} there, {shape}",
                        shader.name, shader.set, shader.binding, b.what
                    ));
                }
            }
            Some(b) => problems.push(format!(
                "shader binding `{}` (set {} binding {}) is a {:?}, but the engine binds {} there as a {:?}",
                shader.name, shader.set, shader.binding, shader.kind, b.what, b.kind
            )),
            None => problems.push(format!(
                "shader binding `{}` (set {} binding {}) is not scene data the engine binds; set {} has {}",
                shader.name,
                shader.set,
                shader.binding,
                shader.set,
                slot_list(table.iter().map(|b| (b.binding, b.what)))
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
fn vertex_input_problems(
    scene: &SceneInterface,
    pass: &PlanPass,
    vs: &ShaderInterface,
) -> Vec<String> {
    let supplied = scene.attributes_for(pass);
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
/// fragment outputs against the attachments, push constants against params
/// (with the ones the recorder sets per draw).
pub fn scene_pass_problems(
    scene: &SceneInterface,
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
    problems.extend(scene_set_problems(scene, &merged, true, pass));
    problems.extend(vertex_input_problems(scene, pass, vs));
    if fs.is_some() {
        problems.extend(link_problems(&merged));
        problems.extend(check_outputs(plan, pass, &merged));
    }
    if let Some((block, _)) = &merged.push {
        if let Err(list) = pack_push(block, &with_per_draw(scene, pass), &FrameValues::default()) {
            problems.extend(list);
        }
    }
    problems
}

/// The pass's parameters with those the recorder sets per draw, at 0.
pub fn with_per_draw(
    scene: &SceneInterface,
    pass: &PlanPass,
) -> std::collections::BTreeMap<String, ParamValue> {
    let mut params = pass.params.clone();
    for name in (scene.per_draw_params)(pass) {
        params.insert(name.to_string(), ParamValue::Number(0.0));
    }
    params
}
