//! Debug views (graphs/debug_views.ron) on geometry whose answers are known
//! exactly, under validation and synchronization validation (zero messages):
//! - N stacked quads that each cover the whole view: overdraw N at every pixel;
//! - the same quads drawn front to back and back to front: overshading 1 and
//!   N with early depth tests, in the forward pass and the G-buffer pass;
//! - a regular grid of triangles of known pixel area: mesh density 2 / k^2;
//! - the shared legend, pixel by pixel;
//! - every view in forward, deferred and tiled;
//! - the overshading total against the pass's pipeline statistics.

use weft_tests::render as common;

use common::graph;
use std::path::{Path, PathBuf};
use weft_gpu::readback::Readback;
use weft_gpu::TimingMode;
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings, Rendered};

const QUADS: usize = 3;
/// The test view: 128 x 128 pixels, 90 degrees vertically, looking down -z.
const SIZE: u32 = 128;

fn scratch(name: &str) -> PathBuf {
    weft_testkit::scratch::scratch(&format!("weft-views-{name}-{}", std::process::id()))
}

const CAMERA: &str = "camera\n{\n\tposition 0 0 0\n\ttarget 0 0 -1\n\tfov_deg 90\n}\n";

/// Writes `NAME.obj` with `obj` and `NAME.scene` placing it under a sun,
/// seen by the test camera; returns the scene.
fn write_scene(dir: &Path, name: &str, obj: &str) -> PathBuf {
    std::fs::write(dir.join(format!("{name}.obj")), obj).unwrap();
    let text = format!(
        "model\n{{\n\tfile \"{name}.obj\"\n}}\nsunlight\n{{\n\tdirection 0 0 -1\n\tcolor 1 1 1\n}}\n{CAMERA}"
    );
    let path = dir.join(format!("{name}.scene"));
    std::fs::write(&path, text).unwrap();
    path
}

/// Quads facing the camera at z = -2, -3, ..., each far wider than the view,
/// nearest first (`front_to_back`) or farthest first, in one mesh so the
/// draw order is the file's order.
fn stacked_scene(dir: &Path, front_to_back: bool) -> PathBuf {
    let mut depths: Vec<usize> = (0..QUADS).collect();
    if !front_to_back {
        depths.reverse();
    }
    let mut obj = String::new();
    for (k, d) in depths.iter().enumerate() {
        let z = -2.0 - *d as f32;
        obj.push_str(&format!(
            "v -50 -50 {z}\nv 50 -50 {z}\nv 50 50 {z}\nv -50 50 {z}\nf {} {} {} {}\n",
            4 * k + 1,
            4 * k + 2,
            4 * k + 3,
            4 * k + 4
        ));
    }
    write_scene(dir, "stacked", &obj)
}

/// A plane at z = -4 that fills the view, cut into a grid of squares of
/// `cell` pixels, each two triangles of cell^2 / 2 pixels.
fn grid_scene(dir: &Path, cell: u32) -> PathBuf {
    // At distance 4 with a 90-degree view the plane spans -4..4: 8 units over SIZE pixels.
    let n = SIZE / cell;
    let step = 8.0 / n as f32;
    let mut obj = String::new();
    for j in 0..=n {
        for i in 0..=n {
            obj.push_str(&format!(
                "v {} {} -4\n",
                -4.0 + i as f32 * step,
                -4.0 + j as f32 * step
            ));
        }
    }
    for j in 0..n {
        for i in 0..n {
            let v = |i: u32, j: u32| j * (n + 1) + i + 1;
            obj.push_str(&format!(
                "f {} {} {}\nf {} {} {}\n",
                v(i, j),
                v(i + 1, j),
                v(i + 1, j + 1),
                v(i, j),
                v(i + 1, j + 1),
                v(i, j + 1)
            ));
        }
    }
    write_scene(dir, "grid", &obj)
}

/// Renders `scene` through `graph_name` with `features` (bloom off) under
/// validation, asserting zero messages.
fn render_view(scene: &Path, graph_name: &str, features: &[&str], timing: TimingMode) -> Rendered {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let mut wanted: Vec<String> = features.iter().map(|f| f.to_string()).collect();
    wanted.push("!bloom".into());
    let settings = RenderSettings {
        graph: graph(graph_name),
        extent: Extent {
            width: SIZE,
            height: SIZE,
        },
        features: wanted,
        timing,
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new(), "{graph_name} {features:?}");
    rendered
}

/// The view image `name` read back.
fn view_image<'r>(rendered: &'r Rendered, name: &str) -> &'r Readback {
    let view = rendered
        .plan
        .views
        .iter()
        .find(|v| v.name == name)
        .unwrap_or_else(|| panic!("view {name} in the plan"));
    let image = &rendered.plan.resources[view.image].name;
    &rendered
        .report
        .readbacks
        .iter()
        .find(|(n, _)| n == image)
        .unwrap_or_else(|| panic!("{image} read back"))
        .1
}

fn counts(rendered: &Rendered, name: &str) -> Vec<f64> {
    view_image(rendered, name)
        .pixels
        .values()
        .expect("a count view")
}

#[test]
fn stacked_quads_overdraw_every_pixel_exactly_n_times() {
    let dir = scratch("overdraw");
    for graph_name in ["forward.ron", "deferred.ron"] {
        let rendered = render_view(
            &stacked_scene(&dir, true),
            graph_name,
            &["overdraw"],
            TimingMode::Off,
        );
        let values = counts(&rendered, "overdraw");
        assert_eq!(values.len(), (SIZE * SIZE) as usize);
        assert!(
            values.iter().all(|&v| v == QUADS as f64),
            "{graph_name}: every pixel {QUADS}"
        );
        let (_, s) = &rendered.views[0];
        assert_eq!((s.mean, s.median, s.p95, s.max), (3.0, 3.0, 3.0, 3.0));
        assert_eq!(s.share_above, 0.0, "threshold 3: none above");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn early_depth_tests_make_overshading_one_front_to_back_and_n_back_to_front() {
    let dir = scratch("overshading");
    for (graph_name, features) in [
        ("forward.ron", vec!["overshading"]),
        ("forward.ron", vec!["overshading", "depth_prepass"]),
        ("deferred.ron", vec!["overshading"]),
    ] {
        for (front_to_back, expected) in [(true, 1.0), (false, QUADS as f64)] {
            let rendered = render_view(
                &stacked_scene(&dir, front_to_back),
                graph_name,
                &features,
                TimingMode::Off,
            );
            let values = counts(&rendered, "overshading");
            // With a pre-pass laying depth down first, the shading pass tests
            // for equality: once per pixel whatever the order.
            let expected = if features.contains(&"depth_prepass") {
                1.0
            } else {
                expected
            };
            assert!(
                values.iter().all(|&v| v == expected),
                "{graph_name} {features:?} front_to_back {front_to_back}: every pixel {expected}, found {:?}",
                values.iter().copied().fold(f64::NAN, f64::max)
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The overshading image's total against the shading pass's
/// fragment-shader-invocation statistic. A device that counts invocations
/// after early depth tests must give the same number in both draw orders.
/// lavapipe counts the fragments it rasterises before its early depth test,
/// in whole blocks: there the statistic is the same for both orders and at
/// least every fragment drawn, while the image counts 1 and N per pixel
/// (docs/debug-views.md gives the figures).
#[test]
fn overshading_totals_against_the_pipeline_statistics() {
    let dir = scratch("statistics");
    let cpu = weft_tests::gpu().info().kind == weft_gpu::DeviceKind::Cpu;
    for (graph_name, pass) in [("forward.ron", "forward"), ("deferred.ron", "gbuffer")] {
        let mut statistics = Vec::new();
        for (front_to_back, per_pixel) in [(true, 1.0), (false, QUADS as f64)] {
            let rendered = render_view(
                &stacked_scene(&dir, front_to_back),
                graph_name,
                &["overshading"],
                TimingMode::GpuTimestamps,
            );
            let total: f64 = counts(&rendered, "overshading").iter().sum();
            assert_eq!(total, per_pixel * f64::from(SIZE * SIZE));
            let invocations = rendered
                .report
                .statistics
                .iter()
                .find(|s| s.pass == pass)
                .expect("statistics for the shading pass")
                .fragment_invocations as f64;
            eprintln!(
                "{graph_name} front_to_back {front_to_back}: image total {total}, statistics {invocations}"
            );
            if cpu {
                assert!(
                    invocations >= (QUADS as u32 * SIZE * SIZE) as f64,
                    "{graph_name}"
                );
            } else {
                assert_eq!(total, invocations, "{graph_name} {pass}");
            }
            statistics.push(invocations);
        }
        if cpu {
            assert_eq!(
                statistics[0], statistics[1],
                "{graph_name}: lavapipe counts before early depth tests"
            );
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_regular_grid_has_the_density_of_its_triangles_areas() {
    let dir = scratch("density");
    for cell in [8u32, 2] {
        let rendered = render_view(
            &grid_scene(&dir, cell),
            "forward.ron",
            &["mesh_density"],
            TimingMode::Off,
        );
        let values = view_image(&rendered, "mesh_density")
            .pixels
            .values()
            .unwrap();
        let expected = 2.0 / f64::from(cell * cell);
        let worst = values
            .iter()
            .map(|v| (v / expected - 1.0).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 1e-3,
            "cell {cell}: density within 0.1% of {expected} at every pixel, worst relative error {worst}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_legend_shows_the_scale_with_its_numbers_and_the_view_its_colours() {
    let dir = scratch("legend");
    let rendered = render_view(
        &stacked_scene(&dir, true),
        "forward.ron",
        &["overdraw"],
        TimingMode::Off,
    );
    let image = rendered.report.output.as_ref().expect("readback");
    let at = |x: i32, y: i32| image.rgba8_at(x as u32, SIZE - 1 - y as u32);
    let bar = 64; // clamp(width / 4, 64, 256)
                  // Every pixel outside the legend is the count's colour: 3 of a top of 3.
    assert!(
        weft_tests::legend::close(at(100, 100), weft_tests::legend::VIRIDIS_END),
        "view {:?}",
        at(100, 100)
    );
    // The scale is the frame's largest count: labels 0, 1, 3.
    weft_tests::legend::assert_legend(at, bar, [0, 1, 3]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn every_view_renders_without_validation_messages_in_every_graph() {
    let demo = common::root().join("scenes/demo.scene");
    for graph_name in ["forward.ron", "deferred.ron", "tiled.ron"] {
        for view in [
            "overdraw",
            "overshading",
            "mesh_density",
            "normals",
            "light_count",
        ] {
            let rendered = render_view(&demo, graph_name, &[view], TimingMode::Off);
            assert!(
                rendered
                    .plan
                    .passes
                    .iter()
                    .any(|p| p.name == format!("show_{view}")),
                "{graph_name} {view}: the view's legend pass runs"
            );
        }
    }
}
