//! `weft render --watch`: edits to a shader, the graph and the scene are picked
//! up; broken edits leave the process alive with the last good image and print
//! the error at file:line; fixing them recovers; SIGTERM and SIGINT exit with status 0.

use crate::watch_support::{brightness, frame_ms, serial, Fixture, Watch, SCENE};
use std::time::{Duration, Instant};

const TONEMAP: &str = "shaders/tonemap.frag";
const GRAPH: &str = "graphs/forward.ron";
const TONEMAP_OUT: &str = "color = vec4(c / (1.0 + c), 1.0);";

#[test]
fn shader_edit_error_and_fix() {
    let _serial = serial();
    let fixture = Fixture::new("shader");
    let mut watch = Watch::start(&fixture, &[]);
    let original = fixture.read(TONEMAP);
    let first = fixture.pixels();

    fixture.save_by_rename(
        TONEMAP,
        &original.replace(TONEMAP_OUT, "color = vec4(1.0, 0.0, 0.0, 1.0);"),
    );
    let line = watch.line();
    assert!(
        line.starts_with("reloaded ") && line.contains("tonemap.frag"),
        "{line}"
    );
    let red = fixture.pixels();
    assert!(
        red.chunks_exact(4).all(|p| p == [255, 0, 0, 255]),
        "every pixel red after the edit"
    );

    let broken_line = original.lines().count() + 1;
    fixture.save_in_place(TONEMAP, &format!("{original}this is not glsl\n"));
    let line = watch.line();
    assert!(
        line.starts_with("error: ")
            && line.contains(&format!("tonemap.frag:{broken_line}: "))
            && line.ends_with("(kept last good)"),
        "{line}"
    );
    assert_eq!(fixture.pixels(), red, "the last good image is kept");

    fixture.save_by_rename(TONEMAP, &original);
    let line = watch.line();
    assert!(line.starts_with("reloaded "), "{line}");
    assert_eq!(
        fixture.pixels(),
        first,
        "fixing the shader recovers the image"
    );
    let status = watch.terminate();
    assert!(status.success(), "{status:?}");
}

#[test]
fn a_broken_first_version_is_waited_for() {
    let _serial = serial();
    let fixture = Fixture::new("startup");
    let original = fixture.read(TONEMAP);
    let broken_line = original.lines().count() + 1;
    fixture.save_in_place(TONEMAP, &format!("{original}this is not glsl\n"));
    let mut watch = Watch::spawn(&fixture, &[]);
    let line = watch.line();
    assert!(
        line.starts_with("error: ")
            && line.contains(&format!("tonemap.frag:{broken_line}: "))
            && line.ends_with("(no good version yet; waiting for a fix)"),
        "{line}"
    );
    assert!(!fixture.path("out/live.png").exists());

    fixture.save_by_rename(TONEMAP, &original);
    let line = watch.line();
    assert!(line.starts_with("wrote out/live.png"), "{line}");
    assert!(brightness(&fixture.pixels()) > 0.0);
    let status = watch.terminate();
    assert!(status.success(), "{status:?}");
}

#[test]
fn shader_include_error_is_located_in_the_include() {
    let _serial = serial();
    let fixture = Fixture::new("include");
    let mut watch = Watch::start(&fixture, &[]);
    let include = "shaders/include/lighting.glsl";
    let original = fixture.read(include);
    let first = fixture.pixels();

    let broken_line = original.lines().count() + 1;
    fixture.save_in_place(include, &format!("{original}this is not glsl\n"));
    let line = watch.line();
    assert!(
        line.starts_with("error: ")
            && line.contains(&format!("lighting.glsl:{broken_line}: "))
            && line.ends_with("(kept last good)"),
        "{line}"
    );
    assert_eq!(fixture.pixels(), first, "the last good image is kept");

    fixture.save_by_rename(include, &format!("{original}// edited\n"));
    let line = watch.line();
    assert!(
        line.starts_with("reloaded ") && line.contains("lighting.glsl"),
        "{line}"
    );
    assert_eq!(fixture.pixels(), first, "a comment changes nothing");
    let status = watch.terminate();
    assert!(status.success(), "{status:?}");
}

#[test]
fn graph_edit_validation_error_and_fix() {
    let _serial = serial();
    let fixture = Fixture::new("graph");
    let mut watch = Watch::start(&fixture, &[]);
    let original = fixture.read(GRAPH);
    let first = fixture.pixels();

    let brighter = original.replace("\"exposure\": 1.0,", "\"exposure\": 4.0,");
    assert_ne!(brighter, original);
    fixture.save_by_rename(GRAPH, &brighter);
    let line = watch.line();
    assert!(
        line.starts_with("reloaded ") && line.contains("forward.ron"),
        "{line}"
    );
    let bright = fixture.pixels();
    assert!(
        brightness(&bright) > brightness(&first) + 5.0,
        "exposure 4 brightens: {} -> {}",
        brightness(&first),
        brightness(&bright)
    );

    let typo = brighter.replace(
        "(name: \"hdr\", enabled_if: [\"!taa\"])",
        "(name: \"hdx\", enabled_if: [\"!taa\"])",
    );
    assert_ne!(typo, brighter);
    let typo_line = typo
        .lines()
        .position(|l| l.contains("\"hdx\""))
        .map(|i| i + 1)
        .unwrap_or_default();
    fixture.save_in_place(GRAPH, &typo);
    let line = watch.line();
    assert!(
        line.starts_with("error: ")
            && line.contains(&format!("forward.ron:{typo_line}: "))
            && line.contains("hdx")
            && line.ends_with("(kept last good)"),
        "{line}"
    );
    assert_eq!(fixture.pixels(), bright, "the last good image is kept");

    fixture.save_by_rename(GRAPH, &original);
    let line = watch.line();
    assert!(line.starts_with("reloaded "), "{line}");
    assert_eq!(
        fixture.pixels(),
        first,
        "restoring the graph recovers the image"
    );
    let status = watch.interrupt();
    assert!(status.success(), "{status:?}");
}

#[test]
fn scene_edit_adds_a_light_and_survives_a_syntax_error() {
    let _serial = serial();
    let fixture = Fixture::new("scene");
    let mut watch = Watch::start(&fixture, &[]);
    let first = fixture.pixels();

    let lit = format!(
        "{SCENE}\npointlight\n{{\n\tposition 0 1 0.5\n\tcolor 3 3 3\n\tattenuation 1 0 1\n}}\n"
    );
    fixture.save_in_place("scenes/tiny.scene", &lit);
    let line = watch.line();
    assert!(
        line.starts_with("reloaded ") && line.contains("tiny.scene"),
        "{line}"
    );
    let brighter = fixture.pixels();
    assert!(
        brightness(&brighter) > brightness(&first) + 2.0,
        "a point light brightens: {} -> {}",
        brightness(&first),
        brightness(&brighter)
    );

    let broken_line = lit.lines().count() + 1;
    fixture.save_by_rename("scenes/tiny.scene", &format!("{lit}pointlight }}\n"));
    let line = watch.line();
    assert!(
        line.starts_with("error: ")
            && line.contains(&format!("tiny.scene:{broken_line}: "))
            && line.ends_with("(kept last good)"),
        "{line}"
    );
    assert_eq!(fixture.pixels(), brighter, "the last good image is kept");

    fixture.save_by_rename("scenes/tiny.scene", SCENE);
    let line = watch.line();
    assert!(line.starts_with("reloaded "), "{line}");
    assert_eq!(
        fixture.pixels(),
        first,
        "removing the light recovers the image"
    );
    let status = watch.terminate();
    assert!(status.success(), "{status:?}");
}

/// Resident memory the soak may add after its warm-up edits, in KiB.
const SOAK_RSS_GROWTH_KIB: u64 = 32 * 1024;

#[test]
fn soak_of_200_alternating_good_and_bad_shader_edits() {
    let _serial = serial();
    let fixture = Fixture::new("soak");
    let mut watch = Watch::start(&fixture, &["--validate"]);
    let original = fixture.read(TONEMAP);
    let mut warm_rss = 0;
    for i in 0..200 {
        let good = i % 2 == 0;
        let text = if good {
            let scale = 0.5 + f64::from(i % 20) * 0.025;
            original.replace(
                TONEMAP_OUT,
                &format!("color = vec4(c / (1.0 + c) * {scale:.3}, 1.0);"),
            )
        } else {
            format!("{original}broken {i}\n")
        };
        if i % 4 < 2 {
            fixture.save_by_rename(TONEMAP, &text);
        } else {
            fixture.save_in_place(TONEMAP, &text);
        }
        let line = watch.line();
        let expected = if good { "reloaded " } else { "error: " };
        assert!(line.starts_with(expected), "edit {i}: {line}");
        if i == 19 {
            warm_rss = watch.rss_kib();
        }
    }
    let end_rss = watch.rss_kib();
    let stderr = watch.stderr();
    assert!(!stderr.contains("validation"), "{stderr}");
    let status = watch.terminate();
    assert!(status.success(), "{status:?}");
    println!("soak RSS: {warm_rss} KiB after 20 edits, {end_rss} KiB after 200");
    assert!(
        end_rss <= warm_rss + SOAK_RSS_GROWTH_KIB,
        "RSS grew from {warm_rss} KiB to {end_rss} KiB"
    );
}

/// Edit-to-image milliseconds without the frame itself: from just before the save
/// to the child's line saying the image was replaced, less the frame time it reports.
fn latencies(watch: &mut Watch, edits: impl Iterator<Item = Box<dyn Fn()>>) -> Vec<f64> {
    let mut out = Vec::new();
    for edit in edits {
        let saved = Instant::now();
        edit();
        let (line, seen) = watch.timed_line();
        assert!(line.starts_with("reloaded "), "{line}");
        out.push(seen.duration_since(saved).as_secs_f64() * 1e3 - frame_ms(&line));
        std::thread::sleep(Duration::from_millis(20));
    }
    out.sort_by(f64::total_cmp);
    out
}

#[test]
fn edit_to_image_latency() {
    let _serial = serial();
    let fixture = std::sync::Arc::new(Fixture::new("latency"));
    let mut watch = Watch::start(&fixture, &[]);
    let shader = fixture.read(TONEMAP);
    let graph = fixture.read(GRAPH);
    let shader_edits = (0..11).map(|i| {
        let (fixture, shader) = (fixture.clone(), shader.clone());
        Box::new(move || {
            let scale = format!("color = vec4(c / (1.0 + c) * 0.{i:02}, 1.0);");
            fixture.save_by_rename(TONEMAP, &shader.replace(TONEMAP_OUT, &scale));
        }) as Box<dyn Fn()>
    });
    let shader_ms = latencies(&mut watch, shader_edits);
    let graph_edits = (0..11).map(|i| {
        let (fixture, graph) = (fixture.clone(), graph.clone());
        Box::new(move || {
            let exposure = format!("\"exposure\": 1.{i:02},");
            let edited = graph.replace("\"exposure\": 1.0,", &exposure);
            assert_ne!(edited, graph, "the graph edit changes the file");
            fixture.save_by_rename(GRAPH, &edited);
        }) as Box<dyn Fn()>
    });
    let graph_ms = latencies(&mut watch, graph_edits);
    let median = |v: &[f64]| v[v.len() / 2];
    println!(
        "edit-to-image latency without the frame, median of 11: shader {:.1} ms, graph {:.1} ms",
        median(&shader_ms),
        median(&graph_ms)
    );
    println!("shader: {shader_ms:.1?}\ngraph: {graph_ms:.1?}");
    assert!(median(&shader_ms) <= 250.0, "{shader_ms:?}");
    assert!(median(&graph_ms) <= 250.0, "{graph_ms:?}");
    let status = watch.terminate();
    assert!(status.success(), "{status:?}");
}

/// A scene script whose `update` fails at its first step is refused at once
/// with its location, also at the default `--time 0` (where no step would
/// otherwise run), and the fixed script is picked up.
#[test]
fn a_script_whose_update_fails_is_reported_at_time_zero() {
    let _serial = serial();
    let fixture = Fixture::new("update-error");
    fixture.save_in_place(
        "scenes/tiny.scene",
        &format!("{SCENE}\nscript \"bad.rhai\"\n"),
    );
    fixture.save_in_place(
        "scenes/bad.rhai",
        "fn update(t, dt) {\n    set_light_on(99, false);\n}\n",
    );
    let mut watch = Watch::spawn(&fixture, &[]);
    let line = watch.line();
    assert!(
        line.starts_with("error: ")
            && line.contains("bad.rhai:2: no light 99: the scene has 1")
            && line.ends_with("(no good version yet; waiting for a fix)"),
        "{line}"
    );
    fixture.save_by_rename(
        "scenes/bad.rhai",
        "fn update(t, dt) {\n    set_light_on(0, true);\n}\n",
    );
    let line = watch.line();
    assert!(line.starts_with("wrote out/live.png"), "{line}");
    let status = watch.terminate();
    assert!(status.success(), "{status:?}");
}
