//! Helpers shared by the GPU tests: a validating context and plan compilation
//! with the device's real memory requirements.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use weft_gpu::{image_requirements, Gpu, GpuOptions};
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

/// Compiles a fixture graph for the device, at the given size.
pub fn compile(gpu: &Gpu, path: &Path, width: u32, height: u32) -> Plan {
    let loaded = weft_graph::load(path);
    let memory = |d: &weft_graph::plan::ImageDesc| image_requirements(gpu, d);
    let options = CompileOptions {
        extent: Extent { width, height },
        features: BTreeSet::new(),
        lights: 1,
        memory: &memory,
    };
    match weft_graph::compile(&loaded, &options) {
        Ok(plan) => plan,
        Err(diagnostics) => panic!("{} does not compile: {diagnostics:?}", path.display()),
    }
}
