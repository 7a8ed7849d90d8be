//! Cross-checks a pass's shaders against the graph: which graph resource
//! feeds each shader binding, whether the kinds agree, whether fragment
//! outputs match the colour attachments; and packs graph parameters into the
//! push-constant block by member name.

use crate::gaussian::GaussianTaps;
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
        if shader.set == crate::draw::SCENE_SET {
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

/// Values the executor supplies to push-constant members no parameter names.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrameValues {
    /// Seconds since the animation started (`time`).
    pub time: f32,
    /// Frame number (`frame`).
    pub frame: u32,
    /// Target size of the pass (`extent`, a vec2 or uvec2).
    pub extent: [u32; 2],
}

/// Packs parameters into the push-constant block; every member must be a
/// graph parameter of the pass, one of `time`, `frame`, `extent`, or one of the
/// values the engine derives from the pass's parameters (`gauss_*`, see
/// [`derived_value`]).
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
                "extent" => frame.extent.iter().map(|&v| f64::from(v)).collect(),
                name => match derived_value(name, params) {
                    Some(Ok(values)) if values.len() > capacity => {
                        problems.push(format!(
                            "push-constant member `{name}` holds {capacity} value(s) but the pass's `sigma` and `radius` need {}",
                            values.len()
                        ));
                        continue;
                    }
                    Some(Ok(mut values)) => {
                        values.resize(capacity, 0.0);
                        values
                    }
                    Some(Err(problem)) => {
                        problems.push(format!("push-constant member `{name}`: {problem}"));
                        continue;
                    }
                    None => {
                        problems.push(format!(
                            "push-constant member `{name}` has no graph parameter of that name"
                        ));
                        continue;
                    }
                },
            },
        };
        if values.len() != capacity {
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

/// Values the engine computes from a pass's parameters rather than taking
/// them literally: a Gaussian blur's taps from `sigma` and `radius`
/// (`gauss_weights`, `gauss_offsets` and the tap count `gauss_taps`, centre
/// included). With `linear_taps: false` the taps are one per texel (offsets
/// 0, 1, 2, ...), otherwise neighbours are paired into linear-filtered fetches.
/// `None` for a name that is not derived.
pub fn derived_value(
    name: &str,
    params: &BTreeMap<String, ParamValue>,
) -> Option<Result<Vec<f64>, String>> {
    if !matches!(name, "gauss_weights" | "gauss_offsets" | "gauss_taps") {
        return None;
    }
    let number = |key: &str| match params.get(key) {
        Some(ParamValue::Number(n)) => Ok(*n),
        _ => Err(format!("the pass needs a numeric parameter `{key}`")),
    };
    let linear = !matches!(params.get("linear_taps"), Some(ParamValue::Bool(false)));
    Some(number("sigma").and_then(|sigma| {
        let radius = number("radius")?;
        if radius.fract() != 0.0 || radius < 0.0 {
            return Err(format!("`radius` must be a whole number, got {radius}"));
        }
        let taps = if linear {
            GaussianTaps::linear(sigma, radius as u32)?
        } else {
            GaussianTaps::discrete(sigma, radius as u32)?
        };
        Ok(match name {
            "gauss_weights" => taps.weights,
            "gauss_offsets" => taps.offsets,
            _ => vec![taps.len() as f64],
        })
    }))
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
            size: 28,
            members: vec![
                member("tint", 0, ScalarKind::Float, 4),
                member("radius", 16, ScalarKind::Int, 1),
                member("frame", 20, ScalarKind::Uint, 1),
                member("enabled", 24, ScalarKind::Uint, 1),
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
        };
        let bytes = pack_push(&block, &params, &frame).expect("packs");
        let word = |i: usize| [bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]];
        assert_eq!(f32::from_ne_bytes(word(8)), 2.0);
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
    fn derives_gaussian_taps_from_sigma_and_radius() {
        let block = PushBlock {
            size: 108,
            members: vec![
                member("direction", 0, ScalarKind::Float, 2),
                member("gauss_taps", 8, ScalarKind::Int, 1),
                array("gauss_weights", 12, ScalarKind::Float, 12),
                array("gauss_offsets", 60, ScalarKind::Float, 12),
            ],
        };
        let params = BTreeMap::from([
            ("direction".to_string(), ParamValue::Vector(vec![1.0, 0.0])),
            ("sigma".to_string(), ParamValue::Number(9.0)),
            ("radius".to_string(), ParamValue::Number(21.0)),
        ]);
        let bytes = pack_push(&block, &params, &FrameValues::default()).expect("packs");
        let float = |i: usize| f32::from_ne_bytes(bytes[i..i + 4].try_into().unwrap());
        let taps = GaussianTaps::linear(9.0, 21).unwrap();
        assert_eq!(i32::from_ne_bytes(bytes[8..12].try_into().unwrap()), 12);
        for k in 0..12 {
            assert_eq!(float(12 + 4 * k), taps.weights[k] as f32);
            assert_eq!(float(60 + 4 * k), taps.offsets[k] as f32);
        }
    }

    #[test]
    fn one_tap_per_texel_when_linear_taps_is_off_and_padding_is_zero() {
        let block = PushBlock {
            size: 4 * 24,
            members: vec![array("gauss_weights", 0, ScalarKind::Float, 24)],
        };
        let params = BTreeMap::from([
            ("sigma".to_string(), ParamValue::Number(9.0)),
            ("radius".to_string(), ParamValue::Number(21.0)),
            ("linear_taps".to_string(), ParamValue::Bool(false)),
        ]);
        let bytes = pack_push(&block, &params, &FrameValues::default()).expect("packs");
        let float = |k: usize| f32::from_ne_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
        let taps = GaussianTaps::discrete(9.0, 21).unwrap();
        for k in 0..22 {
            assert_eq!(float(k), taps.weights[k] as f32);
        }
        assert_eq!((float(22), float(23)), (0.0, 0.0));
    }

    #[test]
    fn reports_a_kernel_that_does_not_fit_and_missing_sigma() {
        let block = PushBlock {
            size: 48,
            members: vec![array("gauss_weights", 0, ScalarKind::Float, 12)],
        };
        let wide = BTreeMap::from([
            ("sigma".to_string(), ParamValue::Number(12.0)),
            ("radius".to_string(), ParamValue::Number(30.0)),
        ]);
        assert_eq!(
            pack_push(&block, &wide, &FrameValues::default()).unwrap_err(),
            vec![
                "push-constant member `gauss_weights` holds 12 value(s) but the pass's `sigma` and `radius` need 16"
                    .to_string()
            ]
        );
        let missing = BTreeMap::from([("radius".to_string(), ParamValue::Number(21.0))]);
        assert_eq!(
            pack_push(&block, &missing, &FrameValues::default()).unwrap_err(),
            vec![
                "push-constant member `gauss_weights`: the pass needs a numeric parameter `sigma`"
                    .to_string()
            ]
        );
    }
}
