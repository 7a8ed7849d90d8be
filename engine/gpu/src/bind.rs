//! Cross-checks a pass's shaders against the graph: which graph resource
//! feeds each shader binding, whether the kinds agree, whether fragment
//! outputs match the colour attachments; and packs graph parameters into the
//! push-constant block by member name.

use crate::reflect::{
    DescriptorKind, ImageShape, PipelineInterface, PushBlock, ScalarKind, ShaderBinding,
};
use std::collections::BTreeMap;
use weft_graph::plan::{Binding, BindingKind, ImageDesc, Plan, PlanPass, ResourceDesc};
use weft_graph::schema::ParamValue;
use weft_graph::vk::Aspect;

/// A shader binding and the graph binding that feeds it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResolvedBinding {
    /// The shader side: set, binding, descriptor kind.
    pub shader: ShaderBinding,
    /// The graph side: which resource, read how.
    pub graph: Binding,
}

/// Matches shader bindings to the pass's graph bindings. A shader variable
/// named like a resource the pass binds gets that resource; any other binding
/// number N gets the pass's N-th binding (so one shader can serve passes that
/// read different resources). Set 1 (scene data) is left to the draw recorder.
/// Every problem is returned, not just the first.
pub fn resolve_bindings(
    plan: &Plan,
    pass: &PlanPass,
    interface: &PipelineInterface,
) -> Result<Vec<ResolvedBinding>, Vec<String>> {
    let mut problems = Vec::new();
    let mut resolved = Vec::new();
    let mut used = vec![false; pass.bindings.len()];
    let name_of = |b: &Binding| {
        plan.resources
            .get(b.resource)
            .map(|r| r.name.as_str())
            .unwrap_or("?")
    };
    for (shader, _) in interface.bindings.values() {
        if shader.set == crate::sets::SCENE_SET {
            continue;
        }
        if shader.set != 0 {
            problems.push(format!(
                "shader binding `{}` is in set {}; graph resources are bound in set 0 (scene data in set 1)",
                shader.name, shader.set
            ));
            continue;
        }
        let by_name = pass.bindings.iter().position(|b| name_of(b) == shader.name);
        let Some(index) = by_name.or_else(|| {
            let n = shader.binding as usize;
            (n < pass.bindings.len()).then_some(n)
        }) else {
            problems.push(format!(
                "shader binding {} `{}` is fed by no graph resource (the pass binds {})",
                shader.binding,
                shader.name,
                describe(plan, &pass.bindings)
            ));
            continue;
        };
        let graph = pass.bindings[index];
        let Some(resource) = plan.resources.get(graph.resource) else {
            problems.push(format!(
                "binding refers to missing resource {}",
                graph.resource
            ));
            continue;
        };
        let is_image = matches!(resource.desc, ResourceDesc::Image(_));
        let expected = match (graph.kind, is_image) {
            (BindingKind::Sampled, true) => DescriptorKind::CombinedImageSampler,
            (BindingKind::Sampled, false) => DescriptorKind::UniformBuffer,
            (_, true) => DescriptorKind::StorageImage,
            (_, false) => DescriptorKind::StorageBuffer,
        };
        if shader.kind != expected {
            problems.push(format!(
                "shader binding {} `{}` is a {:?} but graph resource `{}` is bound as {:?} ({:?})",
                shader.binding, shader.name, shader.kind, resource.name, graph.kind, expected
            ));
            continue;
        }
        if let (ResourceDesc::Image(desc), Some(shape)) = (&resource.desc, &shader.image) {
            if let Some(problem) = image_mismatch(shader, shape, desc) {
                problems.push(format!(
                    "shader binding {} `{}` {problem}, but graph image `{}` is {} with {} layer(s) and {} sample(s)",
                    shader.binding, shader.name, resource.name, desc.format, desc.layers, desc.samples
                ));
                continue;
            }
        }
        used[index] = true;
        resolved.push(ResolvedBinding {
            shader: shader.clone(),
            graph,
        });
    }
    for (b, _) in pass.bindings.iter().zip(&used).filter(|(_, u)| !**u) {
        problems.push(format!(
            "graph resource `{}` is bound to nothing in the pass's shaders",
            name_of(b)
        ));
    }
    if problems.is_empty() {
        Ok(resolved)
    } else {
        Err(problems)
    }
}

/// How a shader's image binding disagrees with the image bound to it, if it does.
fn image_mismatch(shader: &ShaderBinding, shape: &ImageShape, desc: &ImageDesc) -> Option<String> {
    let depth = desc.aspect != Aspect::Color;
    let reads = if depth {
        ScalarKind::Float
    } else {
        attachment_scalar(&desc.format)
    };
    if !shape.two_d {
        return Some("is not a 2D image".into());
    }
    if shape.arrayed != (desc.layers > 1) {
        return Some(format!(
            "is {}an array image",
            if shape.arrayed { "" } else { "not " }
        ));
    }
    if shape.multisampled != (desc.samples > 1) {
        return Some(format!(
            "is {}multisampled",
            if shape.multisampled { "" } else { "not " }
        ));
    }
    if shader.depth_compare && !depth {
        return Some("is a depth-comparison sampler (sampler2DShadow)".into());
    }
    match shape.scalar {
        Some(scalar) if scalar != reads => Some(format!(
            "reads {scalar:?} values (the format gives {reads:?})"
        )),
        _ => None,
    }
}

fn describe(plan: &Plan, bindings: &[Binding]) -> String {
    if bindings.is_empty() {
        return "nothing".into();
    }
    bindings
        .iter()
        .map(|b| {
            format!(
                "`{}`",
                plan.resources
                    .get(b.resource)
                    .map(|r| r.name.as_str())
                    .unwrap_or("?")
            )
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// Fragment inputs the vertex stage does not write at the same location with
/// the same type (`InputNotProduced` and friends at pipeline creation).
pub fn link_problems(interface: &PipelineInterface) -> Vec<String> {
    interface
        .fragment_inputs
        .iter()
        .filter_map(|input| {
            match interface.varyings.iter().find(|v| v.location == input.location) {
                None => Some(format!(
                    "fragment input `{}` at location {} is not written by the vertex shader",
                    input.name, input.location
                )),
                Some(out) if out.shape != input.shape => Some(format!(
                    "fragment input `{}` at location {} is {}, but the vertex shader writes `{}` there as {}",
                    input.name,
                    input.location,
                    shape_name(input.shape),
                    out.name,
                    shape_name(out.shape)
                )),
                Some(_) => None,
            }
        })
        .collect()
}

/// A stage variable's type in words, for messages.
pub fn shape_name(shape: Option<(ScalarKind, u32)>) -> String {
    match shape {
        Some((scalar, 1)) => format!("{scalar:?}").to_lowercase(),
        Some((scalar, n)) => format!("a {n}-component {scalar:?} vector").to_lowercase(),
        None => "not a scalar or vector".into(),
    }
}

/// Checks that a fragment shader writes exactly the pass's colour attachments.
pub fn check_outputs(plan: &Plan, pass: &PlanPass, interface: &PipelineInterface) -> Vec<String> {
    let Some(rp) = &pass.render_pass else {
        return Vec::new();
    };
    let locations: Vec<u32> = interface.outputs.iter().map(|o| o.location).collect();
    let expected: Vec<u32> = (0..rp.color.len() as u32).collect();
    if locations != expected {
        return vec![format!(
            "the fragment shader writes outputs at locations {locations:?} but the pass has {} colour attachment(s)",
            rp.color.len()
        )];
    }
    let mut problems = Vec::new();
    for (output, &index) in interface.outputs.iter().zip(&rp.color) {
        let Some(resource) = rp
            .attachments
            .get(index)
            .and_then(|a| plan.resources.get(a.resource))
        else {
            continue;
        };
        let ResourceDesc::Image(desc) = &resource.desc else {
            continue;
        };
        let wanted = attachment_scalar(&desc.format);
        if output.scalar != wanted {
            problems.push(format!(
                "fragment output {} is {:?} but colour attachment `{}` ({}) takes {:?}",
                output.location, output.scalar, resource.name, desc.format, wanted
            ));
        }
    }
    problems
}

/// The shader scalar type that writes a colour format.
fn attachment_scalar(format: &str) -> ScalarKind {
    if format.ends_with("_UINT") {
        ScalarKind::Uint
    } else if format.ends_with("_SINT") {
        ScalarKind::Int
    } else {
        ScalarKind::Float
    }
}

/// The push-constant bytes every Vulkan device supports (the required
/// minimum of `maxPushConstantsSize`).
pub const MAX_PUSH_CONSTANT_BYTES: u32 = 128;

/// The push-constant member a repeating compute pass's dispatch number goes to.
pub const REPEAT_INDEX: &str = "repeat_index";

/// Values the executor supplies to push-constant members no parameter names.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameValues {
    /// Seconds since the animation started (`time`).
    pub time: f32,
    /// Frame number (`frame`).
    pub frame: u32,
    /// Target size of the pass (`extent`, a vec2 or uvec2).
    pub extent: [u32; 2],
    /// Frames in a row before this one that drew the same camera, scene and
    /// plan (`history_frames`): how many frames' results history images hold,
    /// 0 when they hold nothing usable. Progressive graphs accumulate with it.
    pub history_frames: u32,
    /// Frames drawn before this one with the plan's images (`plan_frames`),
    /// whatever moved between them: history images hold the last frame's
    /// results when it is above 0, seen from wherever the camera was, and
    /// nothing defined when it is 0 (a new plan or scene). Passes that
    /// reproject history across camera motion test it instead of
    /// `history_frames`.
    pub plan_frames: u32,
    /// Which of a repeating compute pass's dispatches this is, from 0
    /// (`repeat_index`; always 0 for a pass that does not repeat).
    pub repeat_index: u32,
}

/// Packs parameters into the push-constant block; every member must be a
/// parameter of the pass (declared in the graph, or derived by a provider and
/// added to the plan's parameters) or one of `time`, `frame`, `extent`,
/// `history_frames`, `plan_frames`, `repeat_index`. An
/// array member may be given fewer elements than it holds; the rest are zero.
pub fn pack_push(
    block: &PushBlock,
    params: &BTreeMap<String, ParamValue>,
    frame: &FrameValues,
) -> Result<Vec<u8>, Vec<String>> {
    if block.size > MAX_PUSH_CONSTANT_BYTES {
        return Err(vec![format!(
            "the push-constant block is {} bytes, over the {MAX_PUSH_CONSTANT_BYTES} every Vulkan device supports (maxPushConstantsSize)",
            block.size
        )]);
    }
    let mut bytes = vec![0u8; block.size as usize];
    let mut problems = Vec::new();
    for m in &block.members {
        let capacity = (m.components * m.count) as usize;
        let values: Vec<f64> = match params.get(&m.name) {
            Some(ParamValue::Number(n)) => vec![*n],
            Some(ParamValue::Vector(v)) => v.clone(),
            Some(ParamValue::Bool(b)) => vec![if *b { 1.0 } else { 0.0 }],
            Some(ParamValue::Reference(r)) => {
                problems.push(format!(
                    "parameter `{}` is an unresolved reference `{r}`",
                    m.name
                ));
                continue;
            }
            None => match m.name.as_str() {
                "time" => vec![f64::from(frame.time)],
                "frame" => vec![f64::from(frame.frame)],
                "history_frames" => vec![f64::from(frame.history_frames)],
                "plan_frames" => vec![f64::from(frame.plan_frames)],
                REPEAT_INDEX => vec![f64::from(frame.repeat_index)],
                "extent" => frame.extent.iter().map(|&v| f64::from(v)).collect(),
                name => {
                    problems.push(format!(
                        "push-constant member `{name}` has no graph parameter of that name"
                    ));
                    continue;
                }
            },
        };
        let short_array = m.count > 1
            && values.len() < capacity
            && values.len().is_multiple_of(m.components as usize);
        if values.len() != capacity && !short_array {
            problems.push(format!(
                "parameter `{}` has {} component(s) but the shader member has {}",
                m.name,
                values.len(),
                capacity
            ));
            continue;
        }
        for (i, v) in values.iter().enumerate() {
            let word: [u8; 4] = match m.scalar {
                ScalarKind::Float => (*v as f32).to_ne_bytes(),
                ScalarKind::Int => (*v as i32).to_ne_bytes(),
                ScalarKind::Uint => (*v as u32).to_ne_bytes(),
            };
            let element = i / m.components as usize;
            let component = i % m.components as usize;
            let at = m.offset as usize + element * m.stride as usize + 4 * component;
            match bytes.get_mut(at..at + 4) {
                Some(slot) => slot.copy_from_slice(&word),
                None => problems.push(format!(
                    "push-constant member `{}` lies outside the block",
                    m.name
                )),
            }
        }
    }
    if problems.is_empty() {
        Ok(bytes)
    } else {
        Err(problems)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::reflect::PushMember;

    fn member(name: &str, offset: u32, scalar: ScalarKind, components: u32) -> PushMember {
        PushMember {
            name: name.into(),
            offset,
            scalar,
            components,
            count: 1,
            stride: 0,
        }
    }

    #[test]
    fn packs_params_and_frame_values_by_name() {
        let block = PushBlock {
            size: 40,
            members: vec![
                member("tint", 0, ScalarKind::Float, 4),
                member("radius", 16, ScalarKind::Int, 1),
                member("frame", 20, ScalarKind::Uint, 1),
                member("enabled", 24, ScalarKind::Uint, 1),
                member("history_frames", 28, ScalarKind::Uint, 1),
                member("repeat_index", 32, ScalarKind::Uint, 1),
                member("plan_frames", 36, ScalarKind::Uint, 1),
            ],
        };
        let params = BTreeMap::from([
            (
                "tint".to_string(),
                ParamValue::Vector(vec![0.5, 1.0, 2.0, 4.0]),
            ),
            ("radius".to_string(), ParamValue::Number(21.0)),
            ("enabled".to_string(), ParamValue::Bool(true)),
        ]);
        let frame = FrameValues {
            time: 0.0,
            frame: 7,
            extent: [4, 4],
            history_frames: 3,
            plan_frames: 9,
            repeat_index: 5,
        };
        let bytes = pack_push(&block, &params, &frame).expect("packs");
        let word = |i: usize| [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]];
        assert_eq!(f32::from_ne_bytes(word(8)), 2.0);
        assert_eq!(u32::from_ne_bytes(word(28)), 3);
        assert_eq!(u32::from_ne_bytes(word(32)), 5);
        assert_eq!(u32::from_ne_bytes(word(36)), 9);
        assert_eq!(i32::from_ne_bytes(word(16)), 21);
        assert_eq!(u32::from_ne_bytes(word(20)), 7);
        assert_eq!(u32::from_ne_bytes(word(24)), 1);
    }

    #[test]
    fn a_block_over_the_guaranteed_size_is_refused() {
        let block = PushBlock {
            size: 132,
            members: vec![member("tint", 124, ScalarKind::Float, 1)],
        };
        let params = BTreeMap::from([("tint".to_string(), ParamValue::Number(1.0))]);
        assert_eq!(
            pack_push(&block, &params, &FrameValues::default()),
            Err(vec![
                "the push-constant block is 132 bytes, over the 128 every Vulkan device supports (maxPushConstantsSize)".to_string()
            ])
        );
        let fits = PushBlock { size: 128, ..block };
        assert!(pack_push(&fits, &params, &FrameValues::default()).is_ok());
    }

    #[test]
    fn reports_missing_and_misshapen_params() {
        let block = PushBlock {
            size: 20,
            members: vec![
                member("direction", 0, ScalarKind::Float, 2),
                member("sigma", 8, ScalarKind::Float, 1),
            ],
        };
        let params = BTreeMap::from([("direction".to_string(), ParamValue::Number(1.0))]);
        let problems = pack_push(&block, &params, &FrameValues::default()).expect_err("fails");
        assert_eq!(
            problems,
            vec![
                "parameter `direction` has 1 component(s) but the shader member has 2".to_string(),
                "push-constant member `sigma` has no graph parameter of that name".to_string(),
            ]
        );
    }

    fn array(name: &str, offset: u32, scalar: ScalarKind, count: u32) -> PushMember {
        PushMember {
            count,
            stride: 4,
            ..member(name, offset, scalar, 1)
        }
    }

    #[test]
    fn a_short_vector_fills_an_array_and_the_rest_is_zero() {
        let block = PushBlock {
            size: 16,
            members: vec![array("weights", 0, ScalarKind::Float, 4)],
        };
        let params = BTreeMap::from([("weights".to_string(), ParamValue::Vector(vec![0.5, 0.25]))]);
        let bytes = pack_push(&block, &params, &FrameValues::default()).expect("packs");
        let float = |k: usize| f32::from_ne_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
        assert_eq!(
            [float(0), float(1), float(2), float(3)],
            [0.5, 0.25, 0.0, 0.0]
        );
        let long = BTreeMap::from([("weights".to_string(), ParamValue::Vector(vec![1.0; 5]))]);
        assert_eq!(
            pack_push(&block, &long, &FrameValues::default()).unwrap_err(),
            ["parameter `weights` has 5 component(s) but the shader member has 4"]
        );
    }
}
