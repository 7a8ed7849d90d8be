//! The example scenes in `scenes/` (one per extension, plus the demo) load with the values
//! FORMAT.md promises.

use crate::common;

use common::repo_scene;
use glam::Vec3;
use weft_scene::animation::lights_at;
use weft_scene::light::{AreaShape, RadiusSource};
use weft_scene::{load_scene, Light, SceneReport};

fn close(a: Vec3, b: Vec3) -> bool {
    a.distance(b) < 1e-4
}

#[test]
fn every_example_scene_loads_without_warnings() {
    let dir = repo_scene("");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("scenes/")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".scene") || n.ends_with(".rhai"))
        .collect();
    names.sort();
    assert_eq!(
        names,
        vec![
            "animation.scene",
            "area_lights.scene",
            "cameras.scene",
            "caustics.scene",
            "cornell.scene",
            "cornell_pan.scene",
            "day_cycle.scene",
            "demo.scene",
            "environment.scene",
            "flight_helmet.scene",
            "flocking.rhai",
            "gltf.scene",
            "grid.rhai",
            "include.scene",
            "many_lights.scene",
            "point_radius.scene",
            "sun_shadows.scene",
            "swinging_spots.rhai",
        ]
    );
    for name in names {
        let scene = load_scene(&dir.join(&name)).unwrap_or_else(|e| panic!("{name}: {e}"));
        // Every HDRI in ../shared/assets/hdri has negative texels: the one
        // warning that counts them is expected (venice.exr: 233).
        let expected: &[&str] = if name == "environment.scene" {
            &["233 texel(s) have negative channels; clamped to 0"]
        } else {
            &[]
        };
        let messages: Vec<&str> = scene.warnings.iter().map(|w| w.message.as_str()).collect();
        assert_eq!(messages, expected, "{name}");
    }
}

#[test]
fn demo_scene() {
    let scene = load_scene(&repo_scene("demo.scene")).expect("loads");
    let report = SceneReport::of(&scene);
    assert_eq!(
        (report.models.len(), report.instances, report.meshes),
        (4, 4, 9)
    );
    assert_eq!(report.triangles, 12 + 100_000 + 69_451 + 960);
    assert_eq!(
        (
            report.lights.sun,
            report.lights.spot,
            report.lights.point,
            report.lights.area
        ),
        (1, 1, 3, 1)
    );
    assert_eq!(report.cameras, vec!["front", "closeup", "flythrough"]);
    let flythrough = scene.camera("flythrough").expect("camera");
    assert_eq!(flythrough.path.len(), 3);
    assert_eq!(flythrough.pose_at(3.0).0, Vec3::new(3.0, 2.5, 6.0));
    // The sphere's file has flat normals; `smooth_normals 1` makes every
    // vertex's point nearly along its position from the centre (measured
    // cos >= 0.99943; the file's flat ones go down to 0.9904).
    let sphere = scene
        .models
        .iter()
        .flat_map(|m| &m.meshes)
        .find(|m| m.triangle_count() == 960)
        .expect("the sphere");
    let worst = sphere
        .positions
        .iter()
        .zip(&sphere.normals)
        .map(|(p, n)| p.normalize().dot(*n))
        .fold(1.0f32, f32::min);
    assert!(worst >= 0.999, "smoothed normals {worst} off radial");
}

#[test]
fn cameras_scene() {
    let scene = load_scene(&repo_scene("cameras.scene")).expect("loads");
    let names: Vec<&str> = scene.cameras.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, vec!["front", "above", "legacy", "orbit"]);
    let front = scene.camera("front").expect("front");
    assert!(close(front.forward(), Vec3::NEG_Z));
    assert_eq!((front.near, front.far), (0.1, 20.0));
    assert!((front.fov_y - 40f32.to_radians()).abs() < 1e-6);
    let above = scene.camera("above").expect("above");
    assert!(close(
        above.forward(),
        Vec3::new(0.0, -0.5, -(3f32.sqrt() / 2.0))
    ));
    assert_eq!(above.fov_y, 0.785);
    let legacy = scene.camera("legacy").expect("legacy");
    assert_eq!((legacy.near, legacy.far), (0.01, 200.0));
    assert!(close(
        legacy.forward(),
        Vec3::new(0.0, 0.1f32.sin(), -(0.1f32.cos()))
    ));
    let orbit = scene.camera("orbit").expect("orbit");
    assert_eq!(orbit.pose_at(1.0).0, Vec3::new(0.0, 1.0, 3.0));
    let (p, q) = orbit.pose_at(4.0);
    assert_eq!(p, Vec3::new(-3.0, 2.0, -0.5));
    assert!(close(
        q * Vec3::NEG_Z,
        (Vec3::new(0.0, 1.0, 0.0) - p).normalize()
    ));
}

#[test]
fn point_radius_scene() {
    let scene = load_scene(&repo_scene("point_radius.scene")).expect("loads");
    let radii: Vec<(f32, RadiusSource)> = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Point(p) => (p.radius, p.radius_source),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(radii[0], (2.0, RadiusSource::Given));
    assert!((radii[1].0 - 512f32.sqrt()).abs() < 1e-3, "{radii:?}");
    assert!((radii[2].0 - 19f32.sqrt() / 2.0).abs() < 1e-3, "{radii:?}");
    let summary = SceneReport::of(&scene).point_light_radius.expect("summary");
    assert_eq!((summary.given, summary.derived, summary.range), (1, 2, 0));
    // Light 2's radius exceeds the diagonal (2.88): nothing cut. The others cut a share.
    assert!(
        summary.max_energy_cut > 0.5 && summary.max_energy_cut < 0.7,
        "{summary:?}"
    );
}

#[test]
fn area_lights_scene() {
    let scene = load_scene(&repo_scene("area_lights.scene")).expect("loads");
    let areas: Vec<_> = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Area(a) => a.clone(),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(
        areas[0].shape,
        AreaShape::Rect {
            width: 0.47,
            height: 0.38
        }
    );
    assert!(close(areas[0].normal(), Vec3::NEG_Y));
    assert_eq!(areas[0].emission, Vec3::new(17.0, 12.0, 4.0));
    assert_eq!(areas[1].shape, AreaShape::Disc { radius: 0.25 });
    assert!(close(areas[1].normal(), Vec3::Z));
    assert!(areas[1].two_sided && !areas[0].two_sided);
    assert!((areas[1].area() - std::f32::consts::PI * 0.0625).abs() < 1e-6);
    assert!(close(areas[2].normal(), Vec3::NEG_Y));
}

#[test]
fn animation_scene() {
    let scene = load_scene(&repo_scene("animation.scene")).expect("loads");
    let at0 = lights_at(&scene.lights, 0.0, 1);
    assert_eq!(at0, scene.lights);
    let later = lights_at(&scene.lights, 3.0, 1);
    assert_eq!(later, lights_at(&scene.lights, 3.0, 1));
    let Light::Sun(sun) = &later[0] else {
        panic!("sun")
    };
    // 45 degrees about +Y: (1, -1, 0)/sqrt2 turns to (cos45, -1, -sin45)/sqrt2.
    let h = std::f32::consts::FRAC_1_SQRT_2;
    assert!(
        close(sun.direction, Vec3::new(h * h, -h, -h * h)),
        "{}",
        sun.direction
    );
    let Light::Spot(spot) = &later[1] else {
        panic!("spot")
    };
    assert!(
        close(spot.direction, Vec3::new(1.0, -2.0, 0.0).normalize()),
        "{}",
        spot.direction
    );
    let Light::Point(moving) = &later[2] else {
        panic!("point")
    };
    let Light::Point(start) = &scene.lights[2] else {
        panic!("point")
    };
    assert_eq!(moving.position.y, start.position.y);
    assert_ne!(moving.position, start.position);
    // It stays on a circle of radius 2 through its start: distance to the start <= 4.
    assert!(moving.position.distance(start.position) <= 4.0 + 1e-4);
}

#[test]
fn include_and_generator_scenes() {
    let scene = load_scene(&repo_scene("include.scene")).expect("loads");
    let kinds: Vec<&str> = scene
        .lights
        .iter()
        .map(|l| match l {
            Light::Sun(_) => "sun",
            Light::Spot(_) => "spot",
            Light::Point(_) => "point",
            Light::Area(_) => "area",
        })
        .collect();
    assert_eq!(kinds, vec!["point", "spot", "sun"]);

    let scene = load_scene(&repo_scene("many_lights.scene")).expect("loads");
    assert_eq!(scene.lights.len(), 10_000);
    for light in &scene.lights {
        let Light::Point(p) = light else {
            panic!("point")
        };
        assert!(
            p.position.cmpge(Vec3::new(-20.0, 0.2, -20.0)).all()
                && p.position.cmplt(Vec3::new(20.0, 2.0, 20.0)).all()
        );
        assert!((4.0..8.0).contains(&p.radius) && p.radius_source == RadiusSource::Given);
        assert!((0.0..0.5).contains(&p.velocity));
    }
    let again = load_scene(&repo_scene("many_lights.scene")).expect("loads");
    assert_eq!(again.lights, scene.lights);
}

#[test]
fn gltf_scene_moves_gltf_lights_with_the_model() {
    let scene = load_scene(&repo_scene("gltf.scene")).expect("loads");
    assert_eq!(
        scene
            .cameras
            .iter()
            .map(|c| c.name.as_str())
            .collect::<Vec<_>>(),
        vec!["Camera"]
    );
    assert_eq!(scene.lights.len(), 3);
    assert_eq!(scene.instances[1].bounds.min.y, 1.5 - 0.900_974_1 * 0.8);
}
