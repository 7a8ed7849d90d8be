//! Which optional shader capabilities the device offers, and whether a
//! compiled shader stays within them. A SPIR-V module declares every
//! capability it uses (`OpCapability`); those that Vulkan makes optional must
//! be offered by the device and enabled, or creating the module is invalid.
//! Checking the declarations before a pipeline is built turns that into an
//! error naming the shader and the feature, not a validation message or a
//! driver crash.

use crate::error::GpuError;
use crate::shader::{CompiledShader, ShaderStage};
use ash::vk;
use spirv::Capability;

/// `OpCapability`'s opcode.
const OP_CAPABILITY: u32 = 17;
/// Words before the first instruction (magic, version, generator, bound, schema).
const HEADER_WORDS: usize = 5;

/// The optional shader capabilities a device offers (and weft enables).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShaderSupport {
    /// `geometryShader`: needed by fragment shaders that read `gl_PrimitiveID`.
    pub geometry: bool,
    /// `shaderFloat64`.
    pub float64: bool,
    /// `shaderInt64`.
    pub int64: bool,
    /// `shaderInt16`.
    pub int16: bool,
    /// `shaderFloat16` (arithmetic on 16-bit floats).
    pub float16: bool,
    /// `shaderInt8` (arithmetic on 8-bit integers).
    pub int8: bool,
    /// The stages that may use subgroup operations.
    pub subgroup_stages: vk::ShaderStageFlags,
    /// The subgroup operation classes offered in those stages.
    pub subgroup_operations: vk::SubgroupFeatureFlags,
}

impl ShaderSupport {
    /// Nothing optional: what every Vulkan 1.3 device accepts.
    pub fn core() -> Self {
        Self {
            geometry: false,
            float64: false,
            int64: false,
            int16: false,
            float16: false,
            int8: false,
            subgroup_stages: vk::ShaderStageFlags::empty(),
            subgroup_operations: vk::SubgroupFeatureFlags::empty(),
        }
    }

    /// What `physical` offers: its features and its subgroup properties.
    pub(crate) fn query(instance: &ash::Instance, physical: vk::PhysicalDevice) -> Self {
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut features = vk::PhysicalDeviceFeatures2::default().push_next(&mut f12);
        unsafe { instance.get_physical_device_features2(physical, &mut features) };
        let core = features.features;
        let mut subgroup = vk::PhysicalDeviceSubgroupProperties::default();
        let mut properties = vk::PhysicalDeviceProperties2::default().push_next(&mut subgroup);
        unsafe { instance.get_physical_device_properties2(physical, &mut properties) };
        Self {
            geometry: core.geometry_shader == vk::TRUE,
            float64: core.shader_float64 == vk::TRUE,
            int64: core.shader_int64 == vk::TRUE,
            int16: core.shader_int16 == vk::TRUE,
            float16: f12.shader_float16 == vk::TRUE,
            int8: f12.shader_int8 == vk::TRUE,
            subgroup_stages: subgroup.supported_stages,
            subgroup_operations: subgroup.supported_operations,
        }
    }

    /// Every optional capability `shader` declares that this device lacks,
    /// as "what it is (the Vulkan feature or property)", each once.
    pub fn unmet(&self, shader: &CompiledShader) -> Vec<String> {
        let mut unmet: Vec<String> = Vec::new();
        for capability in declared(&shader.spirv) {
            if let Some(why) = self.lacks(capability, shader.stage) {
                if !unmet.contains(&why) {
                    unmet.push(why);
                }
            }
        }
        unmet
    }

    /// Why the device (`device`, by name) cannot run `shader`, when it cannot:
    /// every feature it lacks ("needs ..., which the device ... does not offer").
    pub fn refusal(&self, device: &str, shader: &CompiledShader) -> Option<String> {
        let unmet = self.unmet(shader);
        (!unmet.is_empty()).then(|| {
            format!(
                "needs {}, which the device `{device}` does not offer",
                unmet.join(" and ")
            )
        })
    }

    /// An error for `pass` naming each of its `shaders` that needs what the
    /// device (`device`, by name) lacks.
    pub fn check(
        &self,
        device: &str,
        pass: &str,
        shaders: &[&CompiledShader],
    ) -> Result<(), GpuError> {
        let problems: Vec<String> = shaders
            .iter()
            .filter_map(|shader| {
                let refusal = self.refusal(device, shader)?;
                Some(format!("{} {refusal}", shader.path.display()))
            })
            .collect();
        if problems.is_empty() {
            Ok(())
        } else {
            Err(GpuError::Pass {
                pass: pass.to_string(),
                message: problems.join("; "),
            })
        }
    }

    /// Whether `stage` may use the subgroup operations of class `operation`.
    pub fn offers_subgroup(&self, stage: ShaderStage, operation: vk::SubgroupFeatureFlags) -> bool {
        self.subgroup_stages.contains(stage_flag(stage))
            && self.subgroup_operations.contains(operation)
    }

    /// Why `capability` cannot be used in `stage`, when it cannot.
    fn lacks(&self, capability: Capability, stage: ShaderStage) -> Option<String> {
        let feature = |offered: bool, what: &str, feature: &str| {
            (!offered).then(|| format!("{what} (the `{feature}` feature)"))
        };
        match capability {
            Capability::Geometry => feature(
                self.geometry,
                "gl_PrimitiveID or geometry-stage built-ins",
                "geometryShader",
            ),
            Capability::Float64 => feature(self.float64, "64-bit floats", "shaderFloat64"),
            Capability::Int64 => feature(self.int64, "64-bit integers", "shaderInt64"),
            Capability::Int16 => feature(self.int16, "16-bit integers", "shaderInt16"),
            Capability::Float16 => {
                feature(self.float16, "16-bit float arithmetic", "shaderFloat16")
            }
            Capability::Int8 => feature(self.int8, "8-bit integer arithmetic", "shaderInt8"),
            other => {
                let (operation, name) = subgroup_operation(other)?;
                let stage_flag = stage_flag(stage);
                if !self.subgroup_stages.contains(stage_flag) {
                    Some(format!(
                        "subgroup operations in {} shaders (`supportedStages` lacks {stage_flag:?})",
                        stage_name(stage)
                    ))
                } else if !self.subgroup_operations.contains(operation) {
                    Some(format!(
                        "subgroup {name} operations (`supportedOperations` lacks {operation:?})"
                    ))
                } else {
                    None
                }
            }
        }
    }
}

/// The capabilities a SPIR-V module declares, in order. They come first in a
/// module, so reading stops at the first other instruction.
pub fn declared(spirv: &[u32]) -> Vec<Capability> {
    let mut found = Vec::new();
    let mut at = HEADER_WORDS;
    while let Some(&word) = spirv.get(at) {
        let (count, opcode) = ((word >> 16) as usize, word & 0xffff);
        if opcode != OP_CAPABILITY || count < 2 {
            break;
        }
        if let Some(capability) = spirv.get(at + 1).and_then(|&c| Capability::from_u32(c)) {
            found.push(capability);
        }
        at += count;
    }
    found
}

/// The subgroup operation class a capability needs, and its name.
fn subgroup_operation(capability: Capability) -> Option<(vk::SubgroupFeatureFlags, &'static str)> {
    use vk::SubgroupFeatureFlags as Op;
    Some(match capability {
        Capability::GroupNonUniform => (Op::BASIC, "basic"),
        Capability::GroupNonUniformVote => (Op::VOTE, "vote"),
        Capability::GroupNonUniformArithmetic => (Op::ARITHMETIC, "arithmetic"),
        Capability::GroupNonUniformBallot => (Op::BALLOT, "ballot"),
        Capability::GroupNonUniformShuffle => (Op::SHUFFLE, "shuffle"),
        Capability::GroupNonUniformShuffleRelative => (Op::SHUFFLE_RELATIVE, "relative shuffle"),
        Capability::GroupNonUniformClustered => (Op::CLUSTERED, "clustered"),
        Capability::GroupNonUniformQuad => (Op::QUAD, "quad"),
        _ => return None,
    })
}

fn stage_flag(stage: ShaderStage) -> vk::ShaderStageFlags {
    match stage {
        ShaderStage::Vertex => vk::ShaderStageFlags::VERTEX,
        ShaderStage::Fragment => vk::ShaderStageFlags::FRAGMENT,
        ShaderStage::Compute => vk::ShaderStageFlags::COMPUTE,
    }
}

fn stage_name(stage: ShaderStage) -> &'static str {
    match stage {
        ShaderStage::Vertex => "vertex",
        ShaderStage::Fragment => "fragment",
        ShaderStage::Compute => "compute",
    }
}
