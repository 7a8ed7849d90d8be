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
    /// `maxComputeSharedMemorySize`: bytes of `shared` variables.
    pub compute_shared_bytes: u32,
    /// `maxComputeWorkGroupInvocations`.
    pub compute_invocations: u32,
    /// `maxComputeWorkGroupSize`, per axis.
    pub compute_size: [u32; 3],
    /// Ray queries against hardware acceleration structures: the device
    /// offers `VK_KHR_acceleration_structure` and `VK_KHR_ray_query` with
    /// their `accelerationStructure`, `rayQuery` and `bufferDeviceAddress`
    /// features (all enabled when offered): what the ray tracer's hardware
    /// backend needs.
    pub ray_query: bool,
}

impl ShaderSupport {
    /// Nothing optional, and the limits every Vulkan 1.3 device meets (the
    /// specification's required minimums): what `weft graph check --shaders`
    /// assumes without a device.
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
            compute_shared_bytes: 16384,
            compute_invocations: 128,
            compute_size: [128, 128, 64],
            ray_query: false,
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
        let limits = properties.properties.limits;
        Self {
            geometry: core.geometry_shader == vk::TRUE,
            float64: core.shader_float64 == vk::TRUE,
            int64: core.shader_int64 == vk::TRUE,
            int16: core.shader_int16 == vk::TRUE,
            float16: f12.shader_float16 == vk::TRUE,
            int8: f12.shader_int8 == vk::TRUE,
            subgroup_stages: subgroup.supported_stages,
            subgroup_operations: subgroup.supported_operations,
            compute_shared_bytes: limits.max_compute_shared_memory_size,
            compute_invocations: limits.max_compute_work_group_invocations,
            compute_size: limits.max_compute_work_group_size,
            ray_query: crate::ray_query::offered(instance, physical),
        }
    }

    /// Every optional capability `shader` declares that this device lacks,
    /// as "what it is (the Vulkan feature or property)", each once.
    pub fn unmet(&self, shader: &CompiledShader) -> Vec<String> {
        let mut unmet: Vec<String> = Vec::new();
        let header = read_header(&shader.spirv);
        for capability in header.capabilities {
            if let Some(why) = self.lacks(capability, shader.stage) {
                if !unmet.contains(&why) {
                    unmet.push(why);
                }
            }
        }
        for extension in header.extensions {
            let ray_query = self.ray_query && extension == RAY_QUERY_EXTENSION;
            if !ray_query && !ENABLED_EXTENSIONS.contains(&extension.as_str()) {
                unmet.push(format!(
                    "the SPIR-V extension {extension} (weft enables no device extension for it)"
                ));
            }
        }
        if shader.stage == ShaderStage::Compute {
            unmet.extend(self.exceeded(&crate::workgroup::read(&shader.spirv)));
        }
        unmet
    }

    /// The compute limits `workgroup` breaks, each as the limit's name and values.
    fn exceeded(&self, workgroup: &crate::workgroup::Workgroup) -> Vec<String> {
        let mut exceeded = Vec::new();
        if workgroup.shared_bytes > u64::from(self.compute_shared_bytes) {
            exceeded.push(format!(
                "{} bytes of shared memory (`maxComputeSharedMemorySize` is {})",
                workgroup.shared_bytes, self.compute_shared_bytes
            ));
        }
        let [x, y, z] = workgroup.size;
        for ((axis, size), max) in ["x", "y", "z"]
            .iter()
            .zip(workgroup.size)
            .zip(self.compute_size)
        {
            if size > max {
                exceeded.push(format!(
                    "a local size {axis} of {size} (`maxComputeWorkGroupSize` {axis} is {max})"
                ));
            }
        }
        let invocations = u64::from(x) * u64::from(y) * u64::from(z);
        if invocations > u64::from(self.compute_invocations) {
            exceeded.push(format!(
                "{invocations} invocations per workgroup ({x}x{y}x{z}; `maxComputeWorkGroupInvocations` is {})",
                self.compute_invocations
            ));
        }
        exceeded
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
            Capability::RayQueryKHR => (!self.ray_query).then(|| {
                "ray queries (the `rayQuery` feature of VK_KHR_ray_query, with \
                 VK_KHR_acceleration_structure)"
                    .to_string()
            }),
            other if CORE_CAPABILITIES.contains(&other) => None,
            other => {
                let Some((operation, name)) = subgroup_operation(other) else {
                    return Some(format!(
                        "the SPIR-V capability {other:?} (not one weft enables: it needs a device feature or extension)"
                    ));
                };
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

/// The capabilities every Vulkan 1.3 device offers with no feature to enable
/// (the specification's SPIR-V environment table).
const CORE_CAPABILITIES: [Capability; 10] = [
    Capability::Matrix,
    Capability::Shader,
    Capability::InputAttachment,
    Capability::Sampled1D,
    Capability::Image1D,
    Capability::SampledBuffer,
    Capability::ImageBuffer,
    Capability::ImageQuery,
    Capability::DerivativeControl,
    Capability::StorageImageExtendedFormats,
];

/// The SPIR-V extension of ray queries, enabled with the device's
/// `VK_KHR_ray_query` where it is offered.
const RAY_QUERY_EXTENSION: &str = "SPV_KHR_ray_query";

/// SPIR-V extensions that need no device extension on Vulkan 1.3: storage
/// buffers and non-semantic debug information are core, and the Google ones
/// only annotate.
const ENABLED_EXTENSIONS: [&str; 6] = [
    "SPV_KHR_storage_buffer_storage_class",
    "SPV_KHR_non_semantic_info",
    "SPV_KHR_terminate_invocation",
    "SPV_GOOGLE_decorate_string",
    "SPV_GOOGLE_hlsl_functionality1",
    "SPV_GOOGLE_user_type",
];

/// What a module declares before its code: capabilities and extensions.
#[derive(Debug, Default, PartialEq)]
pub struct Header {
    /// `OpCapability` declarations.
    pub capabilities: Vec<Capability>,
    /// `OpExtension` names.
    pub extensions: Vec<String>,
}

/// `OpExtension`'s opcode.
const OP_EXTENSION: u32 = 10;

/// The capabilities and extensions a SPIR-V module declares, in order. They
/// come first in a module, so reading stops at the first other instruction.
pub fn read_header(spirv: &[u32]) -> Header {
    let mut header = Header::default();
    let mut at = HEADER_WORDS;
    while let Some(&word) = spirv.get(at) {
        let (count, opcode) = ((word >> 16) as usize, word & 0xffff);
        if count < 2 || at + count > spirv.len() {
            break;
        }
        match opcode {
            OP_CAPABILITY => {
                if let Some(capability) = Capability::from_u32(spirv[at + 1]) {
                    header.capabilities.push(capability);
                }
            }
            OP_EXTENSION => {
                let bytes: Vec<u8> = spirv[at + 1..at + count]
                    .iter()
                    .flat_map(|w| w.to_le_bytes())
                    .take_while(|&b| b != 0)
                    .collect();
                header
                    .extensions
                    .push(String::from_utf8_lossy(&bytes).into_owned());
            }
            _ => break,
        }
        at += count;
    }
    header
}

/// The capabilities a SPIR-V module declares, in order.
pub fn declared(spirv: &[u32]) -> Vec<Capability> {
    read_header(spirv).capabilities
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
