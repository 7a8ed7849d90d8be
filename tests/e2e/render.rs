//! Scenes rendered through every shipped graph under validation and
//! synchronization validation: zero messages, golden images (per channel 12/255,
//! mean 0.5/255), and forward and deferred shading agreeing on the same scene
//! (RGB channel differences: mean <= 0.25 and 99th percentile <= 1, 8-bit units;
//! measured 0.12 / 1 on cube.scene and 0.14 / 1 on demo.scene).

use weft_tests::render as common;

use common::{
    absolute_paths, agreement, cube_scene, demo_scene, gltf_scene, graph, render_validated,
};
use weft_testkit::{check_golden, Tolerance};

/// Golden tolerance: lavapipe is deterministic on one machine; the slack covers
/// other LLVM versions' rounding of the sRGB conversion and of texture filtering.
const GOLDEN: Tolerance = Tolerance {
    per_channel: 12,
    mean: 0.5,
};

fn golden(name: &str) -> std::path::PathBuf {
    weft_tests::golden(name)
}

fn assert_golden(image: &image::RgbaImage, name: &str) {
    if let Err(e) = check_golden(image, &golden(name), &GOLDEN) {
        panic!("{e}");
    }
}

#[test]
fn forward_renders_the_demo_scene_cleanly_and_matches_its_golden() {
    let out = render_validated(&demo_scene(), &graph("forward.ron"), 320, 180, &[]);
    assert_eq!(out.messages, Vec::new());
    assert_eq!(
        out.passes,
        vec![
            "shadow_sun",
            "forward",
            "area_light_panels",
            "bloom_bright",
            "bloom_blur_h",
            "bloom_blur_v",
            "tonemap"
        ]
    );
    // Nine meshes placed (box parts, dragon, bunny, sphere), each drawn by the
    // shading pass and by the shadow pass once per view (the sun, the spot,
    // the `arealight`, the box's emissive ceiling quad, and six cube faces
    // for each of the three point lights) unless it lies outside that view's
    // frustum: the spot's view leaves out three meshes, each area light's
    // view the two behind its panel, each cube face what lies on the other
    // sides of its light, and the camera one.
    let cube_faces = [
        (7, 2),
        (1, 8),
        (3, 6),
        (3, 6),
        (1, 8),
        (5, 4),
        (1, 8),
        (6, 3),
        (4, 5),
        (6, 3),
        (4, 5),
        (2, 7),
        (6, 3),
        (3, 6),
        (7, 2),
        (2, 7),
        (2, 7),
        (5, 4),
    ];
    let expected: Vec<(String, u64, u64)> = [(9, 0), (6, 3), (7, 2), (7, 2)]
        .into_iter()
        .chain(cube_faces)
        .enumerate()
        .map(|(i, (drawn, culled))| (format!("shadow_sun[{i}]"), drawn, culled))
        .chain([("forward".to_string(), 8, 1)])
        .collect();
    assert_eq!(out.culling, expected);
    // The area-light panel (issue 32) and the two area lights' shadow views
    // (7 meshes each) since the last count of 23; and the panel as a caster
    // in each of the four shadow views (issue 58); then the 18 cube faces
    // of the three point lights (issue 58): the 68 meshes they draw and the
    // panel in each.
    assert_eq!(out.draw_calls, 42 + 68 + 18);
    assert_golden(&out.image, "demo_forward_320x180.png");
}

#[test]
fn deferred_renders_the_demo_scene_cleanly_and_matches_its_golden() {
    let out = render_validated(&demo_scene(), &graph("deferred.ron"), 320, 180, &[]);
    assert_eq!(out.messages, Vec::new());
    assert_eq!(
        out.passes,
        vec![
            "shadow_sun",
            "gbuffer",
            "sun",
            "point_lights",
            "spot_lights",
            "area_lights",
            "area_light_panels",
            "bloom_bright",
            "bloom_blur_h",
            "bloom_blur_v",
            "tonemap"
        ]
    );
    assert_golden(&out.image, "demo_deferred_320x180.png");
}

#[test]
fn depth_prepass_and_no_bloom_variants_run_cleanly() {
    let plain = render_validated(&demo_scene(), &graph("forward.ron"), 160, 90, &["!bloom"]);
    let pre = render_validated(
        &demo_scene(),
        &graph("forward.ron"),
        160,
        90,
        &["!bloom", "depth_prepass"],
    );
    assert_eq!(plain.messages, Vec::new());
    assert_eq!(pre.messages, Vec::new());
    assert_eq!(
        pre.passes,
        vec![
            "shadow_sun",
            "depth_prepass",
            "forward_after_prepass",
            "area_light_panels",
            "tonemap"
        ]
    );
    // The pre-pass lays down the same depths, so the shading pass sees the same surfaces.
    assert_eq!(agreement(&plain.image, &pre.image).max, 0);
    let deferred = render_validated(&demo_scene(), &graph("deferred.ron"), 160, 90, &["!bloom"]);
    assert_eq!(deferred.messages, Vec::new());
}

#[test]
fn forward_and_deferred_agree_on_the_demo_scene() {
    let f = render_validated(&demo_scene(), &graph("forward.ron"), 320, 180, &[]);
    let d = render_validated(&demo_scene(), &graph("deferred.ron"), 320, 180, &[]);
    let a = agreement(&f.image, &d.image);
    eprintln!("forward vs deferred: {a:?}");
    assert!(a.mean <= 0.25 && a.p99 <= 1, "{a:?}");
}

#[test]
fn forward_and_deferred_agree_on_the_15_462_cube_scene() {
    let f = render_validated(&cube_scene(), &graph("forward.ron"), 320, 180, &[]);
    let d = render_validated(&cube_scene(), &graph("deferred.ron"), 320, 180, &[]);
    assert_eq!(f.messages, Vec::new());
    assert_eq!(d.messages, Vec::new());
    let a = agreement(&f.image, &d.image);
    eprintln!("forward vs deferred: {a:?}");
    assert!(a.mean <= 0.25 && a.p99 <= 1, "{a:?}");
}

#[test]
fn forward_and_deferred_agree_on_a_gltf_scene_and_match_their_goldens() {
    let f = render_validated(&gltf_scene(), &graph("forward.ron"), 320, 180, &[]);
    let d = render_validated(&gltf_scene(), &graph("deferred.ron"), 320, 180, &[]);
    assert_eq!(f.messages, Vec::new());
    assert_eq!(d.messages, Vec::new());
    assert!(
        d.passes.contains(&"area_lights".to_string()),
        "{:?}",
        d.passes
    );
    let a = agreement(&f.image, &d.image);
    eprintln!("forward vs deferred: {a:?}");
    assert!(a.mean <= 0.25 && a.p99 <= 1, "{a:?}");
    assert_golden(&f.image, "flight_helmet_forward_320x180.png");
    assert_golden(&d.image, "flight_helmet_deferred_320x180.png");
}

#[test]
fn the_hdr_image_reads_back_as_linear_floats_for_exr() {
    let scene = weft_scene::load_scene(&demo_scene()).expect("scene loads");
    let gpu = weft_gpu::Gpu::new(&weft_gpu::GpuOptions {
        validation: true,
        device: None,
    })
    .expect("device");
    let log = gpu.validation();
    let settings = weft_render::RenderSettings {
        graph: graph("forward.ron"),
        extent: weft_graph::plan::Extent {
            width: 64,
            height: 36,
        },
        extra_readback: vec!["hdr".into()],
        ..weft_render::RenderSettings::default()
    };
    let rendered = weft_render::render(&gpu, &scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let (name, hdr) = &rendered.report.readbacks[0];
    assert_eq!((name.as_str(), hdr.width, hdr.height), ("hdr", 64, 36));
    let weft_gpu::Pixels::RgbaF32(values) = &hdr.pixels else {
        panic!("hdr reads back as floats, got {:?}", hdr.format);
    };
    // The background is cleared to black; lit surfaces are positive and finite.
    assert_eq!(&values[..4], &[0.0, 0.0, 0.0, 1.0]);
    assert!(values.iter().all(|v| v.is_finite() && *v >= 0.0));
    assert!(values.iter().any(|v| *v > 0.1));
}

/// Every glTF file under the shared assets, as a scene with one sun added to
/// the file's own lights (KHR_lights_punctual spots and points), framed by the
/// default camera or the file's first camera.
fn shared_gltf_files() -> Vec<std::path::PathBuf> {
    fn walk(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.expect("directory entry").path())
            .collect();
        entries.sort();
        for path in entries {
            if path.is_dir() {
                walk(&path, out);
            } else if matches!(
                path.extension().and_then(|e| e.to_str()),
                Some("glb" | "gltf")
            ) {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(&common::root().join("../shared/assets/gltf"), &mut files);
    files
}

#[test]
fn forward_deferred_and_tiled_agree_on_every_shared_gltf_file() {
    let files = shared_gltf_files();
    assert!(files.len() >= 21, "{} glTF files", files.len());
    let dir = std::env::temp_dir().join(format!("weft-gltf-agree-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut failures = Vec::new();
    for file in &files {
        let name = file.file_stem().and_then(|s| s.to_str()).unwrap_or("model");
        let scene = dir.join(format!("{name}.scene"));
        std::fs::write(
            &scene,
            format!(
                "model\n{{\n\tfile \"{}\"\n}}\nsunlight\n{{\n\tdirection 0.3 -1 -0.4\n\tcolor 1 1 1\n\tambient 0.05 0.05 0.05\n}}\n",
                file.display()
            ),
        )
        .unwrap();
        let [f, d, t] = ["forward.ron", "deferred.ron", "tiled.ron"]
            .map(|g| render_validated(&scene, &graph(g), 240, 135, &["!bloom"]));
        for (g, out) in [("forward", &f), ("deferred", &d), ("tiled", &t)] {
            assert_eq!(out.messages, Vec::new(), "{name} through {g}");
        }
        let fd = agreement(&f.image, &d.image);
        let td = agreement(&t.image, &d.image);
        eprintln!("{name}: forward vs deferred {fd:?}; tiled vs deferred {td:?}");
        for (what, a) in [("forward vs deferred", fd), ("tiled vs deferred", td)] {
            if !(a.mean <= 0.25 && a.p99 <= 1 && a.max <= 8) {
                failures.push(format!("{name}: {what} {a:?}"));
            }
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(failures.is_empty(), "{failures:#?}");
}

/// A floor from an OBJ file (Blinn-Phong) under DamagedHelmet (glTF,
/// metallic-roughness), a sun and a point light.
fn mixed_models_scene(dir: &std::path::Path) -> std::path::PathBuf {
    std::fs::create_dir_all(dir).expect("scratch dir");
    let root = common::root();
    let text = format!(
        "model\n{{\n\tfile \"{}\"\n}}\n\
         model\n{{\n\tfile \"{}\"\n\tposition 0 1 0\n}}\n\
         sunlight\n{{\n\tdirection 0.3 -1 0.2\n\tcolor 0.8 0.8 0.8\n}}\n\
         pointlight\n{{\n\tposition 1 2 2\n\tcolor 2 2 2\n\tattenuation 1 0 1\n}}\n\
         camera \"view\"\n{{\n\tposition 0 2 4\n\ttarget 0 1 0\n\tfov_deg 50\n}}\n",
        root.join("scenes/models/floor.obj").display(),
        root.join("../shared/assets/gltf/rise/DamagedHelmet.glb")
            .display(),
    );
    let path = dir.join("mixed.scene");
    std::fs::write(&path, text).expect("scene");
    path
}

#[test]
fn draws_are_grouped_by_shading_model_with_one_variant_each_and_the_image_unchanged() {
    let dir = std::env::temp_dir().join(format!("weft-mixed-models-{}", std::process::id()));
    let scene = mixed_models_scene(&dir);
    // The same graph without `draws:`: one variant with both models, chosen
    // per pixel. The models' defines come from the define set `scene_models`
    // (scene_shading.ron), which groups draws; the copy names the models'
    // defines itself instead, without `draws`.
    let text = std::fs::read_to_string(graph("forward.ron")).expect("forward.ron");
    let shading = std::fs::read_to_string(graph("scene_shading.ron")).expect("scene_shading.ron");
    assert!(
        shading.contains(
            r#"(name: "SCENE_BLINN_PHONG", enabled_if: ["blinn_phong"], draws: BlinnPhong)"#
        ),
        "scene_models groups draws by model"
    );
    let ungrouped_text = text
        .replace(r#"define_sets: ["scene_models", "#, "define_sets: [")
        .replace(
            "            defines: [\n",
            "            defines: [\n                (name: \"SCENE_BLINN_PHONG\", enabled_if: [\"blinn_phong\"]),\n                (name: \"SCENE_METALLIC_ROUGHNESS\", enabled_if: [\"metallic_roughness\"]),\n",
        );
    assert_eq!(
        ungrouped_text.matches("SCENE_METALLIC_ROUGHNESS").count(),
        2,
        "both forward passes name the models' defines themselves"
    );
    let ungrouped = dir.join("forward_ungrouped.ron");
    std::fs::write(&ungrouped, absolute_paths(&ungrouped_text)).expect("graph");

    let loaded = weft_scene::load_scene(&scene).expect("scene loads");
    let features = weft_render::scene_features(&loaded);
    let plan_of = |path: &std::path::Path| {
        let options = weft_graph::CompileOptions {
            features: features.iter().cloned().collect(),
            ..weft_graph::CompileOptions::default()
        };
        weft_graph::compile(&weft_graph::load(path), &options).expect("compiles")
    };
    let plan = plan_of(&graph("forward.ron"));
    let pass = plan
        .passes
        .iter()
        .find(|p| p.name == "forward")
        .expect("forward pass");
    let variants = weft_gpu::check::scene_pass_variants(pass);
    assert_eq!(variants.len(), 2, "one variant per shading model");
    let fragment_defines: Vec<&Vec<String>> = variants.iter().map(|v| &v[1].defines).collect();
    let has = |defines: &Vec<String>, name: &str| defines.iter().any(|d| d == name);
    assert!(has(fragment_defines[0], "SCENE_BLINN_PHONG"));
    assert!(!has(fragment_defines[0], "SCENE_METALLIC_ROUGHNESS"));
    assert!(has(fragment_defines[1], "SCENE_METALLIC_ROUGHNESS"));
    assert!(!has(fragment_defines[1], "SCENE_BLINN_PHONG"));
    let text = weft_graph::text::render(&plan);
    assert!(
        text.contains("mesh draws grouped by shading model, one variant each: BlinnPhong +SCENE_BLINN_PHONG, MetallicRoughness +SCENE_METALLIC_ROUGHNESS"),
        "{text}"
    );
    let plain = plan_of(&ungrouped);
    let pass = plain
        .passes
        .iter()
        .find(|p| p.name == "forward")
        .expect("forward pass");
    assert_eq!(weft_gpu::check::scene_pass_variants(pass).len(), 1);

    let grouped = render_validated(&scene, &graph("forward.ron"), 160, 90, &["!bloom"]);
    let single = render_validated(&scene, &ungrouped, 160, 90, &["!bloom"]);
    std::fs::remove_dir_all(&dir).expect("scratch dir removed");
    assert_eq!(grouped.messages, Vec::new());
    assert_eq!(single.messages, Vec::new());
    assert_eq!(grouped.draw_calls, single.draw_calls);
    let a = agreement(&grouped.image, &single.image);
    eprintln!("grouped vs one variant: {a:?}");
    assert!(a.max <= 1, "{a:?}");
    // Both models are on screen: not a comparison of two empty frames.
    let lit = grouped.image.pixels().filter(|p| p.0[0] > 16).count();
    assert!(lit > 160 * 90 / 4, "{lit} lit pixels");
}
