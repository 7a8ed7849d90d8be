//! Transparent materials, in forward's pass that draws every mesh and in
//! deferred's transparent pass after lighting: blended over what lies behind them
//! with their opacity (MTL `d`), in linear HDR.

use weft_tests::render as common;

use std::collections::BTreeMap;

#[test]
fn a_half_transparent_quad_lets_half_the_background_through() {
    let dir = std::env::temp_dir().join(format!("weft-transparency-{}", std::process::id()));
    for graph in ["forward.ron", "deferred.ron"] {
        let quad = |name: &str, d: f32| {
            let scene =
                common::write_quad_scene(&dir.join(name), &format!("Kd 1 1 1\nKs 0 0 0\nd {d}\n"));
            common::centre_hdr(&scene, graph, BTreeMap::new())
        };
        let opaque = quad("opaque", 1.0);
        let glass = quad("glass", 0.5);
        // Kd 1 lit head-on by a unit sun: 1.0; half of it over the black clear colour:
        // 0.5 (R16G16B16A16_SFLOAT stores both exactly).
        assert_eq!(opaque[..3], [1.0, 1.0, 1.0], "{graph}");
        assert_eq!(glass[..3], [0.5, 0.5, 0.5], "{graph}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// Every pipeline variant a scene pass draws with is built before the first
/// frame: a half-transparent OBJ quad (Blinn-Phong, blended in forward's
/// pass that draws every mesh and in deferred's transparent pass) beside a
/// glTF helmet (metallic-roughness, opaque) builds no pipeline while its
/// frames record.
#[test]
fn no_frame_builds_a_scene_pipeline() {
    let dir = std::env::temp_dir().join(format!("weft-variants-{}", std::process::id()));
    let quad = common::write_quad_scene(&dir, "Kd 1 1 1\nKs 0 0 0\nd 0.5\n");
    let helmet = common::root().join("../shared/assets/gltf/rise/DamagedHelmet.glb");
    let scene = dir.join("mixed.scene");
    let quad_text = std::fs::read_to_string(&quad).expect("quad scene");
    std::fs::write(
        &scene,
        format!(
            "{quad_text}model\n{{\n\tfile \"{}\"\n\tposition 0 0 -2\n}}\n",
            helmet.display()
        ),
    )
    .expect("mixed scene");
    for graph in ["forward.ron", "deferred.ron"] {
        let loaded = weft_scene::load_scene(&scene).expect("scene loads");
        let gpu = weft_tests::gpu();
        let log = gpu.validation();
        let mut settings = common::square_settings(graph, 16, None, &[], &["!bloom"]);
        settings.frames = 2;
        let rendered = weft_render::render(&gpu, &loaded, &settings).expect("renders");
        drop(gpu);
        assert_eq!(log.messages(), Vec::new(), "{graph}");
        assert!(rendered.pipelines_prepared > 0, "{graph}");
        assert_eq!(
            rendered.pipelines_built, rendered.pipelines_prepared,
            "{graph}: pipelines built after the first frame began"
        );
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
