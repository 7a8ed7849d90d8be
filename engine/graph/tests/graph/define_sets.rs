//! Define sets: shader defines declared once (`define_sets` in a graph or a
//! fragment) and named by passes, which add their own after them.

use crate::support::load_files;
use weft_graph::compile::CompileOptions;

const SETS: &str = r#"Graph(
    fragment: true,
    define_sets: {
        "models": [
            (name: "SPECIALISED"),
            (name: "BLINN", enabled_if: ["blinn"], draws: BlinnPhong),
            (name: "GGX", enabled_if: ["ggx"], draws: MetallicRoughness),
        ],
        "lights": [(name: "SPECIALISED"), (name: "SUNS", enabled_if: ["suns"])],
    },
)"#;

/// A graph with a mesh pass and a fullscreen pass naming `sets`, the mesh
/// pass adding `own`.
fn graph(sets: &str, own: &str) -> String {
    format!(
        r#"Graph(
    include: [(file: "sets.ron")],
    resources: [Image(name: "hdr", format: R16G16B16A16_SFLOAT), Image(name: "depth", format: D32_SFLOAT), Image(name: "ldr", format: R8G8B8A8_UNORM)],
    passes: [
        Pass(name: "mesh", kind: Raster, shaders: (vertex: "m.vert", fragment: "m.frag"),
             color: [(image: "hdr")], depth: (image: "depth"), draw: Meshes(All),
             define_sets: [{sets}], defines: [{own}]),
        Pass(name: "tonemap", kind: Fullscreen, shaders: (fragment: "t.frag"), sampled: ["hdr"],
             color: [(image: "ldr")], define_sets: [{sets}]),
    ],
    output: "ldr",
)"#
    )
}

fn load(main: &str) -> weft_graph::LoadedGraph {
    load_files(
        "/g/main.ron",
        &[("/g/sets.ron", SETS), ("/g/main.ron", main)],
    )
}

#[test]
fn a_pass_gets_its_sets_defines_then_its_own_and_draws_only_where_it_draws_meshes() {
    let loaded = load(&graph(r#""models", "lights""#, r#"(name: "EXTRA")"#));
    assert_eq!(weft_graph::check(&loaded), Vec::new());
    let options = CompileOptions {
        features: ["blinn", "ggx", "suns"]
            .iter()
            .map(|f| f.to_string())
            .collect(),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&loaded, &options).expect("compiles");
    let pass = |name: &str| plan.passes.iter().find(|p| p.name == name).expect("pass");
    let mesh = pass("mesh");
    assert_eq!(
        mesh.defines,
        ["EXTRA", "SPECIALISED", "SUNS"],
        "sorted, as variant keys are"
    );
    assert_eq!(
        mesh.model_defines,
        [
            ("BlinnPhong".to_string(), "BLINN".to_string()),
            ("MetallicRoughness".to_string(), "GGX".to_string())
        ]
    );
    let tonemap = pass("tonemap");
    assert_eq!(tonemap.defines, ["BLINN", "GGX", "SPECIALISED", "SUNS"]);
    assert!(tonemap.model_defines.is_empty());
    assert_eq!(tonemap.variants, 8, "three features decide its defines");
}

#[test]
fn an_unknown_set_is_an_error_at_its_name_with_the_nearest_set() {
    let diags = weft_graph::check(&load(&graph(r#""model""#, "")));
    let text: Vec<String> = diags.iter().map(ToString::to_string).collect();
    assert_eq!(text.len(), 2, "{text:?}");
    assert!(text[0].starts_with("/g/main.ron:7:28:"), "{text:?}");
    assert!(text[1].starts_with("/g/main.ron:9:53:"), "{text:?}");
    assert!(
        text[0].contains("unknown define set \"model\"")
            && text[0].contains("did you mean \"models\"?"),
        "{text:?}"
    );
}

#[test]
fn a_define_given_twice_under_other_conditions_is_an_error() {
    let diags = weft_graph::check(&load(&graph(
        r#""lights""#,
        r#"(name: "SUNS", enabled_if: ["!suns"])"#,
    )));
    let text: Vec<String> = diags.iter().map(ToString::to_string).collect();
    assert_eq!(text.len(), 1, "{text:?}");
    assert!(
        text[0].contains(
            "define \"SUNS\" is also in one of the pass's define sets, under other conditions"
        ),
        "{text:?}"
    );
}

#[test]
fn a_set_declared_in_two_files_is_an_error_and_one_fragment_included_twice_is_not() {
    let again = r#"Graph(fragment: true, define_sets: { "lights": [(name: "OTHER")] })"#;
    let twice = r#"Graph(
    include: [(file: "sets.ron"), (file: "again.ron"), (file: "sets.ron")],
    resources: [Image(name: "ldr", format: R8G8B8A8_UNORM)],
    passes: [Pass(name: "fill", kind: Fullscreen, shaders: (fragment: "f.frag"), color: [(image: "ldr")], define_sets: ["lights"])],
    output: "ldr",
)"#;
    let loaded = load_files(
        "/g/main.ron",
        &[
            ("/g/sets.ron", SETS),
            ("/g/again.ron", again),
            ("/g/main.ron", twice),
        ],
    );
    let text: Vec<String> = weft_graph::check(&loaded)
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(text.len(), 1, "sets.ron twice is one declaration: {text:?}");
    assert!(
        text[0].starts_with("/g/again.ron:1:")
            && text[0].contains("define set \"lights\" is declared twice")
            && text[0].contains("first at /g/sets.ron:"),
        "{text:?}"
    );
}

#[test]
fn a_set_define_that_is_no_preprocessor_name_is_an_error_at_the_set() {
    let bad =
        r#"Graph(fragment: true, define_sets: { "bad": [(name: "HAS_X"), (name: "lower")] })"#;
    let text: Vec<String> = weft_graph::check(&load_files("/g/bad.ron", &[("/g/bad.ron", bad)]))
        .iter()
        .map(ToString::to_string)
        .collect();
    assert_eq!(text.len(), 2, "{text:?}");
    assert!(
        text[0].contains("names starting HAS_ are the engine's"),
        "{text:?}"
    );
    assert!(
        text[1].contains("\"lower\" is not a preprocessor name"),
        "{text:?}"
    );
}

#[test]
fn a_set_define_with_a_value_is_an_error_at_the_pass() {
    let sets = r#"Graph(fragment: true, params: { "n": 2 },
        define_sets: { "valued": [(name: "N", value: "$n")] })"#;
    let main = r#"Graph(
    include: [(file: "sets.ron")],
    resources: [Image(name: "ldr", format: R8G8B8A8_UNORM)],
    passes: [Pass(name: "t", kind: Fullscreen, shaders: (fragment: "t.frag"), color: [(image: "ldr")],
                  define_sets: ["valued"])],
    output: "ldr",
)"#;
    let text: Vec<String> = weft_graph::check(&load_files(
        "/g/main.ron",
        &[("/g/sets.ron", sets), ("/g/main.ron", main)],
    ))
    .iter()
    .map(ToString::to_string)
    .collect();
    assert_eq!(text.len(), 1, "{text:?}");
    assert!(
        text[0].contains(
            "define set \"valued\" gives \"N\" a value; a define with a value belongs to the pass's own `defines`"
        ),
        "{text:?}"
    );
}
