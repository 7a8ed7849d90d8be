//! Shadow maps against geometry, with validation and synchronization validation
//! on (zero messages): a floating box's shadow on a plane lands where the sun's
//! direction predicts, over a 16-unit plane and over one 1e4 units across; a
//! lit plane shows no acne at the default bias; widening
//! PCF never narrows the penumbra; every configuration (forward or deferred,
//! shadows and bloom on or off) runs cleanly; a shadow view that did not change
//! keeps its tile in the persistent shadow map, and the image is exactly what
//! redrawing every tile gives.

use weft_tests::render as common;

use common::{absolute_paths, agreement};

use glam::{Vec3, Vec4Swizzles};
use std::path::{Path, PathBuf};
use weft_gpu::Pixels;
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings};

const SIZE: u32 = 256;

/// A scene block for a white sun travelling along `d`, without ambient light.
fn sun_block(d: Vec3) -> String {
    format!(
        "sunlight\n{{\n\tdirection {} {} {}\n\tcolor 1 1 1\n\tambient 0\n}}\n",
        d.x, d.y, d.z
    )
}

/// A 16x16 plane at y = 0 and, when `box_on`, a unit box floating at y 1..2,
/// lit by `lights` (scene blocks).
fn write_scene(dir: &Path, lights: &str, camera: (Vec3, Vec3), box_on: bool) -> PathBuf {
    write_scene_sized(dir, lights, camera, box_on, 8.0, "")
}

/// [`write_scene`] with a plane `half` units either side of the origin and
/// `camera_extra` statements in the camera block.
fn write_scene_sized(
    dir: &Path,
    lights: &str,
    camera: (Vec3, Vec3),
    box_on: bool,
    half: f32,
    camera_extra: &str,
) -> PathBuf {
    std::fs::create_dir_all(dir).expect("temp dir");
    let mut obj = format!("mtllib white.mtl\nusemtl white\nv -{half} 0 -{half}\nv {half} 0 -{half}\nv {half} 0 {half}\nv -{half} 0 {half}\nf 1 4 3\nf 1 3 2\n");
    if box_on {
        for i in 0..8 {
            let x = if i & 1 == 0 { -0.5 } else { 0.5 };
            let y = if i & 2 == 0 { 1.0 } else { 2.0 };
            let z = if i & 4 == 0 { -0.5 } else { 0.5 };
            obj.push_str(&format!("v {x} {y} {z}\n"));
        }
        for [a, b, c, d] in [
            [1, 3, 7, 5],
            [2, 6, 8, 4],
            [1, 5, 6, 2],
            [3, 4, 8, 7],
            [1, 2, 4, 3],
            [5, 7, 8, 6],
        ] {
            let (a, b, c, d) = (a + 4, b + 4, c + 4, d + 4);
            obj.push_str(&format!("f {a} {b} {c}\nf {a} {c} {d}\n"));
        }
    }
    std::fs::write(dir.join("plane.obj"), obj).expect("obj");
    std::fs::write(dir.join("white.mtl"), "newmtl white\nKd 1 1 1\nKs 0 0 0\n").expect("mtl");
    let (eye, target) = camera;
    let scene = format!(
        "model\n{{\n\tfile \"plane.obj\"\n}}\n{lights}camera \"top\"\n{{\n\tposition {} {} {}\n\ttarget {} {} {}\n\tfov_deg 40\n{camera_extra}}}\n",
        eye.x, eye.y, eye.z, target.x, target.y, target.z
    );
    let path = dir.join("plane.scene");
    std::fs::write(&path, scene).expect("scene");
    path
}

/// `graphs/<graph>` rewritten into `dir` with shadow parameters overridden.
fn graph_with(dir: &Path, graph: &str, shadow_params: &str) -> PathBuf {
    let root = common::root().join("graphs");
    let text = std::fs::read_to_string(root.join(graph)).expect("graph");
    let include = format!(
        "(file: \"{}\", params: {{ {shadow_params} }})",
        root.join("shadows.ron").display()
    );
    let text = text
        .replace(
            "(file: \"shadows.ron\", params: { \"resolution\": 2048 })",
            "(file: \"shadows.ron\")",
        )
        .replace("(file: \"shadows.ron\")", &include);
    let path = dir.join(graph);
    std::fs::write(&path, absolute_paths(&text)).expect("graph");
    path
}

/// Renders `scene` through `graph` and returns the HDR image's red channel, row by row.
fn render_hdr(scene: &Path, graph: &Path) -> Vec<f32> {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: graph.to_path_buf(),
        extent: Extent {
            width: SIZE,
            height: SIZE,
        },
        features: vec!["!bloom".into()],
        extra_readback: vec!["hdr".into()],
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    assert_eq!(rendered.plan.passes.as_slice()[0].name, "shadow_sun");
    let (_, hdr) = &rendered.report.readbacks[0];
    let Pixels::RgbaF32(values) = &hdr.pixels else {
        panic!("hdr is float");
    };
    values.chunks(4).map(|p| p[0]).collect()
}

/// Pixel coordinates (x right, y down, pixel centres at +0.5) of a world point.
fn project(scene: &Path, p: Vec3) -> glam::Vec2 {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let m = scene.cameras[0].view_projection(0.0, 1.0);
    let c = m * p.extend(1.0);
    (c.xy() / c.w * 0.5 + 0.5) * SIZE as f32
}

/// Where pixel (x, y)'s centre ray meets the plane y = 0, if it does.
fn plane_hit(inv: &glam::Mat4, x: u32, y: u32) -> Option<Vec3> {
    let ndc = (glam::Vec2::new(x as f32, y as f32) + 0.5) / SIZE as f32 * 2.0 - 1.0;
    let a = inv.project_point3(ndc.extend(1.0));
    let b = inv.project_point3(ndc.extend(0.5));
    let t = a.y / (a.y - b.y);
    (t > 0.0).then(|| a + (b - a) * t)
}

/// Where a line of samples first crosses `level` going from index `from` in
/// direction `step`, interpolated between samples, as a sample index.
fn crossing(samples: &[f32], from: usize, step: isize, level: f32) -> f32 {
    let mut i = from as isize;
    loop {
        let j = i + step;
        assert!(
            j >= 0 && (j as usize) < samples.len(),
            "no crossing of {level}"
        );
        let (a, b) = (samples[i as usize], samples[j as usize]);
        if (a - level) * (b - level) <= 0.0 && a != b {
            return i as f32 + step as f32 * (a - level) / (a - b);
        }
        i = j;
    }
}

fn row(image: &[f32], y: usize) -> Vec<f32> {
    image[y * SIZE as usize..(y + 1) * SIZE as usize].to_vec()
}

fn column(image: &[f32], x: usize) -> Vec<f32> {
    (0..SIZE as usize)
        .map(|y| image[y * SIZE as usize + x])
        .collect()
}

/// The sun travels along (-2, -1, 0): the box (x, z in -0.5..0.5, y in 1..2)
/// shadows x in -4.5..-1.5, z in -0.5..0.5 on the plane.
const SUN: Vec3 = Vec3::new(-2.0, -1.0, 0.0);
const TOP: (Vec3, Vec3) = (Vec3::new(-3.0, 10.0, 0.0), Vec3::new(-3.0, 0.0, 0.0));

/// The box shadow's four edges on the row and the column through its
/// centre, each as (edge, measured pixel, predicted pixel): where the image
/// crosses half the lit value (the sun along [`SUN`]) against the projection
/// of the edge's world point.
fn box_shadow_edges(scene: &Path, image: &[f32]) -> Vec<(Vec3, f32, f32)> {
    let lit = 1.0 / 5f32.sqrt();
    let centre = project(scene, Vec3::new(-3.0, 0.0, 0.0));
    let (cx, cy) = (centre.x as usize, centre.y as usize);
    assert!(
        image[cy * SIZE as usize + cx] < 0.01,
        "the centre is in shadow"
    );
    [
        (Vec3::new(-4.5, 0.0, 0.0), true),
        (Vec3::new(-1.5, 0.0, 0.0), true),
        (Vec3::new(-3.0, 0.0, -0.5), false),
        (Vec3::new(-3.0, 0.0, 0.5), false),
    ]
    .into_iter()
    .map(|(edge, along_row)| {
        let p = project(scene, edge);
        let (line, from, predicted) = if along_row {
            (row(image, cy), cx, p.x - 0.5)
        } else {
            (column(image, cx), cy, p.y - 0.5)
        };
        let step = if predicted > from as f32 { 1 } else { -1 };
        (edge, crossing(&line, from, step, lit * 0.5), predicted)
    })
    .collect()
}

#[test]
fn a_box_shadow_lands_where_the_sun_direction_predicts() {
    let dir = std::env::temp_dir().join("weft-shadows-analytic");
    let scene = write_scene(&dir, &sun_block(SUN), TOP, true);
    for (graph, cascades) in [("forward.ron", 1), ("deferred.ron", 1), ("forward.ron", 3)] {
        let g = graph_with(&dir, graph, &format!("\"cascades\": {cascades}"));
        let image = render_hdr(&scene, &g);
        for (edge, measured, predicted) in box_shadow_edges(&scene, &image) {
            eprintln!(
                "{graph}, {cascades} cascade(s): edge {edge}: measured {measured:.2} px, predicted {predicted:.2} px"
            );
            assert!(
                (measured - predicted).abs() <= 1.5,
                "{graph}, {cascades} cascade(s): edge at {edge} measured at pixel {measured:.2}, predicted {predicted:.2}"
            );
        }
    }
}

/// Shadow-map precision in a scene 1e4 units across (issue 19): the box of
/// [`a_box_shadow_lands_where_the_sun_direction_predicts`] over a plane
/// 10,000 units wide, the camera's far plane at 20,000, so the sun's views
/// span the whole scene in depth (the D32 depth's steps grow 500-fold in
/// world units against the 16-unit plane). Measured: with four cascades the
/// shadow's edges land within 1.95 px of the prediction (1.27 px over the
/// 16-unit plane: the shadow moves 0.7 px, 0.02 units, further along the
/// sun's direction); with one 2,048² cascade within 0.62 px; no lit pixel of
/// the plane is darkened in any case (no acne). Held to 2.5 px and under
/// 0.1% darkened with four cascades over the wide plane.
#[test]
fn shadows_in_a_scene_1e4_units_across_keep_their_place_with_cascades() {
    let dir = std::env::temp_dir().join("weft-shadows-1e4");
    for (half, cascades) in [(8.0, 4), (5000.0, 4), (5000.0, 1)] {
        let scene = write_scene_sized(&dir, &sun_block(SUN), TOP, true, half, "\tfar 20000\n");
        let loaded = weft_scene::load_scene(&scene).expect("scene loads");
        let inv = loaded.cameras[0].view_projection(0.0, 1.0).inverse();
        let lit = 1.0 / 5f32.sqrt();
        let g = graph_with(&dir, "forward.ron", &format!("\"cascades\": {cascades}"));
        let image = render_hdr(&scene, &g);
        let mut worst = 0.0f32;
        for (edge, measured, predicted) in box_shadow_edges(&scene, &image) {
            println!("{cascades} cascade(s): edge {edge}: measured {measured:.2} px, predicted {predicted:.2} px");
            worst = worst.max((measured - predicted).abs());
        }
        // Plane pixels 2 units or more outside the shadow (x -4.5..-1.5,
        // z -0.5..0.5), beyond any penumbra, and clear of the box itself.
        let outside: Vec<f32> = (0..SIZE * SIZE)
            .filter(|i| {
                plane_hit(&inv, i % SIZE, i / SIZE)
                    .is_some_and(|p| !(-6.5..=2.0).contains(&p.x) || !(-2.5..=2.5).contains(&p.z))
            })
            .map(|i| image[i as usize])
            .collect();
        let darkened = outside.iter().filter(|v| **v < lit * 0.99).count();
        println!(
            "plane {half} either side, {cascades} cascade(s): worst edge {worst:.2} px; {darkened} of {} lit plane pixels darkened",
            outside.len()
        );
        if cascades == 4 && half > 10.0 {
            assert!(worst <= 2.5, "edges {worst} px from the prediction");
            assert!(
                (darkened as f64) < 0.001 * outside.len() as f64,
                "acne: {darkened}"
            );
        }
    }
}

#[test]
fn a_spot_light_shadow_lands_where_its_position_predicts() {
    // A spot 6 above the plane pointing down: the box's top corners (y = 2,
    // x = +-0.5) cast the shadow's edges at x = +-0.5 * 6 / 4 = +-0.75.
    let dir = std::env::temp_dir().join("weft-shadows-spot");
    let spot = "spotlight\n{\n\tposition 0 6 0\n\tdirection 0 -1 0\n\tcolor 1 1 1\n\texponent 0\n\tangle 40\n\tattenuation 1 0 0\n}\n";
    let camera = (Vec3::new(0.0, 8.0, 6.0), Vec3::ZERO);
    let scene = write_scene(&dir, spot, camera, true);
    for graph in ["forward.ron", "deferred.ron"] {
        let g = graph_with(&dir, graph, "");
        let image = render_hdr(&scene, &g);
        let centre = project(&scene, Vec3::ZERO);
        let (cx, cy) = (centre.x as usize, centre.y as usize);
        assert!(
            image[cy * SIZE as usize + cx] < 0.01,
            "{graph}: the centre is in shadow"
        );
        let line = row(&image, cy);
        for x in [-0.75f32, 0.75] {
            let predicted = project(&scene, Vec3::new(x, 0.0, 0.0)).x - 0.5;
            let lit = 6.0 / (36.0 + x * x).sqrt();
            let step = if predicted > cx as f32 { 1 } else { -1 };
            let measured = crossing(&line, cx, step, lit * 0.5);
            eprintln!("{graph}, spot: edge x = {x}: measured {measured:.2} px, predicted {predicted:.2} px");
            assert!(
                (measured - predicted).abs() <= 1.5,
                "{graph}: spot shadow edge x = {x} measured at pixel {measured:.2}, predicted {predicted:.2}"
            );
        }
    }
}

#[test]
fn a_lit_plane_shows_no_acne_at_the_default_bias() {
    let dir = std::env::temp_dir().join("weft-shadows-acne");
    let camera = (Vec3::new(0.0, 4.0, 9.0), Vec3::new(0.0, 0.0, 0.0));
    for (i, degrees) in [10.0f32, 45.0, 70.0].into_iter().enumerate() {
        let d = dir.join(format!("{i}"));
        let angle = degrees.to_radians();
        let sun = Vec3::new(angle.sin() * 0.6, -angle.cos(), angle.sin() * 0.8);
        let scene = write_scene(&d, &sun_block(sun), camera, false);
        // Pixels whose centre sees the plane at least 0.25 from its edges.
        let loaded = weft_scene::load_scene(&scene).expect("scene loads");
        let inv = loaded.cameras[0].view_projection(0.0, 1.0).inverse();
        let inside: Vec<usize> = (0..SIZE * SIZE)
            .filter(|i| {
                plane_hit(&inv, i % SIZE, i / SIZE)
                    .is_some_and(|p| p.x.abs() < 7.75 && p.z.abs() < 7.75)
            })
            .map(|i| i as usize)
            .collect();
        for graph in ["forward.ron", "deferred.ron"] {
            let g = graph_with(&d, graph, "");
            let image = render_hdr(&scene, &g);
            let lit = angle.cos();
            let plane: Vec<f32> = inside.iter().map(|&i| image[i]).collect();
            let darkened = plane.iter().filter(|v| **v < lit * 0.99).count();
            let share = darkened as f64 / plane.len() as f64;
            eprintln!(
                "{graph}, sun {degrees} degrees: {darkened} of {} plane pixels darkened",
                plane.len()
            );
            assert!(plane.len() > 20_000, "the plane fills most of the view");
            assert!(
                share < 0.001,
                "{graph}, sun {degrees} degrees from the normal: {darkened} of {} lit pixels darkened",
                plane.len()
            );
        }
    }
}

/// Width in pixels of the transition from 10% to 90% of the lit value across
/// the shadow's right edge (x = -1.5), on the row through its centre.
fn penumbra(scene: &Path, image: &[f32]) -> f32 {
    let lit = 1.0 / 5f32.sqrt();
    let centre = project(scene, Vec3::new(-3.0, 0.0, 0.0));
    let line = row(image, centre.y as usize);
    let from = centre.x as usize;
    let step = if project(scene, Vec3::new(-1.5, 0.0, 0.0)).x > centre.x {
        1
    } else {
        -1
    };
    (crossing(&line, from, step, lit * 0.9) - crossing(&line, from, step, lit * 0.1)).abs()
}

#[test]
fn widening_pcf_never_narrows_the_penumbra() {
    let dir = std::env::temp_dir().join("weft-shadows-penumbra");
    let scene = write_scene(&dir, &sun_block(SUN), TOP, true);
    let mut widths = Vec::new();
    for r in 0..=3 {
        let g = graph_with(
            &dir,
            "forward.ron",
            &format!("\"resolution\": 512, \"pcf_radius\": {r}"),
        );
        widths.push(penumbra(&scene, &render_hdr(&scene, &g)));
    }
    eprintln!("penumbra widths (pixels) for pcf_radius 0..3 at 512 texels: {widths:?}");
    for w in widths.windows(2) {
        assert!(w[1] >= w[0], "penumbra widths by radius 0..3: {widths:?}");
    }
    assert!(
        widths[3] > widths[0] + 1.0,
        "a 7x7 kernel widens the edge: {widths:?}"
    );
}

#[test]
fn every_configuration_runs_without_validation_messages() {
    for graph in ["forward.ron", "deferred.ron"] {
        for shadows in ["shadow_casters", "!shadow_casters"] {
            for bloom in ["bloom", "!bloom"] {
                let out = common::render_validated(
                    &common::demo_scene(),
                    &common::graph(graph),
                    96,
                    54,
                    &[shadows, bloom],
                );
                assert_eq!(out.messages, Vec::new(), "{graph} {shadows} {bloom}");
                assert_eq!(
                    out.passes.contains(&"shadow_sun".to_string()),
                    shadows == "shadow_casters",
                    "{graph} {shadows} {bloom}: {:?}",
                    out.passes
                );
                assert_eq!(
                    out.passes.contains(&"bloom_bright".to_string()),
                    bloom == "bloom",
                    "{graph} {shadows} {bloom}: {:?}",
                    out.passes
                );
            }
        }
    }
}

/// `graphs/<graph>` rewritten into `dir` to include `shadows` (a path)
/// instead of the shipped shadow fragment.
fn graph_including(dir: &Path, graph: &str, shadows: &Path) -> PathBuf {
    let text = std::fs::read_to_string(common::root().join("graphs").join(graph))
        .expect("graph")
        .replace(
            "(file: \"shadows.ron\"",
            &format!("(file: \"{}\"", shadows.display()),
        );
    let path = dir.join(graph);
    std::fs::write(&path, absolute_paths(&text)).expect("graph");
    path
}

/// The last of three frames of the demo scene (its spot swivels, the sun and
/// camera stand still) through `graph`: the image and each view's culling.
fn three_frames(graph: &Path) -> (image::RgbaImage, Vec<weft_render::ViewCulling>) {
    let scene = weft_scene::load_scene(&common::demo_scene()).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: graph.to_path_buf(),
        extent: Extent {
            width: 160,
            height: 90,
        },
        frames: 3,
        features: vec!["!bloom".into()],
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let image = rendered.report.output.expect("readback").to_rgba8();
    (image, rendered.culling)
}

#[test]
fn an_unchanged_shadow_view_keeps_its_tile_and_the_image_does_not_change() {
    let dir = std::env::temp_dir().join(format!("weft-kept-tiles-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    // The same shadows, cleared and redrawn every frame.
    let cleared = dir.join("shadows_cleared.ron");
    let shipped =
        std::fs::read_to_string(common::root().join("graphs/shadows.ron")).expect("shadows.ron");
    let text = shipped
        .replace(", persistent: true)", ")")
        .replace("load: Load)", "load: Clear([1.0]))")
        .replace(
            "\"../shaders/",
            &format!("\"{}/", common::root().join("shaders").display()),
        );
    assert_ne!(text, shipped, "the shipped fragment keeps tiles");
    std::fs::write(&cleared, text).expect("write");
    for graph in ["forward.ron", "deferred.ron"] {
        let (kept, culling) = three_frames(&common::graph(graph));
        let shadow_views: Vec<(&str, bool)> = culling
            .iter()
            .filter(|c| c.view.starts_with("shadow_sun"))
            .map(|c| (c.view.as_str(), c.kept))
            .collect();
        // The sun's view, the two area lights' and the cubes of the two
        // still point lights are unchanged since the last frame and keep
        // their tiles; the swivelling spot's view and the circling point
        // light's six faces are drawn again.
        let expected: Vec<(String, bool)> = [true, false, true, true]
            .into_iter()
            .chain([true; 12])
            .chain([false; 6])
            .enumerate()
            .map(|(i, kept)| (format!("shadow_sun[{i}]"), kept))
            .collect();
        let expected: Vec<(&str, bool)> = expected.iter().map(|(v, k)| (v.as_str(), *k)).collect();
        assert_eq!(shadow_views, expected, "{graph}");
        let (redrawn, culling) = three_frames(&graph_including(&dir, graph, &cleared));
        assert!(culling.iter().all(|c| !c.kept), "{culling:?}");
        assert_eq!(agreement(&kept, &redrawn).max, 0, "{graph}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
