//! `weft view` under a private Xvfb: the window opens, renders and presents
//! with validation (synchronization included) silent, resizes, and what it
//! shows matches the headless render of the same camera. Every test starts its
//! own X server on a display number the server picks (`-displayfd`) and stops
//! it when the test ends, passed or failed.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

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

    /// Runs `weft` with `args` on this display.
    fn weft(&self, args: &[&str]) -> Output {
        Command::new(env!("CARGO_BIN_EXE_weft"))
            .args(args)
            .current_dir(repo())
            .env("DISPLAY", &self.display)
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .expect("weft runs")
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-view-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
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

#[test]
fn opens_renders_presents_and_exits_cleanly() {
    let x = Xvfb::start();
    let shot = temp("open.png");
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
    assert!(stdout.contains("graph graphs/forward.ron: features 1 "), "{stdout}");
    let image = load(&shot);
    assert_eq!(image.dimensions(), (160, 90));
    let lit = image.pixels().filter(|p| p[0] > 8 || p[1] > 8 || p[2] > 8).count();
    assert!(lit > 160 * 90 / 4, "only {lit} pixels are not black");
}

#[test]
fn resizing_rebuilds_the_swapchain_and_the_plan() {
    let x = Xvfb::start();
    let shot = temp("resized.png");
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
    let shown = temp("shown.png");
    let headless = temp("headless.png");
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
    let (a, b) = (load(&shown), load(&headless));
    assert_eq!(a.dimensions(), b.dimensions());
    let mut diffs: Vec<u8> = a
        .pixels()
        .zip(b.pixels())
        .flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c])))
        .collect();
    diffs.sort_unstable();
    let mean = diffs.iter().map(|&d| f64::from(d)).sum::<f64>() / diffs.len() as f64;
    let p99 = diffs[diffs.len() * 99 / 100];
    let max = diffs[diffs.len() - 1];
    eprintln!("screenshot vs headless: mean {mean:.4}, p99 {p99}, max {max}");
    assert!(mean <= 0.05 && p99 <= 1 && max <= 1, "mean {mean}, p99 {p99}, max {max}");
}

#[test]
fn a_graph_that_does_not_load_is_reported_at_its_line() {
    let x = Xvfb::start();
    let graph = temp("broken.ron");
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
