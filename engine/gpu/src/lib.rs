//! Vulkan execution of compiled weft render graphs: the context, run-time
//! shader compilation and reflection, and the executor that runs a `Plan`.

pub mod context;
pub mod error;
pub mod reflect;
pub mod shader;
pub mod validation;

pub use context::{DeviceInfo, DeviceKind, Gpu, GpuOptions, MemoryReport};
pub use error::GpuError;
pub use shader::{CompiledShader, ShaderCompiler, ShaderDiagnostic, ShaderError, ShaderStage};
pub use validation::{Severity, ValidationCounts, ValidationLog, ValidationMessage};
