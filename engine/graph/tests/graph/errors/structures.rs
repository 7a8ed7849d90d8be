//! Acceleration structures and the passes that build and read them: a build
//! pass writes one structure, in one scratch buffer, and nothing else, and other passes read one
//! only through ray queries (`storage_read`), after this frame's build.

use super::{assert_error_at, errors};

/// A structure built by one pass and read by a compute pass under
/// `ray_queries`, as graphs/acceleration.ron and the tracing passes do.
const STRUCTURES: &str = r#"Graph(
    resources: [
        AccelerationStructure(name: "tlas"),
        Buffer(name: "scratch", size: 65536),
        Image(name: "out", format: R8G8B8A8_UNORM),
    ],
    passes: [
        Pass(name: "build", kind: BuildAccelerationStructures, storage_write: ["tlas", "scratch"]),
        Pass(name: "trace", kind: Compute, shaders: (compute: "t.comp"), dispatch: Output(8, 8),
             storage_read: [(name: "tlas", enabled_if: ["ray_queries"])], storage_write: ["out"]),
    ],
    output: "out",
)"#;

#[test]
fn a_structure_built_by_one_pass_and_traced_by_another_checks_clean() {
    assert_eq!(errors(STRUCTURES), Vec::new());
}

#[test]
fn structures_are_built_by_their_pass_alone_and_read_by_ray_queries() {
    let cases = [
        (
            ("kind: BuildAccelerationStructures,", r#"kind: BuildAccelerationStructures, shaders: (compute: "b.comp"),"#),
            "BuildAccelerationStructures pass \"build\" takes no `shaders`: it builds the acceleration structure it names in `storage_write`, and nothing else",
            "(compute: \"b.comp\")",
        ),
        (
            ("kind: BuildAccelerationStructures,", "kind: BuildAccelerationStructures, dispatch: Output(8, 8),"),
            "BuildAccelerationStructures pass \"build\" takes no `dispatch`: it builds the acceleration structure it names in `storage_write`, and nothing else",
            "Output(8, 8)",
        ),
        (
            (r#"storage_write: ["tlas", "scratch"]"#, r#"storage_write: ["out", "scratch"]"#),
            "BuildAccelerationStructures pass \"build\" needs exactly one `AccelerationStructure` resource in `storage_write`",
            r#"["out", "scratch"]"#,
        ),
        (
            (r#"storage_write: ["out"]),"#, r#"storage_write: ["out", "tlas"]),"#),
            "pass \"trace\" uses acceleration structure \"tlas\" as a storage write: shaders read one through ray queries (`storage_read`), and only a BuildAccelerationStructures pass writes one",
            r#""tlas"]),"#,
        ),
        (
            ("dispatch: Output(8, 8),\n", "dispatch: Output(8, 8), sampled: [\"tlas\"],\n"),
            "pass \"trace\" uses acceleration structure \"tlas\" as a sampled read: shaders read one through ray queries (`storage_read`), and only a BuildAccelerationStructures pass writes one",
            r#""tlas"],"#,
        ),
        (
            (r#"storage_write: ["tlas", "scratch"]"#, r#"storage_write: ["tlas", "scratch"], enabled_if: ["never"]"#),
            "pass \"trace\" reads \"tlas\" before anything writes it (with features [!never, ray_queries])",
            r#""tlas", enabled_if"#,
        ),
        (
            (r#"AccelerationStructure(name: "tlas"),"#, r#"AccelerationStructure(name: "tlas"), AccelerationStructure(name: "blas"),"#),
            "acceleration structures \"tlas\" and \"blas\": the scene has one, which one BuildAccelerationStructures pass builds",
            r#""blas")"#,
        ),
        (
            ("        Pass(name: \"trace\"", "        Pass(name: \"again\", kind: BuildAccelerationStructures, storage_write: [\"tlas\"], after: [\"build\"]),\n        Pass(name: \"trace\""),
            "passes \"build\" and \"again\" both build acceleration structures: the scene's are built once a frame, by one pass",
            "BuildAccelerationStructures, storage_write: [\"tlas\"], after",
        ),
        (
            (r#"storage_write: ["tlas", "scratch"]"#, r#"storage_write: ["tlas", "scratch", "out"]"#),
            "BuildAccelerationStructures pass \"build\" writes its acceleration structure and one `Buffer`, the scratch it builds in",
            r#"["tlas", "scratch", "out"]"#,
        ),
        (
            (
                r#"storage_write: ["tlas", "scratch"]"#,
                r#"storage_write: ["tlas", (name: "scratch", enabled_if: ["big"])]"#,
            ),
            "BuildAccelerationStructures pass \"build\" writes its structure and scratch whenever it runs: its writes take no `enabled_if`",
            r#"["tlas", (name"#,
        ),
        (
            (r#"storage_write: ["tlas", "scratch"]"#, r#"storage_write: ["tlas"]"#),
            "BuildAccelerationStructures pass \"build\" writes its acceleration structure and one `Buffer`, the scratch it builds in",
            r#"["tlas"]"#,
        ),
        (
            (
                r#"storage_write: ["tlas", "scratch"]"#,
                r#"storage_write: ["tlas", "a", "b"]"#,
            ),
            "BuildAccelerationStructures pass \"build\" writes its acceleration structure and one `Buffer`, the scratch it builds in",
            r#"["tlas", "a", "b"]"#,
        ),
    ];
    let two_buffers = r#"Buffer(name: "a", size: 64), Buffer(name: "b", size: 64),
        Image(name: "out""#;
    let base = STRUCTURES.replacen(r#"Image(name: "out""#, two_buffers, 1);
    assert_eq!(errors(&base), Vec::new(), "unused buffers are no error");
    for ((from, to), message, at) in cases {
        assert!(base.contains(from), "{from}");
        let text = base.replacen(from, to, 1);
        assert_error_at(&text, message, at, to);
    }
}
