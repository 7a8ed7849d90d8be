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

/// A scene of a half-transparent OBJ quad (Blinn-Phong), a glTF helmet
/// (metallic-roughness, opaque) behind it, or both, written in `dir`, with
/// the quad scene's sun and camera.
fn variant_scene(dir: &std::path::Path, quad: bool, helmet: bool) -> std::path::PathBuf {
    let quad_scene = common::write_quad_scene(dir, "Kd 1 1 1\nKs 0 0 0\nd 0.5\n");
    let mut text = std::fs::read_to_string(&quad_scene).expect("quad scene");
    if !quad {
        let model = "model\n{\n\tfile \"quad.obj\"\n}\n";
        assert!(
            text.contains(model),
            "the quad scene's model statement changed"
        );
        text = text.replacen(model, "", 1);
    }
    if helmet {
        let path = common::root().join("../shared/assets/gltf/rise/DamagedHelmet.glb");
        text.push_str(&format!(
            "model\n{{\n\tfile \"{}\"\n\tposition 0 0 -2\n}}\n",
            path.display()
        ));
    }
    let scene = dir.join(format!("variants_{quad}_{helmet}.scene"));
    std::fs::write(&scene, text).expect("scene");
    scene
}

/// The variants forward's pass that draws every mesh names are the scene's
/// own: one per shading model among its draws, opaque or blended as those
/// draws are, and none for a model or a blend the scene lacks (so no
/// pipeline is built for them).
#[test]
fn a_scene_pass_names_only_the_variants_its_scene_draws() {
    use weft_gpu::state::{pass_state, BlendCode};
    use weft_gpu::DrawRecorder;
    use weft_graph::schema::{Draw, SceneTerm};
    let dir = weft_tests::TempDir::new("scene-variants");
    let gpu = weft_tests::gpu();
    let graph = weft_graph::Prepared::new(weft_graph::load(&weft_tests::shipped("forward.ron")))
        .expect("forward loads");
    let (phong, metal) = ("BlinnPhong", "MetallicRoughness");
    // (quad, helmet, the variants as (model, blended)).
    let cases = [
        (true, false, vec![(phong, true)]),
        (false, true, vec![(metal, false)]),
        (true, true, vec![(metal, false), (phong, true)]),
    ];
    for (quad, helmet, expected) in cases {
        let scene = weft_scene::load_scene(&variant_scene(&dir.0, quad, helmet)).expect("scene");
        let settings = common::square_settings("forward.ron", 16, None, &[], &["!bloom"]);
        let plan = weft_render::compile_for_scene(&gpu, &scene, &graph, &settings).expect("plan");
        let uploaded = weft_render::GpuScene::new(&gpu, &scene, false).expect("upload");
        let recorder = weft_render::SceneRecorder::new(&gpu, uploaded);
        let pass = plan
            .passes
            .iter()
            .find(|p| p.draw == Some(Draw::Meshes(SceneTerm("All".into()))))
            .expect("forward draws every mesh");
        let variants = recorder.variants(pass);
        let got: Vec<(Vec<String>, bool)> = variants
            .iter()
            .map(|v| (v.defines.clone(), v.state != pass_state(pass)))
            .collect();
        let want: Vec<(Vec<String>, bool)> = expected
            .iter()
            .map(|&(model, blended)| (pass.defines_for(model), blended))
            .collect();
        assert_eq!(got, want, "quad {quad}, helmet {helmet}");
        for v in variants.iter().filter(|v| v.state != pass_state(pass)) {
            assert!(v.state.blends.iter().all(|b| *b == BlendCode::Alpha));
        }
        drop(recorder);
    }
    weft_tests::assert_no_validation_messages(gpu);
}

/// Every pipeline variant a scene pass draws with is built before the first
/// frame: the quad beside the helmet builds no pipeline while its frames
/// record, in forward's pass that draws every mesh and in deferred's
/// transparent pass after lighting.
#[test]
fn no_frame_builds_a_scene_pipeline() {
    let dir = weft_tests::TempDir::new("variants");
    let scene = variant_scene(&dir.0, true, true);
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
}
