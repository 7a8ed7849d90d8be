//! The `weft graph` commands as a user runs them: exit codes, messages on stderr,
//! JSON stats, and DOT output.

use crate::harness::{repo, weft};
use std::path::PathBuf;

fn temp_graph(name: &str, text: &str) -> PathBuf {
    let dir = crate::harness::scratch(&format!("weft-cli-{}-{name}", std::process::id()));
    let path = dir.join("g.ron");
    std::fs::write(&path, text).expect("write graph");
    path
}

#[test]
fn check_passes_on_shipped_graphs() {
    let out = weft(&[
        "graph",
        "check",
        "graphs/forward.ron",
        "graphs/deferred.ron",
        "graphs/shadows.ron",
        "graphs/bloom.ron",
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert_eq!(
        stderr
            .lines()
            .filter(|l| l.ends_with(": ok (0 warning(s))"))
            .count(),
        4,
        "{stderr}"
    );
}

#[test]
fn check_fails_with_located_errors_on_stderr() {
    let path = temp_graph(
        "bad",
        r#"Graph(
    resources: [Image(name: "hdr", format: R16G16B16A16_SFLOT)],
    passes: [Pass(name: "a", kind: Fullscreen, shaders: (fragment: "a.frag"), color: [(image: "hrd")])],
    output: "hdr",
)"#,
    );
    let out = weft(&["graph", "check", path.to_str().expect("utf-8 path")]);
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    let stderr = String::from_utf8_lossy(&out.stderr);
    let file = path.display();
    assert!(stderr.contains(&format!("{file}:2:44: error: unknown format \"R16G16B16A16_SFLOT\"\n  hint: did you mean \"R16G16B16A16_SFLOAT\"?")), "{stderr}");
    assert!(
        stderr.contains(&format!(
            "{file}:3:95: error: unknown resource \"hrd\"\n  hint: did you mean \"hdr\"?"
        )),
        "{stderr}"
    );
    assert!(stderr.contains("2 error(s), 0 warning(s)"), "{stderr}");
}

#[test]
fn plan_json_has_stats() {
    let out = weft(&[
        "graph",
        "plan",
        "graphs/deferred.ron",
        "--size",
        "1920x1080",
        "--features",
        "shadow_casters,point_lights",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let stats = &json["stats"];
    assert_eq!(stats["passes"], 8);
    // The acceleration-structure build (nothing traces in hardware),
    // bloom_naive_h/v, area_lights, area_light_panels, transparent, rt_ao,
    // gi, rt_specular, the 12 passes of the debug views and the denoiser's
    // 14, ReSTIR's 5 and the radiance cache's 4 (all off).
    assert_eq!(stats["culled"], 45);
    assert!(stats["barriers"].as_u64().expect("barriers") > 10);
    let aliased = stats["transient_bytes"].as_u64().expect("bytes");
    let unaliased = stats["transient_bytes_unaliased"].as_u64().expect("bytes");
    assert!(aliased < unaliased, "{aliased} < {unaliased}");
    assert!(stats["compile_us"].as_f64().expect("time") > 0.0);
    assert_eq!(json["extent"]["width"], 1920);
    assert_eq!(json["culled"][0]["name"], "build_structures");
    assert_eq!(json["culled"][41]["name"], "spot_lights");
}

#[test]
fn plan_text_lists_culled_passes_and_barriers() {
    let out = weft(&[
        "graph",
        "plan",
        "graphs/forward.ron",
        "--features",
        "!bloom",
    ]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success());
    assert!(
        text.starts_with("plan \"forward\" at 1280x720, features []\n"),
        "{text}"
    );
    assert!(
        text.contains("culled:\n  build_structures: no pass that runs traces against what it builds\n  shadow_sun: enabled_if [shadow_casters] is false\n"),
        "{text}"
    );
    assert!(text.contains("     barrier hdr: COLOR_ATTACHMENT_OUTPUT/COLOR_ATTACHMENT_WRITE -> FRAGMENT_SHADER/SHADER_SAMPLED_READ COLOR_ATTACHMENT_OPTIMAL -> SHADER_READ_ONLY_OPTIMAL\n"), "{text}");
}

#[test]
fn plan_of_a_broken_graph_fails() {
    let out = weft(&["graph", "plan", "graphs/shadows.ron"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(
            "this file is a fragment (`fragment: true`) and cannot be compiled on its own"
        ),
        "{stderr}"
    );
}

#[test]
fn dot_greys_culled_passes() {
    let out = weft(&["graph", "dot", "graphs/deferred.ron"]);
    assert!(out.status.success());
    let dot = String::from_utf8_lossy(&out.stdout);
    assert!(dot.starts_with("digraph \"deferred\" {\n"), "{dot}");
    assert!(dot.contains("\"pass:shadow_sun\" [shape=box, label=\"shadow_sun\\n(culled: enabled_if [shadow_casters] is false)\", style=\"filled,dashed\""), "{dot}");
    assert!(
        dot.contains("\"pass:gbuffer\" -> \"res:gbuffer_albedo\" [label=\"colour attachment\"];"),
        "{dot}"
    );
    assert!(
        dot.contains("\"res:hdr\" -> \"pass:tonemap\" [label=\"sampled read\"];"),
        "{dot}"
    );
    assert!(dot.trim_end().ends_with('}'));
}

#[test]
fn bad_size_is_rejected_by_the_argument_parser() {
    let out = weft(&["graph", "plan", "graphs/forward.ron", "--size", "wide"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr)
        .contains("expected WIDTHxHEIGHT such as 1280x720, found \"wide\""));
}

#[test]
fn check_shaders_locates_a_mismatch_at_the_pass() {
    let path = temp_graph(
        "shaders",
        r#"Graph(
    resources: [Image(name: "ldr", format: R8G8B8A8_UNORM)],
    passes: [
        Pass(name: "paint", kind: Fullscreen, shaders: (fragment: "paint.frag"), color: [(image: "ldr")]),
    ],
    output: "ldr",
)"#,
    );
    let shader = path.with_file_name("paint.frag");
    std::fs::write(
        &shader,
        "#version 450\nlayout(set = 0, binding = 0) uniform sampler2D albedo;\nlayout(location = 0) in vec2 uv;\nlayout(location = 0) out vec4 color;\nvoid main() { color = texture(albedo, uv); }\n",
    )
    .expect("write shader");
    let graph = path.to_str().expect("utf-8 path");
    assert!(weft(&["graph", "check", graph]).status.success());
    let out = weft(&["graph", "check", "--shaders", graph]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let first = stderr.lines().next().unwrap_or_default();
    assert!(
        first.starts_with(&format!("{}:4:20: error: pass \"paint\": ", path.display())),
        "{stderr}"
    );
    assert!(first.contains("albedo"), "{stderr}");
}

#[test]
fn plan_with_a_scene_culls_what_the_scene_lacks() {
    let out = weft(&[
        "graph",
        "plan",
        "graphs/deferred.ron",
        "--scene",
        "../shared/assets/462/scenes/dragon.scene",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(
            "dragon.scene: features [shadow_casters, suns, punctual_lights, blinn_phong]"
        ),
        "{stderr}"
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("culled:\n  build_structures: no pass that runs traces against what it builds\n  bloom_naive_h: enabled_if [bloom_naive] is false\n  bloom_naive_v: enabled_if [bloom_naive] is false\n  clear_overdraw: enabled_if [overdraw] is false\n  overdraw: enabled_if [overdraw] is false\n  clear_overshading: enabled_if [overshading] is false\n  clear_light_count: enabled_if [light_count] is false\n  light_count: enabled_if [light_count] is false\n  mesh_density: enabled_if [mesh_density] is false\n  normals: enabled_if [normals] is false\n  show_overdraw: enabled_if [overdraw] is false\n  show_overshading: enabled_if [overshading] is false\n  show_mesh_density: enabled_if [mesh_density] is false\n  show_normals: enabled_if [normals] is false\n  show_light_count: enabled_if [light_count] is false\n  rt_ao: enabled_if [rt_ao] is false\n  gi: enabled_if [gi] is false\n  cache_reset: enabled_if [radiance_cache] is false\n  cache_sweep: enabled_if [radiance_cache] is false\n  cache_update: enabled_if [radiance_cache] is false\n  cache_lookup: enabled_if [radiance_cache] is false\n  rt_specular: enabled_if [rt_specular, specular_lobes] is false\n  guides: enabled_if [denoise] is false\n  denoise_temporal: enabled_if [denoise] is false\n  denoise_variance: enabled_if [denoise] is false\n  denoise_atrous_1: enabled_if [denoise] is false\n  denoise_atrous_2: enabled_if [denoise] is false\n  denoise_atrous_4: enabled_if [denoise] is false\n  denoise_atrous_8: enabled_if [denoise] is false\n  denoise_atrous_16: enabled_if [denoise] is false\n  denoise_modulate: enabled_if [denoise] is false\n  clear_denoise_history: enabled_if [denoise, history_length] is false\n  keep_normal: enabled_if [denoise] is false\n  keep_position: enabled_if [denoise] is false\n  keep_illumination: enabled_if [denoise] is false\n  keep_moments: enabled_if [denoise] is false\n  restir_initial: enabled_if [restir_di] is false\n  restir_spatial: enabled_if [restir_di, restir_spatial] is false\n  restir_keep_sample: enabled_if [restir_di] is false\n  restir_keep_state: enabled_if [restir_di] is false\n  restir_keep_surface: enabled_if [restir_di] is false\n  point_lights: enabled_if [point_lights] is false\n  spot_lights: enabled_if [spot_lights] is false\n"),
        "{text}"
    );
    assert!(text.contains("  0. shadow_sun (Raster)"), "{text}");
    // The variant key: the sun pass compiles the sun loop and Blinn-Phong only
    // (rt_ao, rt_shadows, gi, radiance_cache, rt_specular, restir_di,
    // `specular_lobes`, the scene's lobes rt_specular traces, and
    // ray_queries, the hardware backend's, are among the thirteen features
    // it may depend on).
    assert!(
        text.contains(
            "     defines HAS_SHADOW_MAP SCENE_BLINN_PHONG SCENE_SPECIALISED SCENE_SUNS RAY_COUNT_SLOT=0 (variant key; 1 of up to 8192 variants: 13 of the 16 features a pass may depend on)\n"
        ),
        "{text}"
    );
}

#[test]
fn check_shows_the_offending_line_with_a_caret_and_json_carries_the_same() {
    let path = temp_graph(
        "snippet",
        "Graph(\n    output: \"hdx\",\n    resources: [Image(name: \"hdr\", format: R16G16B16A16_SFLOAT)],\n    passes: [],\n)\n",
    );
    let file = path.to_str().expect("utf-8 path");
    let out = weft(&["graph", "check", file]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&format!(
            "{file}:2:13: error: unknown output \"hdx\"\n  hint: did you mean \"hdr\"?\n   |\n 2 |     output: \"hdx\",\n   |             ^^^^^\n"
        )),
        "{stderr}"
    );
    let json = weft(&["graph", "check", "--json", file]);
    assert_eq!(json.status.code(), Some(1));
    let value: serde_json::Value =
        serde_json::from_slice(&json.stdout).expect("--json prints JSON on stdout");
    let first = &value[0];
    assert_eq!(first["severity"], "error");
    assert_eq!(first["file"], file);
    assert_eq!(
        (first["pos"]["line"].as_u64(), first["pos"]["col"].as_u64()),
        (Some(2), Some(13))
    );
    assert_eq!(first["message"], "unknown output \"hdx\"");
    assert_eq!(first["hint"], "did you mean \"hdr\"?");
}

#[test]
fn provider_arguments_out_of_range_are_errors_at_the_argument() {
    let shadows = std::fs::read_to_string(repo().join("graphs/shadows.ron")).expect("shipped");
    let text = shadows
        .replace("\"cascades\": 1,", "\"cascades\": 9,")
        .replace("../shaders/", &format!("{}/shaders/", repo().display()));
    let path = temp_graph("provider", &text);
    let out = weft(&["graph", "check", path.to_str().expect("utf-8 path")]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("error: `ShadowAtlas` argument `cascades`: 9 is out of range 1..=4"),
        "{stderr}"
    );
    let misspelled = text.replace(
        "pcf_radius: \"$pcf_radius\"",
        "pcf_radiuss: \"$pcf_radius\"",
    );
    let path = temp_graph("misspelled", &misspelled);
    let out = weft(&["graph", "check", path.to_str().expect("utf-8 path")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("error: provider `ShadowAtlas` has no argument `pcf_radiuss`\n  hint: did you mean `pcf_radius`?"),
        "{stderr}"
    );
}

#[test]
fn scene_names_outside_the_renderers_vocabulary_are_located_errors() {
    let text = r#"Graph(
    resources: [
        Image(name: "ldr", format: R8G8B8A8_SRGB),
        Image(name: "depth", format: D32_SFLOAT),
    ],
    passes: [
        Pass(
            name: "draw",
            kind: Raster,
            shaders: (vertex: "a.vert", fragment: "a.frag"),
            color: [(image: "ldr", load: Clear([0.0, 0.0, 0.0, 1.0]))],
            depth: (image: "depth", load: Clear([0.0])),
            draw: Meshes(Opaqe),
            defines: [(name: "PBR", draws: MetalicRoughness)],
        ),
    ],
    caveats: [(note: "no sky light", enabled_if: ["environmnt"])],
    output: "ldr",
)"#;
    let path = temp_graph("vocabulary", text);
    let out = weft(&["graph", "check", path.to_str().expect("utf-8 path")]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    let file = path.display();
    for expected in [
        format!("{file}:13:19: error: unknown mesh filter `Opaqe`\n  hint: did you mean `Opaque`?"),
        format!("{file}:14:44: error: unknown shading model `MetalicRoughness`\n  hint: did you mean `MetallicRoughness`?"),
        format!("{file}:17:50: error: caveat condition \"environmnt\" names a feature neither this graph nor scenes set\n  hint: did you mean \"environment\"?"),
    ] {
        assert!(stderr.contains(&expected), "{expected}\nin\n{stderr}");
    }
    assert!(stderr.contains("3 error(s)"), "{stderr}");
}
