//! The script runtime's tests: the load API, imports and frames; the limits in `limits`.

mod limits;

use super::*;
use crate::light::PointLight;

/// A folder of its own under the temp folder, with `files` written in it.
fn folder(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-script-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (file, text) in files {
        let path = dir.join(file);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    dir
}

fn script_ref(path: &Path) -> ScriptRef {
    ScriptRef {
        path: path.to_path_buf(),
        at: Location::file(path),
        first_light: 0,
        first_model: 0,
        imports: Vec::new(),
    }
}

/// The runtime of the `.rhai` scene at `path`, loaded as a scene.
fn runtime(path: &Path) -> ScriptRuntime {
    try_runtime(path).unwrap()
}

/// The runtime of the `.rhai` scene at `path`, or why it is refused (an
/// `update` that fails at its first step is refused at load).
fn try_runtime(path: &Path) -> Result<ScriptRuntime, SceneError> {
    let scene = crate::load_scene(path).unwrap();
    ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &Limits::default())
}

/// Runs a `.rhai` scene's load with `limits`.
fn load(dir: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
    let path = dir.join("scene.rhai");
    let mut desc = SceneDesc::default();
    let mut script = script_ref(&path);
    run_load(
        &mut script,
        &path,
        &mut desc,
        &mut Diagnostics::default(),
        (&LoadOptions::default(), limits),
    )?;
    desc.script = Some(script);
    Ok(desc)
}

fn point(light: &Light) -> &PointLight {
    match light {
        Light::Point(p) => p,
        other => panic!("not a point light: {other:?}"),
    }
}

#[test]
fn objects_a_script_adds_are_the_scene_files_objects() {
    let dir = folder(
        "objects",
        &[(
            "scene.rhai",
            r#"
            point_light(#{ position: [1, 2, 3], color: [0.5, 0.25, 1], radius: 4 });
            spot_light(#{ position: [0, 5, 0], direction: [0, -1, 0], angle: 30 });
            sun_light(#{ direction: [0, -1, 0], ambient: 0.1 });
            area_light(#{ position: [0, 4, 0], size: [1, 2] });
            model("box.obj", #{ position: [1, 0, 0], scale: 2 });
            camera("top", #{ position: [0, 9, 0.1], target: [0, 0, 0] });
            "#,
        )],
    );
    let from_script = load(&dir, &Limits::default()).unwrap();
    let text = "pointlight\n{\n\tposition 1 2 3\n\tcolor 0.5 0.25 1\n\tradius 4\n}\n\
        spotlight\n{\n\tposition 0 5 0\n\tdirection 0 -1 0\n\tangle 30\n}\n\
        sunlight\n{\n\tdirection 0 -1 0\n\tambient 0.1\n}\n\
        arealight\n{\n\tposition 0 4 0\n\tsize 1 2\n}\n\
        model\n{\n\tfile \"box.obj\"\n\tposition 1 0 0\n\tscale 2\n}\n\
        camera \"top\"\n{\n\tposition 0 9 0.1\n\ttarget 0 0 0\n}\n";
    let from_file =
        crate::scene_desc_from_str(text, &dir.join("scene.rhai"), &mut Diagnostics::default())
            .unwrap();
    assert_eq!(from_script.lights, from_file.lights);
    assert_eq!(from_script.cameras, from_file.cameras);
    assert_eq!(from_script.models.len(), 1);
    assert_eq!(from_script.models[0].file, dir.join("box.obj"));
    assert_eq!(
        from_script.models[0].transform,
        from_file.models[0].transform
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn updates_are_fixed_steps_so_a_time_gives_the_same_lights_however_it_is_reached() {
    let dir = folder(
        "steps",
        &[(
            "scene.rhai",
            r#"
            point_light(#{ position: [0, 0, 0], color: [1, 1, 1] });
            fn init() { #{ steps: 0 } }
            fn update(t, dt) {
                this.steps += 1;
                let p = light_position(0);
                set_light_position(0, p[0] + dt, t, this.steps);
                set_light_on(0, this.steps % 2 == 0);
            }
            "#,
        )],
    );
    let path = dir.join("scene.rhai");
    let runtime = || runtime(&path);
    let mut a = runtime();
    assert!(a.animates());
    // 0.5 s = 30 steps of 1/60 s: x = 30 / 60, y = t of the last step, z = steps.
    let at_half = a.frame_at(0.5).unwrap().lights;
    let p = point(&at_half[0]);
    assert!(
        (p.position - Vec3::new(0.5, 0.5, 30.0)).abs().max_element() < 1e-5,
        "{p:?}"
    );
    assert_eq!(p.color, Vec3::ONE, "step 30 is even: on");
    // Reached through other frame times, or again after going back: the same.
    let mut b = runtime();
    for t in [0.1, 0.25, 0.4999, 0.5] {
        b.frame_at(t).unwrap();
    }
    assert_eq!(b.frame_at(0.5).unwrap().lights, at_half);
    a.frame_at(3.0).unwrap();
    assert_eq!(
        a.frame_at(0.5).unwrap().lights,
        at_half,
        "going back starts over"
    );
    // Step 31 is odd: off, with zero colour.
    assert_eq!(
        point(&a.frame_at(31.0 / 60.0 + 1e-9).unwrap().lights[0]).color,
        Vec3::ZERO
    );
    assert_eq!(
        point(&a.frame_at(0.0).unwrap().lights[0]).position,
        Vec3::ZERO
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The error a script body gets under `limits`, with its location.
fn load_error(name: &str, body: &str, limits: &Limits) -> String {
    let dir = folder(name, &[("scene.rhai", body)]);
    let error = load(&dir, limits)
        .map(|_| ())
        .expect_err(&format!("{name} refused"))
        .to_string();
    std::fs::remove_dir_all(&dir).unwrap();
    error.replace(&dir.join("scene.rhai").display().to_string(), "scene.rhai")
}

#[test]
fn runtime_errors_and_misuse_are_located_at_file_line_and_column() {
    let limits = Limits::default();
    let error = load_error(
        "missing",
        "let x = 1;\n  point_light(#{ position: [1, 2] });",
        &limits,
    );
    assert!(
        error.starts_with("scene.rhai:2:3: pointlight: "),
        "the .scene reader's own message, at the call: {error}"
    );
    assert!(error.contains("position"), "{error}");
    let error = load_error("update-only", "set_light_on(0, false);", &limits);
    assert_eq!(
        error,
        "scene.rhai:1:1: lights are changed in init or update, after the scene has loaded"
    );
    let error = load_error("syntax", "let x = ;", &limits);
    assert!(error.starts_with("scene.rhai:1:9: "), "{error}");
    let dir = folder(
        "adds-late",
        &[(
            "scene.rhai",
            "fn update(t, dt) {\n    point_light(#{});\n}\n",
        )],
    );
    let path = dir.join("scene.rhai");
    let error = try_runtime(&path)
        .err()
        .expect("refused at load, by the first update step")
        .to_string();
    assert_eq!(
        error,
        format!(
            "{}:2:5: pointlight objects are added while the scene loads, not in init or update",
            path.display()
        )
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn imports_reach_only_scripts_under_the_scenes_folder() {
    let dir = folder(
        "imports",
        &[
            (
                "scene.rhai",
                "import \"lib/colours\" as c;\npoint_light(#{ color: c::warm() });",
            ),
            ("lib/colours.rhai", "fn warm() { [1.0, 0.5, 0.25] }"),
        ],
    );
    let desc = load(&dir, &Limits::default()).unwrap();
    assert_eq!(point(&desc.lights[0]).color, Vec3::new(1.0, 0.5, 0.25));
    assert_eq!(
        desc.script.unwrap().imports,
        [dir.canonicalize().unwrap().join("lib/colours.rhai")],
        "imports are recorded, to be watched"
    );
    std::fs::write(dir.join("scene.rhai"), "import \"../outside\" as o;").unwrap();
    std::fs::write(dir.join("../outside.rhai"), "fn f() { 1 }").unwrap();
    let error = load(&dir, &Limits::default())
        .expect_err("refused")
        .to_string();
    assert!(
        error.contains("import \"../outside\": scripts may import only scripts under"),
        "{error}"
    );
    std::fs::remove_file(dir.join("../outside.rhai")).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn import_cycles_are_located_errors_naming_the_chain() {
    let dir = folder(
        "import-cycle",
        &[
            ("scene.rhai", "import \"self\" as s;"),
            ("self.rhai", "import \"self\" as p;\nfn f() { 1 }"),
        ],
    );
    let error = load(&dir, &Limits::default())
        .expect_err("a file importing itself")
        .to_string();
    assert!(
        error.contains("import \"self\" is a cycle: self.rhai -> self.rhai"),
        "{error}"
    );
    assert!(
        error.contains("scene.rhai:1:8: "),
        "located at the scene script's import: {error}"
    );
    std::fs::write(dir.join("scene.rhai"), "import \"a\" as a;").unwrap();
    std::fs::write(dir.join("a.rhai"), "import \"b\" as b;").unwrap();
    std::fs::write(dir.join("b.rhai"), "import \"a\" as a;").unwrap();
    let error = load(&dir, &Limits::default())
        .expect_err("two files importing each other")
        .to_string();
    assert!(
        error.contains("is a cycle: a.rhai -> b.rhai -> a.rhai"),
        "{error}"
    );
    std::fs::write(dir.join("scene.rhai"), "import \"scene\" as s;").unwrap();
    let error = load(&dir, &Limits::default())
        .expect_err("the scene's script importing itself")
        .to_string();
    assert!(
        error.contains("is a cycle: scene.rhai -> scene.rhai"),
        "{error}"
    );
    // The same module imported twice, not in a cycle, is fine.
    std::fs::write(dir.join("scene.rhai"), "import \"c\" as c1;\nimport \"c\" as c2;\npoint_light(#{ color: [c1::v(), c2::v(), 1.0] });").unwrap();
    std::fs::write(dir.join("c.rhai"), "fn v() { 0.5 }").unwrap();
    let desc = load(&dir, &Limits::default()).expect("no cycle");
    assert_eq!(point(&desc.lights[0]).color, Vec3::new(0.5, 0.5, 1.0));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_import_of_a_fifo_is_refused_without_waiting() {
    let dir = folder("import-fifo", &[("scene.rhai", "import \"pipe\" as p;")]);
    let made = std::process::Command::new("mkfifo")
        .arg(dir.join("pipe.rhai"))
        .status()
        .unwrap();
    assert!(made.success());
    let error = load(&dir, &Limits::default())
        .expect_err("a FIFO is no script")
        .to_string();
    assert!(error.contains("is a FIFO, not a regular file"), "{error}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scripts_have_no_file_access_and_no_clock() {
    for (name, body) in [
        ("open", "open_file(\"/etc/passwd\");"),
        ("clock", "let t = timestamp();"),
    ] {
        let error = load_error(name, body, &Limits::default());
        assert!(error.contains("Function not found"), "{name}: {error}");
    }
}

/// A one-triangle OBJ spanning (0, 0, 0)..(1, 1, 0).
const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

#[test]
fn scene_bounds_at_load_are_those_of_the_models_placed_so_far() {
    let dir = folder(
        "bounds",
        &[
            ("tri.obj", TRIANGLE),
            (
                "scene.rhai",
                r#"
                let i = model("tri.obj", #{ position: [10, 0, 0], scale: 2 });
                let b = scene_bounds();
                point_light(#{ position: b.max, radius: 1 });
                point_light(#{ position: b.min, radius: 1 });
                let j = model("tri.obj", #{ position: [-4, 0, 0] });
                point_light(#{ position: scene_bounds().min, radius: i + j });
                "#,
            ),
        ],
    );
    let scene = crate::load_scene(&dir.join("scene.rhai")).unwrap();
    let positions: Vec<Vec3> = scene.lights.iter().map(|l| point(l).position).collect();
    assert_eq!(
        positions,
        [
            Vec3::new(12.0, 2.0, 0.0),
            Vec3::new(10.0, 0.0, 0.0),
            Vec3::new(-4.0, 0.0, 0.0)
        ]
    );
    assert_eq!(
        point(&scene.lights[2]).radius,
        1.0,
        "model() gives indices 0 and 1"
    );
    assert_eq!(scene.models.len(), 1, "the file is loaded once");
    std::fs::write(dir.join("scene.rhai"), "let b = scene_bounds();").unwrap();
    let error = crate::load_scene(&dir.join("scene.rhai"))
        .expect_err("refused")
        .to_string();
    assert!(
        error.ends_with("scene.rhai:1:9: scene_bounds: no model is placed yet"),
        "{error}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn update_moves_placements_and_cameras_as_the_same_blocks_in_a_file_would_place_them() {
    let dir = folder(
        "placements",
        &[
            ("tri.obj", TRIANGLE),
            (
                "scene.rhai",
                r#"
                model("tri.obj", #{ color: [1, 0, 0], roughness: 0.25 });
                model("tri.obj", #{});
                camera("top", #{ position: [0, 9, 0.1], target: [0, 0, 0], fov_deg: 30 });
                fn update(t, dt) {
                    set_model_transform(1, #{ position: [t, 2, 0], orientation: [0, 90, 0], scale: [1, 2, 3] });
                    let p = model_position(1);
                    set_camera("top", #{ position: [p[0], 5, 5], target: p });
                    set_model_color(1, 0, 1, 0.5);
                }
                "#,
            ),
        ],
    );
    let path = dir.join("scene.rhai");
    let scene = crate::load_scene(&path).unwrap();
    assert_eq!(
        scene.instances[0].material,
        crate::material::MaterialOverride {
            color: Some(Vec3::new(1.0, 0.0, 0.0)),
            roughness: Some(0.25),
            ..Default::default()
        }
    );
    assert!(scene.instances[1].material.is_empty());
    let frame = runtime(&path).frame_at(0.5).unwrap();
    let file = "model\n{\n\tfile \"tri.obj\"\n\tposition 0.5 2 0\n\torientation 0 90 0\n\tscale 1 2 3\n}\n\
        camera \"top\"\n{\n\tposition 0.5 5 5\n\ttarget 0.5 2 0\n\tfov_deg 30\n}\n";
    let desc = crate::scene_desc_from_str(file, &path, &mut Diagnostics::default()).unwrap();
    assert_eq!(
        frame.transforms[0], scene.instances[0].transform,
        "not moved"
    );
    assert_eq!(
        frame.colors,
        [
            Some(Vec3::new(1.0, 0.0, 0.0)),
            Some(Vec3::new(0.0, 1.0, 0.5))
        ],
        "the load's override, and the colour set per frame"
    );
    assert_eq!(frame.transforms[1], desc.models[0].transform);
    assert_eq!(frame.cameras.len(), 1, "the camera the script set");
    let (set, file) = (&frame.cameras[0], &desc.cameras[0]);
    assert_eq!(
        (set.position, set.orientation, set.fov_y),
        (file.position, file.orientation, file.fov_y),
        "the field of view kept"
    );
    let error = |body: &str| {
        std::fs::write(&path, format!("camera(\"top\", #{{}});\nmodel(\"tri.obj\", #{{}});\nfn update(t, dt) {{\n    {body}\n}}\n")).unwrap();
        try_runtime(&path)
            .err()
            .expect("refused at load, by the first update step")
            .to_string()
            .replace(&path.display().to_string(), "scene.rhai")
    };
    assert_eq!(
        error("set_model_transform(0, #{ color: [1, 0, 0] });"),
        "scene.rhai:4:5: set_model_transform: 'color' is not a transform property (position, orientation, scale)"
    );
    assert_eq!(
        error("set_model_transform(1, #{});"),
        "scene.rhai:4:5: no model 1: the scene has 1"
    );
    assert_eq!(
        error("set_model_color(0, 1, -1, 0);"),
        "scene.rhai:4:5: colour [1, -1, 0] is negative"
    );
    assert_eq!(
        error("set_camera(\"side\", #{ position: [0, 0, 0] });"),
        "scene.rhai:4:5: no camera 'side': the scene has top"
    );
    assert!(
        error("set_model_transform(0, #{ scale: [1, 2] });")
            .starts_with("scene.rhai:4:5: set_model_transform: "),
        "the .scene reader's message"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
