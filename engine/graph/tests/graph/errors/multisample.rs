//! Multisampled attachments and their resolve targets: a valid 4x graph
//! compiles into a render pass that resolves, and each misuse is refused at
//! the text that causes it.

use super::assert_error_at;
use crate::support::{check_text, load_files};
use weft_graph::{CompileOptions, Diagnostic};

/// A G-buffer pass drawing 4 samples per pixel and resolving its colour
/// into `albedo`, which the next pass samples.
const MSAA: &str = r#"Graph(
    resources: [
        Image(name: "albedo_samples", format: R8G8B8A8_UNORM, samples: 4),
        Image(name: "albedo", format: R8G8B8A8_UNORM),
        Image(name: "depth", format: D32_SFLOAT, samples: 4),
        Image(name: "ldr", format: R8G8B8A8_SRGB),
    ],
    passes: [
        Pass(
            name: "gbuffer",
            kind: Raster,
            shaders: (vertex: "a.vert", fragment: "a.frag"),
            color: [(image: "albedo_samples", load: Clear([0.0, 0.0, 0.0, 1.0]), resolve: "albedo")],
            depth: (image: "depth", load: Clear([0.0])),
            draw: Meshes(Opaque),
        ),
        Pass(
            name: "show",
            kind: Fullscreen,
            shaders: (fragment: "b.frag"),
            sampled: ["albedo"],
            color: [(image: "ldr")],
        ),
    ],
    output: "ldr",
)"#;

#[test]
fn a_resolving_pass_checks_clean_and_compiles_to_a_resolve_attachment() {
    assert_eq!(check_text(MSAA), Vec::<Diagnostic>::new());
    let graph = load_files("g.ron", &[("g.ron", MSAA)]);
    let plan = weft_graph::compile(&graph, &CompileOptions::default()).expect("compiles");
    let gbuffer = plan
        .passes
        .iter()
        .find(|p| p.name == "gbuffer")
        .expect("pass");
    let rp = gbuffer.render_pass.as_ref().expect("a render pass");
    let names: Vec<(&str, u32)> = rp
        .attachments
        .iter()
        .map(|a| (plan.resources[a.resource].name.as_str(), a.samples))
        .collect();
    assert_eq!(names, [("albedo_samples", 4), ("albedo", 1), ("depth", 4)]);
    assert_eq!(
        (rp.color.clone(), rp.resolve.clone()),
        (vec![0], vec![Some(1)])
    );
    // Nothing reads the samples after the resolve: they need not be stored.
    assert_eq!(rp.attachments[0].store, weft_graph::plan::StoreOp::DontCare);
    assert_eq!(rp.attachments[1].store, weft_graph::plan::StoreOp::Store);
}

#[test]
fn sample_counts_and_resolve_targets_that_do_not_fit_are_refused_where_written() {
    let cases = [
        (
            r#"Image(name: "depth", format: D32_SFLOAT, samples: 4)"#,
            r#"Image(name: "depth", format: D32_SFLOAT, samples: 2)"#,
            "attachments of pass \"gbuffer\" differ in size: \"albedo_samples\" is 1920x1080 (4 sample(s)) but \"depth\" is 1920x1080 (2 sample(s)) at output 1920x1080",
            "\"depth\", load",
        ),
        (
            r#"Image(name: "albedo", format: R8G8B8A8_UNORM)"#,
            r#"Image(name: "albedo", format: R8G8B8A8_UNORM, samples: 4)"#,
            "resolve target \"albedo\" has 4 samples; a resolve target has 1",
            "\"albedo\")]",
        ),
        (
            r#"Image(name: "albedo", format: R8G8B8A8_UNORM)"#,
            r#"Image(name: "albedo", format: R16G16B16A16_SFLOAT)"#,
            "resolve target \"albedo\" is R16G16B16A16_SFLOAT but colour attachment \"albedo_samples\" is R8G8B8A8_UNORM: a resolve keeps the format",
            "\"albedo\")]",
        ),
        (
            r#"Image(name: "albedo", format: R8G8B8A8_UNORM)"#,
            r#"Image(name: "albedo", format: R8G8B8A8_UNORM, size: Scale(0.5, 0.5))"#,
            "resolve target \"albedo\" is 960x540 but colour attachment \"albedo_samples\" is 1920x1080 at output 1920x1080",
            "\"albedo\")]",
        ),
        (
            r#"sampled: ["albedo"]"#,
            r#"sampled: ["albedo_samples"]"#,
            "multisampled image \"albedo_samples\" (4 samples) cannot be sampled: shaders and transfers see one sample per texel",
            "\"albedo_samples\"]",
        ),
        (
            r#"depth: (image: "depth", load: Clear([0.0])),"#,
            r#"depth: (image: "depth", load: Clear([0.0]), resolve: "albedo"),"#,
            "a depth attachment cannot resolve (Vulkan 1.0 render passes resolve colour only)",
            "\"albedo\"),",
        ),
        (
            r#"resolve: "albedo")"#,
            r#"resolve: "albdo")"#,
            "unknown resource \"albdo\"",
            "\"albdo\")",
        ),
        (
            r#"format: R8G8B8A8_UNORM, samples: 4)"#,
            r#"format: R8G8B8A8_UNORM, samples: 3)"#,
            "samples must be 1, 2, 4, 8, 16, 32 or 64, found 3",
            "3)",
        ),
    ];
    for (from, to, message, at) in cases {
        assert!(MSAA.contains(from), "{from}");
        let text = MSAA.replacen(from, to, 1);
        assert_error_at(&text, message, at, to);
    }
    // Without samples to resolve, the resolve is refused too.
    let single = MSAA
        .replacen(r#"R8G8B8A8_UNORM, samples: 4)"#, "R8G8B8A8_UNORM)", 1)
        .replacen(r#"D32_SFLOAT, samples: 4)"#, "D32_SFLOAT)", 1);
    assert_error_at(
        &single,
        "colour attachment \"albedo_samples\" has 1 sample, so there is nothing to resolve into \"albedo\"",
        "\"albedo\")]",
        "one sample",
    );
}
