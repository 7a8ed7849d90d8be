//! Bounds counted before work and values held to what a shader holds
//! (issue 60): outputs that are not regular files, system files included by
//! a scene, scripts slow per frame, parameters beyond a 32-bit float or a
//! GLSL int, NaN range bounds, and a camera with nowhere to look. Each is a
//! located error within its deadline, never a hang or a black image.

use super::*;

#[test]
fn outputs_that_are_not_regular_files_are_refused_before_any_work() {
    let dir = temp("fifo-out");
    let fifo = dir.join("out.png");
    mkfifo(&fifo);
    let readback = dir.join("r.png");
    mkfifo(&dir.join("r.hdr.exr"));
    for (out, extra, expected) in [
        (&fifo, None, format!("--out {0}: {0} is a FIFO, not a regular file: weft writes outputs only to regular files", fifo.display())),
        (&readback, Some("hdr"), "--readback hdr:".to_string()),
    ] {
        let mut args = vec![
            "render".to_string(),
            "scenes/demo.scene".into(),
            "--size".into(),
            "8x8".into(),
            "--out".into(),
            out.to_string_lossy().into_owned(),
        ];
        if let Some(name) = extra {
            args.extend(["--readback".into(), name.into()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let run = weft_within(&repo(), &args, 30);
        let err = stderr(&run);
        assert_eq!(run.status.code(), Some(1), "{err}");
        assert!(err.contains(&expected) && err.contains("is a FIFO"), "{err}");
        assert!(!err.contains("device:"), "refused before the device opened: {err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_scene_including_a_system_file_names_it_and_never_shows_it() {
    let dir = temp("scene-include");
    for include in ["/proc/self/environ", "/etc/passwd"] {
        let scene = dir.join("s.scene");
        std::fs::write(&scene, format!("include \"{include}\"\n")).expect("write");
        for json in [false, true] {
            let mut args = vec!["scene", "check"];
            if json {
                args.push("--json");
            }
            let path = scene.to_string_lossy().into_owned();
            args.push(&path);
            let out = command_in(&repo(), &args)
                .env("WEFT_SECRET_FOR_TEST", "do-not-print-me")
                .stdin(Stdio::null())
                .output()
                .expect("weft runs");
            let all = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
            assert_eq!(out.status.code(), Some(1), "{include}: {all}");
            let located = if json {
                all.contains(&format!("\"file\": \"{include}\"")) && all.contains("\"line\": ")
            } else {
                all.contains(&format!("error: {include}:"))
            };
            assert!(
                located
                    && all.contains(
                        "the file is outside the scene's folder, so its content is not shown"
                    ),
                "{include} (json {json}): {all}"
            );
            assert!(
                !all.contains("do-not-print-me") && !all.contains("root:x:0"),
                "{include} echoed: {all}"
            );
        }
    }
    // A system file named as a script (allowed outside the folder) is
    // located, never shown.
    let scene = dir.join("script.scene");
    std::fs::write(&scene, "script \"/proc/self/environ\"\n").expect("write");
    let out = command_in(
        &repo(),
        &[
            "scene",
            "check",
            "--allow-outside",
            &scene.to_string_lossy(),
        ],
    )
    .env("WEFT_SECRET_FOR_TEST", "do-not-print-me")
    .stdin(Stdio::null())
    .output()
    .expect("weft runs");
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("error: /proc/self/environ:1:")
            && err.contains("not a Rhai script (a system file, so its content is not shown)")
            && !err.contains("do-not-print-me"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_script_slow_per_frame_stops_at_the_frames_limit_with_its_location() {
    let dir = temp("slow-script");
    // About 0.1-0.3 s an update step: a frame at t = 5 s runs 300 of them.
    std::fs::write(
        dir.join("scene.rhai"),
        "point_light(#{ position: [0, 1, 0], color: [1, 1, 1] });\ncamera(\"c\", #{ position: [0, 1, 3], target: [0, 0, 0] });\nfn update(t, dt) {\n    let n = 0;\n    for i in 0..400000 { n += i; }\n}\n",
    )
    .expect("script");
    let scene = dir.join("scene.rhai").to_string_lossy().into_owned();
    let png = dir.join("o.png").to_string_lossy().into_owned();
    let started = std::time::Instant::now();
    let out = weft_within(
        &repo(),
        &[
            "render", &scene, "--size", "8x8", "--time", "5", "--out", &png,
        ],
        60,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("scene.rhai:3:1: the script's update steps for one frame ran past the frame's limit of 10 s (300 steps of 1/60 s to reach t = 5 s)"),
        "{err}"
    );
    assert!(started.elapsed().as_secs() < 40, "{:?}", started.elapsed());
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn parameters_beyond_a_float_or_a_glsl_int_and_nan_bounds_are_refused_where_declared() {
    for (graph, param, expected) in [
        (
            "graphs/forward.ron",
            "emissive_boost=1e39",
            "graphs/forward.ron:26:27: error: parameter \"emissive_boost\" must be a finite 32-bit float (at most 3.4e38 in size), found 1e39",
        ),
        (
            "graphs/forward.ron",
            "emissive_boost=1e308",
            "parameter \"emissive_boost\" must be a finite 32-bit float (at most 3.4e38 in size), found 1e308",
        ),
        (
            "graphs/forward.ron",
            "area_samples=-2000000000",
            "parameter \"area_samples\" set to -2000000000: it must be at least 0",
        ),
        (
            "graphs/pathtrace.ron",
            "rr_depth=4294967296",
            "define \"RR_DEPTH\": its value must be a whole number from -2147483648 to 2147483647 (a GLSL int), found 4294967296",
        ),
    ] {
        let out = weft_within(
            &repo(),
            &["render", "scenes/cornell.scene", "--graph", graph, "--size", "8x8", "--param", param, "--out", "/tmp/never-written.png"],
            60,
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{param}: {err}");
        assert!(err.contains(expected), "{param}: {err}");
    }
    let dir = temp("nan-range");
    let text = std::fs::read_to_string(repo().join("graphs/forward.ron")).expect("forward");
    let graph = dir.join("forward.ron");
    std::fs::write(
        &graph,
        text.replace("../shaders", &repo().join("shaders").to_string_lossy())
            .replace(
                r#""area_samples": (integer: true, min: 0, max: 64),"#,
                r#""area_samples": (integer: true, min: NaN, max: 64),"#,
            ),
    )
    .expect("graph");
    let out = weft_within(&repo(), &["graph", "check", &graph.to_string_lossy()], 60);
    let err = format!("{}{}", String::from_utf8_lossy(&out.stdout), stderr(&out));
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the range of \"area_samples\" has a bound of NaN: bounds are numbers"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn a_script_camera_looking_at_its_own_position_is_refused_where_it_is_set() {
    let dir = temp("camera-target");
    std::fs::write(
        dir.join("scene.rhai"),
        "point_light(#{ position: [0, 1, 0], color: [1, 1, 1] });\ncamera(\"c\", #{ position: [0, 1, 3], target: [0, 0, 0] });\nfn update(t, dt) {\n    set_camera(\"c\", #{ position: [1, 1, 1], target: [1, 1, 1] });\n}\n",
    )
    .expect("script");
    let scene = dir.join("scene.rhai").to_string_lossy().into_owned();
    let out = weft_within(
        &repo(),
        &[
            "render",
            &scene,
            "--size",
            "8x8",
            "--out",
            "/tmp/never-written.png",
        ],
        60,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("scene.rhai:4:")
            && err.contains(
                "the camera's target is its position (1 1 1): there is no direction to look in"
            ),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

/// A 2 KB glTF whose 40 nodes each list the next twice as a child
/// (2⁴⁰ − 1 instances if expanded): `scene check` and `render` refuse it
/// at once, naming the limit and a node with two parents.
#[test]
fn a_gltf_node_graph_that_doubles_at_every_level_is_refused_at_once() {
    let dir = temp("gltf-bomb");
    let nodes: Vec<String> = (0..40)
        .map(|i| {
            if i == 39 {
                r#"{"mesh":0}"#.to_string()
            } else {
                format!(r#"{{"mesh":0,"children":[{0},{0}]}}"#, i + 1)
            }
        })
        .collect();
    // One triangle: three positions and no indices, in a data URI.
    let positions: Vec<u8> = [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    const TABLE: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let data: String = positions
        .chunks(3)
        .flat_map(|c| {
            let n = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
            (0..4).map(move |i| TABLE[(n >> (18 - 6 * i) & 63) as usize] as char)
        })
        .collect();
    let gltf = dir.join("bomb.gltf");
    std::fs::write(
        &gltf,
        format!(
            r#"{{"asset":{{"version":"2.0"}},"buffers":[{{"uri":"data:application/octet-stream;base64,{data}","byteLength":36}}],"bufferViews":[{{"buffer":0,"byteLength":36}}],"accessors":[{{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}}],"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}}}}]}}],"nodes":[{}],"scenes":[{{"nodes":[0]}}]}}"#,
            nodes.join(",")
        ),
    )
    .expect("gltf");
    let path = gltf.to_string_lossy().into_owned();
    for args in [
        vec!["scene", "check", path.as_str()],
        vec![
            "render",
            path.as_str(),
            "--size",
            "8x8",
            "--out",
            "/tmp/never-written.png",
        ],
    ] {
        let out = weft_within(&repo(), &args, 30);
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{args:?}: {err}");
        assert!(
            err.contains("bomb.gltf: the node hierarchy expands to 1099511627775 node instances, over the limit of 100000; node 1 has 2 parents (or is listed twice), where glTF 2.0 allows one"),
            "{args:?}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
