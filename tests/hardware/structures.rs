//! The mutation test over the acceleration-structure passes, on a device
//! with ray queries: each edit of graphs/acceleration.ron, of the path
//! tracer's reads of the structure or of the include that brings it in is
//! either refused by `weft graph check --shaders` (which checks the
//! hardware variants on such a device), refused by the hardware render (a
//! scratch too small for the scene, which a check without a scene cannot
//! know), or renders the Cornell box on both backends with zero validation
//! messages, synchronization validation on.
//! Each edit says which it must be, so a check that stops refusing a broken
//! graph fails here as surely as a render that breaks.

use std::path::Path;
use weft_graph::plan::Extent;
use weft_render::{check_graph_and_shaders, render, RenderSettings, ShaderTarget, TraceBackend};
use weft_tests::render::root;
use weft_tests::TempDir;

/// What an edit must lead to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expect {
    /// `graph check --shaders` reports an error whose message holds this.
    Refused(&'static str),
    /// Check accepts, and the hardware backend's render fails for this reason.
    RenderRefused(&'static str),
    /// Check accepts, and both backends render clean.
    Rendered,
}

/// One edit: the file under the repository, the text replaced (every
/// occurrence) and its replacement, and what it must lead to.
const EDITS: &[(&str, &str, &str, Expect)] = &[
    // The build pass writes nothing.
    (
        "graphs/acceleration.ron",
        "storage_write: [\"scene_structures\", \"structure_scratch\"],",
        "",
        Expect::Refused("needs exactly one `AccelerationStructure` resource in `storage_write`"),
    ),
    // The build pass becomes a compute pass.
    (
        "graphs/acceleration.ron",
        "kind: BuildAccelerationStructures",
        "kind: Compute",
        Expect::Refused("Compute pass \"build_structures\" needs a compute shader"),
    ),
    // The structure becomes a buffer.
    (
        "graphs/acceleration.ron",
        "AccelerationStructure(name: \"scene_structures\")",
        "Buffer(name: \"scene_structures\", size: 64)",
        Expect::Refused("needs exactly one `AccelerationStructure` resource in `storage_write`"),
    ),
    // The build reads what it should write.
    (
        "graphs/acceleration.ron",
        "storage_write",
        "storage_read",
        Expect::Refused("takes no `storage_read`"),
    ),
    // The build is off while the traces read it.
    (
        "graphs/acceleration.ron",
        "storage_write: [\"scene_structures\", \"structure_scratch\"],",
        "storage_write: [\"scene_structures\", \"structure_scratch\"], enabled_if: [\"never\"],",
        Expect::Refused("reads \"scene_structures\" before anything writes it"),
    ),
    // The path tracer traces in hardware without reading the structure.
    (
        "graphs/path_tracer.ron",
        "(name: \"scene_structures\", enabled_if: [\"ray_queries\"]), ",
        "",
        Expect::Refused(
            "is the scene's acceleration structure, which a pass traces against only when it \
             reads one the plan builds",
        ),
    ),
    // The path tracer reads the structure where the software walk traces.
    (
        "graphs/path_tracer.ron",
        "[\"ray_queries\"]",
        "[\"!ray_queries\"]",
        Expect::Refused("builds acceleration structures without `ray_queries`"),
    ),
    // The graph does not include the structure its fragment reads.
    (
        "graphs/pathtrace.ron",
        "(file: \"acceleration.ron\"),",
        "",
        Expect::Refused("needs resource \"scene_structures\""),
    ),
    // The build without its scratch.
    (
        "graphs/acceleration.ron",
        "[\"scene_structures\", \"structure_scratch\"]",
        "[\"scene_structures\"]",
        Expect::Refused(
            "writes its acceleration structure and one `Buffer`, the scratch it builds in",
        ),
    ),
    // The scratch sized by a scene value the renderer does not measure.
    (
        "graphs/acceleration.ron",
        "scene_values: [\"structure_scratch_bytes\"]",
        "scene_values: [\"structure_scratch_byte\"]",
        Expect::Refused("unknown scene value `structure_scratch_byte`"),
    ),
    // The scratch half what the builds need: the check cannot know the
    // scene, the build pass refuses it before recording.
    (
        "graphs/acceleration.ron",
        "size: \"structure_scratch_bytes\"",
        "size: \"structure_scratch_bytes / 2\"",
        Expect::RenderRefused("bytes of scratch, and its scratch buffer holds"),
    ),
    // The build pass renamed: nothing names it.
    (
        "graphs/acceleration.ron",
        "\"build_structures\"",
        "\"build_tlas\"",
        Expect::Rendered,
    ),
    // The trace ordered after the build by name as well as by data.
    (
        "graphs/path_tracer.ron",
        "derive: [RayTracing()],",
        "derive: [RayTracing()], after: [\"build_structures\"],",
        Expect::Rendered,
    ),
];

/// Copies `from` into `to`, folders and all.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("folder");
    for entry in std::fs::read_dir(from).expect("readable") {
        let path = entry.expect("entry").path();
        let target = to.join(path.file_name().expect("name"));
        if path.is_dir() {
            copy_tree(&path, &target);
        } else {
            std::fs::copy(&path, &target).expect("copy");
        }
    }
}

/// What a graph led to: the check's errors, one per line, a render's
/// error, or a render on both backends.
#[derive(Debug)]
enum Outcome {
    Refused(String),
    RenderRefused(String),
    Rendered,
}

/// What `graph` leads to: refused by the check on `gpu`'s device, refused
/// by a render, or rendered on both backends; a render that validates with
/// messages panics.
fn outcome(gpu: &weft_gpu::Gpu, graph: &Path, label: &str) -> Outcome {
    let loaded = weft_graph::load(graph);
    let diags = check_graph_and_shaders(&loaded, &ShaderTarget::of(gpu)).expect("check runs");
    let errors: Vec<String> = diags
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.to_string())
        .collect();
    if !errors.is_empty() {
        return Outcome::Refused(errors.join("\n"));
    }
    let scene = weft_scene::load_scene(&root().join("scenes/cornell.scene")).expect("loads");
    for backend in [TraceBackend::Hardware, TraceBackend::Software] {
        let before = gpu.validation().messages().len();
        let settings = RenderSettings {
            graph: graph.to_path_buf(),
            extent: Extent {
                width: 16,
                height: 16,
            },
            frames: 2,
            trace_backend: backend,
            ..RenderSettings::default()
        };
        if let Err(e) = render(gpu, &scene, &settings) {
            return Outcome::RenderRefused(format!("{backend:?}: {e}"));
        }
        let messages = gpu.validation().messages();
        assert_eq!(
            messages[before..].len(),
            0,
            "{label} {backend:?}: {:?}",
            &messages[before..]
        );
    }
    Outcome::Rendered
}

#[test]
fn every_edit_of_the_structure_passes_is_refused_by_check_or_renders_clean() {
    let gpu = crate::gpu();
    for (i, &(file, from, to, expected)) in EDITS.iter().enumerate() {
        let tree = TempDir::new(&format!("structure-mutant-{i}"));
        for folder in ["graphs", "shaders"] {
            copy_tree(&root().join(folder), &tree.0.join(folder));
        }
        let text = std::fs::read_to_string(root().join(file)).expect("readable");
        assert!(text.contains(from), "{file} holds {from:?}");
        std::fs::write(tree.0.join(file), text.replace(from, to)).expect("written");
        let label = format!("{file}: {from:?} -> {to:?}");
        let graph = tree.0.join("graphs/pathtrace.ron");
        match (expected, outcome(&gpu, &graph, &label)) {
            (Expect::Refused(because), Outcome::Refused(errors)) => {
                assert!(
                    errors.contains(because),
                    "{label}: refused, but for {errors}"
                );
            }
            (Expect::RenderRefused(because), Outcome::RenderRefused(error)) => {
                assert!(
                    error.contains(because),
                    "{label}: render refused, but for {error}"
                );
            }
            (Expect::Rendered, Outcome::Rendered) => {}
            (expected, found) => panic!("{label}: expected {expected:?}, found {found:?}"),
        }
    }
}

/// A frame that fails after its build pass recorded never runs that build:
/// the scene records it again at the next frame, rather than trace a top
/// level that was never built; a build that was submitted counts.
#[test]
fn a_build_recorded_into_a_frame_never_submitted_is_recorded_again() {
    let gpu = crate::gpu();
    let log = gpu.validation();
    let scene = weft_scene::load_scene(&root().join("scenes/cornell.scene")).expect("loads");
    let mut uploaded = weft_render::GpuScene::new(&gpu, &scene, false).expect("uploads");
    uploaded.trace_in_hardware(true).expect("hardware");
    let bytes = weft_render::structure_scratch_bytes(&gpu, &scene).expect("measured");
    let scratch = weft_gpu::acceleration::Scratch::new(&gpu, bytes).expect("scratch");
    // The frame's build pass records; a later pass fails, so nothing is submitted.
    let failed = gpu.one_shot(|cmd| {
        uploaded.record_structures("build_structures", cmd, scratch.span())?;
        Err(weft_gpu::GpuError::Plan("a later pass failed".into()))
    });
    assert!(failed.is_err());
    uploaded.forget_unsubmitted_structures();
    let rebuilt = uploaded.build_structures_now().expect("builds");
    assert!(
        rebuilt.bottom_build > std::time::Duration::ZERO,
        "the bottom levels are built again"
    );
    let after = uploaded.build_structures_now().expect("nothing to build");
    assert_eq!(after.bottom_build, std::time::Duration::ZERO, "built once");
    // What the scene value says before the scene is on the device is what
    // the structures built from its geometry need.
    assert_eq!(rebuilt.scratch_bytes, bytes);
    drop(scratch);
    drop(uploaded);
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
}
