//! Numerical stability at the extremes (issue 19): radiance from 0 to 1e30 and
//! beyond; NaN or infinity injected into one input (a light's colour, a
//! material, a vertex), injected into the loaded scene (the `.scene` format
//! itself refuses `nan` and `inf`); degenerate lights and 100,000 lights;
//! outputs of 1x1, 1xN, Nx1 and the device's largest, shadow maps of 16² and
//! the largest; degenerate triangles; scales from 1e-6 to 1e6, mirrored and
//! non-uniform; the demo scene moved 1e3 to 1e7 units from the origin. Each case renders through forward, deferred
//! and tiled under validation and synchronization validation (zero messages)
//! and reads the linear HDR image back. docs/stability.md records the results.
//!
//! What is asserted, and why:
//! - every HDR value is finite and within [0, 65504] (RGBA16F's range): the
//!   passes clamp their output to 8,192 and at most seven add into one image;
//! - the tonemapped images of the three graphs agree (RGB mean <= 0.25, p99 <=
//!   1, max <= 8 in 8-bit units, the tolerance of the other agreement tests);
//! - an injected NaN or infinity changes nothing beyond the input it was
//!   injected into: the image equals (max 0) the one rendered without that
//!   input, or with the value the sanitizing rule gives it.

use weft_tests::render as common;

use common::agreement;
use glam::Vec3;
use image::RgbaImage;
use std::path::{Path, PathBuf};
use weft_gpu::Pixels;
use weft_graph::plan::Extent;
use weft_render::RADIANCE_MAX;
use weft_render::{render, RenderSettings};
use weft_scene::{Light, Scene};

mod geometry;
mod sizes;

const GRAPHS: [&str; 3] = ["forward.ron", "deferred.ron", "tiled.ron"];

/// A folder removed when the test ends.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("weft-extremes-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("scratch folder");
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// A floor quad and a box (OBJ), a camera, and `lights` (`.scene` blocks);
/// `vertex` replaces the box's first vertex, `kd` the floor's diffuse colour.
fn write_scene(dir: &Path, lights: &str, vertex: &str, kd: &str) -> PathBuf {
    std::fs::write(
        dir.join("room.mtl"),
        format!("newmtl floor\nKd {kd}\nKs 0.2 0.2 0.2\nNs 20\nnewmtl box\nKd 0.7 0.6 0.5\n"),
    )
    .expect("mtl");
    std::fs::write(
        dir.join("room.obj"),
        format!(
            "mtllib room.mtl\n\
             v -3 0 3\nv 3 0 3\nv 3 0 -3\nv -3 0 -3\n\
             {vertex}\nv 0.5 0 0.5\nv 0.5 1 0.5\nv -0.5 1 0.5\n\
             v -0.5 0 -0.5\nv 0.5 0 -0.5\nv 0.5 1 -0.5\nv -0.5 1 -0.5\n\
             usemtl floor\nf 1 2 3\nf 1 3 4\n\
             usemtl box\nf 5 6 7\nf 5 7 8\nf 6 10 11\nf 6 11 7\nf 8 7 11\nf 8 11 12\nf 9 5 8\nf 9 8 12\n"
        ),
    )
    .expect("obj");
    let path = dir.join("room.scene");
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"room.obj\"\n}}\n{lights}\
             camera \"view\"\n{{\n\tposition 0 3 5\n\ttarget 0 0 0\n\tfov_deg 50\n}}\n"
        ),
    )
    .expect("scene");
    path
}

const BOX_CORNER: &str = "v -0.5 0 0.5";
const GREY: &str = "0.5 0.5 0.5";

/// A sun, a point light and a rectangular area light, each of colour `c`.
fn lights_of(c: &str) -> String {
    format!(
        "sunlight\n{{\n\tdirection 0.3 -1 0.2\n\tcolor {c}\n\tambient 0.05 0.05 0.05\n}}\n\
         pointlight\n{{\n\tposition 1 1.5 1\n\tcolor {c}\n\tattenuation 1 0 1\n\tradius 4\n}}\n\
         arealight\n{{\n\tshape rect\n\tsize 0.5 0.5\n\tposition -1 2 0\n\tdirection 0 -1 0\n\temission {c}\n}}\n"
    )
}

/// `scene` through `graph` at 96x64 on a validating context (zero messages
/// asserted): the tonemapped image with bloom off, and the HDR image (RGBA
/// floats) with bloom on, which must stay finite too.
fn render_both(scene: &Scene, graph: &str) -> (RgbaImage, Vec<f32>) {
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = |features: &[&str], readback: &[&str]| RenderSettings {
        graph: common::graph(graph),
        extent: Extent {
            width: 96,
            height: 64,
        },
        features: features.iter().map(|f| f.to_string()).collect(),
        extra_readback: readback.iter().map(|r| r.to_string()).collect(),
        ..RenderSettings::default()
    };
    let plain = render(&gpu, scene, &settings(&["!bloom"], &[])).expect("renders");
    let bloomed = render(&gpu, scene, &settings(&[], &["hdr"])).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new(), "{graph}");
    let image = plain.report.output.expect("readback").to_rgba8();
    let Pixels::RgbaF32(values) = &bloomed.report.readbacks[0].1.pixels else {
        panic!("hdr is a float image");
    };
    (image, values.clone())
}

fn assert_finite_and_bounded(values: &[f32], what: &str) {
    let bad = values
        .iter()
        .filter(|v| !v.is_finite() || **v < 0.0 || **v > 65504.0)
        .count();
    assert_eq!(bad, 0, "{what}: {bad} values outside [0, 65504]");
}

/// Every graph's tonemapped image of `scene`, each HDR image checked finite and bounded.
fn render_all(scene: &Scene, what: &str) -> Vec<RgbaImage> {
    GRAPHS
        .iter()
        .map(|g| {
            let (image, hdr) = render_both(scene, g);
            assert_finite_and_bounded(&hdr, &format!("{g}: {what}"));
            image
        })
        .collect()
}

/// Forward's and tiled's images (`images` in [`GRAPHS`] order) against
/// deferred's: mean <= 0.25 and p99 <= 1 in 8-bit units.
fn assert_agree_with_deferred(images: &[RgbaImage], what: &str) {
    for (g, image) in [(GRAPHS[0], &images[0]), (GRAPHS[2], &images[2])] {
        let a = agreement(image, &images[1]);
        eprintln!("{what}: {g} vs deferred {a:?}");
        assert!(
            a.mean <= 0.25 && a.p99 <= 1,
            "{what}: {g} vs deferred {a:?}"
        );
    }
}

#[test]
fn radiance_from_zero_to_1e30_and_infinity_stays_finite_and_the_graphs_agree() {
    let dir = Scratch::new("radiance");
    for c in [0.0, 1e-30, 1.0, 1e30, f32::MAX, f32::INFINITY] {
        let mut scene =
            weft_scene::load_scene(&write_scene(&dir.0, &lights_of("1 1 1"), BOX_CORNER, GREY))
                .expect("scene loads");
        for light in &mut scene.lights {
            match light {
                Light::Sun(s) => s.color = Vec3::splat(c),
                Light::Point(p) => p.color = Vec3::splat(c),
                Light::Area(a) => a.emission = Vec3::splat(c),
                Light::Spot(s) => s.color = Vec3::splat(c),
            }
        }
        let what = format!("lights {c}");
        assert_agree_with_deferred(&render_all(&scene, &what), &what);
    }
}

#[test]
fn a_nan_or_infinite_input_changes_nothing_beyond_itself() {
    let dir = Scratch::new("nan");
    let base = weft_scene::load_scene(&write_scene(&dir.0, &lights_of("1 1 1"), BOX_CORNER, GREY))
        .expect("scene loads");
    let same = |a: &[RgbaImage], b: &[RgbaImage], what: &str| {
        for ((x, y), g) in a.iter().zip(b).zip(GRAPHS) {
            let d = agreement(x, y);
            assert_eq!(d.max, 0, "{what}: {g} {d:?}");
        }
    };
    let with_point = |color: Vec3, position: Vec3| {
        let mut scene = base.clone();
        let Some(Light::Point(template)) =
            base.lights.iter().find(|l| matches!(l, Light::Point(_)))
        else {
            panic!("the scene has a point light")
        };
        scene.lights.push(Light::Point(weft_scene::PointLight {
            position,
            color,
            ..template.clone()
        }));
        scene
    };
    let reference = render_all(&base, "reference");
    let at = Vec3::new(-1.0, 1.0, 1.0);
    // A light colour channel that is NaN counts as 0; +inf as the largest radiance.
    same(
        &render_all(&with_point(Vec3::new(f32::NAN, 1.0, 1.0), at), "NaN colour"),
        &render_all(&with_point(Vec3::new(0.0, 1.0, 1.0), at), "zero channel"),
        "a NaN colour channel counts as 0",
    );
    same(
        &render_all(
            &with_point(Vec3::new(f32::INFINITY, 1.0, 1.0), at),
            "inf colour",
        ),
        &render_all(
            &with_point(Vec3::new(RADIANCE_MAX, 1.0, 1.0), at),
            "largest channel",
        ),
        "an infinite colour channel counts as the largest radiance",
    );
    // A light at a NaN or infinite position lights nothing.
    for position in [
        Vec3::new(f32::NAN, 1.0, 1.0),
        Vec3::new(0.0, f32::INFINITY, 1.0),
    ] {
        same(
            &render_all(&with_point(Vec3::splat(5.0), position), "lost light"),
            &reference,
            "a light at a non-finite position lights nothing",
        );
    }
    // A material colour of NaN or inf is bounded, not spread.
    let with_diffuse = |kd: Vec3| {
        let mut scene = base.clone();
        let floor = scene.models[0]
            .materials
            .iter_mut()
            .find(|m| m.name == "floor")
            .expect("floor material");
        floor.base_color = kd.extend(1.0);
        scene
    };
    same(
        &render_all(&with_diffuse(Vec3::new(f32::NAN, 0.5, 0.5)), "NaN diffuse"),
        &render_all(&with_diffuse(Vec3::new(0.0, 0.5, 0.5)), "zero diffuse"),
        "a NaN diffuse channel counts as 0",
    );
    // A non-finite vertex drops the triangles that use it, and only those.
    for bad in [f32::NAN, f32::INFINITY] {
        let mut scene = base.clone();
        let mesh = scene.models[0]
            .meshes
            .iter_mut()
            .find(|m| m.positions.contains(&Vec3::new(-0.5, 0.0, 0.5)))
            .expect("the box mesh");
        let corner = mesh
            .positions
            .iter()
            .position(|p| *p == Vec3::new(-0.5, 0.0, 0.5))
            .expect("the box corner");
        mesh.positions[corner].x = bad;
        let images = render_all(&scene, "non-finite vertex");
        for ((a, b), g) in reference.iter().zip(&images).zip(GRAPHS) {
            let changed = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
            // The triangles at that corner cover part of the box: some pixels
            // change, far from all.
            assert!(
                changed > 0 && changed < 96 * 64 / 8,
                "{g}, vertex {bad}: {changed} pixels changed"
            );
        }
    }
}

/// `base` with its lights replaced by `lights`.
fn with_lights(base: &Scene, lights: Vec<Light>) -> Scene {
    let mut scene = base.clone();
    scene.lights = lights;
    scene
}

#[test]
fn degenerate_lights_stay_finite_and_the_graphs_agree() {
    let dir = Scratch::new("lights");
    let base = weft_scene::load_scene(&write_scene(&dir.0, &lights_of("1 1 1"), BOX_CORNER, GREY))
        .expect("scene loads");
    let find = |pick: fn(&Light) -> bool| {
        base.lights
            .iter()
            .find(|l| pick(l))
            .cloned()
            .expect("the scene has the light")
    };
    let sun = find(|l| matches!(l, Light::Sun(_)));
    let Light::Point(point) = find(|l| matches!(l, Light::Point(_))) else {
        unreachable!()
    };
    let Light::Area(area) = find(|l| matches!(l, Light::Area(_))) else {
        unreachable!()
    };
    let spot = |angle: f32| {
        Light::Spot(weft_scene::light::SpotLight {
            position: Vec3::new(0.0, 2.0, 1.0),
            direction: Vec3::NEG_Y,
            color: Vec3::splat(3.0),
            exponent: 1.0,
            angle,
            inner_angle: None,
            length: Some(4.0),
            attenuation: point.attenuation,
            swivel: None,
        })
    };
    let point_with = |f: &dyn Fn(&mut weft_scene::PointLight)| {
        let mut p = point.clone();
        f(&mut p);
        Light::Point(p)
    };
    let area_with = |f: &dyn Fn(&mut weft_scene::AreaLight)| {
        let mut a = area.clone();
        f(&mut a);
        Light::Area(a)
    };
    let cases: Vec<(&str, Vec<Light>)> = vec![
        ("no lights", vec![]),
        (
            "point radius 1e-30",
            vec![sun.clone(), point_with(&|p| p.radius = 1e-30)],
        ),
        (
            "point attenuation 0 0 0",
            vec![
                sun.clone(),
                point_with(&|p| {
                    p.attenuation = weft_scene::Attenuation {
                        constant: 0.0,
                        linear: 0.0,
                        quadratic: 0.0,
                    }
                }),
            ],
        ),
        (
            "point on the floor",
            vec![
                sun.clone(),
                point_with(&|p| p.position = Vec3::new(1.0, 0.0, 1.0)),
            ],
        ),
        (
            "area 1e-30 across",
            vec![
                sun.clone(),
                area_with(&|a| {
                    a.shape = weft_scene::AreaShape::Rect {
                        width: 1e-30,
                        height: 1e-30,
                    }
                }),
            ],
        ),
        (
            "area of zero size",
            vec![
                sun.clone(),
                area_with(&|a| {
                    a.shape = weft_scene::AreaShape::Disc { radius: 0.0 };
                }),
            ],
        ),
        (
            "area on the floor",
            vec![
                sun.clone(),
                area_with(&|a| a.position = Vec3::new(-1.0, 0.0, 0.0)),
            ],
        ),
        ("spot angle 0", vec![sun.clone(), spot(0.0)]),
        ("spot angle 180", vec![sun.clone(), spot(180.0)]),
    ];
    for (what, lights) in cases {
        assert_agree_with_deferred(&render_all(&with_lights(&base, lights), what), what);
    }
}

#[test]
fn a_hundred_thousand_lights_shade_tiled_and_light_volumes_refuse_them_with_a_reason() {
    let dir = Scratch::new("many");
    let base = weft_scene::load_scene(&write_scene(&dir.0, &lights_of("1 1 1"), BOX_CORNER, GREY))
        .expect("scene loads");
    let Some(Light::Point(point)) = base.lights.iter().find(|l| matches!(l, Light::Point(_)))
    else {
        panic!("the scene has a point light")
    };
    let lights: Vec<Light> = (0..100_000)
        .map(|i| {
            let (x, z) = ((i % 316) as f32 / 316.0, (i / 316) as f32 / 316.0);
            Light::Point(weft_scene::PointLight {
                position: Vec3::new(x * 6.0 - 3.0, 0.02, z * 6.0 - 3.0),
                color: Vec3::splat(0.05),
                radius: 0.05,
                ..point.clone()
            })
        })
        .collect();
    let scene = with_lights(&base, lights);
    let (_, hdr) = render_both(&scene, "tiled.ron");
    assert_finite_and_bounded(&hdr, "tiled, 100,000 lights");
    let lit = hdr.chunks_exact(4).filter(|p| p[0] > 0.0).count();
    assert!(lit > 96 * 64 / 4, "the floor is lit: {lit} pixels");
    let gpu = weft_tests::gpu();
    let settings = RenderSettings {
        graph: common::graph("deferred.ron"),
        extent: Extent {
            width: 96,
            height: 64,
        },
        ..RenderSettings::default()
    };
    let err = match render(&gpu, &scene, &settings) {
        Ok(_) => panic!("light volumes accepted 100,000 lights"),
        Err(e) => e.to_string(),
    };
    assert!(
        err.contains("100000 light volumes exceed the 65536 a frame draws this way")
            && err.contains("graphs/tiled.ron"),
        "{err}"
    );
}

/// `scene` rendered with `settings`, bloom off and the HDR image read back,
/// on a validating context (zero messages asserted): the tonemapped image,
/// and the HDR image checked finite and bounded. `what` names the render in
/// failure messages.
fn render_checked(scene: &Scene, settings: RenderSettings, what: &str) -> RgbaImage {
    let settings = RenderSettings {
        features: vec!["!bloom".into()],
        extra_readback: vec!["hdr".into()],
        ..settings
    };
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let rendered = render(&gpu, scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new(), "{what}");
    let Pixels::RgbaF32(values) = &rendered.report.readbacks[0].1.pixels else {
        panic!("hdr is a float image");
    };
    assert_finite_and_bounded(values, what);
    rendered.report.output.expect("readback").to_rgba8()
}

/// `scene` through `graph` at `width` x `height` with the graph parameters
/// `params`, checked as [`render_checked`] checks it.
fn render_sized(
    scene: &Scene,
    graph: &str,
    [width, height]: [u32; 2],
    params: &[(&str, f64)],
) -> RgbaImage {
    let settings = RenderSettings {
        graph: common::graph(graph),
        extent: Extent { width, height },
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), weft_graph::schema::ParamValue::Number(*v)))
            .collect(),
        ..RenderSettings::default()
    };
    render_checked(scene, settings, &format!("{graph} at {width}x{height}"))
}
