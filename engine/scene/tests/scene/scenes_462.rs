//! The CMU 15-462 scene pack, loaded as it is: exact counts, light parameters and the
//! warnings its quirks must produce; scenes whose models are missing name the missing file.

use crate::common;

use common::{asset, short_warnings};
use glam::Vec3;
use weft_scene::light::RadiusSource;
use weft_scene::{load_scene, Light, SceneError};

fn close(a: Vec3, b: Vec3) -> bool {
    a.distance(b) < 1e-5
}

#[test]
fn cube_scene_loads_with_its_quirks_reported() {
    let scene = load_scene(&asset("462/scenes/cube.scene")).expect("cube.scene loads");
    assert_eq!(scene.models.len(), 2);
    assert_eq!(scene.instances.len(), 3);
    assert_eq!(scene.triangle_count(), 12 + 12 + 2);
    assert_eq!(scene.models[0].materials.len(), 5);
    assert_eq!(scene.cameras.len(), 1);
    let cam = &scene.cameras[0];
    assert_eq!(cam.name, "camera0");
    assert_eq!(cam.fov_y, 0.785);
    assert_eq!((cam.near, cam.far), (0.01, 500.0));
    assert_eq!(cam.position, Vec3::new(-4.8, 2.8, -8.8));
    let declared = scene.declared_bounds.expect("boundingbox block");
    assert_eq!(
        (declared.min, declared.max),
        (Vec3::splat(-10.0), Vec3::splat(10.0))
    );
    assert_eq!(scene.bounds.min, Vec3::new(-200.0, 0.0, -200.0));
    assert_eq!(scene.lights.len(), 5);
    let Light::Sun(sun) = &scene.lights[0] else {
        panic!("sun first")
    };
    assert!(close(
        sun.direction,
        Vec3::new(10.0, -5.0, -10.0).normalize()
    ));
    assert_eq!(sun.ambient, Vec3::splat(0.2));
    let Light::Point(p) = &scene.lights[1] else {
        panic!("point second")
    };
    assert_eq!(p.position, Vec3::new(8.0, 2.0, -5.0));
    assert_eq!(
        (
            p.attenuation.constant,
            p.attenuation.linear,
            p.attenuation.quadratic
        ),
        (0.0, 0.0, 0.3)
    );
    assert_eq!(p.radius_source, RadiusSource::Derived);
    assert!((p.radius - 29.2119).abs() < 1e-3, "{}", p.radius);
    let Light::Point(blue) = &scene.lights[3] else {
        panic!("point")
    };
    assert_eq!(blue.velocity, 1.0);
    let Light::Spot(spot) = &scene.lights[4] else {
        panic!("spot last")
    };
    assert_eq!(spot.position, Vec3::new(0.0, 10.0, 0.0));
    assert_eq!(spot.angle, 60.0);
    let swivel = spot.swivel.expect("slerp gives a swivel");
    // A swivelling spotlight starts at the swivel's first direction, whatever `orientation` says.
    assert_eq!(spot.direction, swivel.from);
    assert!(close(
        swivel.from,
        Vec3::new(0.0, -(2.09f32.sin()), 2.09f32.cos())
    ));
    assert!(close(
        swivel.to,
        Vec3::new(0.0, -(1.04f32.sin()), 1.04f32.cos())
    ));
    assert_eq!(
        short_warnings(&scene.warnings),
        vec![
            "cube.scene:5: 'orientation' has 4 values; read as angle (radians) and axis, as the 15-462 reference loader does",
            "cube.scene:12: 'orientation' has 4 values; read as angle (radians) and axis, as the 15-462 reference loader does",
            "cube.scene:55: spotlight 'orientation' is not in the format; read as a rotation of the +Z axis",
            "cube.scene:57: spotlight 'correction' has no documented meaning; ignored",
            "cube.scene:59: spotlight 'slerp' is not in the format; read as a swivel between two angle-axis rotations of +Z, period 4 s",
        ]
    );
}

#[test]
fn dragon_scene_loads() {
    let scene = load_scene(&asset("462/scenes/dragon.scene")).expect("dragon.scene loads");
    assert_eq!(scene.models.len(), 1);
    assert_eq!(scene.models[0].meshes.len(), 1);
    assert_eq!(scene.triangle_count(), 100_000);
    assert_eq!(scene.models[0].meshes[0].positions.len(), 50_000);
    assert!(scene.models[0].materials.is_empty());
    assert_eq!(scene.models[0].meshes[0].material, None);
    assert_eq!(scene.lights.len(), 1);
    assert_eq!(scene.cameras[0].position, Vec3::new(0.0, -0.5, 10.0));
    assert_eq!(
        short_warnings(&scene.warnings),
        vec![
            "dragon.scene:6: 'orientation' has 4 values; read as angle (radians) and axis, as the 15-462 reference loader does",
        ]
    );
}

fn missing(rel: &str) -> (String, String) {
    match load_scene(&asset(rel)) {
        Err(SceneError::MissingFile { at, path }) => (
            format!(
                "{}:{}",
                at.file.file_name().unwrap_or_default().to_string_lossy(),
                at.line.unwrap_or(0)
            ),
            path.file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .into_owned(),
        ),
        other => panic!("{rel}: expected a missing file, got {other:?}"),
    }
}

#[test]
fn scenes_with_missing_models_name_the_file() {
    assert_eq!(
        missing("462/scenes/toy.scene"),
        ("toy.scene:3".into(), "toyplane.obj".into())
    );
    assert_eq!(
        missing("462/scenes/sibenik/sibenik.scene"),
        ("sibenik.scene:3".into(), "sibenik.obj".into())
    );
    assert_eq!(
        missing("462/scenes/shadows/villa/newvilla.scene"),
        ("newvilla.scene:3".into(), "newvilla.obj".into())
    );
    assert_eq!(
        missing("462/scenes/shadows/closedcitadel/mycitadel.scene"),
        ("mycitadel.scene:3".into(), "mycitadel.obj".into())
    );
}

#[test]
fn description_quirks_of_scenes_with_missing_models() {
    use weft_scene::{read_scene_desc, Diagnostics};
    let mut diag = Diagnostics::default();
    let desc =
        read_scene_desc(&asset("462/scenes/sibenik/sibenik.scene"), &mut diag).expect("parses");
    let Light::Sun(sun) = &desc.lights[0] else {
        panic!("sun")
    };
    assert_eq!(sun.color, Vec3::splat(0.7));
    assert_eq!(sun.ambient, Vec3::splat(0.7 * 0.4));
    assert_eq!(
        short_warnings(&diag.warnings),
        vec![
            "sibenik.scene:10: property name 'direction:' has a trailing colon; read as 'direction'",
            "sibenik.scene:11: property name 'color:' has a trailing colon; read as 'color'",
            "sibenik.scene:12: property name 'ambient:' has a trailing colon; read as 'ambient'",
        ]
    );

    let mut diag = Diagnostics::default();
    let desc = read_scene_desc(
        &asset("462/scenes/shadows/closedcitadel/mycitadel.scene"),
        &mut diag,
    )
    .expect("parses");
    let Light::Sun(sun) = &desc.lights[0] else {
        panic!("sun")
    };
    assert_eq!(sun.ambient, Vec3::splat(0.2));
    assert_eq!(
        short_warnings(&diag.warnings),
        vec!["mycitadel.scene:14: 'ambient' has 3 values; read as an RGB ambient colour (the format has one intensity)"]
    );

    let mut diag = Diagnostics::default();
    let desc = read_scene_desc(&asset("462/scenes/toy.scene"), &mut diag).expect("parses");
    assert_eq!(desc.models.len(), 5);
    assert_eq!(desc.lights.len(), 5);
    let Light::Spot(spot) = &desc.lights[4] else {
        panic!("spot")
    };
    assert!(close(spot.direction, Vec3::new(-1.0, 0.0, 0.000_796_3)));
    assert_eq!(desc.cameras[0].far, 200.0);
    assert_eq!(diag.warnings.len(), 5);
}
