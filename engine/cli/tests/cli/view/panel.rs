//! The viewer's panel (F1) under Xvfb, driven by `--press` and `--ui`
//! scripts: it docks beside the 3D view (which renders in the rest of the
//! window) and stays out of screenshots, sets features and parameters as
//! `weft render` does, measures the live error as `weft compare` does,
//! saves bookmarks in the user's data folder, and keeps validation silent
//! across a resize.

use super::{assert_clean, differences, load, text, Temp, Xvfb};
use crate::harness::{command_in, repo};
use std::path::PathBuf;

/// `frames` frames of `weft view` of the demo in a window of `size`,
/// paused, with validation, saving the last frame to `shot`; `extra` adds
/// arguments.
fn view_demo(
    x: &Xvfb,
    (shot, size): (&std::path::Path, &str),
    frames: &str,
    extra: &[&str],
) -> String {
    view_scene(x, "scenes/demo.scene", (shot, size), frames, extra)
}

/// [`view_demo`] of `scene`.
fn view_scene(
    x: &Xvfb,
    scene: &str,
    (shot, size): (&std::path::Path, &str),
    frames: &str,
    extra: &[&str],
) -> String {
    let mut args = vec![
        "view",
        scene,
        "--size",
        size,
        "--paused",
        "--frames",
        frames,
        "--validate",
        "--screenshot-on-exit",
        shot.to_str().expect("utf-8 path"),
    ];
    args.extend_from_slice(extra);
    let out = x.weft(&args);
    assert_clean(&out);
    text(&out.stdout)
}

/// Asserts the viewer's screenshot `shown` equals `weft render ARGS` at its
/// size (the view renders beside the docked panel), written to `headless`.
fn assert_render_matches(
    x: &Xvfb,
    shown: &std::path::Path,
    headless: &std::path::Path,
    args: &[&str],
) {
    let (width, height) = load(shown).dimensions();
    let size = format!("{width}x{height}");
    let mut render = vec!["render"];
    render.extend_from_slice(args);
    render.extend([
        "--size",
        &size,
        "--out",
        headless.to_str().expect("utf-8 path"),
    ]);
    let out = x.weft(&render);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (mean, p99, max) = differences(&load(shown), &load(headless));
    assert!(
        mean <= 0.05 && p99 <= 1 && max <= 1,
        "viewer vs render: mean {mean}, p99 {p99}, max {max}"
    );
}

#[test]
fn the_panel_docks_beside_the_view_and_stays_out_of_screenshots_unless_asked() {
    let x = Xvfb::start();
    let tmp = Temp::new("panel-toggle");
    let plain = tmp.file("plain.png");
    let hidden_again = tmp.file("hidden-again.png");
    let shown = tmp.file("shown.png");
    let shown_captured = tmp.file("shown-captured.png");
    let narrow = tmp.file("narrow.png");
    view_demo(&x, (&plain, "160x90"), "5", &[]);
    view_demo(
        &x,
        (&hidden_again, "160x90"),
        "5",
        &["--press", "1:f1,3:f1", "--screenshot-panel"],
    );
    view_demo(&x, (&shown, "160x90"), "5", &["--press", "1:f1"]);
    view_demo(
        &x,
        (&shown_captured, "160x90"),
        "5",
        &["--press", "1:f1", "--screenshot-panel"],
    );
    let plain = load(&plain);
    assert_eq!(
        load(&hidden_again),
        plain,
        "with the panel toggled off the view has the whole window again"
    );
    // Shown, the panel docks on the right (at most three quarters of the
    // window) and the 3D view renders at the width it leaves, which the
    // screenshot holds alone: the view a window that narrow shows.
    let shown = load(&shown);
    let (width, height) = shown.dimensions();
    assert!(
        (40..160).contains(&width) && height == 90,
        "{width}x{height}"
    );
    let out = x.weft(&[
        "view",
        "scenes/demo.scene",
        "--size",
        &format!("{width}x90"),
        "--paused",
        "--frames",
        "5",
        "--screenshot-on-exit",
        narrow.to_str().expect("utf-8 path"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (mean, p99, max) = differences(&shown, &load(&narrow));
    assert!(
        mean <= 0.05 && p99 <= 1 && max <= 1,
        "docked view vs a window that wide: mean {mean}, p99 {p99}, max {max}"
    );
    // With --screenshot-panel the window is captured whole: the same view
    // on the left, the panel beside it, not over it.
    let with_panel = load(&shown_captured);
    assert_eq!(with_panel.dimensions(), (160, 90));
    let left = image::imageops::crop_imm(&with_panel, 0, 0, width, 90).to_image();
    assert_eq!(left, shown, "the panel does not cover the view");
    let right = image::imageops::crop_imm(&with_panel, width, 0, 160 - width, 90).to_image();
    assert!(
        right.pixels().any(|p| p != &image::Rgba([0, 0, 0, 255])),
        "the panel is drawn beside it"
    );
}

/// A feature past the ninth key (`rt_shadows`, the tiled graph's
/// sixteenth) is switched on and `exposure` typed as 2 through the panel's
/// own widgets; the next frames equal `weft render` with the same toggle
/// and `--param`.
#[test]
fn a_feature_and_a_parameter_set_in_the_panel_render_as_weft_render_does() {
    let x = Xvfb::start();
    let tmp = Temp::new("panel-set");
    let shown = tmp.file("shown.png");
    let headless = tmp.file("headless.png");
    let stdout = view_demo(
        &x,
        (&shown, "640x360"),
        "16",
        &[
            "--graph",
            "graphs/tiled.ron",
            "--panel",
            "--ui",
            "1:click:feature:rt_shadows,5:click:param:exposure,6:text:2,6:enter",
        ],
    );
    // The view renders beside the docked panel: compared at its size.
    let (width, height) = load(&shown).dimensions();
    assert!(width < 640 && height == 360, "{width}x{height}");
    let lists: Vec<&str> = stdout.lines().filter(|l| l.starts_with("graph ")).collect();
    assert_eq!(lists.len(), 2, "{stdout}");
    assert!(lists[0].contains("Shift+7 rt_shadows [off]"), "{stdout}");
    assert!(lists[1].contains("Shift+7 rt_shadows [on]"), "{stdout}");
    assert!(stdout.contains("parameter exposure = 2\n"), "{stdout}");
    assert_render_matches(
        &x,
        &shown,
        &headless,
        &[
            "scenes/demo.scene",
            "--graph",
            "graphs/tiled.ron",
            "--features",
            "rt_shadows",
            "--param",
            "exposure=2",
        ],
    );
}

#[test]
fn a_click_on_a_widget_the_panel_does_not_have_says_which_it_has() {
    let x = Xvfb::start();
    let out = x.weft(&[
        "view",
        "scenes/cornell.scene",
        "--size",
        "64x36",
        "--frames",
        "20",
        "--panel",
        "--ui",
        "1:click:feature:no_such_thing",
    ]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("--ui click:feature:no_such_thing: the panel showed no widget")
            && stderr.contains("feature:bloom"),
        "{stderr}"
    );
}

/// The live error of forward on the Cornell box against a 16-spp
/// reference is the map and number `weft compare` writes for that view at
/// 16 spp (same seed, so equal to FLIP's own rounding).
#[test]
fn the_live_error_is_the_map_weft_compare_writes() {
    let x = Xvfb::start();
    let tmp = Temp::new("panel-live-error");
    let map = tmp.file("live.png");
    let out = x.weft(&[
        "view",
        "scenes/cornell.scene",
        "--size",
        "64x36",
        "--paused",
        "--frames",
        "24",
        "--validate",
        "--press",
        "0:l",
        "--reference-spp",
        "16",
        "--live-error-out",
        map.to_str().expect("utf-8 path"),
    ]);
    assert_clean(&out);
    let stdout = text(&out.stdout);
    let live: f64 = stdout
        .lines()
        .find_map(|l| l.strip_prefix("live error: HDR-FLIP "))
        .and_then(|rest| rest.split(' ').next())
        .and_then(|v| v.parse().ok())
        .unwrap_or_else(|| panic!("no live error line: {stdout}"));
    assert!(stdout.contains("at 16 spp"), "{stdout}");
    let compared = tmp.file("compare");
    let out = command_in(
        &repo(),
        &[
            "compare",
            "scenes/cornell.scene",
            "--graphs",
            "graphs/forward.ron",
            "--size",
            "64x36",
            "--spp",
            "16",
            "--out",
            compared.to_str().expect("utf-8 path"),
        ],
    )
    .output()
    .expect("weft runs");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(compared.join("report.json")).expect("report.json"))
            .expect("json");
    let flip = report["configurations"][0]["flip"]
        .as_f64()
        .expect("a flip figure");
    assert!((live - flip).abs() <= 1e-6, "live {live} vs compare {flip}");
    assert_eq!(
        load(&map),
        load(&compared.join("forward.flip.png")),
        "the live map, legend and mean included, is compare's"
    );
}

/// B saves the flown camera as numbered `camera` blocks in the user's data
/// folder (never beside the scene, in a working tree), or in `--bookmarks
/// FILE`, which reads back as a scene.
#[test]
fn b_saves_numbered_bookmarks_in_the_data_folder_or_the_file_named() {
    let x = Xvfb::start();
    let tmp = Temp::new("panel-bookmarks");
    let original = std::fs::read_to_string(repo().join("scenes/cornell.scene")).expect("scene");
    let assets = repo().join("../shared/assets");
    let scene = tmp.file("box.scene");
    std::fs::write(
        &scene,
        original.replace("../../shared/assets", assets.to_str().expect("utf-8 path")),
    )
    .expect("scene copy");
    let data = tmp.file("data");
    let out = x
        .command(
            &[
                "view",
                scene.to_str().expect("utf-8 path"),
                "--size",
                "32x18",
                "--frames",
                "4",
                "--validate",
                "--press",
                "1:b,2:b",
            ],
            &repo(),
        )
        .env("XDG_DATA_HOME", &data)
        .output()
        .expect("weft runs");
    assert_clean(&out);
    let stdout = text(&out.stdout);
    let saved_in: Vec<PathBuf> = std::fs::read_dir(data.join("weft/bookmarks"))
        .expect("the data folder's bookmarks")
        .map(|e| e.expect("entry").path())
        .collect();
    let [file] = saved_in.as_slice() else {
        panic!("one bookmarks file: {saved_in:?}");
    };
    let name = file
        .file_name()
        .expect("name")
        .to_string_lossy()
        .into_owned();
    assert!(
        name.starts_with("box-") && name.ends_with(".bookmarks.scene"),
        "{name}"
    );
    assert!(
        stdout.contains(&format!("saved bookmark 2 to {}", file.display())),
        "{stdout}"
    );
    assert!(
        !tmp.file("box.bookmarks.scene").exists(),
        "nothing written beside the scene"
    );
    let saved = std::fs::read_to_string(file).expect("bookmarks file");
    let block = |n: u32| {
        format!(
            "camera \"bookmark {n}\"\n{{\n\tposition 0 1 3.9\n\ttarget 0 1 2.9\n\tfov_deg 40\n\tnear 0.1\n\tfar 20\n}}\n"
        )
    };
    assert_eq!(saved, format!("{}{}", block(1), block(2)));
    let out = command_in(
        &repo(),
        &["scene", "check", file.to_str().expect("utf-8 path")],
    )
    .output()
    .expect("weft runs");
    assert!(out.status.success(), "{}", text(&out.stderr));
    // --bookmarks names the file instead.
    let named = tmp.file("marks.scene");
    let out = x.weft(&[
        "view",
        scene.to_str().expect("utf-8 path"),
        "--size",
        "32x18",
        "--frames",
        "2",
        "--bookmarks",
        named.to_str().expect("utf-8 path"),
        "--validate",
        "--press",
        "1:b",
    ]);
    assert_clean(&out);
    assert_eq!(
        std::fs::read_to_string(&named).expect("named bookmarks file"),
        block(1)
    );
}

#[test]
fn the_overlay_and_live_error_stay_silent_across_a_resize() {
    let x = Xvfb::start();
    let out = x.weft(&[
        "view",
        "scenes/cornell.scene",
        "--size",
        "96x54",
        "--frames",
        "8",
        "--resize-to",
        "120x80",
        "--panel",
        "--press",
        "0:l",
        "--validate",
    ]);
    assert_clean(&out);
    assert!(
        text(&out.stdout).contains("live error on"),
        "{}",
        text(&out.stdout)
    );
}

#[test]
fn the_panel_turns_the_environment_map_as_a_scenes_rotation_deg_does() {
    let x = Xvfb::start();
    let tmp = Temp::new("panel-environment");
    let shown = tmp.file("shown.png");
    let headless = tmp.file("headless.png");
    let stdout = view_scene(
        &x,
        "scenes/environment.scene",
        (&shown, "480x270"),
        "10",
        &[
            "--panel",
            "--ui",
            "3:click:environment:rotation_deg,4:text:90,4:enter",
        ],
    );
    assert!(
        stdout.contains("environment rotation_deg = 90\n"),
        "{stdout}"
    );
    // The same scene with the map turned in the file, rendered headless at
    // the view's size beside the panel.
    let text_of = std::fs::read_to_string(repo().join("scenes/environment.scene")).expect("scene");
    let turned = tmp.file("turned.scene");
    let scenes = repo().join("scenes");
    let absolute = text_of
        .replace(
            "\"../../shared",
            &format!("\"{}/../shared", repo().display()),
        )
        .replace("\"models/", &format!("\"{}/models/", scenes.display()))
        .replace("rotation_deg 0", "rotation_deg 90");
    assert_ne!(absolute, text_of);
    std::fs::write(&turned, absolute).expect("scene");
    assert_render_matches(
        &x,
        &shown,
        &headless,
        &[turned.to_str().expect("utf-8 path")],
    );
}

#[test]
fn the_panel_picks_another_map_as_environment_does() {
    let x = Xvfb::start();
    let tmp = Temp::new("panel-pick-map");
    let shown = tmp.file("shown.png");
    let headless = tmp.file("headless.png");
    view_scene(
        &x,
        "scenes/environment.scene",
        (&shown, "480x270"),
        "12",
        &[
            "--panel",
            "--ui",
            "3:click:environment,4:click:environment:sky.exr",
        ],
    );
    let sky = repo().join("../shared/assets/hdri/sky.exr");
    let sky = sky.to_str().expect("utf-8 path");
    assert_render_matches(
        &x,
        &shown,
        &headless,
        &["scenes/environment.scene", "--environment", sky],
    );
}
