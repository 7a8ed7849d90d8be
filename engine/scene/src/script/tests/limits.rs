//! Each limit stops a script with a located error.

use super::*;

#[test]
fn each_limit_stops_a_script_with_a_located_error() {
    let small = Limits {
        operations: 10_000,
        call_depth: 8,
        expression_depth: 16,
        string_bytes: 64,
        array_len: 16,
        map_len: 4,
        ..Limits::default()
    };
    let cases = [
        (
            "loop",
            "let x = 0;\nloop { x += 1; }",
            "scene.rhai:2:",
            "Too many operations",
        ),
        (
            "depth",
            "fn f(n) { f(n + 1) }\nf(0);",
            "scene.rhai:2:",
            "Stack overflow",
        ),
        (
            "string",
            "let s = \"\";\nfor i in 0..100 { s += \"x\"; }",
            "scene.rhai:2:",
            "Length of string",
        ),
        (
            "array",
            "let a = [];\nfor i in 0..100 { a.push(i); }",
            "scene.rhai:2:",
            "Size of array",
        ),
        (
            "map",
            "let m = #{ a: 1, b: 2, c: 3 };\nm.mixin(#{ d: 4, e: 5, f: 6 });",
            "scene.rhai:2:",
            "Size of object map",
        ),
        (
            "expression",
            &format!("let x = {}1{};", "(".repeat(40), ")".repeat(40)),
            "scene.rhai:1:",
            "Expression exceeds maximum complexity",
        ),
    ];
    for (name, body, at, message) in cases {
        let error = load_error(name, body, &small);
        assert!(error.starts_with(at), "{name}: {error}");
        assert!(error.contains(message), "{name}: {error}");
    }
}

#[test]
fn the_load_adds_at_most_the_object_limit_and_each_call_has_a_time_limit() {
    let few = Limits {
        objects: 3,
        ..Limits::default()
    };
    let error = load_error(
        "objects",
        "for i in 0..2000000 {\n    point_light(#{ position: [0, 1, 0], color: [1, 1, 1] });\n}",
        &few,
    );
    assert_eq!(
        error,
        "scene.rhai:2:5: pointlight: a script may add at most 3 objects (lights, models and cameras) while the scene loads"
    );
    // Growing an array costs Rhai time quadratic in its length; the call's
    // clock stops it, located where it was.
    let quick = Limits {
        call_seconds: 0.2,
        ..Limits::default()
    };
    let started = std::time::Instant::now();
    let error = load_error("slow", "let a = [];\nloop {\n    a.push(1);\n}", &quick);
    assert!(
        started.elapsed() < std::time::Duration::from_secs(5),
        "{:?}",
        started.elapsed()
    );
    assert!(
        error.starts_with("scene.rhai:3:")
            && error.ends_with("the script ran past its limit of 0.2 s for one call (the load, init or one update step)"),
        "{error}"
    );
    let dir = folder(
        "slow-update",
        &[(
            "scene.rhai",
            "fn update(t, dt) {\n    let a = [];\n    loop { a.push(t); }\n}\n",
        )],
    );
    let path = dir.join("scene.rhai");
    let scene = crate::load_scene(&path).unwrap();
    let error = ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &quick)
        .err()
        .expect("stopped at load, in the first update step")
        .to_string();
    assert!(
        error.starts_with(&format!("{}:1:1: ", path.display()))
            && error.contains("ran past its limit of 0.2 s"),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn maps_grown_by_indexing_are_held_to_the_size_limit() {
    let small = Limits {
        map_len: 4,
        ..Limits::default()
    };
    let error = load_error(
        "map-index",
        "let m = #{};\nfor i in 0..10 { m[\"k\" + i] = i; }",
        &small,
    );
    assert_eq!(
        error,
        "scene.rhai:1:1: variable `m`: Size of object map too large"
    );
    let dir = folder(
        "map-state",
        &[(
            "scene.rhai",
            "fn init() { #{ m: #{} } }\nfn update(t, dt) { this.m[\"k\" + t] = t; }\n",
        )],
    );
    let path = dir.join("scene.rhai");
    let scene = crate::load_scene(&path).unwrap();
    let mut runtime = ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &small).unwrap();
    // Rhai counts nested maps' entries together: `m` and three keys are four.
    runtime
        .frame_at(3.5 * STEP)
        .expect("four entries are within the limit");
    let error = runtime
        .frame_at(4.5 * STEP)
        .expect_err("a fifth entry")
        .to_string();
    assert_eq!(
        error,
        format!(
            "{}:2:1: the state (`this`) after update at t = 0.067 s: Size of object map too large",
            path.display()
        )
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A script whose `update` step spins for about `ms` milliseconds.
fn slow_update(name: &str, ms: u32) -> PathBuf {
    folder(
        name,
        &[(
            "scene.rhai",
            &format!(
                "point_light(#{{ position: [0, 1, 0], color: [1, 1, 1] }});\nfn update(t, dt) {{\n    let n = 0;\n    for i in 0..{} {{ n += i; }}\n}}\n",
                ms * 2_000
            ),
        )],
    )
}

#[test]
fn a_frames_update_steps_share_one_time_limit_and_a_render_another() {
    // Each step is cheap enough for the per-call limit; a frame asking for
    // 5 s of scene time runs 300 of them, past the frame's limit.
    let dir = slow_update("frame-limit", 20);
    let path = dir.join("scene.rhai");
    let scene = crate::load_scene(&path).unwrap();
    let limits = Limits {
        frame_seconds: 0.3,
        ..Limits::default()
    };
    let mut runtime = ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &limits).unwrap();
    let started = std::time::Instant::now();
    let error = runtime
        .frame_at(5.0)
        .expect_err("past the frame's limit")
        .to_string();
    let took = started.elapsed();
    assert!(took < std::time::Duration::from_secs(3), "{took:?}");
    assert!(
        error.starts_with(&format!("{}:", path.display()))
            && error.ends_with("the script's update steps for one frame ran past the frame's limit of 0.3 s (300 steps of 1/60 s to reach t = 5 s)"),
        "{error}"
    );
    // Frames that each stay within their limit still add up to the render's.
    let limits = Limits {
        render_seconds: 0.4,
        ..Limits::default()
    };
    let mut runtime = ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &limits).unwrap();
    let started = std::time::Instant::now();
    let mut frame = 0;
    let error = loop {
        frame += 1;
        match runtime.frame_at(f64::from(frame) * STEP) {
            Ok(_) => assert!(frame < 200, "never stopped"),
            Err(e) => break e.to_string(),
        }
    };
    assert!(
        started.elapsed() < std::time::Duration::from_secs(3),
        "{:?}",
        started.elapsed()
    );
    assert!(
        error.contains(
            "the script's update steps ran past their limit of 0.4 s in all for this render"
        ),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn init_and_update_of_the_wrong_arity_are_refused_where_they_are_declared() {
    for (name, body, expected) in [
        (
            "update-arity",
            "point_light(#{ position: [0, 1, 0], color: [1, 1, 1] });\n\nfn update(t) {\n    set_light(0, #{ color: [t, 0, 0] });\n}\n",
            ":3:1: `fn update` takes 1 parameter; weft calls fn update(t, dt) with 2, so it would never run",
        ),
        (
            "init-arity",
            "fn init(seed) {\n    #{}\n}\n",
            ":1:1: `fn init` takes 1 parameter; weft calls fn init() with 0, so it would never run",
        ),
    ] {
        let dir = folder(name, &[("scene.rhai", body)]);
        let path = dir.join("scene.rhai");
        let error = try_runtime(&path).err().expect("refused").to_string();
        assert_eq!(error, format!("{}{expected}", path.display()));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

#[test]
fn steps_too_short_for_rhais_progress_check_still_meet_the_frames_limit() {
    // A handful of operations a step: Rhai's own check (every 1,024
    // operations of one call) never runs; the loop's check between steps
    // stops 36,000 of them at the frame's limit.
    let dir = folder(
        "short-steps",
        &[(
            "scene.rhai",
            "point_light(#{ position: [0, 1, 0], color: [1, 1, 1] });\nfn update(t, dt) {\n    let x = t * 2.0;\n}\n",
        )],
    );
    let path = dir.join("scene.rhai");
    let scene = crate::load_scene(&path).unwrap();
    let limits = Limits {
        frame_seconds: 0.02,
        ..Limits::default()
    };
    let mut runtime = ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &limits).unwrap();
    let error = runtime
        .frame_at(600.0)
        .expect_err("past the frame's limit")
        .to_string();
    assert!(
        error.starts_with(&format!("{}:2:1: ", path.display()))
            && error.ends_with("the script's update steps for one frame ran past the frame's limit of 0.02 s (36000 steps of 1/60 s to reach t = 600 s)"),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
