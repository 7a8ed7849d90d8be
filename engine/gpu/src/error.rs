//! Errors of the Vulkan context and the executor.

use ash::vk;

/// Anything that can go wrong creating the context or running a plan.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    /// The Vulkan loader library could not be loaded.
    #[error("cannot load the Vulkan loader: {0}")]
    Loader(String),
    /// A Vulkan call failed.
    #[error("{call} failed: {result}")]
    Vulkan {
        /// The Vulkan entry point that failed.
        call: &'static str,
        /// What it returned.
        result: vk::Result,
    },
    /// Validation was requested but the Khronos layer is not installed.
    #[error(
        "validation requested but VK_LAYER_KHRONOS_validation is not installed (run tools/setup)"
    )]
    NoValidationLayer,
    /// No device matched (or none supports Vulkan 1.3 with what weft needs).
    #[error("no suitable Vulkan 1.3 device{}; available: {available}", match .wanted { Some(w) => format!(" matching \"{w}\""), None => String::new() })]
    NoDevice {
        /// The `--device` substring asked for, if any.
        wanted: Option<String>,
        /// Names of every device found.
        available: String,
    },
    /// Device memory could not be allocated.
    #[error("memory allocation for {what} failed: {message}")]
    Allocation {
        /// What the memory was for.
        what: String,
        /// The allocator's reason.
        message: String,
    },
    /// A table read through a texel buffer is larger than the device's
    /// texel buffers can be.
    #[error("{what} needs {texels} texels; this device's texel buffers hold at most {limit} (maxTexelBufferElements)")]
    TooManyTexels {
        /// What the table holds.
        what: String,
        /// Its size in texels.
        texels: u64,
        /// The device's `maxTexelBufferElements`.
        limit: u32,
    },
    /// A shader failed to compile or reflect.
    #[error(transparent)]
    Shader(#[from] crate::shader::ShaderError),
    /// The plan asks for something the executor cannot do, or is inconsistent
    /// with its shaders.
    #[error("pass `{pass}`: {message}")]
    Pass {
        /// The pass, as named in the graph.
        pass: String,
        /// What is wrong.
        message: String,
    },
    /// A pass's shaders disagree with the graph (bindings, outputs, parameters).
    #[error("pass `{pass}`: {}", problems.join("; "))]
    Mismatch {
        /// The pass, as named in the graph.
        pass: String,
        /// Every disagreement found.
        problems: Vec<String>,
    },
    /// The plan itself is inconsistent.
    #[error("plan: {0}")]
    Plan(String),
    /// Something the device does not offer.
    #[error("{what} need {needs}, which the device `{device}` does not offer")]
    Unsupported {
        /// What was asked for.
        what: String,
        /// The device, by name.
        device: String,
        /// The extensions or features it would need.
        needs: String,
    },
}

/// Extension that turns `VkResult` errors into `GpuError::Vulkan` naming the
/// call: the one conversion every crate uses (`result.call("vkCreateX")`).
pub trait VkCall<T> {
    /// Labels a failed call.
    fn call(self, call: &'static str) -> Result<T, GpuError>;
}

impl<T> VkCall<T> for Result<T, vk::Result> {
    fn call(self, call: &'static str) -> Result<T, GpuError> {
        self.map_err(|result| GpuError::Vulkan { call, result })
    }
}
