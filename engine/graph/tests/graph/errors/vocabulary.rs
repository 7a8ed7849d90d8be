//! Located errors for scene names the renderer's vocabulary does not hold:
//! mesh filters, light kinds, shading models, and the features caveats and
//! the camera jitter test.

use super::*;
use weft_graph::vocabulary::{check_vocabulary, SceneFeature, SceneValue, SceneVocabulary};

/// A vocabulary as a renderer might register one (the real one is
/// weft-render's, checked against every shipped graph by `weft graph check`).
const SCENES: SceneVocabulary = SceneVocabulary {
    features: &[
        SceneFeature {
            name: "suns",
            reason: "the scene has a sun",
        },
        SceneFeature {
            name: "transparent",
            reason: "a placed mesh blends",
        },
    ],
    values: &[SceneValue {
        name: "structure_scratch_bytes",
        meaning: "bytes a build of the scene's acceleration structures works in",
    }],
    mesh_filters: &["All", "Opaque", "Transparent"],
    light_volumes: &["Point", "Spot"],
    shading_models: &["BlinnPhong", "MetallicRoughness"],
};

fn vocabulary_errors(text: &str) -> Vec<Diagnostic> {
    let graph = load_files("g.ron", &[("g.ron", text)]);
    assert!(!graph.has_errors(), "{:#?}", graph.diagnostics);
    check_vocabulary(&graph, &SCENES)
}

/// `edit` applied to [`VALID`] gives exactly one error, `message` with
/// `hint`, located where the text starts with `at`.
fn assert_vocabulary_error(edit: (&str, &str), message: &str, hint: &str, at: &str) {
    assert!(VALID.contains(edit.0), "{}", edit.0);
    let text = VALID.replacen(edit.0, edit.1, 1);
    let found = vocabulary_errors(&text);
    assert_eq!(found.len(), 1, "{}: {found:#?}", edit.1);
    let d = &found[0];
    assert_eq!(d.message, message);
    assert_eq!(d.hint.as_deref(), Some(hint));
    assert!(
        text_at(&text, d).starts_with(at),
        "{message}: at {:?}",
        text_at(&text, d)
    );
}

#[test]
fn the_shipped_names_of_a_valid_graph_are_all_known() {
    assert_eq!(vocabulary_errors(VALID), Vec::<Diagnostic>::new());
}

#[test]
fn an_unknown_mesh_filter_or_light_kind_is_an_error_at_the_draw() {
    assert_vocabulary_error(
        ("Meshes(Opaque)", "Meshes(Opaqe)"),
        "unknown mesh filter `Opaqe`",
        "did you mean `Opaque`?",
        "Meshes(Opaqe)",
    );
    assert_vocabulary_error(
        ("Meshes(Opaque)", "LightVolumes(Area)"),
        "unknown light kind `Area`",
        "scenes offer: Point, Spot",
        "LightVolumes(Area)",
    );
}

#[test]
fn an_unknown_shading_model_is_an_error_at_its_draws_in_a_pass_or_a_set() {
    assert_vocabulary_error(
        (
            "draw: Meshes(Opaque),",
            r#"draw: Meshes(Opaque), defines: [(name: "A"), (name: "B", draws: Phong)],"#,
        ),
        "unknown shading model `Phong`",
        "scenes offer: BlinnPhong, MetallicRoughness",
        "Phong)",
    );
    assert_vocabulary_error(
        (
            "Graph(",
            r#"Graph(define_sets: { "models": [(name: "M", draws: MetalicRoughness)] },"#,
        ),
        "unknown shading model `MetalicRoughness`",
        "did you mean `MetallicRoughness`?",
        "MetalicRoughness)",
    );
}

#[test]
fn a_scene_value_is_one_the_renderer_measures_and_sizes_buffers_once_declared() {
    assert_vocabulary_error(
        (
            "Graph(",
            r#"Graph(scene_values: ["structure_scratch_bytes", "scratch_bytes"],"#,
        ),
        "unknown scene value `scratch_bytes`",
        "scenes offer: structure_scratch_bytes (bytes a build of the scene's acceleration structures works in)",
        r#""scratch_bytes"]"#,
    );
    // A size expression may use a declared value, and no other.
    let sized = |declared: &str| {
        VALID.replacen(
            "Graph(\n    resources: [",
            &format!(
                "Graph(\n    scene_values: [{declared}],\n    resources: [\n        Buffer(name: \"s\", size: \"structure_scratch_bytes * 2\"),"
            ),
            1,
        )
    };
    let declared = sized(r#""structure_scratch_bytes""#);
    assert_eq!(vocabulary_errors(&declared), Vec::<Diagnostic>::new());
    assert_eq!(errors(&declared), Vec::<Diagnostic>::new());
    let undeclared = sized("");
    let found = errors(&undeclared);
    assert_eq!(found.len(), 1, "{found:#?}");
    assert!(
        found[0].message.contains("structure_scratch_bytes"),
        "{}",
        found[0].message
    );
}

#[test]
fn caveats_and_jitter_name_features_the_graph_has_or_scenes_set() {
    assert_vocabulary_error(
        (
            "Graph(",
            r#"Graph(caveats: [(note: "sky", enabled_if: ["sunz"])],"#,
        ),
        "caveat condition \"sunz\" names a feature neither this graph nor scenes set",
        "did you mean \"suns\"?",
        r#"["sunz"]"#,
    );
    assert_vocabulary_error(
        (
            "Graph(",
            r#"Graph(jitter: [(enabled_if: ["!transparnt"])],"#,
        ),
        "jitter condition \"!transparnt\" names a feature neither this graph nor scenes set",
        "did you mean \"transparent\"?",
        r#"["!transparnt"]"#,
    );
    // A feature a pass uses is known, and so is one scenes set, which no
    // pass need use.
    let known = VALID
        .replacen(
            "Graph(",
            r#"Graph(caveats: [(note: "glow", enabled_if: ["!glow"]), (note: "sky", enabled_if: ["suns"])],"#,
            1,
        )
        .replacen(
            "draw: Meshes(Opaque),",
            r#"draw: Meshes(Opaque), defines: [(name: "GLOW", enabled_if: ["glow"])],"#,
            1,
        );
    assert_eq!(vocabulary_errors(&known), Vec::<Diagnostic>::new());
}
