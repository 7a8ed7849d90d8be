//! The `.scene` extensions and their errors, from small texts: exact values, exact messages.

use crate::common;

use common::{short_warnings, temp_dir};
use glam::Vec3;
use std::path::Path;
use weft_scene::material::MaterialOverride;
use weft_scene::{load_scene, scene_desc_from_str, Diagnostics, Light, SceneDesc, SceneReport};

fn desc(text: &str) -> (SceneDesc, Vec<String>) {
    let mut diag = Diagnostics::default();
    let d = scene_desc_from_str(text, Path::new("t.scene"), &mut diag)
        .unwrap_or_else(|e| panic!("{e}"));
    (d, short_warnings(&diag.warnings))
}

fn error(text: &str) -> String {
    let mut diag = Diagnostics::default();
    scene_desc_from_str(text, Path::new("t.scene"), &mut diag)
        .expect_err(text)
        .to_string()
}

#[test]
fn unknown_objects_and_properties_are_skipped_with_warnings() {
    let (d, warnings) =
        desc("fog\n{\n density 2\n}\npointlight\n{\n colour 1 0 0\n position 1 2 3\n}\n");
    assert_eq!(d.lights.len(), 1);
    assert_eq!(
        warnings,
        vec![
            "t.scene:1: unknown object 'fog'; skipped",
            "t.scene:7: unknown property 'colour' in 'pointlight'; skipped",
        ]
    );
}

#[test]
fn later_duplicates_override() {
    let (d, _) = desc("pointlight\n{\n position 1 2 3\n position 4 5 6\n}\n");
    let Light::Point(p) = &d.lights[0] else {
        panic!("point")
    };
    assert_eq!(p.position, Vec3::new(4.0, 5.0, 6.0));
}

#[test]
fn model_orientation_and_scale() {
    let (d, warnings) =
        desc("model\n{\n file \"a\\\\b.obj\"\n position 1 0 0\n orientation 0 90 0\n scale 2\n}\n");
    assert!(warnings.is_empty());
    let m = &d.models[0];
    assert!(m.file.ends_with("a/b.obj"), "{}", m.file.display());
    let moved = m.transform.transform_point3(Vec3::X);
    assert!(moved.distance(Vec3::new(1.0, 0.0, -2.0)) < 1e-6, "{moved}");
}

#[test]
fn extension_errors_are_located() {
    let cases = [
        ("camera\n{\n fov 45\n}\n", "t.scene:3: 'fov' is in radians and must be in (0, pi), found 45; use 'fov_deg' for degrees"),
        ("camera\n{\n target 0 0 0\n orientation 0 0 0\n}\n", "t.scene:4: give 'orientation' or 'target', not both"),
        ("camera\n{\n key 1 0 0 0 0 0 -1\n key 1 1 0 0 0 0 -1\n}\n", "t.scene:4: camera 'key' times must increase"),
        ("camera\n{\n near 5\n far 1\n}\n", "t.scene:1: camera clip distances must satisfy 0 < near < far, found near 5 far 1"),
        ("camera\n{\n fov_deg 200\n}\n", "t.scene:3: 'fov_deg' must be in (0, 180), found 200"),
        ("arealight\n{\n shape hexagon\n}\n", "t.scene:3: arealight 'shape' must be rect or disc, found 'hexagon'"),
        ("pointlights\n{\n count 2.5\n}\n", "t.scene:3: 'count' must be a whole number from 0 to 1000000, found 2.5"),
        ("pointlights\n{\n count 2000000\n}\n", "t.scene:3: 'count' must be a whole number from 0 to 1000000, found 2000000"),
        ("pointlight\n{\n attenuation 0 0 0\n}\n", "t.scene:3: 'attenuation' terms must be >= 0 and not all 0"),
        ("pointlight\n{\n radius -1\n}\n", "t.scene:3: 'radius' must be > 0, found -1"),
        ("pointlight\n{\n position 1 2\n}\n", "t.scene:3: 'position' expects 3 numbers, found 2"),
        ("pointlight\n{\n position 1 nan 2\n}\n", "t.scene:3: 'position' expects numbers, found 'nan'"),
        ("sunlight\n{\n direction 0 0 0\n}\n", "t.scene:3: 'direction' must not be a zero vector"),
        ("arealight\n{\n size 0 0\n}\n", "t.scene:3: 'size' must be two numbers > 0, found 0 0"),
        ("arealight\n{\n size 2 -1\n}\n", "t.scene:3: 'size' must be two numbers > 0, found 2 -1"),
        ("arealight\n{\n shape disc\n radius 0\n}\n", "t.scene:4: 'radius' must be > 0, found 0"),
        ("pointlights\n{\n radius -1 -5\n}\n", "t.scene:3: 'radius' must be a range lo hi with 0 < lo <= hi, found -1 -5"),
        ("pointlights\n{\n radius 5 1\n}\n", "t.scene:3: 'radius' must be a range lo hi with 0 < lo <= hi, found 5 1"),
        ("sunlight\n{\n intensity 1\n}}\n", "t.scene:4: expected '}' alone on its line to close 'sunlight' (line 1), found '}}'"),
        ("spotlight\n{\n angle 200\n}\n", "t.scene:3: 'angle' must be within 0..180 degrees, found 200"),
        ("spotlight\n{\n swivel 0 -1 0 1 0 0 -2\n}\n", "t.scene:3: 'swivel' period must be > 0"),
        ("model\n{\n orientation 1 0 0 0\n}\n", "t.scene:3: 'orientation' has a zero rotation axis"),
        ("model\n{\n orientation 1 2\n}\n", "t.scene:3: 'orientation' expects 3 numbers (pitch yaw roll, degrees) or 4 (angle in radians, axis x y z), found 2"),
        // A camera that looks at its own position has no direction to look in.
        ("camera\n{\n position 1 2 3\n target 1 2 3\n}\n", "t.scene:4: the camera's target is its position (1 2 3): there is no direction to look in"),
        ("camera\n{\n key 0 1 2 3 1 2 3\n}\n", "t.scene:3: the camera's target is its position (1 2 3): there is no direction to look in"),
        // Light is not taken away: no negative colour, emission or ambient.
        ("pointlight\n{\n color 1 -0.5 1\n}\n", "t.scene:3: 'color' channels must not be negative (a light or surface cannot take light away), found 1 -0.5 1"),
        ("spotlight\n{\n color -1 0 0\n}\n", "t.scene:3: 'color' channels must not be negative (a light or surface cannot take light away), found -1 0 0"),
        ("sunlight\n{\n color 0 0 -2\n}\n", "t.scene:3: 'color' channels must not be negative (a light or surface cannot take light away), found 0 0 -2"),
        ("sunlight\n{\n ambient -0.1\n}\n", "t.scene:3: 'ambient' must not be negative, found [-0.1, -0.1, -0.1]"),
        ("arealight\n{\n emission 1 1 -1\n}\n", "t.scene:3: 'emission' channels must not be negative (a light or surface cannot take light away), found 1 1 -1"),
        ("pointlights\n{\n color_min -1 0 0\n}\n", "t.scene:3: 'color_min' channels must not be negative (a light or surface cannot take light away), found -1 0 0"),
    ];
    for (text, expected) in cases {
        assert_eq!(error(text), expected, "{text}");
    }
}

#[test]
fn huge_directions_normalise_without_overflow() {
    let (d, _) = desc("sunlight\n{\n direction 3e38 3e38 3e38\n}\n");
    let Light::Sun(sun) = &d.lights[0] else {
        panic!("sun")
    };
    let expected = Vec3::splat(1.0 / 3f32.sqrt());
    assert!(sun.direction.distance(expected) < 1e-6, "{}", sun.direction);
}

#[test]
fn a_byte_order_mark_is_not_part_of_the_first_name() {
    let (d, warnings) = desc("\u{feff}sunlight\n{\n direction 0 -1 0\n}\n");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(d.lights.len(), 1);
    let dir = temp_dir("bom");
    let path = dir.join("bom.scene");
    std::fs::write(&path, b"\xEF\xBB\xBFsunlight\n{\n direction 0 -1 0\n}\n").expect("write");
    let scene = load_scene(&path).expect("loads");
    assert_eq!(scene.lights.len(), 1);
}

#[test]
fn devices_and_fifos_are_refused_without_reading() {
    let dir = temp_dir("special");
    let scene = dir.join("s.scene");
    std::fs::write(&scene, "include \"/dev/zero\"\n").expect("write");
    let err = load_scene(&scene).expect_err("a device");
    assert_eq!(
        err.to_string(),
        format!(
            "{}:1: /dev/zero is a device, not a regular file",
            scene.display()
        )
    );
    let fifo = dir.join("pipe.obj");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo");
    assert!(made.success());
    std::fs::write(&scene, "model\n{\n file \"pipe.obj\"\n}\n").expect("write");
    let err = load_scene(&scene).expect_err("a FIFO");
    assert_eq!(
        err.to_string(),
        format!(
            "{}:3: {} is a FIFO, not a regular file",
            scene.display(),
            fifo.display()
        )
    );
}

#[test]
fn generator_is_seeded() {
    let text = "pointlights\n{\n count 3\n seed 7\n min 0 0 0\n max 1 1 1\n}\n";
    let (a, _) = desc(text);
    let (b, _) = desc(text);
    let (c, _) = desc(&text.replace("seed 7", "seed 8"));
    assert_eq!(a.lights.len(), 3);
    assert_eq!(a.lights, b.lights);
    assert_ne!(a.lights, c.lights);
    for l in &a.lights {
        let Light::Point(p) = l else { panic!("point") };
        assert_eq!(p.attenuation, weft_scene::Attenuation::INVERSE_SQUARE);
        assert_eq!(p.radius_source, weft_scene::light::RadiusSource::Derived);
        assert!(
            (p.radius - 16.0).abs() < 1e-4,
            "white light, 1/d^2 = 1/256 at 16: {}",
            p.radius
        );
    }
}

#[test]
fn includes_nest_and_cycles_are_errors() {
    let dir = temp_dir("includes");
    std::fs::create_dir_all(dir.join("sub")).expect("dir");
    std::fs::write(
        dir.join("main.scene"),
        "include \"sub/lights.scene\"\nsunlight\n{\n}\n",
    )
    .expect("write");
    std::fs::write(
        dir.join("sub/lights.scene"),
        "pointlight\n{\n}\ninclude \"more.scene\"\n",
    )
    .expect("write");
    std::fs::write(dir.join("sub/more.scene"), "spotlight\n{\n bogus 1\n}\n").expect("write");
    let scene = load_scene(&dir.join("main.scene")).expect("loads");
    assert_eq!(scene.lights.len(), 3);
    assert_eq!(
        short_warnings(&scene.warnings)[0],
        "more.scene:3: unknown property 'bogus' in 'spotlight'; skipped"
    );

    std::fs::write(dir.join("sub/more.scene"), "include \"../main.scene\"\n").expect("write");
    let err = load_scene(&dir.join("main.scene")).expect_err("cycle");
    let shown = err.to_string();
    assert!(shown.contains("more.scene:1: include cycle:"), "{shown}");

    std::fs::write(dir.join("sub/more.scene"), "include \"gone.scene\"\n").expect("write");
    let err = load_scene(&dir.join("main.scene")).expect_err("missing");
    assert!(
        matches!(&err, weft_scene::SceneError::MissingFile { at, path }
        if at.line == Some(1) && path.ends_with("gone.scene")),
        "{err}"
    );
}

#[test]
fn lights_without_falloff_get_the_scene_diagonal() {
    let dir = temp_dir("falloff");
    std::fs::write(
        dir.join("s.scene"),
        "boundingbox\n{\n min 0 0 0\n max 3 4 0\n}\npointlight\n{\n attenuation 1 0 0\n}\n",
    )
    .expect("write");
    let scene = load_scene(&dir.join("s.scene")).expect("loads");
    let Light::Point(p) = &scene.lights[0] else {
        panic!("point")
    };
    assert_eq!(p.radius, 5.0);
    assert_eq!(
        short_warnings(&scene.warnings),
        vec!["s.scene: 1 point lights never fall off (no linear or quadratic attenuation); radius set to the scene diagonal 5"]
    );
    assert_eq!(scene.cameras[0].name, "default");
    assert!(
        scene.cameras[0]
            .forward()
            .distance((Vec3::new(1.5, 2.0, 0.0) - scene.cameras[0].position).normalize())
            < 1e-5
    );
}

#[test]
fn report_text_and_json() {
    let scene = load_scene(&common::asset("462/scenes/cube.scene")).expect("loads");
    let report = SceneReport::of(&scene);
    let text = report.to_string();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(
        lines[1],
        "  models: 2 files, 3 instances; 2 meshes, 26 triangles, 10 materials, 5 textures"
    );
    assert_eq!(lines[4], "  lights: 1 sun, 1 spot, 3 point, 0 area");
    assert!(lines[5].starts_with(
        "  point-light radii: 0 given, 3 derived, 0 from glTF range; energy cut off: max "
    ));
    assert_eq!(lines[6], "  cameras: camera0");
    assert_eq!(lines[7], "  bounds: (-200, 0, -200) .. (200, 6, 200)");
    assert_eq!(lines[8], "  warnings: 5");
    let json: serde_json::Value = serde_json::to_value(&report).expect("json");
    assert_eq!(json["triangles"], 26);
    assert_eq!(json["lights"]["point"], 3);
    assert_eq!(json["cameras"][0], "camera0");
    assert_eq!(json["warnings"][0]["at"]["line"], 5);
    assert_eq!(json["bounds"]["max"][1], 6.0);
    assert_eq!(json["point_light_radius"]["derived"], 3);
}

#[test]
fn model_absorption_is_one_or_three_numbers_of_at_least_zero() {
    let (d, warnings) = desc("model\n{\n file \"glass.obj\"\n absorption 0.5 0.25 0\n}\n");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(d.models[0].absorption, Some(Vec3::new(0.5, 0.25, 0.0)));
    let (d, _) = desc("model\n{\n file \"glass.obj\"\n absorption 2\n}\n");
    assert_eq!(d.models[0].absorption, Some(Vec3::splat(2.0)));
    let (d, _) = desc("model\n{\n file \"glass.obj\"\n}\n");
    assert_eq!(d.models[0].absorption, None);
    let message = error("model\n{\n file \"glass.obj\"\n absorption -1\n}\n");
    assert_eq!(
        message,
        "t.scene:4: 'absorption' expects 1 or 3 finite numbers of at least 0 (per world unit)"
    );
}

#[test]
fn model_ior_and_thin_override_the_glass() {
    let (d, warnings) = desc("model\n{\n file \"glass.obj\"\n ior 1.33\n thin 1\n}\n");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(
        (d.models[0].ior, d.models[0].thin),
        (Some(1.33), Some(true))
    );
    let (d, _) = desc("model\n{\n file \"glass.obj\"\n thin 0\n}\n");
    assert_eq!((d.models[0].ior, d.models[0].thin), (None, Some(false)));
    assert_eq!(
        error("model\n{\n file \"glass.obj\"\n ior 0.5\n}\n"),
        "t.scene:4: 'ior' must be a finite index of refraction of at least 1, found 0.5"
    );
    assert_eq!(
        error("model\n{\n file \"glass.obj\"\n\n thin 2\n}\n"),
        "t.scene:5: 'thin' must be 0 or 1, found 2"
    );
}

#[test]
fn model_smooth_normals_is_0_or_1() {
    let (d, warnings) = desc("model\n{\n file \"sphere.obj\"\n smooth_normals 1\n}\n");
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(d.models[0].smooth_normals);
    let (d, _) = desc("model\n{\n file \"sphere.obj\"\n}\n");
    assert!(!d.models[0].smooth_normals);
    assert_eq!(
        error("model\n{\n file \"sphere.obj\"\n smooth_normals 2\n}\n"),
        "t.scene:4: 'smooth_normals' must be 0 or 1, found 2"
    );
}

#[test]
fn model_material_overrides_are_read_and_checked_at_their_line() {
    let (d, warnings) = desc(
        "model\n{\n file \"a.obj\"\n color 1 0.5 0\n emission 0 0 2\n roughness 0.25\n metallic 1\n}\n",
    );
    assert!(warnings.is_empty(), "{warnings:?}");
    assert_eq!(
        d.models[0].material,
        MaterialOverride {
            color: Some(Vec3::new(1.0, 0.5, 0.0)),
            emission: Some(Vec3::new(0.0, 0.0, 2.0)),
            roughness: Some(0.25),
            metallic: Some(1.0),
        }
    );
    let (d, _) = desc("model\n{\n file \"a.obj\"\n}\n");
    assert!(d.models[0].material.is_empty());
    for (property, message) in [
        (
            "color -1 0 0",
            "'color' channels must not be negative (a light or surface cannot take light away), found -1 0 0",
        ),
        ("color 1 0", "'color' expects 3 numbers, found 2"),
        (
            "emission 1 inf 0",
            "'emission' expects numbers, found 'inf'",
        ),
        (
            "emission 1e39 0 0",
            "number '1e39' is not a finite 32-bit float",
        ),
        ("roughness 1.5", "'roughness' must be in [0, 1], found 1.5"),
        ("metallic -0.1", "'metallic' must be in [0, 1], found -0.1"),
    ] {
        assert_eq!(
            error(&format!("model\n{{\n file \"a.obj\"\n\n {property}\n}}\n")),
            format!("t.scene:5: {message}")
        );
    }
}

#[test]
fn a_material_override_replaces_factors_and_turns_mtl_materials_metallic_roughness() {
    use weft_scene::material::ShadingModel;
    let mtl = weft_scene::Material {
        base_color: glam::Vec4::new(0.5, 0.5, 0.5, 0.75),
        roughness: 0.4,
        ..Default::default()
    };
    let coloured = MaterialOverride {
        color: Some(Vec3::new(1.0, 0.0, 0.0)),
        ..Default::default()
    }
    .apply(&mtl);
    assert_eq!(
        coloured.base_color,
        glam::Vec4::new(1.0, 0.0, 0.0, 0.75),
        "alpha kept"
    );
    assert_eq!(coloured.shading, ShadingModel::BlinnPhong);
    let metal = MaterialOverride {
        metallic: Some(1.0),
        ..Default::default()
    }
    .apply(&mtl);
    assert_eq!(metal.shading, ShadingModel::MetallicRoughness);
    assert_eq!(
        (metal.metallic, metal.roughness),
        (1.0, 0.4),
        "roughness from Ns kept"
    );
}

#[test]
fn values_that_lose_precision_are_warned_about_at_their_line() {
    let (_, warnings) = desc(
        "pointlight\n{\n position 0 1 0\n color 1e30 1 1\n}\n\
         arealight\n{\n shape rect\n size 1 1\n emission 70000 0 0\n}\n\
         spotlight\n{\n color 2 2 2\n}\n",
    );
    assert_eq!(
        warnings,
        vec![
            "t.scene:4: 'color' 1000000000000000000000000000000 is beyond the half-float range (65504) of HDR images: the lit surfaces saturate; each pass clamps what it writes at 8192",
            "t.scene:10: 'emission' 70000 is beyond the half-float range (65504) of HDR images: the lit surfaces saturate; each pass clamps what it writes at 8192",
        ]
    );
}

#[test]
fn a_model_placed_a_million_units_out_is_warned_about_at_its_block() {
    let dir = temp_dir("far");
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let scene = dir.join("far.scene");
    std::fs::write(
        &scene,
        "model\n{\n file \"tri.obj\"\n}\nmodel\n{\n file \"tri.obj\"\n position 2e6 0 0\n}\n",
    )
    .unwrap();
    let loaded = load_scene(&scene).unwrap();
    let warnings = short_warnings(&loaded.warnings);
    assert_eq!(
        warnings,
        vec!["far.scene:3: this model reaches 1.999872e6 units from the scene's origin (its first camera, else its first position): the scene spans more than 1e6 units, where float32 positions step by 0.12 units; keep what is drawn within 5e5 units of the first camera"]
    );
    assert_eq!(loaded.origin, glam::DVec3::new(1999872.0, 0.0, 0.0));
}

/// Positions are read in f64 and stored relative to the first camera's
/// position snapped to a 1024-unit grid: a scene ten million units out keeps
/// quarter units (float32 steps by 1 unit there).
#[test]
fn positions_far_from_zero_are_stored_relative_to_the_first_camera_in_full_precision() {
    let dir = temp_dir("relative");
    std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let scene = dir.join("relative.scene");
    std::fs::write(
        &scene,
        "model\n{\n file \"tri.obj\"\n position 10000001.75 -0.25 3\n}\n\
         pointlight\n{\n position 10000000.5 2.25 0\n attenuation 1 0 1\n}\n\
         camera\n{\n position 10000000.25 1.5 5\n target 10000000.25 1.5 0\n}\n",
    )
    .unwrap();
    let loaded = load_scene(&scene).unwrap();
    assert_eq!(loaded.origin, glam::DVec3::new(10000384.0, 0.0, 0.0));
    assert_eq!(
        loaded.cameras[0].position,
        glam::Vec3::new(-383.75, 1.5, 5.0)
    );
    assert_eq!(
        loaded.instances[0].transform.w_axis.truncate(),
        glam::Vec3::new(-382.25, -0.25, 3.0)
    );
    let weft_scene::Light::Point(light) = &loaded.lights[0] else {
        panic!("a point light");
    };
    assert_eq!(light.position, glam::Vec3::new(-383.5, 2.25, 0.0));
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
}
