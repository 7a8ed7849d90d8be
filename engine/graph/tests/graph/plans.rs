//! Every graph in `graphs/`: it checks clean, its text plans match the reviewed
//! snapshots in `tests/snapshots/` (insta: review a change with `cargo insta review`, or
//! accept it with `INSTA_UPDATE=always`),
//! and every plan passes the independent synchronization checker.

use crate::support;

use std::path::PathBuf;
use support::checker::{check_aliasing, check_plan};
use support::repo_root;
use weft_graph::plan::ResourceDesc;
use weft_graph::{CompileOptions, Extent};

const FEATURE_SETS: &[(&str, &[&str])] = &[
    ("default", &[]),
    ("no-bloom", &["!bloom"]),
    (
        "all",
        &[
            "shadow_casters",
            "point_lights",
            "spot_lights",
            "area_lights",
            "depth_prepass",
            "transparent",
            // Tracing in hardware: the acceleration structure's build and reads.
            "ray_queries",
            "rt_shadows",
        ],
    ),
];

fn graph_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo_root().join("graphs"))
        .expect("graphs/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_shipped_graph_checks_clean() {
    let files = graph_files();
    assert!(
        files.len() >= 4,
        "expected the shipped graphs, found {files:?}"
    );
    for file in files {
        let diags = weft_graph::check(&weft_graph::load(&file));
        assert!(diags.is_empty(), "{}: {diags:#?}", file.display());
    }
}

#[test]
fn plans_match_snapshots_and_pass_the_checker() {
    let mut compared = 0;
    for file in graph_files() {
        let graph = weft_graph::load(&file);
        if graph.is_fragment {
            continue;
        }
        let stem = file
            .file_stem()
            .and_then(|s| s.to_str())
            .expect("utf-8 name");
        for (label, requested) in FEATURE_SETS {
            let options = CompileOptions {
                extent: Extent {
                    width: 1920,
                    height: 1080,
                },
                features: graph.features(requested),
                ..CompileOptions::default()
            };
            let plan = weft_graph::compile(&graph, &options)
                .unwrap_or_else(|e| panic!("{stem} {label}: {e:#?}"));
            check_plan(&plan, 3).unwrap_or_else(|e| panic!("{stem} {label}: {e}"));
            check_aliasing(&plan).unwrap_or_else(|e| panic!("{stem} {label}: {e}"));
            compared += 1;
            insta::with_settings!({ prepend_module_to_snapshot => false, omit_expression => true }, {
                insta::assert_snapshot!(format!("{stem}-{label}"), weft_graph::text::render(&plan));
            });
        }
    }
    assert_eq!(
        compared, 24,
        "forward, forward_msaa, deferred, tiled, hybrid, pathtrace, pathtrace_denoised and pathtrace_wavefront, three feature sets each"
    );
}

#[test]
fn caveats_apply_under_their_features_from_the_graph_and_its_fragments() {
    let caveats = |file: &str, requested: &[&str]| -> Vec<String> {
        let graph = weft_graph::load(&repo_root().join("graphs").join(file));
        let options = CompileOptions {
            features: graph.features(requested),
            ..CompileOptions::default()
        };
        let plan = weft_graph::compile(&graph, &options).expect("compiles");
        plan.caveats
            .iter()
            .map(|c| c.split([' ', ':']).next().unwrap_or_default().to_string())
            .collect()
    };
    // forward.ron's own notes first (it traces neither the environment nor
    // bounces), bloom.ron's while bloom is on (a default feature), then
    // taa.ron's: one sample per pixel, or under `taa` the frames' average.
    assert_eq!(
        caveats("forward.ron", &[]),
        ["nothing", "direct", "bloom", "one"]
    );
    assert_eq!(
        caveats("forward.ron", &["!bloom"]),
        ["nothing", "direct", "one"]
    );
    assert_eq!(
        caveats("forward.ron", &["!bloom", "taa"]),
        ["nothing", "direct", "temporal"]
    );
    // Shadow maps under shadow casters with a sun or a spot, once with both;
    // none of their notes once `rt_shadows` traces every light's shadows,
    // and the area lights' note says how.
    assert_eq!(
        caveats(
            "forward.ron",
            &["!bloom", "shadow_casters", "area_lights", "point_lights"]
        ),
        ["nothing", "direct", "area", "point", "one"]
    );
    assert_eq!(
        caveats(
            "forward.ron",
            &["!bloom", "shadow_casters", "suns", "spot_lights"]
        ),
        ["nothing", "direct", "sun", "one"]
    );
    let traced = caveats(
        "forward.ron",
        &[
            "!bloom",
            "shadow_casters",
            "suns",
            "spot_lights",
            "point_lights",
            "area_lights",
            "rt_shadows",
        ],
    );
    assert_eq!(traced, ["nothing", "direct", "area", "one"]);
    let graph = weft_graph::load(&repo_root().join("graphs/forward.ron"));
    let options = CompileOptions {
        features: graph.features(&["area_lights", "rt_shadows"]),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    assert!(
        plan.caveats
            .iter()
            .any(|c| c
                .starts_with("area lights and emissive surfaces shadow by the traced fraction")),
        "{:?}",
        plan.caveats
    );
    // deferred.ron: rt_ao.ron's note holds until rt_ao or gi traces the
    // environment, gi.ron's "direct light only" until gi adds a bounce, and
    // its one-bounce note then.
    assert_eq!(
        caveats("deferred.ron", &["!bloom"]),
        ["one", "nothing", "direct"]
    );
    assert_eq!(
        caveats("deferred.ron", &["!bloom", "rt_ao"]),
        ["one", "direct"]
    );
    assert_eq!(caveats("deferred.ron", &["!bloom", "gi"]), ["one", "one"]);
}

#[test]
fn removing_any_barrier_makes_the_checker_fail() {
    let graph = weft_graph::load(&repo_root().join("graphs/deferred.ron"));
    let options = CompileOptions {
        features: graph.features(&[
            "shadow_casters",
            "point_lights",
            "spot_lights",
            "area_lights",
            "transparent",
        ]),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("deferred compiles");
    let removed = assert_every_barrier_is_needed(&plan);
    assert!(removed > 15, "only {removed} barriers");
}

/// Removes each barrier of `plan` (passes' and epilogue's) in turn and
/// asserts the checker notices; returns how many passes' barriers there were.
fn assert_every_barrier_is_needed(plan: &weft_graph::Plan) -> usize {
    let mut removed = 0;
    for p in plan.passes.ids() {
        for b in 0..plan.passes[p].barriers.len() {
            let mut broken = plan.clone();
            let barrier = broken.passes[p].barriers.remove(b);
            let name = &plan.resources[barrier.resource].name;
            assert!(
                check_plan(&broken, 2).is_err(),
                "removing the barrier on \"{name}\" before \"{}\" went unnoticed",
                plan.passes[p].name
            );
            removed += 1;
        }
    }
    for e in 0..plan.epilogue.len() {
        let mut broken = plan.clone();
        broken.epilogue.remove(e);
        assert!(
            check_plan(&broken, 2).is_err(),
            "removing epilogue barrier {e} went unnoticed"
        );
    }
    removed
}

/// The same with buffers in transient memory: the wavefront path tracer's
/// queues and the structures' scratch share memory with images, so every
/// hand-over between a buffer and an image is a barrier the checker needs.
#[test]
fn removing_any_barrier_of_a_plan_with_placed_buffers_makes_the_checker_fail() {
    let graph = weft_graph::load(&repo_root().join("graphs/pathtrace_wavefront.ron"));
    let options = CompileOptions {
        features: graph.features(&["ray_queries", "area_lights"]),
        scene_values: [("structure_scratch_bytes".to_string(), 1e6)].into(),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    let placed_buffers = plan
        .resources
        .iter()
        .filter(|r| r.placement.is_some() && matches!(r.desc, ResourceDesc::Buffer(_)))
        .count();
    assert!(placed_buffers >= 2, "{placed_buffers} placed buffers");
    check_plan(&plan, 2).expect("the plan is sound");
    assert_every_barrier_is_needed(&plan);
    // A hand-over to a buffer must also reach the buffer's use: the same
    // barrier with an empty destination scope is noticed.
    let mut emptied = 0;
    for p in plan.passes.ids() {
        for b in 0..plan.passes[p].barriers.len() {
            let barrier = &plan.passes[p].barriers[b];
            let placed = plan.resources[barrier.resource].placement.is_some();
            if !placed || barrier.layouts.is_some() {
                continue;
            }
            let mut broken = plan.clone();
            broken.passes[p].barriers[b].dst_stage = weft_graph::vk::Stage::empty();
            broken.passes[p].barriers[b].dst_access = weft_graph::vk::Access::empty();
            assert!(
                check_plan(&broken, 2).is_err(),
                "a barrier on \"{}\" before \"{}\" reaching nothing went unnoticed",
                plan.resources[barrier.resource].name,
                plan.passes[p].name
            );
            emptied += 1;
        }
    }
    assert!(emptied >= 2, "{emptied} buffer barriers");
}

#[test]
fn scene_features_cull_passes_and_variants() {
    let graph = weft_graph::load(&repo_root().join("graphs/deferred.ron"));
    let options = CompileOptions {
        features: graph.features::<&str>(&[]),
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    let culled: Vec<(&str, &str)> = plan
        .culled
        .iter()
        .map(|c| (c.name.as_str(), c.reason.as_str()))
        .collect();
    assert_eq!(
        culled,
        [
            (
                "build_structures",
                "no pass that runs traces against what it builds"
            ),
            ("shadow_sun", "enabled_if [shadow_casters] is false"),
            ("bloom_naive_h", "enabled_if [bloom_naive] is false"),
            ("bloom_naive_v", "enabled_if [bloom_naive] is false"),
            ("clear_overdraw", "enabled_if [overdraw] is false"),
            ("overdraw", "enabled_if [overdraw] is false"),
            ("clear_overshading", "enabled_if [overshading] is false"),
            ("clear_light_count", "enabled_if [light_count] is false"),
            ("light_count", "enabled_if [light_count] is false"),
            ("mesh_density", "enabled_if [mesh_density] is false"),
            ("normals", "enabled_if [normals] is false"),
            ("show_overdraw", "enabled_if [overdraw] is false"),
            ("show_overshading", "enabled_if [overshading] is false"),
            ("show_mesh_density", "enabled_if [mesh_density] is false"),
            ("show_normals", "enabled_if [normals] is false"),
            ("show_light_count", "enabled_if [light_count] is false"),
            ("rt_ao", "enabled_if [rt_ao] is false"),
            ("gi", "enabled_if [gi] is false"),
            ("cache_reset", "enabled_if [radiance_cache] is false"),
            ("cache_sweep", "enabled_if [radiance_cache] is false"),
            ("cache_update", "enabled_if [radiance_cache] is false"),
            ("cache_lookup", "enabled_if [radiance_cache] is false"),
            (
                "rt_specular",
                "enabled_if [rt_specular, specular_lobes] is false",
            ),
            ("guides", "enabled_if [denoise] is false"),
            ("denoise_temporal", "enabled_if [denoise] is false"),
            ("denoise_variance", "enabled_if [denoise] is false"),
            ("denoise_atrous_1", "enabled_if [denoise] is false"),
            ("denoise_atrous_2", "enabled_if [denoise] is false"),
            ("denoise_atrous_4", "enabled_if [denoise] is false"),
            ("denoise_atrous_8", "enabled_if [denoise] is false"),
            ("denoise_atrous_16", "enabled_if [denoise] is false"),
            ("denoise_modulate", "enabled_if [denoise] is false"),
            (
                "clear_denoise_history",
                "enabled_if [denoise, history_length] is false"
            ),
            ("keep_normal", "enabled_if [denoise] is false"),
            ("keep_position", "enabled_if [denoise] is false"),
            ("keep_illumination", "enabled_if [denoise] is false"),
            ("keep_moments", "enabled_if [denoise] is false"),
            ("restir_initial", "enabled_if [restir_di] is false"),
            (
                "restir_spatial",
                "enabled_if [restir_di, restir_spatial] is false"
            ),
            ("restir_keep_sample", "enabled_if [restir_di] is false"),
            ("restir_keep_state", "enabled_if [restir_di] is false"),
            ("restir_keep_surface", "enabled_if [restir_di] is false"),
            ("point_lights", "enabled_if [point_lights] is false"),
            ("spot_lights", "enabled_if [spot_lights] is false"),
            ("area_lights", "enabled_if [area_lights] is false"),
            ("area_light_panels", "enabled_if [area_lights] is false"),
            ("transparent", "enabled_if [transparent] is false"),
        ]
    );
    let sun = plan
        .passes
        .iter()
        .find(|p| p.name == "sun")
        .expect("sun pass");
    // No shadow variant without shadow casters, and no light type or shading
    // model compiled without the scene's features: only the variant marker.
    assert_eq!(sun.defines, ["SCENE_SPECIALISED"]);
    assert!(plan.resource("shadow_map").is_none());
}

#[test]
fn the_annotated_example_in_graphs_readme_checks_clean() {
    let readme = std::fs::read_to_string(repo_root().join("graphs/README.md")).expect("README");
    let start = readme.find("```ron\n").expect("a ron block") + "```ron\n".len();
    let end = start + readme[start..].find("```").expect("closed block");
    let example = readme[start..end].to_string();
    let graphs = repo_root().join("graphs");
    let root = graphs.join("README-example.ron");
    let read = |p: &std::path::Path| {
        if p == root {
            Ok(example.clone())
        } else {
            std::fs::read_to_string(p)
        }
    };
    let graph = weft_graph::load_with(&root, &read);
    assert_eq!(weft_graph::check(&graph), Vec::new());
    assert_eq!(graph.sources.len(), 3);
}

#[test]
fn images_read_back_after_the_frame_are_kept_and_left_readable() {
    let graph = weft_graph::load(&repo_root().join("graphs/forward.ron"));
    let options = CompileOptions {
        features: graph.features::<&str>(&[]),
        readback: vec!["hdr".into()],
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&graph, &options).expect("compiles");
    let hdr = plan.resource("hdr").expect("hdr");
    assert_eq!(plan.readback, vec![hdr]);
    assert_eq!(
        plan.resources[hdr].residency,
        weft_graph::plan::Residency::Output
    );
    assert_eq!(plan.resources[hdr].placement, None);
    let last = plan
        .epilogue
        .iter()
        .find(|b| b.resource == hdr)
        .expect("epilogue barrier");
    assert_eq!(
        last.layouts.map(|l| l.1),
        Some(weft_graph::vk::Layout::TransferSrcOptimal)
    );
    check_plan(&plan, 3).expect("synchronized");

    let unknown = CompileOptions {
        readback: vec!["hdrr".into()],
        ..CompileOptions::default()
    };
    let errors = weft_graph::compile(&graph, &unknown).expect_err("unknown image");
    assert_eq!(
        errors[0].message,
        "cannot read back \"hdrr\": the graph has no image of that name"
    );
    assert_eq!(errors[0].hint.as_deref(), Some("did you mean \"hdr\"?"));
}

/// An `enabled_if` entry of alternatives holds when one of them does: a
/// pass reading the shadow map "for spots or unless traced" runs in three
/// of the four combinations, and the graph's feature names include each
/// alternative's.
#[test]
fn alternatives_in_a_condition_decide_culling() {
    let text = r#"Graph(
    resources: [Image(name: "map", format: R8G8B8A8_UNORM), Image(name: "ldr", format: R8G8B8A8_SRGB)],
    passes: [
        Pass(name: "shadow", kind: Fullscreen, shaders: (fragment: "s.frag"), color: [(image: "map")],
             enabled_if: ["shadow_casters", "spot_lights|!rt_shadows"]),
        Pass(name: "shade", kind: Fullscreen, shaders: (fragment: "t.frag"),
             sampled: [(name: "map", enabled_if: ["shadow_casters", "spot_lights|!rt_shadows"])],
             color: [(image: "ldr")]),
    ],
    output: "ldr",
)"#;
    let graph = crate::support::load_files("/g/main.ron", &[("/g/main.ron", text)]);
    assert_eq!(weft_graph::check(&graph), Vec::new());
    let prepared = weft_graph::Prepared::new(graph.clone()).expect("prepares");
    let names = weft_graph::feature_names(prepared.ir());
    for name in ["shadow_casters", "spot_lights", "rt_shadows"] {
        assert!(names.contains(name), "{name} in {names:?}");
    }
    let runs = |features: &[&str]| {
        let options = CompileOptions {
            features: features.iter().map(|f| f.to_string()).collect(),
            ..CompileOptions::default()
        };
        let plan = weft_graph::compile(&graph, &options).expect("compiles");
        plan.passes.iter().any(|p| p.name == "shadow")
    };
    assert!(runs(&["shadow_casters"]));
    assert!(runs(&["shadow_casters", "spot_lights"]));
    assert!(runs(&["shadow_casters", "spot_lights", "rt_shadows"]));
    assert!(!runs(&["shadow_casters", "rt_shadows"]));
    assert!(!runs(&["spot_lights"]));
}
