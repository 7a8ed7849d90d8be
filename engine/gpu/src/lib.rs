//! Vulkan execution of compiled weft render graphs: the context, run-time
//! shader compilation and reflection, and the executor that runs a `Plan`.

#![warn(missing_docs)]

pub mod acceleration;
pub mod bind;
pub mod buffer;
pub mod capabilities;
pub mod check;
pub mod commands;
pub mod context;
pub mod convert;
pub mod descriptors;
mod download;
pub mod draw;
pub mod error;
pub mod executor;
mod frame;
pub mod graphics;
pub mod layouts;
pub mod pipeline;
pub mod present;
pub mod ray_query;
pub mod readback;
pub mod record;
pub mod reflect;
pub mod renderpass;
pub mod resources;
pub mod samplers;
pub mod scene;
pub mod scene_check;
pub mod sets;
pub mod shader;
pub mod spirv_cache;
pub mod state;
pub mod statistics;
pub mod swapchain;
pub mod texture;
pub mod timing;
pub mod validation;
pub mod workgroup;

pub use capabilities::ShaderSupport;
pub use check::ShaderProblem;
pub use context::{DeviceInfo, DeviceKind, Gpu, GpuOptions, MemoryReport};
pub use draw::{DrawRecorder, NoDraws, RasterContext};
pub use error::{GpuError, VkCall};
pub use executor::shader_check::check_shaders;
pub use executor::{FrameOptions, FrameReport, Renderer};
pub use present::{Capture, Overlay, OverlayTarget, PresentSource, Presented, Presenter};
pub use readback::{Pixels, Readback};
pub use resources::{
    image_requirements, memory_requirements, oversized_images, unsupported_sample_counts,
    FrameResources,
};
pub use sets::{MATERIAL_SET, SCENE_SET};
pub use shader::{CompiledShader, ShaderCompiler, ShaderDiagnostic, ShaderError, ShaderStage};
pub use statistics::PassStatistics;
pub use swapchain::Swapchain;
pub use timing::{format_timings, PassTiming, TimingMode, TimingSource};
pub use validation::{Severity, ValidationCounts, ValidationLog, ValidationMessage};
