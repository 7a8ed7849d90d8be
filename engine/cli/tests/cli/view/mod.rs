//! `weft view` under a private Xvfb: the window opens, renders and presents
//! with validation (synchronization included) silent, resizes, what it shows
//! matches the headless render of the same camera, and shader edits are hot
//! reloaded (a broken one keeps the last good version). Every test starts its
//! own X server on a display number the server picks (`-displayfd`) and stops
//! it when the test ends, passed or failed.

mod input;
mod panel;
mod reload;

use crate::harness::{command_in, repo};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

/// An Xvfb server of this test, killed on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    /// Starts Xvfb, letting it pick a free display and report it on stdout.
    fn start() -> Self {
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1024x768x24",
                "-nolisten",
                "tcp",
            ])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("Xvfb runs (tools/setup installs it)");
        let stdout = child.stdout.take().expect("piped stdout");
        let mut line = String::new();
        let read = BufReader::new(stdout).read_line(&mut line);
        let number = line.trim().to_string();
        let server = Self {
            child,
            display: format!(":{number}"),
        };
        assert!(
            read.is_ok() && !number.is_empty() && number.bytes().all(|b| b.is_ascii_digit()),
            "Xvfb did not report a display: {line:?}"
        );
        server
    }

    /// `weft` with `args` on this display, run in `dir`.
    fn command(&self, args: &[&str], dir: &Path) -> Command {
        let mut command = command_in(dir, args);
        command
            .env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY");
        command
    }

    /// Runs `weft` with `args` on this display in the repository.
    fn weft(&self, args: &[&str]) -> Output {
        self.command(args, &repo()).output().expect("weft runs")
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// A test's own temporary folder, removed when the test ends.
struct Temp(PathBuf);

impl Temp {
    fn new(test: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("weft-view-cli-{test}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("temp dir");
        Self(dir)
    }

    fn file(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Temp {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Asserts a clean exit with validation on and nothing reported.
fn assert_clean(out: &Output) {
    let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
    assert!(out.status.success(), "stdout:\n{stdout}\nstderr:\n{stderr}");
    assert!(
        stdout.contains("validation: 0 errors, 0 warnings, 0 performance warnings"),
        "{stdout}"
    );
    assert!(!stderr.contains("validation"), "{stderr}");
}

fn load(path: &Path) -> image::RgbaImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgba8()
}

/// Per-channel differences of two images of one size: (mean, p99, max).
fn differences(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, u8, u8) {
    assert_eq!(a.dimensions(), b.dimensions());
    let mut diffs: Vec<u8> = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
        .collect();
    diffs.sort_unstable();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    (mean, diffs[diffs.len() * 99 / 100], diffs[diffs.len() - 1])
}

#[test]
fn opens_renders_presents_and_exits_cleanly() {
    let x = Xvfb::start();
    let tmp = Temp::new("open");
    let shot = tmp.file("open.png");
    let out = x.weft(&[
        "view",
        "scenes/demo.scene",
        "--size",
        "160x90",
        "--frames",
        "4",
        "--validate",
        "--screenshot-on-exit",
        shot.to_str().expect("utf-8 path"),
    ]);
    assert_clean(&out);
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("graph graphs/forward.ron: features 1 "),
        "{stdout}"
    );
    let image = load(&shot);
    assert_eq!(image.dimensions(), (160, 90));
    let lit = image
        .pixels()
        .filter(|p| p[0] > 8 || p[1] > 8 || p[2] > 8)
        .count();
    assert!(lit > 160 * 90 / 4, "only {lit} pixels are not black");
}

#[test]
fn resizing_rebuilds_the_swapchain_and_the_plan() {
    let x = Xvfb::start();
    let tmp = Temp::new("resize");
    let shot = tmp.file("resized.png");
    let out = x.weft(&[
        "view",
        "scenes/demo.scene",
        "--graph",
        "graphs/deferred.ron",
        "--size",
        "160x90",
        "--frames",
        "8",
        "--resize-to",
        "96x120",
        "--validate",
        "--screenshot-on-exit",
        shot.to_str().expect("utf-8 path"),
    ]);
    assert_clean(&out);
    assert_eq!(load(&shot).dimensions(), (96, 120));
}

/// The presented image equals the headless render of the same camera: the
/// blit is same-size and sRGB to sRGB, so the only allowed difference is
/// rounding, at most 1 of 255 per channel (measured: 0).
#[test]
fn screenshot_matches_the_headless_render() {
    let x = Xvfb::start();
    let tmp = Temp::new("match");
    let shown = tmp.file("shown.png");
    let headless = tmp.file("headless.png");
    let out = x.weft(&[
        "view",
        "scenes/demo.scene",
        "--size",
        "128x72",
        "--camera",
        "closeup",
        "--paused",
        "--frames",
        "1",
        "--screenshot-on-exit",
        shown.to_str().expect("utf-8 path"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = x.weft(&[
        "render",
        "scenes/demo.scene",
        "--size",
        "128x72",
        "--camera",
        "closeup",
        "--out",
        headless.to_str().expect("utf-8 path"),
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let (mean, p99, max) = differences(&load(&shown), &load(&headless));
    eprintln!("screenshot vs headless: mean {mean:.4}, p99 {p99}, max {max}");
    assert!(
        mean <= 0.05 && p99 <= 1 && max <= 1,
        "mean {mean}, p99 {p99}, max {max}"
    );
}

#[test]
fn a_graph_that_does_not_load_is_reported_at_its_line() {
    let x = Xvfb::start();
    let tmp = Temp::new("broken");
    let graph = tmp.file("broken.ron");
    std::fs::write(&graph, "(\n  name: \"broken\",\n  passes: [,\n").expect("write graph");
    let out = x.weft(&[
        "view",
        "scenes/demo.scene",
        "--graph",
        graph.to_str().expect("utf-8 path"),
        "--frames",
        "1",
    ]);
    assert!(!out.status.success());
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains(&format!("{}:3", graph.display())),
        "{stderr}"
    );
}

/// Keys pressed by script: G switches to the next graph in `graphs/`, 1 flips the
/// first feature, F12 saves what the window shows into the user's pictures
/// folder (here one set up in a temporary XDG config), not the current
/// directory; validation stays silent.
#[test]
fn scripted_keys_switch_graph_toggle_a_feature_and_save_a_screenshot() {
    let x = Xvfb::start();
    let tmp = Temp::new("keys");
    let dir = tmp.0.clone();
    let config = dir.join("config");
    let pictures = dir.join("pictures");
    std::fs::create_dir_all(&config).expect("config dir");
    std::fs::write(
        config.join("user-dirs.dirs"),
        format!("XDG_PICTURES_DIR=\"{}\"\n", pictures.display()),
    )
    .expect("user-dirs.dirs");
    let scene = repo().join("scenes/demo.scene");
    let graph = repo().join("graphs/forward.ron");
    let out = x
        .command(
            &[
                "view",
                scene.to_str().expect("utf-8 path"),
                "--graph",
                graph.to_str().expect("utf-8 path"),
                "--size",
                "96x54",
                "--frames",
                "6",
                "--press",
                "1:g,2:g,3:1,4:f12",
                "--validate",
            ],
            &dir,
        )
        .env("XDG_CONFIG_HOME", &config)
        .output()
        .expect("weft runs");
    assert_clean(&out);
    let stdout = text(&out.stdout);
    let graphs: Vec<&str> = stdout.lines().filter(|l| l.starts_with("graph ")).collect();
    assert_eq!(graphs.len(), 4, "{stdout}");
    assert!(graphs[0].contains("forward.ron: features"), "{stdout}");
    assert!(
        graphs[1].contains("forward_msaa.ron: features"),
        "G moved on to the next graph in graphs/: {stdout}"
    );
    assert!(
        graphs[2].contains("hybrid.ron: features 1 bloom"),
        "G moved on: {stdout}"
    );
    let first_feature = |line: &str| {
        let list = line.split(": features ").nth(1).expect("feature list");
        list.split(", ").next().expect("first feature").to_string()
    };
    let (before, after) = (first_feature(graphs[2]), first_feature(graphs[3]));
    assert_ne!(before, after, "key 1 flips the first feature");
    assert_eq!(
        before.replace("[on]", "[off]").replace("[off]", ""),
        after.replace("[on]", "[off]").replace("[off]", ""),
        "the same feature"
    );
    let saved = stdout
        .lines()
        .find_map(|l| l.strip_prefix("wrote "))
        .unwrap_or_else(|| panic!("no screenshot line: {stdout}"));
    let saved = Path::new(saved);
    assert_eq!(
        saved.parent(),
        Some(pictures.join("weft").as_path()),
        "{stdout}"
    );
    assert!(saved
        .file_name()
        .is_some_and(|n| n.to_string_lossy().starts_with("weft-")));
    assert_eq!(load(saved).dimensions(), (96, 54));
    let in_cwd: Vec<_> = std::fs::read_dir(&dir)
        .expect("test dir")
        .filter_map(|e| e.ok())
        .filter(|e| e.path().extension().is_some_and(|x| x == "png"))
        .collect();
    assert!(
        in_cwd.is_empty(),
        "a PNG in the current directory: {in_cwd:?}"
    );
}

/// The path tracer on an animated scene starts over every frame: the viewer
/// says why and that Space pauses time, once, and says nothing when time is
/// paused from the start (then the image converges).
#[test]
fn a_progressive_graph_on_an_animated_scene_says_the_animation_restarts_it() {
    let hint = "progressive image restarts every frame: the scene animates; Space pauses time";
    let running = view_32x18("animation.scene", "pathtrace.ron", 8, &[]);
    assert_eq!(running.matches(hint).count(), 1, "{running}");
    let paused = view_32x18("animation.scene", "pathtrace.ron", 8, &["--paused"]);
    assert!(!paused.contains(hint), "{paused}");
}

/// `frames` frames at 32x18 of `scenes/SCENE` through `graphs/GRAPH` with
/// `extra` arguments, validation on and silent; what it printed.
fn view_32x18(scene: &str, graph: &str, frames: u32, extra: &[&str]) -> String {
    let x = Xvfb::start();
    let scene = repo().join("scenes").join(scene);
    let graph = repo().join("graphs").join(graph);
    let frames = frames.to_string();
    let mut args = vec![
        "view",
        scene.to_str().expect("utf-8 path"),
        "--graph",
        graph.to_str().expect("utf-8 path"),
        "--size",
        "32x18",
        "--frames",
        &frames,
        "--validate",
    ];
    args.extend_from_slice(extra);
    let out = x.weft(&args);
    assert_clean(&out);
    text(&out.stdout)
}

/// Three frames of the Cornell box through the forward graph with `press`
/// (a `--press` script).
fn cornell_pressing(press: &str) -> String {
    view_32x18("cornell.scene", "forward.ron", 3, &["--press", press])
}

/// C prints the camera as a `.scene` block; before any flying it is the
/// scene's own camera (scenes/cornell.scene's "front": position 0 1 3.9,
/// target 0 1 0, 40 degrees, near 0.1, far 20), with the target one unit ahead.
#[test]
fn c_prints_the_camera_as_a_scene_block() {
    let stdout = cornell_pressing("1:c");
    assert!(
        stdout.contains(
            "camera \"flown\"\n{\n\tposition 0 1 3.9\n\ttarget 0 1 2.9\n\tfov_deg 40\n\tnear 0.1\n\tfar 20\n}\n"
        ),
        "{stdout}"
    );
}

/// Features past the ninth are reached with Shift: on the forward graph over
/// the Cornell box, the graph's own twelve take 1-9 and Shift+1 to Shift+3,
/// and the scene's follow, `area_lights` (the box's emissive quad) at
/// Shift+4, which turns it off.
#[test]
fn shift_and_a_digit_toggle_the_features_past_the_ninth() {
    let stdout = cornell_pressing("1:shift+4");
    let lists: Vec<&str> = stdout.lines().filter(|l| l.starts_with("graph ")).collect();
    assert_eq!(lists.len(), 2, "{stdout}");
    assert!(lists[0].contains(", Shift+4 area_lights [on]"), "{stdout}");
    assert!(lists[1].contains(", Shift+4 area_lights [off]"), "{stdout}");
    assert!(
        lists[0].contains("9 overshading [off], Shift+1 rt_shadows [off]"),
        "{stdout}"
    );
}
