//! The graphs' `emissive_boost` parameter scales material emission (MTL `Ke`)
//! in linear HDR, the same in forward, deferred and tiled, and only emission.

use weft_tests::render as common;

use std::collections::BTreeMap;
use std::path::PathBuf;
use weft_graph::schema::ParamValue;

/// A folder removed when the test ends.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn emissive_boost_scales_emission_alone_in_every_graph() {
    let dir = TempDir(std::env::temp_dir().join(format!("weft-emissive-{}", std::process::id())));
    // Diffuse Kd = 0.5 lit head-on by the unit sun, plus emission Ke.
    let scene = common::write_quad_scene(&dir.0, "Kd 0.5 0.5 0.5\nKs 0 0 0\nKe 0.25 0.5 1\n");
    let boost = |b: f64| BTreeMap::from([("emissive_boost".to_string(), ParamValue::Number(b))]);
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        // Exact in RGBA16F.
        let plain = common::centre_hdr(&scene, graph, BTreeMap::new());
        assert_eq!(plain[..3], [0.75, 1.0, 1.5], "{graph}");
        let boosted = common::centre_hdr(&scene, graph, boost(4.0));
        assert_eq!(
            boosted[..3],
            [1.5, 2.5, 4.5],
            "{graph} with emissive_boost 4"
        );
    }
}

/// DamagedHelmet facing the camera under `sun` (a `.scene` light block).
fn helmet_scene(dir: &std::path::Path, sun: &str) -> PathBuf {
    std::fs::create_dir_all(dir).expect("scratch folder");
    let model = common::root().join("../shared/assets/gltf/rise/DamagedHelmet.glb");
    let path = dir.join("helmet.scene");
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"{}\"\n}}\n{sun}\
             camera \"front\"\n{{\n\tposition 0 0 3\n\ttarget 0 0 0\n\tfov_deg 45\n}}\n",
            model.display()
        ),
    )
    .expect("scene written");
    path
}

#[test]
fn emissive_and_occlusion_textures_apply_alike_in_every_graph() {
    let dir = TempDir(std::env::temp_dir().join(format!("weft-helmet-{}", std::process::id())));
    // Emission alone (a black sun adds nothing), then ambient alone.
    let cases = [
        (
            "emission",
            "sunlight\n{\n\tdirection 0 -1 0\n\tcolor 0 0 0\n}\n",
        ),
        (
            "ambient",
            "sunlight\n{\n\tdirection 0 -1 0\n\tcolor 0 0 0\n\tambient 0.5 0.5 0.5\n}\n",
        ),
    ];
    let mut forward_images = Vec::new();
    for (what, sun) in cases {
        let scene = helmet_scene(&dir.0, sun);
        let outputs: Vec<_> = ["forward.ron", "deferred.ron", "tiled.ron"]
            .iter()
            .map(|g| common::render_validated(&scene, &common::graph(g), 320, 320, &["!bloom"]))
            .collect();
        for out in &outputs {
            assert_eq!(out.messages, Vec::new(), "{what}");
        }
        assert!(
            outputs[1].passes.contains(&"gbuffer".to_string()),
            "{:?}",
            outputs[1].passes
        );
        for (name, out) in [("forward", &outputs[0]), ("tiled", &outputs[2])] {
            let a = common::agreement(&out.image, &outputs[1].image);
            eprintln!("{what}: {name} vs deferred {a:?}");
            assert!(
                a.mean <= 0.25 && a.p99 <= 1 && a.max <= 8,
                "{what}: {name} {a:?}"
            );
        }
        forward_images.push(outputs[0].image.clone());
    }
    // The emissive factor is white: untextured, every helmet pixel glowed
    // white. Textured, only the lamps and the visor's display do. The helmet's
    // pixels are those the ambient light reaches.
    let [emission, ambient] = &forward_images[..] else {
        unreachable!("two cases")
    };
    let helmet = ambient.pixels().filter(|p| p.0[..3] != [0, 0, 0]).count();
    let glowing = emission
        .pixels()
        .filter(|p| p.0[..3].iter().any(|c| *c > 128))
        .count();
    eprintln!("{glowing} of {helmet} helmet pixels glow");
    assert!(helmet > 320 * 320 / 5, "{helmet}");
    assert!(glowing * 10 < helmet, "{glowing} of {helmet}");
    assert!(glowing > 0, "the lamps glow");
}

#[test]
fn the_path_tracer_emits_through_emissive_textures_as_raster_graphs_do() {
    // Emission alone, seen by camera rays (max_depth 1): the tracer reads the
    // helmet's emissive texture where its rays hit, as forward does. Before,
    // it emitted the white factor everywhere (14 times the light). Measured
    // mean luminance 0.00460 traced, 0.00539 forward: the raster path's
    // mip-filtered texture against the tracer's level 0 under a box filter.
    let dir = TempDir(std::env::temp_dir().join(format!("weft-helmet-pt-{}", std::process::id())));
    let scene = helmet_scene(
        &dir.0,
        "sunlight\n{\n\tdirection 0 -1 0\n\tcolor 0 0 0\n}\n",
    );
    let mean_luminance = |graph: &str, samples: Option<u64>, params: &[(&str, f64)]| {
        let settings = weft_tests::render::square_settings(graph, 96, samples, params, &["!bloom"]);
        let (_, values) = weft_tests::render::render_hdr_validated(&scene, settings);
        let sum: f64 = values
            .chunks(4)
            .map(|p| 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
            .sum();
        sum / (values.len() / 4) as f64
    };
    let traced = mean_luminance("pathtrace.ron", Some(64), &[("max_depth", 1.0)]);
    let forward = mean_luminance("forward.ron", None, &[]);
    eprintln!("emission: traced {traced:.5}, forward {forward:.5}");
    assert!(
        forward > 0.0 && (traced / forward - 1.0).abs() < 0.2,
        "traced {traced}, forward {forward}"
    );
}
