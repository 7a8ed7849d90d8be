//! Located errors for values out of range, caveats, progressive sample
//! counts, defines and conditional attachments.

use super::*;

/// A graph with one compute pass writing the output, for dispatch rules.
const COMPUTE: &str = r#"Graph(
    resources: [
        Image(name: "img", format: R8G8B8A8_UNORM),
    ],
    passes: [
        Pass(
            name: "fill",
            kind: Compute,
            shaders: (compute: "c.comp"),
            storage_write: ["img"],
            dispatch: Output(8, 8),
        ),
    ],
    output: "img",
)"#;

/// Values the GPU would reject, or silently misuse, are errors at the line that
/// gives them: each case is (base graph, edit, message, text at the location).
#[test]
fn out_of_range_values_are_located_errors() {
    let cases: [(&str, (&str, &str), &str, &str); 25] = [
        (VALID, (r#"load: Clear([0.0])"#, r#"load: Clear([2.0])"#),
            "a depth clear must be in [0, 1], found 2", "Clear([2.0])"),
        (VALID, (r#"load: Clear([0.0])"#, r#"load: Clear([NaN])"#),
            "a depth clear must be in [0, 1], found NaN", "Clear([NaN])"),
        (VALID, (r#"load: Clear([0.0])"#, r#"load: Clear([inf])"#),
            "a depth clear must be in [0, 1], found inf", "Clear([inf])"),
        (VALID, (r#"Clear([0.0, 0.0, 0.0, 1.0])"#, r#"Clear([0.0, NaN, 0.0, 1.0])"#),
            "clear values must be finite numbers, found NaN", "Clear([0.0, NaN"),
        (VALID, (r#"load: Clear([0.0]))"#, r#"load: DontCare, read_only: true)"#),
            "a read-only depth attachment tests against earlier depth, so it needs `load: Load`", "DontCare"),
        (VALID, (r#"format: R8G8B8A8_UNORM)"#, r#"format: R8G8B8A8_UNORM, mips: 4)"#),
            "\"albedo\" has 4 mip level(s) and 1 layer(s), but attachments render to a single mip level and layer", "\"albedo\", load"),
        (VALID, (r#"format: R8G8B8A8_UNORM)"#, r#"format: R8G8B8A8_UNORM, size: Like("ldr", 1.0, 4294967296))"#),
            "scale (1, 4294967296) must be in (0, 16]", "Like("),
        (VALID, (r#"format: R8G8B8A8_UNORM)"#, r#"format: R8G8B8A8_UNORM, size: Like("ldr", NaN, 1.0))"#),
            "a scale must be a finite number, found NaN", "Like("),
        (VALID, (r#"format: R8G8B8A8_UNORM)"#, r#"format: R8G8B8A8_UNORM, size: Scale(16.0, 16.0))"#),
            "\"albedo\" would be 30720x17280 at output size 1920x1080, over the 16384 pixels an image side may have", "Scale("),
        (VALID, ("draw: Meshes(Opaque),", r#"draw: Meshes(Opaque), params: { "bias": NaN },"#),
            "parameter \"bias\" must be a finite 32-bit float (at most 3.4e38 in size), found NaN", "NaN },"),
        (VALID, ("Graph(", r#"Graph(params: { "scale": [1.0, inf] },"#),
            "parameter \"scale\" must be a finite 32-bit float (at most 3.4e38 in size), found inf", "[1.0, inf] },"),
        (VALID, ("Graph(", r#"Graph(params: { "boost": 1e39 },"#),
            "parameter \"boost\" must be a finite 32-bit float (at most 3.4e38 in size), found 1e39", "1e39 },"),
        (VALID, ("draw: Meshes(Opaque),", r#"draw: Meshes(Opaque), raster: (depth_bias: (NaN, 1.0)),"#),
            "a depth bias must be a finite number, found NaN", "(NaN, 1.0)"),
        (VALID, ("kind: Fullscreen,", "kind: Fullscreen, raster: (cull: Back),"),
            "a Fullscreen pass has no raster state (only Raster passes draw triangles with it)", "(cull: Back)"),
        (VALID, (r#"            depth: (image: "depth", load: Clear([0.0])),
"#, "            raster: (depth_compare: Less),\n"),
            "`depth_compare` needs a depth attachment, and the pass has none", "Less)"),
        (VALID, (r#"            depth: (image: "depth", load: Clear([0.0])),
"#, "            raster: (depth_clamp: true),\n"),
            "`depth_clamp` needs a depth attachment, and the pass has none", "true)"),
        (VALID, (r#"format: R8G8B8A8_UNORM)"#, r#"format: R8G8B8A8_UNORM, history: true, persistent: true)"#),
            "\"albedo\" is both `history` (read before this frame writes it) and `persistent` (written, then read); choose one", "true)"),
        (VALID, ("draw: Meshes(Opaque),", r#"draw: Meshes(Opaque), defines: [(name: "D0", enabled_if: ["f0"]), (name: "D1", enabled_if: ["f1"]), (name: "D2", enabled_if: ["f2"]), (name: "D3", enabled_if: ["f3"]), (name: "D4", enabled_if: ["f4"]), (name: "D5", enabled_if: ["f5"]), (name: "D6", enabled_if: ["f6"]), (name: "D7", enabled_if: ["f7"]), (name: "D8", enabled_if: ["f8"]), (name: "D9", enabled_if: ["f9"]), (name: "D10", enabled_if: ["f10"]), (name: "D11", enabled_if: ["f11"]), (name: "D12", enabled_if: ["f12"]), (name: "D13", enabled_if: ["f13"]), (name: "D14", enabled_if: ["f14"]), (name: "D15", enabled_if: ["f15"]), (name: "D16", enabled_if: ["f16"])],"#),
            "pass \"gbuffer\" has shader defines decided by 17 features: up to 131072 variants, more than the 65536 a pass may have", "\"gbuffer\""),
        (VALID, ("Graph(", r#"Graph(views: [(name: "v", image: "albedo", threshold: 1)],"#),
            "view \"v\" reads image \"albedo\" of format R8G8B8A8_UNORM; views summarise R32_UINT or R32_SFLOAT", r#""albedo", threshold"#),
        (VALID, ("Graph(", r#"Graph(views: [(name: "v", image: "albdo", threshold: 1)],"#),
            "unknown resource \"albdo\"", r#""albdo", threshold"#),
        (VALID, (r#"output: "ldr","#, r#"output: "ldr", readback: ["ldr", "albdo"],"#),
            "unknown resource \"albdo\"", r#""albdo"]"#),
        (COMPUTE, ("Output(8, 8)", "Output(0, 16)"),
            "work-group sizes must be at least 1, found 0", "Output(0, 16)"),
        (COMPUTE, ("Output(8, 8)", "Groups(1, 70000, 1)"),
            "group counts must be from 1 to 65535, found 70000", "Groups("),
        (COMPUTE, ("Output(8, 8)", r#"Indirect("img", 10)"#),
            "an indirect dispatch's stride must be a multiple of 4 of at least 12 bytes (three u32 group counts), found 10", "Indirect("),
        (COMPUTE, ("Output(8, 8)", r#"Indirect("img", 16)"#),
            "an indirect dispatch reads its group counts from a buffer; \"img\" is an image", "Indirect("),
    ];
    for (base, (from, to), message, at) in cases {
        assert!(base.contains(from), "{from}");
        let text = base.replacen(from, to, 1);
        assert_error_at(&text, message, at, to);
    }
}

#[test]
fn caveats_need_a_note_and_well_formed_conditions() {
    let cases = [
        (
            r#"Graph(caveats: [(note: " ")],"#,
            "a caveat's note is empty",
            r#"" ")]"#,
        ),
        (
            r#"Graph(jitter: [(enabled_if: ["bloom|"])],"#,
            "condition \"bloom|\" has an empty alternative: write features (`a`), negations (`!a`) and alternatives joined by `|` (`a|!b`)",
            r#"["bloom|"]"#,
        ),
    ];
    for (edit, message, at) in cases {
        let text = VALID.replacen("Graph(", edit, 1);
        assert_error_at(&text, message, at, edit);
    }
    // Whether a caveat's feature exists is the scene vocabulary's question
    // (errors/vocabulary.rs): the graph alone does not know scenes' features.
    let scene_feature = VALID.replacen(
        "Graph(",
        r#"Graph(caveats: [(note: "no sky", enabled_if: ["suns"])],"#,
        1,
    );
    assert_eq!(errors(&scene_feature), Vec::<Diagnostic>::new());
}

#[test]
fn progressive_samples_per_frame_must_be_a_whole_number_in_range() {
    let graph = |value: &str| {
        VALID.replace(
            r#"    output: "ldr","#,
            &format!("    output: \"ldr\",\n    params: {{ \"spf\": 0.5 }},\n    progressive: (samples_per_frame: {value}),"),
        )
    };
    let text = graph("0");
    let d = only_error(&text);
    assert_eq!(
        d.message,
        "samples_per_frame must be a whole number from 1 to 4096, found 0"
    );
    assert!(text_at(&text, &d).starts_with("0)"), "{d:?}");
    let d = only_error(&graph("\"$spf\""));
    assert_eq!(
        d.message,
        "samples_per_frame must be a whole number from 1 to 4096, found 0.5"
    );
    let d = only_error(&graph("\"$spp\""));
    assert_eq!(d.message, "unknown parameter \"$spp\"");
    assert_eq!(d.hint.as_deref(), Some("did you mean \"$spf\"?"));
    assert!(check_text(&graph("16")).is_empty());
}

#[test]
fn a_define_must_be_a_preprocessor_name_the_engine_does_not_own() {
    let graph = |name: &str| {
        VALID.replace(
            r#"draw: Meshes(Opaque),"#,
            &format!("draw: Meshes(Opaque),\n            defines: [(name: \"{name}\", enabled_if: [\"x\"])],"),
        )
    };
    let text = graph("scene-mirrors");
    let d = only_error(&text);
    assert_eq!(
        d.message,
        "define \"scene-mirrors\" is not a preprocessor name: use capitals, digits and underscores"
    );
    assert!(text_at(&text, &d).starts_with("\"scene-mirrors\""), "{d:?}");
    let d = only_error(&graph("HAS_X"));
    assert!(
        d.message.contains("names starting HAS_ are the engine's"),
        "{d:?}"
    );
    assert_eq!(
        d.hint.as_deref(),
        Some("choose another prefix, e.g. SCENE_")
    );
    assert!(errors(&graph("SCENE_MIRRORS")).is_empty());
}

#[test]
fn a_define_value_is_a_whole_number_or_a_parameter_holding_one() {
    let graph = |value: &str| {
        VALID
            .replacen("Graph(", r#"Graph(params: { "choice": 2, "scale": 0.5, "on": true },"#, 1)
            .replace(
                r#"draw: Meshes(Opaque),"#,
                &format!("draw: Meshes(Opaque),\n            defines: [(name: \"CHOICE\", value: {value})],"),
            )
    };
    assert!(errors(&graph("\"$choice\"")).is_empty());
    assert!(errors(&graph("3")).is_empty());
    let text = graph("\"$scale\"");
    let d = only_error(&text);
    assert_eq!(
        d.message,
        "define \"CHOICE\": its value must be a whole number from -2147483648 to 2147483647 (a GLSL int), found 0.5"
    );
    assert!(text_at(&text, &d).starts_with("\"$scale\""), "{d:?}");
    let d = only_error(&graph("\"$on\""));
    assert_eq!(
        d.message,
        "define \"CHOICE\": its value must be a whole number from -2147483648 to 2147483647 (a GLSL int), found true"
    );
    // A whole number past a GLSL int would reach the compiler as "numeric
    // literal too big".
    let d = only_error(&graph("4294967296"));
    assert_eq!(
        d.message,
        "define \"CHOICE\": its value must be a whole number from -2147483648 to 2147483647 (a GLSL int), found 4294967296"
    );
    let d = only_error(&graph("\"$choise\""));
    assert_eq!(
        d.message,
        "define \"CHOICE\": unknown parameter \"$choise\""
    );
}

#[test]
fn a_define_for_one_shading_model_needs_a_pass_that_draws_meshes() {
    let on_meshes = VALID.replace(
        r#"draw: Meshes(Opaque),"#,
        "draw: Meshes(Opaque),\n            defines: [(name: \"SCENE_PBR\", draws: MetallicRoughness)],",
    );
    assert!(errors(&on_meshes).is_empty());
    let text = VALID.replace(
        r#"color: [(image: "ldr")],"#,
        "color: [(image: \"ldr\")],\n            defines: [(name: \"SCENE_PBR\", draws: MetallicRoughness)],",
    );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        "define \"SCENE_PBR\": `draws` groups a pass's mesh draws by shading model, and pass `resolve` draws no meshes"
    );
    assert!(text_at(&text, &d).starts_with("MetallicRoughness"), "{d:?}");
    assert_eq!(
        d.hint.as_deref(),
        Some("remove `draws`, or give the pass `draw: Meshes(...)`")
    );
}

#[test]
fn conditional_colour_attachments_come_last_and_depth_is_never_conditional() {
    let text = VALID.replace(
        r#"color: [(image: "albedo", load: Clear([0.0, 0.0, 0.0, 1.0]))],"#,
        r#"color: [(image: "ldr", enabled_if: ["x"]), (image: "albedo", load: Clear([0.0, 0.0, 0.0, 1.0]))],"#,
    );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        "colour attachment \"albedo\" follows the conditional attachment \"ldr\": its fragment output location would depend on features"
    );
    assert!(text_at(&text, &d).starts_with("\"albedo\""), "{d:?}");
    assert_eq!(
        d.hint.as_deref(),
        Some("list conditional colour attachments last")
    );
    let text = VALID.replace(
        r#"depth: (image: "depth", load: Clear([0.0])),"#,
        r#"depth: (image: "depth", load: Clear([0.0]), enabled_if: ["x"]),"#,
    );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        "a depth attachment cannot be conditional: make the pass conditional instead"
    );
    assert!(text_at(&text, &d).starts_with("[\"x\"]"), "{d:?}");
}

#[test]
fn repeat_is_a_whole_number_in_range_on_compute_passes_only() {
    let graph = |value: &str| {
        COMPUTE
            .replace("Output(8, 8),", &format!("Output(8, 8), repeat: {value},"))
            .replace(
                "    output: \"img\",",
                "    output: \"img\",\n    params: { \"n\": 2.5 },",
            )
    };
    for (value, found) in [("0", "0"), ("4097", "4097"), ("\"$n\"", "2.5")] {
        let text = graph(value);
        let d = only_error(&text);
        assert_eq!(
            d.message,
            format!("repeat must be a whole number from 1 to 4096, found {found}")
        );
        assert!(text_at(&text, &d).starts_with(value), "{d:?}");
    }
    assert!(check_text(&graph("64")).is_empty());
    let fullscreen = VALID.replacen("kind: Fullscreen,", "kind: Fullscreen, repeat: 2,", 1);
    let d = only_error(&fullscreen);
    assert!(
        d.message.starts_with("only compute passes repeat; pass \"")
            && d.message.ends_with("\" is Fullscreen"),
        "{d:?}"
    );
    assert!(text_at(&fullscreen, &d).starts_with("2,"), "{d:?}");
}
