//! Scripted scenes (scenes/SCRIPTING.md): every example in scenes/ renders
//! through forward, deferred and tiled with zero validation messages at a
//! time its script has animated; a time gives the same image on every run,
//! and the animation changes the image.

use weft_tests::render as common;

use common::{graph, root};
use std::path::Path;
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings};

const EXAMPLES: [&str; 4] = [
    "scenes/flocking.rhai",
    "scenes/day_cycle.scene",
    "scenes/swinging_spots.rhai",
    "scenes/grid.rhai",
];

/// Settings for `graph_name` at a size and time.
fn settings(graph_name: &str, width: u32, height: u32, time: f32) -> RenderSettings {
    RenderSettings {
        graph: graph(graph_name),
        extent: Extent { width, height },
        time,
        ..RenderSettings::default()
    }
}

/// The image of `scene` at `time` through `graph_name`, under validation
/// (asserting zero messages).
fn image_at(scene: &Path, graph_name: &str, time: f32) -> image::RgbaImage {
    let loaded = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        features: vec!["!bloom".into()],
        ..settings(graph_name, 160, 90, time)
    };
    let rendered =
        render(&gpu, &loaded, &settings).unwrap_or_else(|e| panic!("{}: {e}", scene.display()));
    drop(gpu);
    assert_eq!(
        log.messages(),
        Vec::new(),
        "{} {graph_name}",
        scene.display()
    );
    rendered.report.output.expect("readback").to_rgba8()
}

#[test]
fn every_example_renders_in_every_graph_without_validation_messages() {
    for example in EXAMPLES {
        let scene = root().join(example);
        for graph_name in ["forward.ron", "deferred.ron", "tiled.ron"] {
            image_at(&scene, graph_name, 1.5);
        }
    }
}

#[test]
fn a_time_gives_the_same_image_every_run_and_the_script_moves_it() {
    let scene = root().join("scenes/flocking.rhai");
    let first = image_at(&scene, "forward.ron", 2.0);
    let again = image_at(&scene, "forward.ron", 2.0);
    assert!(first == again, "the same time, the same image");
    let start = image_at(&scene, "forward.ron", 0.0);
    let changed = first
        .pixels()
        .zip(start.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(changed > 100, "the flock moved: {changed} pixels changed");
}

#[test]
fn a_failing_update_is_a_located_render_error() {
    let dir = std::env::temp_dir().join(format!("weft-scripting-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let scene = dir.join("bad.rhai");
    std::fs::write(
        &scene,
        "point_light(#{ position: [0, 1, 0] });\nfn update(t, dt) {\n    set_light_color(0, 1, 1, -1);\n}\n",
    )
    .unwrap();
    let loaded = weft_scene::load_scene(&scene).expect("loads: the error is per frame");
    let gpu = weft_tests::gpu();
    let settings = settings("forward.ron", 32, 18, 1.0);
    let error = render(&gpu, &loaded, &settings)
        .err()
        .expect("refused")
        .to_string();
    assert_eq!(
        error,
        format!("{}:3:5: colour [1, 1, -1] is negative", scene.display())
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn lights_a_script_adds_decide_the_passes_like_a_files_lights() {
    let scene = weft_scene::load_scene(&root().join("scenes/swinging_spots.rhai")).expect("loads");
    let gpu = weft_tests::gpu();
    let settings = settings("deferred.ron", 32, 18, 0.0);
    let rendered = render(&gpu, &scene, &settings).expect("renders");
    let passes: Vec<&str> = rendered
        .plan
        .passes
        .iter()
        .map(|p| p.name.as_str())
        .collect();
    assert!(passes.contains(&"spot_lights"), "{passes:?}");
    assert!(
        !passes.contains(&"point_lights"),
        "the script adds no point light: {passes:?}"
    );
}
