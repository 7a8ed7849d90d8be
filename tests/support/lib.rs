//! Helpers for the end-to-end tests in `tests/e2e/`: a validating context,
//! paths of the repository's graphs and this package's fixtures, and plans
//! compiled as the renderer compiles them (provider values included).

pub mod gltf;
pub mod legend;
pub mod render;

use std::path::{Path, PathBuf};
use weft_gpu::{memory_requirements, Gpu, GpuOptions};
use weft_graph::plan::{Extent, Plan};
use weft_graph::CompileOptions;

/// A context with validation and synchronization validation on.
pub fn gpu() -> Gpu {
    share_compiled_shaders();
    Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("a Vulkan 1.3 device with the validation layer (run tools/setup)")
}

/// Keeps compiled shaders in `target/e2e-spirv` (weft_gpu::spirv_cache),
/// so a shader variant the tests compile once is not compiled again by the
/// next test or graph mutant that uses it: the cache key covers the whole
/// preprocessed source, defines, target and compiler version, so an edited
/// shader (a mutant, a hot-reload test's edit) is always compiled afresh.
fn share_compiled_shaders() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        weft_gpu::spirv_cache::set_dir(Some(repo().join("target").join("e2e-spirv")));
    });
}

/// The repository root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the repository")
        .to_path_buf()
}

/// Path of a fixture graph in `tests/graphs/`.
pub fn graph(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("graphs")
        .join(name)
}

/// Path of a graph shipped in the repository's `graphs/`.
pub fn shipped(name: &str) -> PathBuf {
    repo().join("graphs").join(name)
}

/// Path of a golden image in `tests/golden/`.
pub fn golden(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("golden")
        .join(name)
}

/// Compiles a graph as the renderer does, for `gpu`'s memory requirements,
/// with features requested as on the command line (`name`, `!name`) and
/// extra images to read back.
pub fn compile(
    gpu: &Gpu,
    path: &Path,
    extent: Extent,
    features: &[&str],
    readback: Vec<String>,
) -> Plan {
    let graph = weft_graph::Prepared::new(weft_graph::load(path))
        .unwrap_or_else(|d| panic!("{} does not load: {d:?}", path.display()));
    let memory = memory_requirements(gpu);
    let options = CompileOptions {
        extent,
        features: graph.graph().features(features),
        memory: &memory,
        scene_values: Default::default(),
        readback,
        readback_asked: true,
    };
    weft_render::compile_plan(&graph, &options)
        .unwrap_or_else(|d| panic!("{} does not compile: {d:?}", path.display()))
}

/// Destroys the context (so leak reports at destruction count too) and asserts
/// the validation layer said nothing.
pub fn assert_no_validation_messages(gpu: Gpu) {
    let log = gpu.validation();
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
}

/// A scratch folder under the system's temporary one, removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    /// `weft-NAME-PID`, created.
    pub fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("weft-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("scratch folder");
        Self(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
