//! Reflection of SPIR-V with spirq: the descriptor bindings, push-constant
//! block and fragment outputs a shader declares, so pipeline layouts come
//! from the shaders themselves and can be cross-checked against the graph.

use crate::shader::{CompiledShader, ShaderError, ShaderStage};
use ash::vk;
use spirq::prelude::*;
use spirq::ty::{DescriptorType, ScalarType, Type};
use std::collections::BTreeMap;

/// What kind of descriptor a shader binding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DescriptorKind {
    /// `sampler2D` and friends: sampled graph images.
    CombinedImageSampler,
    /// `image2D`: storage images.
    StorageImage,
    /// `uniform` blocks: sampled graph buffers.
    UniformBuffer,
    /// `buffer` blocks: storage buffers.
    StorageBuffer,
    /// `samplerBuffer` and friends: a buffer read through `texelFetch`.
    UniformTexelBuffer,
    /// `accelerationStructureEXT`: a top level that ray queries trace.
    AccelerationStructure,
}

impl DescriptorKind {
    /// The Vulkan descriptor type.
    pub fn vk(self) -> vk::DescriptorType {
        match self {
            Self::CombinedImageSampler => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
            Self::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            Self::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
            Self::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            Self::UniformTexelBuffer => vk::DescriptorType::UNIFORM_TEXEL_BUFFER,
            Self::AccelerationStructure => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
        }
    }
}

/// One descriptor binding a shader declares.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShaderBinding {
    /// Descriptor set number.
    pub set: u32,
    /// Binding number within the set.
    pub binding: u32,
    /// The GLSL variable name, or the block name for buffer blocks without an
    /// instance name; the executor matches it to a graph resource of that name.
    pub name: String,
    /// Descriptor type.
    pub kind: DescriptorKind,
    /// Array size (1 for a single descriptor).
    pub count: u32,
    /// A depth-comparison sampler (`sampler2DShadow`): bound with the compare
    /// sampler, so `texture`/`textureProj` return filtered visibility.
    pub depth_compare: bool,
    /// For image bindings, what the shader expects of the image, compared with
    /// the graph resource's format, layers and samples.
    pub image: Option<ImageShape>,
}

/// What a shader declares about an image binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ImageShape {
    /// Scalar type of what a read returns (`sampler2D` float, `usampler2D`
    /// uint, `isampler2D` int); `None` for storage images, whose format says it.
    pub scalar: Option<ScalarKind>,
    /// A 2D image (`sampler2D`, `image2D`), the only kind of graph image.
    pub two_d: bool,
    /// An array image (`sampler2DArray`).
    pub arrayed: bool,
    /// A multisampled image (`sampler2DMS`).
    pub multisampled: bool,
}

/// Scalar type of a push-constant member.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ScalarKind {
    /// 32-bit float.
    Float,
    /// 32-bit signed integer.
    Int,
    /// 32-bit unsigned integer.
    Uint,
}

/// One member of the push-constant block: a graph parameter lands here by name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PushMember {
    /// Member name, matched to a parameter name.
    pub name: String,
    /// Byte offset in the block.
    pub offset: u32,
    /// Scalar type of each component.
    pub scalar: ScalarKind,
    /// 1 for scalars, 2 to 4 for vectors.
    pub components: u32,
    /// Array length; 1 for a member that is not an array.
    pub count: u32,
    /// Bytes between array elements (0 when not an array).
    pub stride: u32,
}

/// The push-constant block of a shader.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct PushBlock {
    /// Block size in bytes.
    pub size: u32,
    /// Members in declaration order.
    pub members: Vec<PushMember>,
}

/// A fragment shader output.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FragmentOutput {
    /// Output location (colour attachment index).
    pub location: u32,
    /// Scalar type.
    pub scalar: ScalarKind,
    /// Number of components.
    pub components: u32,
}

/// A shader input or output variable at a location (vertex attributes,
/// values passed from the vertex to the fragment shader).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StageVariable {
    /// The GLSL name, for messages.
    pub name: String,
    /// Location.
    pub location: u32,
    /// Scalar type and component count; `None` for types other than scalars
    /// and vectors (matrices, arrays, blocks), which are not compared.
    pub shape: Option<(ScalarKind, u32)>,
}

/// The resource interface of one shader stage.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ShaderInterface {
    /// The stage this interface belongs to.
    pub stage: ShaderStage,
    /// Descriptor bindings, sorted by set and binding.
    pub bindings: Vec<ShaderBinding>,
    /// The push-constant block, if declared.
    pub push: Option<PushBlock>,
    /// Colour outputs of fragment shaders, by location.
    pub outputs: Vec<FragmentOutput>,
    /// Inputs by location: vertex attributes, or a fragment shader's inputs.
    pub inputs: Vec<StageVariable>,
    /// A vertex shader's outputs by location (what the fragment shader reads).
    pub varyings: Vec<StageVariable>,
}

impl ShaderInterface {
    /// Reflects a compiled shader's `main` entry point.
    pub fn reflect(shader: &CompiledShader) -> Result<Self, ShaderError> {
        let fail = |message: String| ShaderError::Reflect {
            path: shader.path.clone(),
            message,
        };
        let mut entry = reflect_main(shader, false)?;
        entry.vars.extend(atomic_images(shader, &entry.vars)?);
        let mut bindings = Vec::new();
        let mut push = None;
        let mut outputs = Vec::new();
        let mut inputs = Vec::new();
        let mut varyings = Vec::new();
        for var in entry.vars {
            match var {
                Variable::Descriptor {
                    name,
                    desc_bind,
                    desc_ty,
                    ty,
                    nbind,
                } => {
                    let kind = match desc_ty {
                        DescriptorType::CombinedImageSampler() => {
                            DescriptorKind::CombinedImageSampler
                        }
                        DescriptorType::StorageImage(_) => DescriptorKind::StorageImage,
                        DescriptorType::UniformBuffer() => DescriptorKind::UniformBuffer,
                        DescriptorType::StorageBuffer(_) => DescriptorKind::StorageBuffer,
                        DescriptorType::UniformTexelBuffer() => DescriptorKind::UniformTexelBuffer,
                        DescriptorType::AccelStruct() => DescriptorKind::AccelerationStructure,
                        other => {
                            return Err(fail(format!(
                                "binding {} uses unsupported descriptor type {other:?}",
                                desc_bind.bind()
                            )))
                        }
                    };
                    let name = name
                        .filter(|n| !n.is_empty())
                        .or_else(|| struct_name(&ty))
                        .unwrap_or_default();
                    bindings.push(ShaderBinding {
                        set: desc_bind.set(),
                        binding: desc_bind.bind(),
                        name,
                        kind,
                        count: nbind.max(1),
                        depth_compare: is_depth_sampler(&ty),
                        image: image_shape(&ty),
                    });
                }
                Variable::PushConstant { ty, .. } => {
                    push = Some(push_block(&ty).map_err(fail)?);
                }
                Variable::Output { location, ty, .. } if shader.stage == ShaderStage::Fragment => {
                    let (scalar, components) = scalar_shape(&ty).ok_or_else(|| {
                        fail(format!("output {} has an unsupported type", location.loc()))
                    })?;
                    outputs.push(FragmentOutput {
                        location: location.loc(),
                        scalar,
                        components,
                    });
                }
                _ => {}
            }
        }
        // Stage inputs and outputs count whether or not the code reads them:
        // pipeline creation matches every interface variable.
        for var in reflect_main(shader, true)?.vars {
            let variable =
                |name: Option<String>, location: spirq::prelude::InterfaceLocation, ty: &Type| {
                    StageVariable {
                        name: name.unwrap_or_default(),
                        location: location.loc(),
                        shape: scalar_shape(ty),
                    }
                };
            match var {
                Variable::Input { name, location, ty } => {
                    inputs.push(variable(name, location, &ty))
                }
                Variable::Output { name, location, ty } if shader.stage == ShaderStage::Vertex => {
                    varyings.push(variable(name, location, &ty))
                }
                _ => {}
            }
        }
        inputs.sort_by_key(|v| v.location);
        varyings.sort_by_key(|v| v.location);
        bindings.sort_by_key(|b| (b.set, b.binding));
        outputs.sort_by_key(|o| o.location);
        Ok(Self {
            stage: shader.stage,
            bindings,
            push,
            outputs,
            inputs,
            varyings,
        })
    }
}

fn is_depth_sampler(ty: &Type) -> bool {
    match ty {
        Type::CombinedImageSampler(t) => t.sampled_image_ty.is_depth == Some(true),
        _ => false,
    }
}

/// Storage images the code uses only through image atomics
/// (`OpImageTexelPointer`), which spirq's static-use analysis does not see:
/// their descriptors from the reflection of every resource, less those in
/// `used` already.
fn atomic_images(shader: &CompiledShader, used: &[Variable]) -> Result<Vec<Variable>, ShaderError> {
    let atomics = texel_pointer_bindings(&shader.spirv);
    if atomics.is_empty() {
        return Ok(Vec::new());
    }
    let bound = |v: &Variable| match v {
        Variable::Descriptor { desc_bind, .. } => Some((desc_bind.set(), desc_bind.bind())),
        _ => None,
    };
    let seen: Vec<(u32, u32)> = used.iter().filter_map(bound).collect();
    Ok(reflect_main(shader, true)?
        .vars
        .into_iter()
        .filter(|v| bound(v).is_some_and(|b| atomics.contains(&b) && !seen.contains(&b)))
        .collect())
}

/// (set, binding) of every variable an `OpImageTexelPointer` points into.
fn texel_pointer_bindings(words: &[u32]) -> Vec<(u32, u32)> {
    const OP_DECORATE: u32 = 71;
    const OP_IMAGE_TEXEL_POINTER: u32 = 60;
    const DECORATION_BINDING: u32 = 33;
    const DECORATION_DESCRIPTOR_SET: u32 = 34;
    let mut sets = std::collections::HashMap::new();
    let mut bindings = std::collections::HashMap::new();
    let mut images = Vec::new();
    // Instructions start after the five-word header; each gives its word count.
    let mut at = 5;
    while at < words.len() {
        let count = (words[at] >> 16) as usize;
        let opcode = words[at] & 0xffff;
        let operands = &words[(at + 1).min(words.len())..(at + count.max(1)).min(words.len())];
        match (opcode, operands) {
            (OP_DECORATE, [target, DECORATION_DESCRIPTOR_SET, value, ..]) => {
                sets.insert(*target, *value);
            }
            (OP_DECORATE, [target, DECORATION_BINDING, value, ..]) => {
                bindings.insert(*target, *value);
            }
            (OP_IMAGE_TEXEL_POINTER, [_, _, image, ..]) => images.push(*image),
            _ => {}
        }
        at += count.max(1);
    }
    images
        .iter()
        .filter_map(|id| Some((*sets.get(id)?, *bindings.get(id)?)))
        .collect()
}

/// The `main` entry point, with only the resources its code uses or with all.
fn reflect_main(
    shader: &CompiledShader,
    all: bool,
) -> Result<spirq::entry_point::EntryPoint, ShaderError> {
    let fail = |message: String| ShaderError::Reflect {
        path: shader.path.clone(),
        message,
    };
    ReflectConfig::new()
        .spv(shader.spirv.as_slice())
        .ref_all_rscs(all)
        .combine_img_samplers(true)
        .reflect()
        .map_err(|e| fail(format!("SPIR-V reflection failed: {e}")))?
        .into_iter()
        .find(|e| e.name == "main")
        .ok_or_else(|| fail("no `main` entry point".into()))
}

fn image_shape(ty: &Type) -> Option<ImageShape> {
    use spirq::ty::Dim;
    match ty {
        Type::CombinedImageSampler(t) => {
            let t = &t.sampled_image_ty;
            Some(ImageShape {
                scalar: scalar_kind(&t.scalar_ty),
                two_d: t.dim == Dim::Dim2D,
                arrayed: t.is_array,
                multisampled: t.is_multisampled,
            })
        }
        Type::StorageImage(t) => Some(ImageShape {
            scalar: None,
            two_d: t.dim == Dim::Dim2D,
            arrayed: t.is_array,
            multisampled: t.is_multisampled,
        }),
        _ => None,
    }
}

fn struct_name(ty: &Type) -> Option<String> {
    match ty {
        Type::Struct(s) => s.name.clone(),
        _ => None,
    }
}

fn scalar_kind(s: &ScalarType) -> Option<ScalarKind> {
    match s {
        ScalarType::Float { .. } => Some(ScalarKind::Float),
        ScalarType::Integer {
            is_signed: true, ..
        } => Some(ScalarKind::Int),
        ScalarType::Integer {
            is_signed: false, ..
        } => Some(ScalarKind::Uint),
        _ => None,
    }
}

fn scalar_shape(ty: &Type) -> Option<(ScalarKind, u32)> {
    match ty {
        Type::Scalar(s) => Some((scalar_kind(s)?, 1)),
        Type::Vector(v) => Some((scalar_kind(&v.scalar_ty)?, v.nscalar)),
        _ => None,
    }
}

fn push_block(ty: &Type) -> Result<PushBlock, String> {
    let Type::Struct(s) = ty else {
        return Err("push constant is not a block".into());
    };
    let size = ty.nbyte().ok_or("push-constant block has no size")? as u32;
    let mut members = Vec::new();
    for m in &s.members {
        let name = m.name.clone().unwrap_or_default();
        let (element, count, stride) = match &m.ty {
            Type::Array(a) => match (a.nelement, a.stride) {
                (Some(n), Some(stride)) => (a.element_ty.as_ref(), n, stride as u32),
                _ => {
                    return Err(format!(
                        "push-constant member `{name}` must be an array of fixed length"
                    ))
                }
            },
            other => (other, 1, 0),
        };
        let (scalar, components) = scalar_shape(element).ok_or_else(|| {
            format!(
                "push-constant member `{name}` must be a 32-bit scalar or vector, or an array of them"
            )
        })?;
        let offset = m.offset.ok_or("push-constant member without an offset")? as u32;
        members.push(PushMember {
            name,
            offset,
            scalar,
            components,
            count,
            stride,
        });
    }
    Ok(PushBlock { size, members })
}

/// The merged interface of a pipeline's stages: one descriptor set layout per
/// set and one push-constant range covering every stage that uses it.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct PipelineInterface {
    /// (set, binding) to the binding and the stages that use it.
    pub bindings: BTreeMap<(u32, u32), (ShaderBinding, vk::ShaderStageFlags)>,
    /// Push-constant block shared by the stages, with the stages using it.
    pub push: Option<(PushBlock, vk::ShaderStageFlags)>,
    /// Fragment outputs.
    pub outputs: Vec<FragmentOutput>,
    /// What the vertex stage writes for the fragment stage, by location.
    pub varyings: Vec<StageVariable>,
    /// What the fragment stage reads from the vertex stage, by location.
    pub fragment_inputs: Vec<StageVariable>,
}

impl PipelineInterface {
    /// Merges stage interfaces; the same binding must have the same kind in all stages.
    pub fn merge(stages: &[&ShaderInterface]) -> Result<Self, String> {
        let mut merged = Self::default();
        for stage in stages {
            let flag = stage_flag(stage.stage);
            for b in &stage.bindings {
                match merged.bindings.get_mut(&(b.set, b.binding)) {
                    Some((existing, flags)) => {
                        if existing.kind != b.kind {
                            return Err(format!(
                                "set {} binding {} is {:?} in one stage and {:?} in another",
                                b.set, b.binding, existing.kind, b.kind
                            ));
                        }
                        *flags |= flag;
                    }
                    None => {
                        merged
                            .bindings
                            .insert((b.set, b.binding), (b.clone(), flag));
                    }
                }
            }
            if let Some(p) = &stage.push {
                merged.push = Some(match merged.push.take() {
                    Some((mut block, flags)) => {
                        block.size = block.size.max(p.size);
                        for m in &p.members {
                            if !block.members.iter().any(|x| x.name == m.name) {
                                block.members.push(m.clone());
                            }
                        }
                        (block, flags | flag)
                    }
                    None => (p.clone(), flag),
                });
            }
            match stage.stage {
                ShaderStage::Fragment => {
                    merged.outputs.clone_from(&stage.outputs);
                    merged.fragment_inputs.clone_from(&stage.inputs);
                }
                ShaderStage::Vertex => merged.varyings.clone_from(&stage.varyings),
                ShaderStage::Compute => {}
            }
        }
        Ok(merged)
    }

    /// The `VkDescriptorSetLayoutBinding`s of one set, each visible to the
    /// stages that declare it.
    pub fn set_layout_bindings(&self, set: u32) -> Vec<vk::DescriptorSetLayoutBinding<'static>> {
        self.bindings
            .iter()
            .filter(|((s, _), _)| *s == set)
            .map(|(_, (b, stages))| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(b.binding)
                    .descriptor_type(b.kind.vk())
                    .descriptor_count(b.count)
                    .stage_flags(*stages)
            })
            .collect()
    }

    /// The push-constant range (one, from offset 0, for every stage using the block).
    pub fn push_constant_ranges(&self) -> Vec<vk::PushConstantRange> {
        self.push
            .iter()
            .map(|(block, stages)| {
                vk::PushConstantRange::default()
                    .stage_flags(*stages)
                    .offset(0)
                    .size(block.size)
            })
            .collect()
    }

    /// The number of descriptor set layouts a pipeline needs (highest set + 1).
    pub fn set_count(&self) -> u32 {
        self.bindings.keys().map(|(s, _)| s + 1).max().unwrap_or(0)
    }
}

/// The Vulkan stage flag of a stage.
pub fn stage_flag(stage: ShaderStage) -> vk::ShaderStageFlags {
    match stage {
        ShaderStage::Vertex => vk::ShaderStageFlags::VERTEX,
        ShaderStage::Fragment => vk::ShaderStageFlags::FRAGMENT,
        ShaderStage::Compute => vk::ShaderStageFlags::COMPUTE,
    }
}
