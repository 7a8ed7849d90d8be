//! Mutants once accepted by `check` and refused by a render, pinned: each
//! must stay refused by check.

use super::*;

/// Two mutants `check --shaders` once accepted and a render then refused
/// (issue 60): a binding moved in a pass that runs only when the scene has
/// spot lights and shadow casters and shadows are not traced, and an
/// `Absolute` size on the denoiser's history, which its copy meets only at
/// render. Both are refused by check now, located at their pass.
#[test]
fn passes_under_scene_features_and_copies_of_unequal_sizes_are_refused_by_check() {
    let gpu = weft_tests::gpu();
    let scene = weft_scene::load_scene(&demo_scene()).expect("demo scene");
    for (file, from, to, graph, expected) in [
        (
            "shaders/deferred_spot.frag",
            "layout(set = 0, binding = 4) uniform sampler2DShadow shadow_map;",
            "layout(set = 0, binding = 0) uniform sampler2DShadow shadow_map;",
            "deferred.ron",
            "pass \"spot_lights\": graph resource `gbuffer_albedo` is bound to nothing",
        ),
        (
            "graphs/denoise.ron",
            r#"Image(name: "moments_prev", format: R32G32B32A32_SFLOAT, history: true),"#,
            r#"Image(name: "moments_prev", format: R32G32B32A32_SFLOAT, history: true, size: Absolute(64, 64)),"#,
            "pathtrace_denoised.ron",
            "copy pass \"keep_moments\": `moments` is 1280x720 and `moments_prev` 64x64 at output size 1280x720; a copy needs equal sizes (a Blit scales)",
        ),
    ] {
        let text = std::fs::read_to_string(root().join(file)).expect("read");
        assert!(text.contains(from), "{file} changed");
        let tree = Tree::new("scene-features");
        std::fs::write(tree.0.join(file), text.replacen(from, to, 1)).expect("write mutant");
        let loaded = weft_graph::load(&tree.0.join("graphs").join(graph));
        let diags = check_graph_and_shaders(&loaded, &ShaderTarget::of(&gpu)).expect("check runs");
        let errors: Vec<&str> = diags
            .iter()
            .filter(|d| d.is_error())
            .map(|d| d.message.as_str())
            .collect();
        assert!(
            errors.iter().any(|m| m.starts_with(expected)),
            "{file}: {errors:?}"
        );
        let outcome = run_mutant(&gpu, &scene, &tree.0.join("graphs").join(graph))
            .unwrap_or_else(|problem| panic!("{file}: {problem}"));
        assert!(matches!(outcome, Outcome::Refused), "{file}");
    }
}
