//! Helpers shared by the GPU tests: a validating context and plan compilation
//! with the device's real memory requirements.
// Each test crate compiles this module and uses only some of it.

use std::path::{Path, PathBuf};
use weft_gpu::{memory_requirements, Gpu, GpuOptions};
use weft_graph::plan::{Extent, Plan};
use weft_graph::CompileOptions;

/// A context with validation and synchronization validation on.
pub fn gpu() -> Gpu {
    Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("a Vulkan 1.3 device with the validation layer (run tools/setup)")
}

/// Path of a fixture graph.
pub fn graph(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/graphs")
        .join(name)
}

/// Compiles a graph for the device at the given size with its default features.
pub fn compile(gpu: &Gpu, path: &Path, width: u32, height: u32) -> Plan {
    compile_with(gpu, path, width, height, &[])
}

/// Compiles a graph with features requested as on the command line (`name`, `!name`).
pub fn compile_with(gpu: &Gpu, path: &Path, width: u32, height: u32, features: &[&str]) -> Plan {
    let loaded = weft_graph::load(path);
    let memory = memory_requirements(gpu);
    let options = CompileOptions {
        extent: Extent { width, height },
        features: loaded.features(features),
        memory: &memory,
        ..CompileOptions::default()
    };
    match weft_graph::compile(&loaded, &options) {
        Ok(plan) => plan,
        Err(diagnostics) => panic!("{} does not compile: {diagnostics:?}", path.display()),
    }
}

/// Renders `frames` frames of a plan without scene draws and reads the output back.
pub fn render_readback(gpu: &Gpu, plan: &Plan, frames: u32) -> weft_gpu::FrameReport {
    let mut renderer = weft_gpu::Renderer::new(gpu).expect("renderer");
    let options = weft_gpu::FrameOptions {
        readback: true,
        ..weft_gpu::FrameOptions::default()
    };
    weft_testkit::render_frames(
        &mut renderer,
        plan,
        &mut weft_gpu::NoDraws,
        frames,
        0.0,
        &options,
    )
    .expect("frames render")
}

/// Destroys the context (so leak reports at destruction count too) and asserts
/// the validation layer said nothing.
pub fn assert_no_validation_messages(gpu: Gpu) {
    let log = gpu.validation();
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
}
