//! Bad command-line values, files outside a scene's folder, and parameters
//! held to the type and range their graph declares.

use super::*;

#[test]
fn output_folders_negative_times_and_empty_feature_names() {
    let out = weft_within(
        &repo(),
        &[
            "render",
            "scenes/demo.scene",
            "--size",
            "8x8",
            "--out",
            "/nonexistent/dir/x.png",
        ],
        60,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--out /nonexistent/dir/x.png: the folder /nonexistent/dir does not exist"),
        "{err}"
    );
    assert!(!Path::new("/nonexistent").exists());
    let dir = temp("negative-time");
    let png = dir.join("t.png");
    let out = weft_within(
        &repo(),
        &[
            "render",
            "scenes/animation.scene",
            "--size",
            "8x8",
            "--time",
            "-5",
            "--out",
            &png.to_string_lossy(),
        ],
        120,
    );
    assert!(
        out.status.success(),
        "--time -5 is a value: {}",
        stderr(&out)
    );
    let unknown = "unknown feature \"bench_floors\"; this graph's features are:";
    let empty = "an empty feature name (a stray comma, or `!` alone)";
    for (features, expected) in [
        ("bench_floors", unknown),
        ("!", empty),
        (",,,", empty),
        ("bloom,,shadow_casters", empty),
    ] {
        let out = weft_within(
            &repo(),
            &[
                "render",
                "scenes/demo.scene",
                "--size",
                "8x8",
                "--features",
                features,
                "--out",
                &png.to_string_lossy(),
            ],
            60,
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{features}: {err}");
        assert!(err.contains(expected), "{features}: {err}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn scenes_and_gltf_files_read_only_inside_their_folder_unless_allowed() {
    let dir = temp("outside");
    let inner = dir.join("scene");
    std::fs::create_dir_all(&inner).expect("dir");
    std::fs::write(
        dir.join("outside.rhai"),
        "point_light(#{ position: [0, 2, 0], color: [1, 1, 1] });\n",
    )
    .expect("script");
    let scene = inner.join("s.scene");
    std::fs::write(&scene, "script \"../outside.rhai\"\n").expect("scene");
    let out = weft_within(&repo(), &["scene", "check", &scene.to_string_lossy()], 60);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("s.scene:1: script "), "{err}");
    assert!(err.contains("outside.rhai lies outside"), "{err}");
    assert!(
        err.contains("weft reads it only with --allow-outside"),
        "{err}"
    );
    let out = weft_within(
        &repo(),
        &[
            "--allow-outside",
            "scene",
            "check",
            &scene.to_string_lossy(),
        ],
        60,
    );
    assert!(out.status.success(), "{}", stderr(&out));
    // A glTF buffer that climbs out of the glTF's folder.
    let gltf = inner.join("m.gltf");
    std::fs::write(
        &gltf,
        r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"../../../../../../../../etc/passwd","byteLength":12}],"bufferViews":[{"buffer":0,"byteLength":12}],"accessors":[{"bufferView":0,"componentType":5126,"count":1,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"nodes":[{"mesh":0}],"scenes":[{"nodes":[0]}]}"#,
    )
    .expect("gltf");
    let out = weft_within(
        &repo(),
        &["scene", "check", "--no-cache", &gltf.to_string_lossy()],
        60,
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("buffer 0: buffer ") && err.contains("etc/passwd lies outside"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).expect("clean up");
}

#[test]
fn params_are_held_to_the_type_and_range_their_graph_declares() {
    for (param, expected) in [
        (
            "max_depth=-1",
            "pathtrace.ron:26:22: error: parameter \"max_depth\" set to -1: it must be at least 1",
        ),
        (
            "sampling=99",
            "parameter \"sampling\" set to 99: it must be one of 0, 1, 2",
        ),
        (
            "exposure=true",
            "parameter \"exposure\" set to true: it must be a number, like its default",
        ),
        (
            "samples_per_frame=0.5",
            "parameter \"samples_per_frame\" set to 0.5: it must be a whole number",
        ),
    ] {
        let out = weft_within(
            &repo(),
            &[
                "render",
                "scenes/demo.scene",
                "--graph",
                "graphs/pathtrace.ron",
                "--size",
                "8x8",
                "--param",
                param,
                "--out",
                "/tmp/weft-never-written.png",
            ],
            60,
        );
        let err = stderr(&out);
        assert_eq!(out.status.code(), Some(1), "{param}: {err}");
        assert!(err.contains(expected), "{param}: {err}");
    }
}
