//! Including a whole graph: the includer builds on it (the bench graphs add
//! floor passes to a shipped graph), taking its output and read-backs.

use crate::support::load_files;
use std::path::Path;
use weft_graph::compile::CompileOptions;

const BASE: &str = r#"Graph(
    name: "base",
    resources: [Image(name: "hdr", format: R16G16B16A16_SFLOAT), Image(name: "ldr", format: R8G8B8A8_UNORM)],
    passes: [
        Pass(name: "shade", kind: Fullscreen, shaders: (fragment: "s.frag"), color: [(image: "hdr")]),
        Pass(name: "tonemap", kind: Fullscreen, shaders: (fragment: "t.frag"), sampled: ["hdr"], color: [(image: "ldr")]),
    ],
    output: "ldr",
    readback: ["hdr"],
)"#;

const FLOOR: &str = r#"Graph(
    fragment: true,
    inputs: ["hdr"],
    resources: [Image(name: "floor", format: R8G8B8A8_UNORM)],
    passes: [Pass(name: "floor", kind: Fullscreen, shaders: (fragment: "f.frag"), sampled: ["hdr"], color: [(image: "floor")])],
)"#;

#[test]
fn a_graph_including_a_whole_graph_takes_its_name_output_and_read_backs() {
    let bench = r#"Graph(include: [(file: "base.ron"), (file: "floor.ron")], readback: ["floor"])"#;
    let graph = load_files(
        "/g/bench.ron",
        &[
            ("/g/base.ron", BASE),
            ("/g/floor.ron", FLOOR),
            ("/g/bench.ron", bench),
        ],
    );
    assert_eq!(weft_graph::check(&graph), Vec::new());
    assert_eq!(graph.name, "base");
    assert_eq!(graph.output.as_deref(), Some("ldr"));
    assert_eq!(graph.readback_names(), ["floor", "hdr"]);
    let options = CompileOptions {
        readback: graph.readback_names(),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    let passes: Vec<&str> = plan.passes.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(passes, ["shade", "tonemap", "floor"]);
}

#[test]
fn an_included_graphs_other_output_is_ignored_with_a_warning() {
    let bench = r#"Graph(
    name: "bench",
    include: [(file: "base.ron")],
    output: "hdr",
)"#;
    let graph = load_files(
        "/g/bench.ron",
        &[("/g/base.ron", BASE), ("/g/bench.ron", bench)],
    );
    assert_eq!(graph.name, "bench");
    assert_eq!(graph.output.as_deref(), Some("hdr"));
    let warnings: Vec<String> = graph.diagnostics.iter().map(|d| d.to_string()).collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("/g/base.ron:8:13")
            && warnings[0].contains("this included graph's output \"ldr\" is ignored"),
        "{warnings:?}"
    );
}

#[test]
fn the_bench_graphs_include_the_shipped_ones_which_include_no_bench_file() {
    let graphs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../graphs");
    for shipped in ["forward", "deferred", "tiled"] {
        let graph = weft_graph::load(&graphs.join(format!("{shipped}.ron")));
        assert!(
            graph
                .sources
                .iter()
                .all(|s| !s.file.starts_with(graphs.join("bench"))),
            "{shipped} includes a bench file"
        );
        let bench = weft_graph::load(&graphs.join(format!("bench/{shipped}_floors.ron")));
        assert_eq!(weft_graph::check(&bench), Vec::new());
        assert_eq!(bench.output, graph.output);
        assert!(bench
            .readback_names()
            .contains(&"floor_mesh_color".to_string()));
        assert!(bench.readback_names().contains(&"hdr".to_string()));
    }
}
