//! Multisample anti-aliasing as graph data (graphs/forward_msaa.ron): a
//! pixel half covered along a known edge resolves to half its colour, with
//! the validation layers (synchronization included) silent, and a sample
//! count the device's attachments cannot have is refused at the graph's line.

use std::path::Path;
use weft_graph::plan::Extent;
use weft_render::RenderSettings;
use weft_tests::render::render_image_validated;
use weft_tests::TempDir;

/// A white quad lit head-on by a sun, from x = -20 to x = `edge` (and -20
/// to 20 in y) at z = 0, before nothing, seen from z = 5 with a 90-degree
/// field of view: at 32 pixels across, pixel column 16 spans x = 0 to
/// 0.3125 and its centre is at 0.15625.
fn edge_scene(dir: &Path, edge: f32) -> std::path::PathBuf {
    std::fs::write(dir.join("m.mtl"), "newmtl white\nKd 1 1 1\nKs 0 0 0\n").expect("mtl");
    std::fs::write(
        dir.join("quad.obj"),
        format!(
            "mtllib m.mtl\nusemtl white\nv -20 -20 0\nv {edge} -20 0\nv {edge} 20 0\nv -20 20 0\nvn 0 0 1\n\
             f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n"
        ),
    )
    .expect("obj");
    let path = dir.join("edge.scene");
    std::fs::write(
        &path,
        "model\n{\n\tfile \"quad.obj\"\n}\n\
         sunlight\n{\n\tdirection 0 0 -1\n\tcolor 1 1 1\n\tambient 0\n}\n\
         camera\n{\n\tposition 0 0 5\n\ttarget 0 0 0\n\tfov_deg 90\n}\n",
    )
    .expect("scene");
    path
}

fn settings(graph: &str) -> RenderSettings {
    RenderSettings {
        graph: weft_tests::shipped(graph),
        extent: Extent {
            width: 32,
            height: 32,
        },
        features: vec!["!bloom".into()],
        ..RenderSettings::default()
    }
}

/// With the edge through the centres of column 16, two of the four
/// standard sample positions (x offsets 1/8 and 3/8 of the pixel) are
/// covered: the resolved pixel holds half the quad's colour, within the
/// 1/4 one sample is worth; the columns either side are whole. Moved a
/// quarter pixel right, three samples are covered.
#[test]
fn a_half_covered_pixel_resolves_to_its_covered_fraction() {
    for (edge, fraction) in [(0.15625f32, 0.5f32), (0.234375, 0.75)] {
        let dir = TempDir::new("msaa-edge");
        let scene = edge_scene(&dir.0, edge);
        let (_, hdr) = render_image_validated(&scene, settings("forward_msaa.ron"), "hdr");
        for y in [4usize, 16, 27] {
            let at = |x: usize| hdr[(y * 32 + x) * 4 + 1];
            let full = at(8);
            assert!(full > 0.1, "the quad is lit: {full}");
            assert_eq!(at(15), full, "column 15 is covered");
            assert_eq!(at(17), 0.0, "column 17 is not");
            let covered = at(16) / full;
            assert!(
                (covered - fraction).abs() <= 0.25,
                "edge at x = {edge}: row {y}'s pixel 16 holds {covered} of the colour, not {fraction}"
            );
        }
    }
}

/// A count the device's attachments lack (lavapipe offers 1 and 4) is
/// refused before any image is created, at its `samples:` in the graph.
#[test]
fn a_sample_count_the_device_lacks_is_refused_at_its_line() {
    let gpu = weft_tests::gpu();
    let offered = gpu.info().attachment_sample_counts;
    let lacking = [2u32, 8, 16, 32, 64]
        .into_iter()
        .find(|n| offered & n == 0)
        .expect("a device offering every sample count");
    let dir = TempDir::new("msaa-lacking");
    let scene = edge_scene(&dir.0, 0.15625);
    let text = std::fs::read_to_string(weft_tests::shipped("forward_msaa.ron"))
        .expect("graph")
        .replace("samples: 4", &format!("samples: {lacking}"))
        .replace(
            "\"../shaders/",
            &format!("\"{}/shaders/", weft_tests::repo().display()),
        )
        .replace(
            "(file: \"",
            &format!("(file: \"{}/graphs/", weft_tests::repo().display()),
        );
    let graph = dir.0.join("forward_msaa.ron");
    std::fs::write(&graph, &text).expect("graph");
    let scene = weft_scene::load_scene(&scene).expect("scene");
    let settings = RenderSettings {
        graph: graph.clone(),
        ..settings("forward_msaa.ron")
    };
    let err = match weft_render::render(&gpu, &scene, &settings) {
        Ok(_) => panic!("{lacking} samples rendered"),
        Err(e) => e.to_string(),
    };
    let line = text
        .lines()
        .position(|l| l.contains(&format!("samples: {lacking}")))
        .expect("the line")
        + 1;
    assert!(
        err.contains(&format!("forward_msaa.ron:{line}:"))
            && err.contains(&format!("has {lacking} samples, which attachments on")),
        "{err}"
    );
}
