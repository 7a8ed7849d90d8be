//! Scripted scenes (scenes/SCRIPTING.md): every example in scenes/ renders
//! through forward, deferred and tiled with zero validation messages at a
//! time its script has animated; a time gives the same image on every run,
//! and the animation changes the image.

use weft_tests::render as common;

use common::{graph, root};
use std::path::Path;
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings, Rendered};

const EXAMPLES: [&str; 4] = [
    "scenes/flocking.rhai",
    "scenes/day_cycle.scene",
    "scenes/swinging_spots.rhai",
    "scenes/grid.rhai",
];

/// Settings for `graph_name` at a size and time.
fn settings(graph_name: &str, width: u32, height: u32, time: f64) -> RenderSettings {
    RenderSettings {
        graph: graph(graph_name),
        extent: Extent { width, height },
        time,
        ..RenderSettings::default()
    }
}

/// `frames` frames of `scene` at `width`×`height` from `time`, half a second
/// apart, through `graph_name`, under validation (asserting zero messages).
fn rendered(
    scene: &Path,
    graph_name: &str,
    [width, height]: [u32; 2],
    (time, frames): (f64, u32),
) -> Rendered {
    let loaded = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        features: vec!["!bloom".into()],
        frames,
        frame_time: 0.5,
        ..settings(graph_name, width, height, time)
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
    rendered
}

/// The last frame's image.
fn image_of(rendered: Rendered) -> image::RgbaImage {
    rendered.report.output.expect("readback").to_rgba8()
}

/// How many pixels of `a` and `b` differ.
fn pixels_differing(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels().zip(b.pixels()).filter(|(a, b)| a != b).count()
}

/// The image of `scene` at `time` through `graph_name` at 160×90.
fn image_at(scene: &Path, graph_name: &str, time: f64) -> image::RgbaImage {
    image_of(rendered(scene, graph_name, [160, 90], (time, 1)))
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
    let changed = pixels_differing(&first, &start);
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

/// A floor quad (grey) and a unit cube, with the cube also in red.
const FLOOR_OBJ: &str =
    "mtllib grey.mtl\nusemtl grey\nv -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 1 3 2\nf 1 4 3\n";
const CUBE_FACES: &str = "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
    v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
    f 1 4 3\nf 1 3 2\nf 5 6 7\nf 5 7 8\nf 1 5 8\nf 1 8 4\n\
    f 2 3 7\nf 2 7 6\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\n";
/// The script's lights where it leaves them at step 90.
const LIGHTS: &str = "pointlight\n{\n\tposition 2 4 1.25\n\tcolor 1 1 1\n\tradius 20\n}\n\
    sunlight\n{\n\tdirection -0.3 -1 -0.3125\n\tcolor 0.5 0.5 0.5\n}\n";

/// A folder of its own for `test`: the models, a script that moves the
/// cube, the camera and the lights each step (the cube to x = 1.25, turned
/// 90 degrees, at step 90 = 1.5 s) and turns the green cube red from step
/// 85, and the files that place them there.
fn placement_scenes(test: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let files = [
        ("grey.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n".to_string()),
        ("red.mtl", "newmtl red\nKd 0.9 0.2 0.1\n".to_string()),
        ("floor.obj", FLOOR_OBJ.to_string()),
        ("cube.obj", format!("mtllib grey.mtl\nusemtl grey\n{CUBE_FACES}")),
        ("cube_red.obj", format!("mtllib red.mtl\nusemtl red\n{CUBE_FACES}")),
        (
            "moved.rhai",
            r#"model("floor.obj", #{});
model("cube.obj", #{ color: [0.2, 0.9, 0.1] });
camera("main", #{ position: [0, 3, 6], target: [0, 0, 0] });
point_light(#{ position: [2, 4, 2], color: [1, 1, 1], radius: 20 });
sun_light(#{ direction: [-0.3, -1, -0.4], color: [0.5, 0.5, 0.5] });
fn init() { #{ n: 0 } }
fn update(t, dt) {
    this.n += 1;
    let x = (this.n - 80).to_float() * 0.125;
    set_model_transform(1, #{ position: [x, 0.5, 0], orientation: [0, this.n, 0] });
    set_camera("main", #{ position: [x, 3, 6], target: [x, 0.5, 0] });
    set_light_position(0, 2, 4, x);
    set_light_direction(1, -0.3, -1, -0.25 * x);
    if this.n >= 85 { set_model_color(1, 0.9, 0.2, 0.1); }
}
"#
            .to_string(),
        ),
        (
            "placed.scene",
            format!(
                "model\n{{\n\tfile \"floor.obj\"\n}}\n\
                 model\n{{\n\tfile \"cube.obj\"\n\tposition 1.25 0.5 0\n\torientation 0 90 0\n\tcolor 0.9 0.2 0.1\n}}\n\
                 camera \"main\"\n{{\n\tposition 1.25 3 6\n\ttarget 1.25 0.5 0\n}}\n{LIGHTS}"
            ),
        ),
        (
            "mixed.rhai",
            r#"model("floor.obj", #{});
model("cube.obj", #{ position: [0, 0.5, 0] });
camera("main", #{ position: [0, 3, 6], target: [0, 0, 0] });
point_light(#{ position: [2, 1, 0], color: [1, 0.5, 0.2], radius: 6, velocity: 2, amplitude: 1.5 });
point_light(#{ position: [-2, 1, 0], color: [0.2, 0.5, 1], radius: 6, velocity: 2, amplitude: 1.5 });
fn update(t, dt) {
    if t > 1.0 { set_light_position(1, -2, 1, 2); }
}
"#
            .to_string(),
        ),
        (
            "mixed.scene",
            "model\n{\n\tfile \"floor.obj\"\n}\n\
             model\n{\n\tfile \"cube.obj\"\n\tposition 0 0.5 0\n}\n\
             camera \"main\"\n{\n\tposition 0 3 6\n\ttarget 0 0 0\n}\n\
             pointlight\n{\n\tposition 2 1 0\n\tcolor 1 0.5 0.2\n\tradius 6\n\tvelocity 2\n\tamplitude 1.5\n}\n\
             pointlight\n{\n\tposition -2 1 2\n\tcolor 0.2 0.5 1\n\tradius 6\n}\n"
                .to_string(),
        ),
        (
            "caster.rhai",
            r#"model("floor.obj", #{});
model("cube.obj", #{ position: [-1, 0.5, 0] });
camera("main", #{ position: [0, 3, 6], target: [0, 0, 0] });
sun_light(#{ direction: [-0.3, -1, -0.4], color: [0.5, 0.5, 0.5] });
spot_light(#{ position: [2.5, 3, -2.5], direction: [0, -1, 0], angle: 20, color: [1, 1, 1] });
fn update(t, dt) {
    if t > 1.2 { set_model_transform(1, #{ position: [1, 0.5, 0] }); }
}
"#
            .to_string(),
        ),
        (
            "caster.scene",
            "model\n{\n\tfile \"floor.obj\"\n}\n\
             model\n{\n\tfile \"cube.obj\"\n\tposition 1 0.5 0\n}\n\
             camera \"main\"\n{\n\tposition 0 3 6\n\ttarget 0 0 0\n}\n\
             sunlight\n{\n\tdirection -0.3 -1 -0.4\n\tcolor 0.5 0.5 0.5\n}\n\
             spotlight\n{\n\tposition 2.5 3 -2.5\n\tdirection 0 -1 0\n\tangle 20\n\tcolor 1 1 1\n}\n"
                .to_string(),
        ),
        (
            "recoloured.rhai",
            r#"model("floor.obj", #{});
model("cube.obj", #{ position: [1.25, 0.5, 0], orientation: [0, 90, 0], color: [0.2, 0.9, 0.1] });
camera("main", #{ position: [1.25, 3, 6], target: [1.25, 0.5, 0] });
point_light(#{ position: [2, 4, 1.25], color: [1, 1, 1], radius: 20 });
sun_light(#{ direction: [-0.3, -1, -0.3125], color: [0.5, 0.5, 0.5] });
fn update(t, dt) {
    if t > 1.2 { set_model_color(1, 0.9, 0.2, 0.1); }
}
"#
            .to_string(),
        ),
        (
            "placed_red.scene",
            format!(
                "model\n{{\n\tfile \"floor.obj\"\n}}\n\
                 model\n{{\n\tfile \"cube_red.obj\"\n\tposition 1.25 0.5 0\n\torientation 0 90 0\n}}\n\
                 camera \"main\"\n{{\n\tposition 1.25 3 6\n\ttarget 1.25 0.5 0\n}}\n{LIGHTS}"
            ),
        ),
    ];
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    dir
}

/// The last of `frames` frames of `scene` from `time`, half a second apart,
/// through `graph_name` at 96×64.
fn last_frame(scene: &Path, graph_name: &str, time: f64, frames: u32) -> image::RgbaImage {
    image_of(rendered(scene, graph_name, [96, 64], (time, frames)))
}

#[test]
fn a_script_moving_and_recolouring_a_placement_and_moving_the_camera_and_lights_draws_what_a_file_placing_them_there_draws(
) {
    let dir = placement_scenes("placements");
    for graph_name in ["forward.ron", "deferred.ron", "pathtrace.ron"] {
        // Frame 0 at 1 s (step 60), frame 1 at 1.5 s (step 90): the second
        // frame rewrites the draw records (and rebuilds the ray tracer's BVH),
        // and the sun's shadow map follows both the cube and the sun.
        let moved = last_frame(&dir.join("moved.rhai"), graph_name, 1.0, 2);
        let placed = last_frame(&dir.join("placed.scene"), graph_name, 0.0, 1);
        assert!(moved == placed, "{graph_name}: the same image");
        let before = last_frame(&dir.join("moved.rhai"), graph_name, 1.0, 1);
        let changed = pixels_differing(&before, &placed);
        assert!(
            changed > 500,
            "{graph_name}: the cube and camera moved: {changed} pixels"
        );
    }
    let red = last_frame(&dir.join("placed_red.scene"), "forward.ron", 0.0, 1);
    let overridden = last_frame(&dir.join("placed.scene"), "forward.ron", 0.0, 1);
    assert!(
        red == overridden,
        "a grey cube placed with `color 0.9 0.2 0.1` is the red cube"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn lights_the_script_leaves_alone_keep_their_scene_motions() {
    let dir = placement_scenes("motions");
    // Light 0 circles by its `velocity` in both; light 1, moved by the
    // script after 1 s, stands where the file puts it.
    let scripted = last_frame(&dir.join("mixed.rhai"), "forward.ron", 1.5, 1);
    let file = last_frame(&dir.join("mixed.scene"), "forward.ron", 1.5, 1);
    assert!(scripted == file, "the same lights at 1.5 s");
    let start = last_frame(&dir.join("mixed.rhai"), "forward.ron", 0.0, 1);
    let changed = pixels_differing(&start, &scripted);
    assert!(changed > 500, "the lights moved: {changed} pixels");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_moved_caster_redraws_exactly_the_shadow_views_it_meets() {
    let dir = placement_scenes("casters");
    let render_frames = |scene: &str, time: f64, frames: u32| {
        let rendered = rendered(&dir.join(scene), "forward.ron", [96, 64], (time, frames));
        let kept: Vec<bool> = rendered
            .culling
            .iter()
            .filter(|c| c.view.starts_with("shadow"))
            .map(|c| c.kept)
            .collect();
        (image_of(rendered), kept)
    };
    // Frame 0 at 1 s draws both views; the cube moves before frame 1 at
    // 1.5 s, inside the sun's view and outside the spot's; the sun and the
    // scene's bounds stay as they were, so the sun's view is bit-identical.
    let (moved, kept) = render_frames("caster.rhai", 1.0, 2);
    assert_eq!(
        kept,
        [false, true],
        "the sun's tile redrawn, the spot's kept"
    );
    let (placed, _) = render_frames("caster.scene", 0.0, 1);
    assert!(moved == placed, "the shadow follows the cube");
    let (_, kept) = render_frames("caster.rhai", 1.5, 2);
    assert_eq!(
        kept,
        [true, true],
        "nothing moved from 1.5 s to 2 s: both kept"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_grid_example_at_two_seconds_matches_its_golden() {
    // Placements moved and recoloured and the camera swung by the script,
    // over material overrides from its load: a regression check of the
    // whole path (tolerance as for the other goldens, tests/e2e/render.rs).
    let image = image_at(&root().join("scenes/grid.rhai"), "forward.ron", 2.0);
    let tolerance = weft_testkit::Tolerance {
        per_channel: 12,
        mean: 0.5,
    };
    if let Err(e) = weft_testkit::check_golden(
        &image,
        &weft_tests::golden("grid_script_forward_160x90.png"),
        &tolerance,
    ) {
        panic!("{e}");
    }
}

#[test]
fn a_recolour_alone_restarts_the_path_tracers_accumulation() {
    let dir = placement_scenes("recolour");
    // Frame 0 at 1 s traces the green cube; only its colour changes before
    // frame 1, which must start the running mean again: the red cube's first
    // frame, not a blend of the two.
    let recoloured = last_frame(&dir.join("recoloured.rhai"), "pathtrace.ron", 1.0, 2);
    let red = last_frame(&dir.join("placed.scene"), "pathtrace.ron", 0.0, 1);
    assert!(recoloured == red, "the accumulation started again");
    std::fs::remove_dir_all(&dir).unwrap();
}
