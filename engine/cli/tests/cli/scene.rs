//! `weft scene check` as a user runs it.

use crate::harness::{command_in, repo, weft};

#[test]
fn check_summarises_a_real_scene_with_its_quirk_warning() {
    let out = weft(&["scene", "check", "../shared/assets/462/scenes/dragon.scene"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("1 meshes, 100000 triangles"), "{text}");
    assert!(
        text.contains("lights: 1 sun, 0 spot, 0 point, 0 area"),
        "{text}"
    );
    assert!(
        text.contains("dragon.scene:6: warning: 'orientation' has 4 values"),
        "{text}"
    );
}

#[test]
fn check_json_has_counts() {
    let out = weft(&["scene", "check", "scenes/demo.scene", "--json"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    assert_eq!(json["lights"]["sun"], 1);
    assert!(json["triangles"].as_u64().expect("triangles") > 100_000);
    // 20-byte vertices: every vertex of the demo's models and the light-volume meshes.
    assert_eq!(json["vertex_bytes"], 20);
    let scene = weft_scene::load_scene(&repo().join("scenes/demo.scene")).expect("demo loads");
    let vertices = weft_render::SceneGeometry::new(&scene).vertices.len() as u64;
    assert_eq!(json["vertex_buffer_bytes"].as_u64(), Some(vertices * 20));
}

#[test]
fn check_reports_emissive_geometry_as_raster_lights() {
    // The Cornell box's ceiling light is one emissive quad (two triangles, Ke 17 12 4).
    let out = weft(&["scene", "check", "scenes/cornell.scene"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("emissive geometry: 2 triangles -> 1 polygon lights (1 quads merged)"),
        "{text}"
    );
    // The damaged helmet's emission is textured: it lights raster graphs
    // through the texture's mean over each triangle, its glowing triangles
    // clustered into at most the budget of lights.
    let out = weft(&["scene", "check", "scenes/gltf.scene", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("valid JSON");
    let lights = &json["emitter_lights"];
    let polygons = lights["polygons"].as_u64().unwrap_or(0);
    assert!(polygons > 0 && polygons <= 64, "{lights}");
    assert_eq!(lights["textured"], 1);
    assert!(lights["clusters"].as_u64() > Some(0), "{lights}");
}

#[test]
fn check_fails_on_a_missing_file() {
    let out = weft(&["scene", "check", "scenes/no-such.scene"]);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.starts_with("error: ") && stderr.contains("no-such.scene"),
        "{stderr}"
    );
}

#[test]
fn a_closed_pipe_ends_the_command_quietly() {
    use std::io::Read;
    use std::os::unix::process::ExitStatusExt;
    let mut child = command_in(&repo(), &["scene", "check", "--json", "scenes/demo.scene"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("weft runs");
    // Close the reading end before the scene has loaded, as `| head` does
    // once it has what it wants: the first write then meets a closed pipe.
    drop(child.stdout.take());
    let mut stderr = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut stderr)
        .expect("stderr");
    let status = child.wait().expect("exits");
    assert_eq!(stderr, "", "nothing printed, no panic");
    const SIGPIPE: i32 = 13;
    assert_eq!(status.signal(), Some(SIGPIPE), "{status:?}");
}

#[test]
fn a_scene_error_shows_the_offending_line() {
    let dir = crate::harness::scratch(&format!("weft-scene-cli-{}", std::process::id()));
    let path = dir.join("bad.scene");
    std::fs::write(&path, "camera {\n  position 0 0 5\n  fov banana\n}\n").expect("write");
    let out = weft(&["scene", "check", path.to_str().expect("utf-8 path")]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.ends_with(&format!(
            "error: {}:3: 'fov' expects numbers, found 'banana'\n   |\n 3 |   fov banana\n   |   ^^^^^^^^^^\n",
            path.display()
        )),
        "{stderr}"
    );
}

/// The model cache is used by default (in `$WEFT_CACHE_DIR/models`): the
/// second check reads the entry the first wrote and reports the same scene,
/// warnings included; `--no-cache` writes nothing.
#[test]
fn check_uses_the_model_cache_unless_told_not_to() {
    let cache =
        crate::harness::scratch_path(&format!("weft-scene-cli-cache-{}", std::process::id()));
    let check = |extra: &[&str]| {
        let mut args = vec![
            "scene",
            "check",
            "../shared/assets/462/scenes/dragon.scene",
            "--json",
        ];
        args.extend_from_slice(extra);
        let out = command_in(&repo(), &args)
            .env("WEFT_CACHE_DIR", &cache)
            .output()
            .expect("weft runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let entries = || {
        std::fs::read_dir(cache.join("models"))
            .map(|d| d.filter_map(Result::ok).count())
            .unwrap_or(0)
    };
    let uncached = check(&["--no-cache"]);
    assert_eq!(entries(), 0, "--no-cache wrote an entry");
    let cold = check(&[]);
    assert_eq!(entries(), 1, "one model, one entry");
    let warm = check(&[]);
    assert_eq!(cold, uncached);
    assert_eq!(warm, cold, "the cached model reports the same scene");
}
