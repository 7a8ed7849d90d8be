//! `weft render` as a user runs it: device and output path printed, the image
//! written at the requested size, validation clean, bad input reported.

use crate::harness::{repo, weft};
use std::path::{Path, PathBuf};

fn temp_png(name: &str) -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(|| crate::harness::scratch(&format!("weft-render-cli-{}", std::process::id())))
        .join(name)
}

#[test]
fn renders_the_demo_through_deferred_with_validation_and_json() {
    let out_path = temp_png("demo.png");
    let out_arg = out_path.to_string_lossy().into_owned();
    let out = weft(&[
        "render",
        "scenes/demo.scene",
        "--graph",
        "graphs/deferred.ron",
        "--size",
        "64x36",
        "--frames",
        "2",
        "--camera",
        "closeup",
        "--validate",
        "--json",
        "--out",
        &out_arg,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(json["camera"], "closeup");
    assert_eq!(json["size"], serde_json::json!([64, 36]));
    assert_eq!(json["frames"], 2);
    assert_eq!(json["validation"]["errors"], 0);
    assert_eq!(json["validation"]["warnings"], 0);
    assert_eq!(json["passes"][1], "gbuffer");
    let image = image_size(&out_path);
    assert_eq!(image, (64, 36));
}

#[test]
fn prints_the_device_and_where_the_image_went() {
    let out_path = temp_png("text.png");
    let out_arg = out_path.to_string_lossy().into_owned();
    let out = weft(&[
        "render",
        "scenes/demo.scene",
        "--size",
        "32x18",
        "--features",
        "!bloom",
        "--timings",
        "cpu",
        "--out",
        &out_arg,
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.starts_with("device: "), "{text}");
    assert!(text.contains(&format!("wrote {out_arg}")), "{text}");
    assert!(text.contains("cpu wall (submit+wait)"), "{text}");
    // The demo's area light is drawn by its panel pass.
    assert!(
        text.contains("shadow_sun -> forward -> area_light_panels -> tonemap"),
        "{text}"
    );
}

#[test]
fn unknown_camera_and_bad_output_name_fail_with_a_message() {
    let out = weft(&[
        "render",
        "scenes/demo.scene",
        "--camera",
        "nope",
        "--size",
        "8x8",
    ]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("no camera named \"nope\"; the scene has: front, closeup, flythrough"),
        "{err}"
    );
    let out = weft(&["render", "scenes/demo.scene", "--out", "x.jpg"]);
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("use a .png or .exr file name"));
}

/// Width and height from a PNG's IHDR chunk.
fn image_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).expect("png written");
    assert_eq!(&bytes[1..4], b"PNG");
    let word =
        |at: usize| u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    (word(16), word(20))
}

#[test]
fn bad_times_frame_counts_and_feature_names_are_refused() {
    let cases: [(&[&str], &str); 7] = [
        (&["--time", "NaN"], "time must be a finite number of seconds, found \"NaN\""),
        (&["--time", "inf"], "time must be a finite number of seconds, found \"inf\""),
        (&["--frames", "0"], "invalid value '0' for '--frames <FRAMES>'"),
        (
            &["--features", "blom"],
            "error: --features: unknown feature \"blom\" (did you mean \"bloom\"?); this graph's features are: ",
        ),
        (
            &["--features", "!shadow_caster"],
            "unknown feature \"shadow_caster\" (did you mean \"shadow_casters\"?)",
        ),
        // The backend's feature is the renderer's, whichever way it is asked.
        (
            &["--features", "ray_queries"],
            "graphs/forward.ron:1:1: error: feature `ray_queries` is the renderer's: it is on exactly when passes trace with ray queries",
        ),
        (
            &["--features", "rt_shadows,!ray_queries"],
            "hint: choose the backend with --backend hardware or --backend software",
        ),
    ];
    for (extra, expected) in cases {
        let mut args = vec!["render", "scenes/demo.scene", "--size", "8x8"];
        args.extend_from_slice(extra);
        let out = weft(&args);
        assert_eq!(
            out.status.code(),
            Some(if extra[0] == "--features" { 1 } else { 2 }),
            "{extra:?}"
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(expected), "{extra:?}: {err}");
    }
}

#[test]
fn more_light_volumes_than_the_limit_are_refused_at_the_pass() {
    let dir = crate::harness::scratch(&format!("weft-volumes-{}", std::process::id()));
    let scene = dir.join("many.scene");
    std::fs::write(
        &scene,
        "pointlights\n{\n count 65537\n min -1 -1 -1\n max 1 1 1\n radius 0.1 0.2\n}\ncamera\n{\n position 0 0 4\n target 0 0 0\n}\n",
    )
    .expect("scene");
    let out = weft(&[
        "render",
        scene.to_str().expect("utf-8"),
        "--graph",
        "graphs/deferred.ron",
        "--size",
        "16x16",
        "--out",
        dir.join("o.png").to_str().expect("utf-8"),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    let line = std::fs::read_to_string(repo().join("graphs/deferred.ron"))
        .expect("graph")
        .lines()
        .position(|l| l.contains("name: \"point_lights\""))
        .expect("the pass")
        + 1;
    assert!(
        err.contains(&format!(
            "error: graphs/deferred.ron:{line}:19: pass `point_lights`: 65537 light volumes exceed the 65536 a frame draws this way"
        )),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// `weft render SCENE --graph GRAPH --size 16x16 --out OUT` and `extra`.
fn render_exr((scene, graph): (&str, &str), out: &Path, extra: &[&str]) -> std::process::Output {
    let mut a = vec![
        "render",
        scene,
        "--graph",
        graph,
        "--size",
        "16x16",
        "--out",
        out.to_str().expect("utf-8"),
    ];
    a.extend_from_slice(extra);
    weft(&a)
}

#[test]
fn readback_images_are_written_beside_the_output_and_the_first_is_the_exr() {
    let dir = crate::harness::scratch(&format!("weft-readback-{}", std::process::id()));
    let out = dir.join("o.exr");
    let args =
        |extra: &[&str]| render_exr(("scenes/demo.scene", "graphs/deferred.ron"), &out, extra);
    let done = args(&["--readback", "hdr,gbuffer_albedo"]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let exr = std::fs::read(&out).expect("exr");
    assert_eq!(&exr[..4], b"v/1\x01", "OpenEXR magic");
    assert_eq!(
        exr,
        std::fs::read(dir.join("o.hdr.exr")).expect("hdr"),
        "the first readback is the EXR"
    );
    assert!(dir.join("o.gbuffer_albedo.exr").is_file());
    // Without --readback the graph's own list (`readback: ["hdr"]`) picks the EXR's image.
    std::fs::remove_file(&out).expect("remove");
    let done = args(&[]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert_eq!(std::fs::read(&out).expect("exr"), exr);
    let failed = args(&["--readback", "nope"]);
    assert_eq!(failed.status.code(), Some(1));
    let err = String::from_utf8_lossy(&failed.stderr);
    assert!(
        err.contains("cannot read back \"nope\": the graph has no image of that name"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// A graph that reads `hdr` back only without `denoise` and `denoised` with
/// it (hybrid.ron, `denoise` on): its own list gives the EXR `denoised`, and
/// `--readback hdr` still reads `hdr` back, as asked, whatever the graph's
/// conditions.
#[test]
fn read_backs_asked_by_name_are_kept_whatever_the_graphs_conditions() {
    let dir = crate::harness::scratch(&format!("weft-readback-asked-{}", std::process::id()));
    let out = dir.join("o.exr");
    let args =
        |extra: &[&str]| render_exr(("scenes/cornell.scene", "graphs/hybrid.ron"), &out, extra);
    let done = args(&["--readback", "hdr,denoised"]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    let first = std::fs::read(&out).expect("exr");
    assert_eq!(
        first,
        std::fs::read(dir.join("o.hdr.exr")).expect("hdr"),
        "the first asked is the EXR"
    );
    let denoised = std::fs::read(dir.join("o.denoised.exr")).expect("denoised");
    assert_ne!(first, denoised, "the lit image and the denoised one differ");
    std::fs::remove_file(&out).expect("remove");
    let done = args(&[]);
    assert!(
        done.status.success(),
        "{}",
        String::from_utf8_lossy(&done.stderr)
    );
    assert_eq!(
        std::fs::read(&out).expect("exr"),
        denoised,
        "the graph's own list: `denoised` under `denoise`"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Renders the Cornell box through the path tracer to `spp` samples per pixel
/// with `seed`; returns the JSON summary and the PNG's bytes.
fn path_traced(name: &str, spp: &str, seed: &str, extra: &[&str]) -> (serde_json::Value, Vec<u8>) {
    let out_path = temp_png(name);
    let out_arg = out_path.to_string_lossy().into_owned();
    let mut args = vec![
        "render",
        "scenes/cornell.scene",
        "--graph",
        "graphs/pathtrace.ron",
        "--size",
        "24x24",
        "--spp",
        spp,
        "--seed",
        seed,
        "--validate",
        "--json",
        "--out",
        &out_arg,
    ];
    args.extend_from_slice(extra);
    let out = weft(&args);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(json["validation"]["errors"], 0);
    assert_eq!(json["validation"]["warnings"], 0);
    (json, std::fs::read(&out_path).expect("png"))
}

#[test]
fn spp_renders_a_progressive_graph_to_a_sample_count_the_same_for_a_seed() {
    // Two samples per frame: 5 spp takes 3 frames and holds 6 samples.
    let (json, first) = path_traced("pt-a.png", "5", "7", &["--param", "samples_per_frame=2"]);
    assert_eq!(json["frames"], 3);
    assert_eq!(json["samples_per_pixel"], 6);
    let (_, again) = path_traced("pt-b.png", "5", "7", &["--param", "samples_per_frame=2"]);
    assert_eq!(first, again, "a seed renders the same image every run");
    let (_, other) = path_traced("pt-c.png", "5", "8", &["--param", "samples_per_frame=2"]);
    assert_ne!(first, other, "another seed, other samples");
}

#[test]
fn a_time_limit_stops_early_and_reports_the_samples_reached() {
    // The first frame builds pipelines and is no measure of the rest: frames
    // of 24x24 pixels take milliseconds, so a budget of seconds draws many.
    let (json, _) = path_traced("pt-limit.png", "100000", "1", &["--time-limit", "2"]);
    let frames = json["frames"].as_u64().expect("frames");
    assert!((3..100_000).contains(&frames), "{json}");
    assert_eq!(json["samples_per_pixel"], frames);
}

#[test]
fn a_time_limit_counts_rendering_not_pipeline_builds() {
    // lavapipe builds the path tracer's pipeline in about 165 ms here; the
    // render builds it, the BVH and the ray tracer's tables before its clock
    // starts and reports the time apart. (Counting frames within a short
    // budget instead would measure this machine's load.)
    let (json, _) = path_traced("pt-quick.png", "100000", "1", &["--time-limit", "0.1"]);
    let prepare_ms = json["prepare_ms"].as_f64().expect("prepare_ms");
    assert!(prepare_ms > 10.0, "{json}");
    let frames = json["frames"].as_u64().expect("frames");
    assert!(frames >= 1, "{json}");
    assert_eq!(json["samples_per_pixel"], frames);
}

#[test]
fn spp_on_a_graph_that_does_not_accumulate_is_refused() {
    let out = weft(&[
        "render",
        "scenes/cornell.scene",
        "--graph",
        "graphs/forward.ron",
        "--spp",
        "4",
        "--size",
        "16x16",
    ]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("--spp needs a progressive graph") && stderr.contains("graphs/forward.ron"),
        "{stderr}"
    );
}

#[test]
fn environment_lights_a_bare_model_and_a_map_with_nan_is_refused_with_its_texel() {
    let dir = crate::harness::scratch(&format!("weft-render-env-{}", std::process::id()));
    let map = dir.join("sky.exr");
    let mut texels = vec![[0.25f32, 0.5, 1.0]; 8 * 4];
    texels[3] = [-2.0, 0.5, 1.0];
    std::fs::write(
        &map,
        weft_io::exr::encode_rgb(8, 4, &texels).expect("encodes"),
    )
    .expect("map");
    let out_path = temp_png("environment.png");
    let args = |map: &Path| {
        vec![
            "render".to_string(),
            "../shared/assets/gltf/rise/Box.glb".into(),
            "--environment".into(),
            map.to_string_lossy().into_owned(),
            "--size".into(),
            "32x18".into(),
            "--validate".into(),
            "--out".into(),
            out_path.to_string_lossy().into_owned(),
        ]
    };
    let run = |map: &Path| {
        let args = args(map);
        weft(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };
    let out = run(&map);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{stderr}{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(
        stderr.contains(&format!(
            "warning: {}: 1 texel(s) have negative channels; clamped to 0",
            map.display()
        )),
        "{stderr}"
    );
    texels[13] = [0.0, f32::INFINITY, 0.0];
    std::fs::write(
        &map,
        weft_io::exr::encode_rgb(8, 4, &texels).expect("encodes"),
    )
    .expect("map");
    let out = run(&map);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("texel (5, 1) is [0.0, inf, 0.0]: environment radiance must be finite"),
        "{stderr}"
    );
}

#[test]
fn both_ray_tracing_backends_render_and_an_unknown_one_is_refused() {
    let out_path = temp_png("backend.png");
    // On the lavapipe with ray queries tools/setup unpacks, where the
    // default device has none (docs/hardware_rt.md).
    let offered = weft_gpu::Gpu::new(&weft_gpu::GpuOptions::default())
        .expect("a Vulkan device")
        .info()
        .shaders
        .ray_query;
    let icd = weft_gpu::ray_query::unpacked_icd().filter(|_| !offered);
    let rays = |backend: &str| {
        let mut command = crate::harness::command_in(
            &crate::harness::repo(),
            &[
                "render",
                "scenes/cornell.scene",
                "--graph",
                "graphs/pathtrace.ron",
                "--spp",
                "2",
                "--size",
                "24x24",
                "--backend",
                backend,
                "--validate",
                "--out",
                &out_path.to_string_lossy(),
            ],
        );
        if let Some(icd) = &icd {
            command.env("VK_ICD_FILENAMES", icd);
        }
        let out = command.output().expect("weft runs");
        let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{backend}: {stderr}{stdout}");
        assert!(
            stdout.contains("validation: 0 errors, 0 warnings"),
            "{backend}: {stdout}"
        );
        stdout
            .lines()
            .find(|l| l.starts_with("rays per pixel"))
            .unwrap_or_else(|| panic!("{backend}: no ray counts in {stdout}"))
            .to_string()
    };
    // The same paths on both: the same rays per pixel.
    let software = rays("software");
    assert_eq!(rays("hardware"), software);
    let out = weft(&["render", "scenes/cornell.scene", "--backend", "rtx"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("expected auto, software or hardware, found `rtx`"),
        "{stderr}"
    );
}
