//! One test per class of graph error: the message, the exact line and column, and
//! the hint. Each location is also checked to point at the offending text.

use crate::support;

use support::{check_text, load_files};
use weft_graph::{Diagnostic, Severity};

mod multisample;
mod structures;
mod values;
mod vocabulary;

/// The text at a diagnostic's position, up to the end of its line.
fn text_at<'a>(text: &'a str, d: &Diagnostic) -> &'a str {
    let line = text
        .lines()
        .nth(d.pos.line as usize - 1)
        .expect("line exists");
    let start = line
        .char_indices()
        .nth(d.pos.col as usize - 1)
        .map(|(i, _)| i)
        .unwrap_or(line.len());
    &line[start..]
}

fn errors(text: &str) -> Vec<Diagnostic> {
    check_text(text)
        .into_iter()
        .filter(Diagnostic::is_error)
        .collect()
}

/// Asserts that checking `text` reports the error `message` at a position
/// where the text starts with `at`; `label` names the case in failures.
fn assert_error_at(text: &str, message: &str, at: &str, label: &str) {
    let found = errors(text);
    let d = found
        .iter()
        .find(|d| d.message == message)
        .unwrap_or_else(|| panic!("{label}: expected \"{message}\", got {found:#?}"));
    assert!(
        text_at(text, d).starts_with(at),
        "{label}: located at {:?}",
        text_at(text, d)
    );
}

fn only_error(text: &str) -> Diagnostic {
    let mut errors = errors(text);
    assert_eq!(
        errors.len(),
        1,
        "expected exactly one error, got {errors:#?}"
    );
    errors.remove(0)
}

const VALID: &str = r#"Graph(
    resources: [
        Image(name: "albedo", format: R8G8B8A8_UNORM),
        Image(name: "depth", format: D32_SFLOAT),
        Image(name: "ldr", format: R8G8B8A8_SRGB),
    ],
    passes: [
        Pass(
            name: "gbuffer",
            kind: Raster,
            shaders: (vertex: "a.vert", fragment: "a.frag"),
            color: [(image: "albedo", load: Clear([0.0, 0.0, 0.0, 1.0]))],
            depth: (image: "depth", load: Clear([0.0])),
            draw: Meshes(Opaque),
        ),
        Pass(
            name: "resolve",
            kind: Fullscreen,
            shaders: (fragment: "b.frag"),
            sampled: ["albedo", "depth"],
            color: [(image: "ldr")],
        ),
    ],
    output: "ldr",
)"#;

#[test]
fn the_valid_base_graph_checks_clean() {
    assert_eq!(check_text(VALID), Vec::<Diagnostic>::new());
}

#[test]
fn ron_syntax_error_is_located() {
    let text = VALID.replace("kind: Raster,", "kind: Raster");
    let d = only_error(&text);
    assert_eq!((d.pos.line, d.pos.col), (11, 13));
    assert!(d.message.starts_with("RON syntax: "), "{}", d.message);
    assert!(text_at(&text, &d).starts_with("shaders:"));
}

#[test]
fn unknown_field_is_a_syntax_error_naming_the_expected_fields() {
    let text = VALID.replace("draw: Meshes", "drwa: Meshes");
    let d = only_error(&text);
    assert_eq!((d.pos.line, d.pos.col), (14, 13));
    assert!(d.message.contains("drwa"), "{}", d.message);
}

#[test]
fn unknown_resource_has_a_did_you_mean_hint() {
    let text = VALID.replace(r#"sampled: ["albedo""#, r#"sampled: ["albdo""#);
    let d = only_error(&text);
    assert_eq!(d.message, r#"unknown resource "albdo""#);
    assert_eq!((d.pos.line, d.pos.col), (20, 23));
    assert_eq!(text_at(&text, &d), r#""albdo", "depth"],"#);
    assert_eq!(d.hint.as_deref(), Some(r#"did you mean "albedo"?"#));
}

#[test]
fn unknown_pass_in_after() {
    let text = VALID.replace(
        r#"kind: Fullscreen,"#,
        r#"kind: Fullscreen, after: ["gbufer"],"#,
    );
    let d = only_error(&text);
    assert_eq!(d.message, r#"unknown pass "gbufer""#);
    assert_eq!(text_at(&text, &d), r#""gbufer"],"#);
    assert_eq!(d.hint.as_deref(), Some(r#"did you mean "gbuffer"?"#));
}

#[test]
fn unknown_format_has_a_hint_and_all_of_them_are_reported() {
    let text = VALID
        .replace("R8G8B8A8_UNORM", "R8G8B8A8_UNROM")
        .replace("D32_SFLOAT", "D32_FLOAT");
    let errs = errors(&text);
    assert_eq!(errs.len(), 2, "{errs:#?}");
    assert_eq!(errs[0].message, r#"unknown format "R8G8B8A8_UNROM""#);
    assert_eq!((errs[0].pos.line, errs[0].pos.col), (3, 39));
    assert_eq!(
        errs[0].hint.as_deref(),
        Some(r#"did you mean "R8G8B8A8_UNORM"?"#)
    );
    assert_eq!(errs[1].message, r#"unknown format "D32_FLOAT""#);
    assert_eq!(
        errs[1].hint.as_deref(),
        Some(r#"did you mean "D32_SFLOAT"?"#)
    );
}

#[test]
fn unknown_parameter_reference() {
    let text = VALID.replace(
        "draw: Meshes(Opaque),",
        r#"draw: Meshes(Opaque), params: { "bias": "$bais" },"#,
    );
    let text = text.replacen("Graph(", r#"Graph(params: { "bias": 0.5 },"#, 1);
    let d = only_error(&text);
    assert_eq!(d.message, r#"unknown parameter "$bais""#);
    assert_eq!(text_at(&text, &d), r#""$bais" },"#);
    assert_eq!(d.hint.as_deref(), Some(r#"did you mean "$bias"?"#));
}

#[test]
fn depth_format_as_colour_attachment() {
    let text = VALID.replace(r#"color: [(image: "ldr")]"#, r#"color: [(image: "depth")]"#);
    let errs = errors(&text);
    let d = errs
        .iter()
        .find(|d| d.message.contains("used as a colour attachment"))
        .expect("depth-as-colour error");
    assert_eq!(
        d.message,
        r#"depth format D32_SFLOAT of "depth" used as a colour attachment"#
    );
    assert_eq!((d.pos.line, d.pos.col), (21, 29));
    assert_eq!(text_at(&text, d), r#""depth")],"#);
}

#[test]
fn colour_format_as_depth_attachment() {
    let text = VALID.replace(r#"depth: (image: "depth""#, r#"depth: (image: "albedo""#);
    let errs = errors(&text);
    let d = errs
        .iter()
        .find(|d| d.message.contains("used as a depth attachment"))
        .expect("colour-as-depth error");
    assert_eq!(
        d.message,
        r#"colour format R8G8B8A8_UNORM of "albedo" used as a depth attachment"#
    );
    assert_eq!(text_at(&text, d), r#""albedo", load: Clear([0.0])),"#);
    assert_eq!(
        d.hint.as_deref(),
        Some("use a depth format such as D32_SFLOAT")
    );
}

#[test]
fn format_that_cannot_be_used_that_way() {
    let text = VALID.replace(
        r#"Image(name: "albedo", format: R8G8B8A8_UNORM)"#,
        r#"Image(name: "albedo", format: E5B9G9R9_UFLOAT_PACK32)"#,
    );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        r#"format E5B9G9R9_UFLOAT_PACK32 of "albedo" cannot be used as a colour attachment: Vulkan does not guarantee it"#
    );
    assert_eq!((d.pos.line, d.pos.col), (12, 29));
    assert!(d
        .hint
        .as_deref()
        .unwrap_or("")
        .starts_with("formats that can: R8_UNORM"));

    let blended = VALID
        .replace(
            r#"color: [(image: "ldr")]"#,
            r#"color: [(image: "ldr", blend: Additive)]"#,
        )
        .replace(
            r#"Image(name: "ldr", format: R8G8B8A8_SRGB)"#,
            r#"Image(name: "ldr", format: R32G32B32A32_SFLOAT)"#,
        );
    let d = only_error(&blended);
    assert_eq!(
        d.message,
        r#"format R32G32B32A32_SFLOAT of "ldr" cannot be used as a blended colour attachment: Vulkan does not guarantee it"#
    );

    let storage = VALID
        .replace(
            r#"sampled: ["albedo", "depth"],"#,
            r#"sampled: ["depth"], storage_read: ["albedo"],"#,
        )
        .replace("R8G8B8A8_UNORM", "R8G8B8A8_SRGB");
    let d = only_error(&storage);
    assert_eq!(
        d.message,
        r#"format R8G8B8A8_SRGB of "albedo" cannot be used as a storage image: Vulkan does not guarantee it"#
    );
    assert_eq!(text_at(&storage, &d), r#""albedo"],"#);
}

#[test]
fn attachments_of_different_sizes() {
    let text = VALID.replace(
        r#"Image(name: "depth", format: D32_SFLOAT)"#,
        r#"Image(name: "depth", format: D32_SFLOAT, size: Scale(0.5, 0.5))"#,
    );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        r#"attachments of pass "gbuffer" differ in size: "albedo" is 1920x1080 (1 sample(s)) but "depth" is 960x540 (1 sample(s)) at output 1920x1080"#
    );
    assert_eq!(text_at(&text, &d), r#""depth", load: Clear([0.0])),"#);

    // Sizes that coincide at one output size only are still different.
    let text = VALID.replace(
        r#"Image(name: "depth", format: D32_SFLOAT)"#,
        r#"Image(name: "depth", format: D32_SFLOAT, size: Absolute(1920, 1080))"#,
    );
    let d = only_error(&text);
    assert!(d.message.ends_with("at output 1280x720"), "{}", d.message);
}

#[test]
fn resource_read_before_anything_writes_it() {
    let text = VALID
        .replace(
            r#"Image(name: "ldr", format: R8G8B8A8_SRGB),"#,
            r#"Image(name: "ldr", format: R8G8B8A8_SRGB), Image(name: "noise", format: R8_UNORM),"#,
        )
        .replace(
            r#"sampled: ["albedo", "depth"]"#,
            r#"sampled: ["albedo", "depth", "noise"]"#,
        );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        r#"pass "resolve" reads "noise" before anything writes it"#
    );
    assert_eq!(text_at(&text, &d), r#""noise"],"#);
    assert_eq!(
        d.hint.as_deref(),
        Some("add a pass that writes it, or mark it `history: true` to read last frame's contents")
    );

    let load = VALID.replace(
        r#"color: [(image: "albedo", load: Clear([0.0, 0.0, 0.0, 1.0]))]"#,
        r#"color: [(image: "albedo", load: Load)]"#,
    );
    let d = only_error(&load);
    assert_eq!(
        d.message,
        r#"pass "gbuffer" reads "albedo" before anything writes it"#
    );
    assert_eq!(
        d.hint.as_deref(),
        Some("use `load: Clear(...)` or `load: DontCare` for the first pass that writes it")
    );
}

#[test]
fn two_writers_without_order() {
    let text = VALID.replace(
        "    ],\n    output:",
        r#"        Pass(
            name: "overlay",
            kind: Fullscreen,
            shaders: (fragment: "c.frag"),
            color: [(image: "ldr", load: Load, blend: Alpha)],
        ),
    ],
    output:"#,
    );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        r#"passes "resolve" and "overlay" both write "ldr" with no order between them"#
    );
    assert_eq!(text_at(&text, &d), r#""overlay","#);
    assert_eq!(
        d.hint.as_deref(),
        Some(r#"add `after: ["resolve"]` to "overlay""#)
    );
    let fixed = text.replace(
        r#"shaders: (fragment: "c.frag"),"#,
        r#"shaders: (fragment: "c.frag"), after: ["resolve"],"#,
    );
    assert_eq!(errors(&fixed), Vec::<Diagnostic>::new());
}

#[test]
fn cycle() {
    let text = VALID.replace(
        r#"draw: Meshes(Opaque),"#,
        r#"draw: Meshes(Opaque), after: ["resolve"],"#,
    );
    let d = only_error(&text);
    assert_eq!(
        d.message,
        r#"passes form a cycle: gbuffer -> resolve -> gbuffer"#
    );
    assert_eq!((d.pos.line, d.pos.col), (9, 19));
}

#[test]
fn missing_include() {
    let root = VALID.replacen("Graph(", r#"Graph(include: [(file: "nope.ron")],"#, 1);
    let g = load_files("dir/g.ron", &[("dir/g.ron", &root)]);
    let diags = weft_graph::check(&g);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(
        diags[0].to_string(),
        "dir/g.ron:1:24: error: included file \"dir/nope.ron\" cannot be read: No such file or directory (os error 2)\n  hint: include paths are relative to the including file"
    );
}

#[test]
fn include_cycle() {
    let a = r#"Graph(fragment: true, include: [(file: "b.ron")])"#;
    let b = r#"Graph(fragment: true, include: [(file: "a.ron")])"#;
    let g = load_files("a.ron", &[("a.ron", a), ("b.ron", b)]);
    let diags = weft_graph::check(&g);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(diags[0].file.to_str(), Some("b.ron"));
    assert_eq!(
        diags[0].message,
        "\"a.ron\" includes itself: a.ron -> b.ron -> a.ron"
    );
    assert_eq!((diags[0].pos.line, diags[0].pos.col), (1, 40));

    let selfish = r#"Graph(fragment: true, include: [(file: "s.ron")])"#;
    let g = load_files("s.ron", &[("s.ron", selfish)]);
    assert_eq!(
        weft_graph::check(&g)[0].message,
        "\"s.ron\" includes itself: s.ron -> s.ron"
    );
}

#[test]
fn no_output() {
    let text = VALID.replace("    output: \"ldr\",\n", "");
    let d = only_error(&text);
    assert_eq!(d.message, "the graph has no output");
    assert_eq!(
        d.hint.as_deref(),
        Some("add `output: \"ldr\"` naming the image to present")
    );
}

#[test]
fn include_overrides_unknown_parameter() {
    let frag = r#"Graph(fragment: true, params: { "resolution": 1024 })"#;
    let root = VALID.replacen(
        "Graph(",
        r#"Graph(include: [(file: "f.ron", params: { "resolutoin": 2048 })],"#,
        1,
    );
    let g = load_files("g.ron", &[("g.ron", &root), ("f.ron", frag)]);
    let diags = weft_graph::check(&g);
    assert_eq!(diags.len(), 1, "{diags:#?}");
    assert_eq!(
        diags[0].message,
        "unknown parameter \"resolutoin\" for \"f.ron\""
    );
    assert_eq!(
        diags[0].hint.as_deref(),
        Some("did you mean \"resolution\"?")
    );
    assert_eq!((diags[0].pos.line, diags[0].pos.col), (1, 43));
    assert!(text_at(&root, &diags[0]).starts_with(r#""resolutoin": 2048"#));
}

#[test]
fn every_error_is_collected_not_just_the_first() {
    let text = VALID
        .replace(r#"sampled: ["albedo""#, r#"sampled: ["albdo""#)
        .replace("D32_SFLOAT", "D32_SFLAOT")
        .replace(r#"output: "ldr""#, r#"output: "ldrr""#);
    let messages: Vec<String> = errors(&text).into_iter().map(|d| d.message).collect();
    assert_eq!(
        messages,
        [
            r#"unknown format "D32_SFLAOT""#,
            r#"unknown resource "albdo""#,
            r#"unknown output "ldrr""#,
        ]
    );
}

/// The valid graph with one more pass, `name`, writing an image `scratch`
/// that nothing reads.
fn with_scratch_writer(name: &str) -> String {
    VALID
        .replace(
            "    ],\n    output:",
            &format!(
                r#"        Pass(
            name: "{name}",
            kind: Fullscreen,
            shaders: (fragment: "d.frag"),
            color: [(image: "scratch")],
        ),
    ],
    output:"#
            ),
        )
        .replace(
            r#"Image(name: "ldr", format: R8G8B8A8_SRGB),"#,
            r#"Image(name: "ldr", format: R8G8B8A8_SRGB), Image(name: "scratch", format: R8_UNORM),"#,
        )
}

#[test]
fn warnings_for_unread_resources_and_culled_passes() {
    let text = with_scratch_writer("debug");
    let diags = check_text(&text);
    let warnings: Vec<String> = diags
        .iter()
        .filter(|d| d.severity == Severity::Warning)
        .map(|d| d.message.clone())
        .collect();
    assert_eq!(
        warnings,
        [r#"pass "debug" is culled: it contributes nothing to the output"#]
    );
    assert_eq!(diags.len(), 1);
}

/// An `enabled_if` entry with an empty alternative is an error (a read's
/// condition is reported at its pass); alternatives themselves (`a|!b`)
/// check clean.
#[test]
fn a_condition_with_an_empty_alternative() {
    let read = |condition: &str| {
        VALID.replace(
            r#"sampled: ["albedo", "depth"],"#,
            &format!(r#"sampled: ["albedo", (name: "depth", enabled_if: ["{condition}"])],"#),
        )
    };
    let good = read("spot_lights|!rt");
    assert!(errors(&good).is_empty(), "{:#?}", errors(&good));
    let text = read("spot_lights||!rt");
    let d = only_error(&text);
    assert!(
        d.message
            .starts_with(r#"condition "spot_lights||!rt" has an empty alternative"#),
        "{}",
        d.message
    );
    assert_eq!(text_at(&text, &d), r#""resolve","#);
}

/// A pass whose output only a conditional read takes is culled without a
/// warning where that read is off: another feature set needs it. One that
/// no feature set needs is still warned about (above).
#[test]
fn a_pass_some_feature_set_needs_is_culled_elsewhere_without_a_warning() {
    let text = with_scratch_writer("extra_input").replace(
        r#"sampled: ["albedo", "depth"],"#,
        r#"sampled: ["albedo", "depth", (name: "scratch", enabled_if: ["extra"])],"#,
    );
    assert_eq!(check_text(&text), Vec::<Diagnostic>::new(), "{text}");
}
