//! A build pass's scratch: a transient buffer sized by a scene value the
//! renderer measures, addressed by the build, and sharing memory with what
//! other passes use at other times.

use crate::support::load_files;
use std::collections::BTreeMap;
use weft_graph::plan::{Plan, ResourceDesc};
use weft_graph::vk::{Access, BufferUsage, Stage};
use weft_graph::CompileOptions;

/// A structure built in its scratch, traced into a transient image that a
/// last pass turns into the output: the scratch and the image are never
/// used at once.
const SCRATCH: &str = r#"Graph(
    scene_values: ["structure_scratch_bytes"],
    resources: [
        AccelerationStructure(name: "tlas"),
        Buffer(name: "scratch", size: "structure_scratch_bytes + 256"),
        Image(name: "lit", format: R16G16B16A16_SFLOAT),
        Image(name: "out", format: R8G8B8A8_UNORM),
    ],
    passes: [
        Pass(name: "build", kind: BuildAccelerationStructures, storage_write: ["tlas", "scratch"]),
        Pass(name: "trace", kind: Compute, shaders: (compute: "t.comp"), dispatch: Output(8, 8),
             storage_read: [(name: "tlas", enabled_if: ["ray_queries"])], storage_write: ["lit"]),
        Pass(name: "show", kind: Compute, shaders: (compute: "s.comp"), dispatch: Output(8, 8),
             storage_read: ["lit"], storage_write: ["out"]),
    ],
    output: "out",
)"#;

fn compile(scene_values: &[(&str, f64)]) -> Plan {
    let graph = load_files("g.ron", &[("g.ron", SCRATCH)]);
    let options = CompileOptions {
        features: ["ray_queries".to_string()].into(),
        scene_values: scene_values
            .iter()
            .map(|(k, v)| (k.to_string(), *v))
            .collect::<BTreeMap<_, _>>(),
        ..CompileOptions::default()
    };
    weft_graph::compile(&graph, &options).expect("compiles")
}

#[test]
fn the_scratch_is_sized_by_the_scene_and_addressed_by_the_build() {
    let plan = compile(&[("structure_scratch_bytes", 100_000.0)]);
    let scratch = plan.resource("scratch").expect("kept");
    let ResourceDesc::Buffer(desc) = &plan.resources[scratch].desc else {
        panic!("a buffer");
    };
    assert_eq!(desc.size, 100_256);
    assert_eq!(
        desc.usage,
        BufferUsage::STORAGE | BufferUsage::SHADER_DEVICE_ADDRESS
    );
    let build = plan
        .passes
        .iter()
        .find(|p| p.name == "build")
        .expect("runs");
    assert_eq!(build.scratch, Some(scratch));
    assert!(build.bindings.is_empty(), "a build binds nothing");
    // Without a scene (graph check, graph plan) a scene value is 0.
    let bare = compile(&[]);
    let ResourceDesc::Buffer(desc) = &bare.resources[bare.resource("scratch").expect("kept")].desc
    else {
        panic!("a buffer");
    };
    assert_eq!(desc.size, 256);
}

#[test]
fn the_scratch_shares_memory_with_an_image_used_at_another_time() {
    let plan = compile(&[("structure_scratch_bytes", 100_000.0)]);
    let placed = |name: &str| {
        plan.resources[plan.resource(name).expect("kept")]
            .placement
            .expect("transient")
    };
    let (scratch, lit) = (placed("scratch"), placed("lit"));
    assert_eq!((scratch.block, scratch.offset), (lit.block, lit.offset));
    assert!(plan.memory.transient_bytes < plan.memory.transient_bytes_unaliased);
    // The image takes the memory over once the build is done with it.
    let trace = plan
        .passes
        .iter()
        .find(|p| p.name == "trace")
        .expect("runs");
    let lit_id = plan.resource("lit").expect("kept");
    let handover = trace
        .barriers
        .iter()
        .find(|b| b.resource == lit_id)
        .expect("a barrier before the first write of lit");
    assert!(handover
        .src_stage
        .contains(Stage::ACCELERATION_STRUCTURE_BUILD));
    assert!(handover
        .src_access
        .contains(Access::ACCELERATION_STRUCTURE_WRITE));
}

#[test]
fn a_buffer_size_that_is_no_byte_count_is_an_error_at_the_size() {
    let text = SCRATCH.replace(
        r#"size: "structure_scratch_bytes + 256""#,
        r#"size: "65536 / structure_scratch_bytes""#,
    );
    let graph = load_files("g.ron", &[("g.ron", &text)]);
    let options = CompileOptions {
        features: ["ray_queries".to_string()].into(),
        ..CompileOptions::default()
    };
    let errors = weft_graph::compile(&graph, &options).expect_err("refused");
    assert_eq!(errors.len(), 1, "{errors:#?}");
    assert_eq!(
        errors[0].message,
        "buffer \"scratch\" size \"65536 / structure_scratch_bytes\" cannot be evaluated (division by zero at character 8) at 1280x720: a size is a byte count up to 2^48"
    );
    assert_eq!(
        errors[0].hint.as_deref(),
        Some("the graph's scene values here (0 where none was measured): structure_scratch_bytes = 0")
    );
    assert_eq!(errors[0].pos.line, 5, "at the buffer's size");
    // A value too large for any device is refused as well.
    let huge = SCRATCH.replace(
        r#"size: "structure_scratch_bytes + 256""#,
        r#"size: "pixels * pixels * pixels""#,
    );
    let graph = load_files("g.ron", &[("g.ron", &huge)]);
    let errors = weft_graph::compile(&graph, &options).expect_err("refused");
    assert_eq!(
        errors[0].message,
        "buffer \"scratch\" size \"pixels * pixels * pixels\" gives 782757789696000000 bytes at 1280x720: a size is a byte count up to 2^48"
    );
    // So is a negative one, and a number written out too large.
    let negative = SCRATCH.replace(
        r#"size: "structure_scratch_bytes + 256""#,
        r#"size: "width - 2000""#,
    );
    let graph = load_files("g.ron", &[("g.ron", &negative)]);
    let errors = weft_graph::compile(&graph, &options).expect_err("refused");
    assert!(
        errors[0]
            .message
            .contains("\"width - 2000\" gives -720 bytes at 1280x720"),
        "{}",
        errors[0].message
    );
    let literal = SCRATCH.replace(r#"size: "structure_scratch_bytes + 256""#, "size: 1e15");
    let graph = load_files("g.ron", &[("g.ron", &literal)]);
    let errors = weft_graph::compile(&graph, &options).expect_err("refused");
    assert_eq!(
        errors[0].message,
        "buffer size must be a whole number of bytes from 1 to 2^48, found 1000000000000000"
    );
}
