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
use weft_render::sanitize::RADIANCE_MAX;
use weft_render::{render, RenderSettings};
use weft_scene::{Light, Scene};

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

/// Outputs of one pixel, one column and one row (issue 19, sizes). The field
/// of view is vertical, so the centre column of a 65x65 image and a 1x65
/// image cast the same rays (pixel centres at NDC x = 0), and the centre
/// pixel, a 1x1 image and the middle pixel of a 65x1 image (which sees 88
/// degrees either side) do too; each must match in every graph with zero
/// validation messages. What may differ: the sun's shadow cascades are
/// fitted to each view's frustum, so their texels could fall differently.
/// Measured: identical (max 0) in all nine cases; held to max <= 1.
#[test]
fn one_pixel_one_column_and_one_row_see_what_the_full_image_sees() {
    let dir = Scratch::new("sizes");
    let scene = weft_scene::load_scene(&write_scene(&dir.0, &lights_of("1 1 1"), BOX_CORNER, GREY))
        .expect("scene loads");
    for graph in GRAPHS {
        let full = render_sized(&scene, graph, [65, 65], &[]);
        let column = render_sized(&scene, graph, [1, 65], &[]);
        let row = render_sized(&scene, graph, [65, 1], &[]);
        let pixel = render_sized(&scene, graph, [1, 1], &[]);
        let full_column = image::imageops::crop_imm(&full, 32, 0, 1, 65).to_image();
        let middle = image::imageops::crop_imm(&row, 32, 0, 1, 1).to_image();
        let full_pixel = image::imageops::crop_imm(&full, 32, 32, 1, 1).to_image();
        for (what, a, b) in [
            ("1x65", &column, &full_column),
            ("65x1", &middle, &full_pixel),
            ("1x1", &pixel, &full_pixel),
        ] {
            let d = agreement(a, b);
            println!("{graph} {what}: mean {:.3}, max {}", d.mean, d.max);
            assert!(d.max <= 1, "{graph} {what}: {d:?}");
        }
    }
}

/// The largest output the device allows (16,384 texels wide on lavapipe, one
/// high) and shadow atlases of 16² and the largest (16,384², 1 GiB of D32):
/// zero validation messages and a finite HDR image in every graph. Against
/// the default 2,048² atlas at 96x64, the 16,384² atlas changes the image
/// only where shadow edges sharpen and the area light's penumbra follows
/// its smaller texels (measured mean 0.161, p99 0, max 79), and the 16²
/// atlas, a 16-texel sun shadow, blurs them (mean 1.01, p99 57, max 104),
/// the same in all three graphs. Held to mean <= 0.25 and <= 2.
#[test]
fn the_largest_output_and_the_smallest_and_largest_shadow_maps_render() {
    let dir = Scratch::new("largest");
    let scene = weft_scene::load_scene(&write_scene(&dir.0, &lights_of("1 1 1"), BOX_CORNER, GREY))
        .expect("scene loads");
    let max = weft_tests::gpu().info().max_image_dimension.min(16_384);
    for graph in GRAPHS {
        let wide = render_sized(&scene, graph, [max, 1], &[]);
        assert_eq!(wide.dimensions(), (max, 1));
        let default = render_sized(&scene, graph, [96, 64], &[]);
        for resolution in [16.0, f64::from(max)] {
            let image = render_sized(
                &scene,
                graph,
                [96, 64],
                &[("shadows.resolution", resolution)],
            );
            let d = agreement(&image, &default);
            println!(
                "{graph} shadow atlas {resolution}: against 2048, mean {:.3}, p99 {}, max {}",
                d.mean, d.p99, d.max
            );
            let bound = if resolution > 2048.0 { 0.25 } else { 2.0 };
            assert!(d.mean <= bound, "{graph} atlas {resolution}: {d:?}");
        }
    }
}

/// Degenerate triangles (issue 19, geometry): a floor, a quad over it with a
/// zero-area triangle (a repeated vertex, twice) and a collinear one, and a
/// normal-mapped quad of one triangle whose three UVs coincide (MikkTSpace's
/// degenerate case) and one with zero-length normals. Every vertex reaches the GPU with a
/// finite, unit, orthogonal tangent frame (within 1e-5); every
/// graph, the path tracer's BVH included, renders them with zero validation
/// messages and a finite image; and the degenerate triangles add nothing to
/// the picture: every raster graph's image is identical (max 0 measured,
/// held to 1) to the same scene without the zero-area triangles.
#[test]
fn degenerate_triangles_load_and_render_as_if_absent() {
    let dir = Scratch::new("degenerate");
    image::RgbaImage::from_pixel(4, 4, image::Rgba([128, 128, 255, 255]))
        .save(dir.0.join("flat.png"))
        .expect("normal map");
    std::fs::write(
        dir.0.join("d.mtl"),
        "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl mapped\nKd 0.8 0.3 0.2\nKs 0.3 0.3 0.3\nNs 30\nnorm flat.png\n",
    )
    .expect("mtl");
    let quad = "v -1 0.5 -1\nv 1 0.5 -1\nv 1 0.5 1\nv -1 0.5 1\n\
                vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 1 0\nvn 0 0 0\n\
                usemtl floor\nf 1/1/1 3/3/1 2/2/1\nf 1/1/1 4/4/1 3/3/1\n";
    let floor = "v -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nf 5//1 7//1 6//1\nf 5//1 8//1 7//1\n";
    // In both scenes: a normal-mapped quad of one triangle whose three UVs
    // coincide and one whose normals are zero.
    let odd_attributes = "v 1.5 0.8 -0.5\nv 2.5 0.8 -0.5\nv 2.5 0.8 0.5\nv 1.5 0.8 0.5\n\
                          usemtl mapped\nf 9/1/1 11/1/1 10/1/1\nf 9/1/2 12/4/2 11/3/2\n";
    // Only in the first: triangles of no area.
    let degenerate = "v -1 0.5 0\nv 0 0.5 0\nv 1 0.5 0\nusemtl mapped\n\
                      f 1/1/1 1/1/1 3/3/1\nf 1/1/1 2/2/1 1/1/1\nf 13/1/1 14/2/1 15/3/1\n";
    let write = |name: &str, extra: &str| {
        let obj = format!("mtllib d.mtl\n{quad}{floor}{odd_attributes}{extra}");
        std::fs::write(dir.0.join(format!("{name}.obj")), obj).expect("obj");
        let path = dir.0.join(format!("{name}.scene"));
        std::fs::write(
            &path,
            format!(
                "model\n{{\n\tfile \"{name}.obj\"\n}}\n{}\
                 camera \"view\"\n{{\n\tposition 0 3 5\n\ttarget 0 0 0\n\tfov_deg 50\n}}\n",
                lights_of("1 1 1")
            ),
        )
        .expect("scene");
        weft_scene::load_scene(&path).expect("scene loads")
    };
    let with = write("with", degenerate);
    let without = write("without", "");
    // The frame each vertex reaches the GPU with: the bake's tangent (zero
    // where there is none) made a frame and packed, as the geometry upload does.
    use weft_scene::tangent_frame::{pack, unpack, TangentFrame};
    for mesh in with.models.iter().flat_map(|m| &m.meshes) {
        for (i, t) in mesh.tangents.iter().enumerate() {
            assert!(t.is_finite(), "{}: vertex {i}: tangent {t}", mesh.name);
            let tangent = Some(*t).filter(|t| *t != glam::Vec4::ZERO);
            let f = unpack(pack(&TangentFrame::new(mesh.normals[i], tangent)));
            let unit = |v: Vec3| v.is_finite() && (v.length() - 1.0).abs() < 1e-5;
            assert!(
                unit(f.normal) && unit(f.tangent) && f.normal.dot(f.tangent).abs() < 1e-5,
                "{}: vertex {i}: {f:?}",
                mesh.name
            );
        }
    }
    for graph in GRAPHS {
        let a = render_sized(&with, graph, [96, 64], &[]);
        let b = render_sized(&without, graph, [96, 64], &[]);
        let d = agreement(&a, &b);
        println!("{graph}: with the degenerate triangles against without: {d:?}");
        assert!(d.max <= 1, "{graph}: {d:?}");
    }
    let settings = RenderSettings {
        graph: common::graph("pathtrace.ron"),
        extent: Extent {
            width: 32,
            height: 24,
        },
        samples: Some(4),
        ..RenderSettings::default()
    };
    let (_, values) = common::render_hdr_validated(&dir.0.join("with.scene"), settings);
    assert!(
        values.iter().all(|v| v.is_finite() && *v >= 0.0),
        "pathtrace: not finite"
    );
    assert!(
        values.iter().any(|v| *v > 0.0),
        "the path tracer sees the scene"
    );
}

/// `obj` (vertices and faces without normals) with its vertices scaled by
/// `scale` and a normal per face, so no vertex normal is smoothed.
fn faceted(obj: &str, scale: Vec3) -> String {
    let mut vertices = Vec::new();
    let mut out = String::new();
    for line in obj.lines() {
        if let Some(v) = line.strip_prefix("v ") {
            let p: Vec<f32> = v
                .split_whitespace()
                .map(|c| c.parse().expect("number"))
                .collect();
            let p = Vec3::new(p[0], p[1], p[2]) * scale;
            vertices.push(p);
            out += &format!("v {} {} {}\n", p.x, p.y, p.z);
        } else if let Some(f) = line.strip_prefix("f ") {
            let i: Vec<usize> = f
                .split_whitespace()
                .map(|c| c.parse().expect("index"))
                .collect();
            let [a, b, c] = [vertices[i[0] - 1], vertices[i[1] - 1], vertices[i[2] - 1]];
            let n = (b - a).cross(c - a).normalize();
            out += &format!(
                "vn {} {} {}\nf {}//-1 {}//-1 {}//-1\n",
                n.x, n.y, n.z, i[0], i[1], i[2]
            );
        } else {
            out += &format!("{line}\n");
        }
    }
    out
}

/// The room of [`write_scene`] placed with `model` statements (a `scale`)
/// from the OBJ `file`, lit by a sun travelling along `sun` (its light does
/// not depend on distance) with ambient, seen by a camera scaled by `s`
/// (position, near and far).
fn placed_room(dir: &Path, file: &str, model: &str, sun: &str, s: f64) -> Scene {
    let path = dir.join(format!(
        "placed-{}.scene",
        dir.read_dir().map_or(0, |d| d.count())
    ));
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"{file}\"\n{model}}}\n\
             sunlight\n{{\n\tdirection {sun}\n\tcolor 1 1 1\n\tambient 0.1 0.1 0.1\n}}\n\
             camera \"view\"\n{{\n\tposition 0 {} {}\n\ttarget 0 0 0\n\tfov_deg 50\n\tnear {}\n\tfar {}\n}}\n",
            3.0 * s,
            5.0 * s,
            0.01 * s,
            100.0 * s
        ),
    )
    .expect("scene");
    weft_scene::load_scene(&path).expect("scene loads")
}

/// Scales (issue 19, geometry), every graph, zero validation messages, finite
/// HDR, 96x64, against the unscaled room, in 8-bit units:
/// - the whole scene scaled by 1e-6, 1e-3, 1e3 and 1e6 renders the image it
///   renders at scale 1 (floats keep their relative precision; what would
///   break is an absolute epsilon or bias in world units). Measured: mean
///   0.007 and max 7 at 1e-6 (one shadow-edge pixel), elsewhere max <= 1;
/// - a model scaled by -1 along X, lit by the mirrored sun, is the image
///   mirrored (winding and normals follow the determinant's sign);
/// - a model scaled by 2 1 0.5 equals the same OBJ with its vertices scaled
///   (the normals follow by the inverse transpose). Both have a normal per
///   face: smoothed vertex normals, averaged over a vertex's faces, are not
///   invariant under non-uniform scale (averaging before or after stretching
///   gives different normals: 26 pixels along the box's edges differ, max
///   19).
///
/// Held to mean <= 0.25 and max <= 8 (the agreement tests' tolerance).
#[test]
fn scales_from_1e_minus_6_to_1e6_mirrored_and_non_uniform_render_what_they_should() {
    let dir = Scratch::new("scales");
    write_scene(&dir.0, "", BOX_CORNER, GREY);
    let obj = std::fs::read_to_string(dir.0.join("room.obj")).expect("obj");
    std::fs::write(dir.0.join("faceted.obj"), faceted(&obj, Vec3::ONE)).expect("obj");
    let stretched = faceted(&obj, Vec3::new(2.0, 1.0, 0.5));
    std::fs::write(dir.0.join("stretched.obj"), stretched).expect("obj");
    let sun = "0.3 -1 0.2";
    let unit = placed_room(&dir.0, "room.obj", "", sun, 1.0);
    let check = |what: &str, graph: &str, image: &RgbaImage, reference: &RgbaImage| {
        let d = agreement(image, reference);
        let differing: Vec<(u32, u32)> = image
            .enumerate_pixels()
            .filter(|(x, y, p)| {
                (0..3).any(|c| p.0[c].abs_diff(reference.get_pixel(*x, *y).0[c]) > 8)
            })
            .map(|(x, y, _)| (x, y))
            .collect();
        println!(
            "{graph} {what}: mean {:.3}, p99 {}, max {} {differing:?}",
            d.mean, d.p99, d.max
        );
        assert!(d.mean <= 0.25 && d.max <= 8, "{graph} {what}: {d:?}");
    };
    for graph in GRAPHS {
        let reference = render_sized(&unit, graph, [96, 64], &[]);
        for s in [1e-6, 1e-3, 1e3, 1e6] {
            let scaled = placed_room(&dir.0, "room.obj", &format!("\tscale {s:e}\n"), sun, s);
            let image = render_sized(&scaled, graph, [96, 64], &[]);
            check(&format!("scale {s:e}"), graph, &image, &reference);
        }
        let mirrored = placed_room(&dir.0, "room.obj", "\tscale -1 1 1\n", "-0.3 -1 0.2", 1.0);
        let image = render_sized(&mirrored, graph, [96, 64], &[]);
        check(
            "scale -1 1 1",
            graph,
            &image::imageops::flip_horizontal(&image),
            &reference,
        );
        let a = render_sized(
            &placed_room(&dir.0, "faceted.obj", "\tscale 2 1 0.5\n", sun, 1.0),
            graph,
            [96, 64],
            &[],
        );
        let b = render_sized(
            &placed_room(&dir.0, "stretched.obj", "", sun, 1.0),
            graph,
            [96, 64],
            &[],
        );
        check("scale 2 1 0.5", graph, &a, &b);
    }
}

/// `scenes/demo.scene` moved by `offset` along (1, 1, 1): every `position`,
/// `target` and camera `key` shifted (a model block without a position gets
/// one), model files made absolute.
fn translated_demo(dir: &Path, offset: f64) -> Scene {
    let repo = weft_tests::repo();
    let text = std::fs::read_to_string(repo.join("scenes/demo.scene")).expect("demo scene");
    let shift = |words: &[&str]| -> String {
        words
            .iter()
            .map(|w| format!("{}", w.parse::<f64>().expect("number") + offset))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut out = String::new();
    let (mut block, mut placed) = (String::new(), false);
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            [name] if *name != "{" && *name != "}" => block = name.to_string(),
            ["position", ..] => placed = true,
            ["}"] if block == "model" && !placed => {
                out += &format!("\tposition {offset} {offset} {offset}\n")
            }
            _ => {}
        }
        if words.as_slice() == ["}"] {
            (block, placed) = (String::new(), false);
        }
        let moved = match words.as_slice() {
            ["position", rest @ ..] | ["target", rest @ ..] if rest.len() == 3 => {
                format!("\t{} {}", words[0], shift(rest))
            }
            ["key", t, a, b, c, d, e, f] => {
                format!("\tkey {t} {} {}", shift(&[a, b, c]), shift(&[d, e, f]))
            }
            ["file", name] => {
                let path = repo.join("scenes").join(name.trim_matches('"'));
                format!("\tfile \"{}\"", path.display())
            }
            _ => line.to_string(),
        };
        out += &moved;
        out.push('\n');
    }
    let path = dir.join(format!("demo-{offset:e}.scene"));
    std::fs::write(&path, out).expect("scene");
    weft_scene::load_scene(&path).expect("scene loads")
}

/// Far from the origin (issue 19): the demo scene moved by 1e3, 1e5 and 1e7
/// along each axis renders, at 160x90 in every graph, the image the demo
/// renders at the origin. The loader reads positions in f64 and stores them
/// relative to an origin by the first camera (`weft_scene::Scene::origin`),
/// so no large coordinate reaches f32, let alone the GPU. Before, the image
/// at 1e5 differed by mean 1.43 (p99 25, max 157) and at 1e7 by mean 31.9
/// (p99 179). Measured now: mean 0.001 to 0.003, p99 0, one pixel on an edge
/// up to 17. Held to mean <= 0.05, p99 0, and at most 4 pixels differing by
/// more than 8 (8-bit units).
#[test]
fn the_demo_far_from_the_origin_renders_the_image_it_renders_at_the_origin() {
    let dir = Scratch::new("far");
    let home = translated_demo(&dir.0, 0.0);
    for graph in GRAPHS {
        let reference = render_sized(&home, graph, [160, 90], &[]);
        for offset in [1e3, 1e5, 1e7] {
            let moved = translated_demo(&dir.0, offset);
            assert!(
                moved.origin.min_element() > offset - 1024.0,
                "{:?}",
                moved.origin
            );
            let image = render_sized(&moved, graph, [160, 90], &[]);
            let d = agreement(&image, &reference);
            let far_off = image
                .enumerate_pixels()
                .filter(|(x, y, p)| {
                    (0..3).any(|c| p.0[c].abs_diff(reference.get_pixel(*x, *y).0[c]) > 8)
                })
                .count();
            println!(
                "{graph} moved by {offset:e}: mean {:.3}, p99 {}, max {}, {far_off} pixels beyond 8",
                d.mean, d.p99, d.max
            );
            assert!(
                d.mean <= 0.05 && d.p99 == 0 && far_off <= 4,
                "{graph} {offset:e}: {d:?}, {far_off}"
            );
        }
    }
}

/// Blinn-Phong at grazing angles with exponents 1 to 1e6 (issue 19): the
/// room's floor (Ks 0.2) with `Ns` 1, 1e3 and 1e6, seen from 1e-3 above it
/// (N·V about 2e-4 at the centre) and from 3 above, lit by the sun, the point
/// light and the area light of [`lights_of`]. Every HDR value finite and in
/// range in every graph (the shaders' `pow(N·H, Ns)` is bounded by 1 for
/// every exponent; what could break is N·H or the half vector at grazing
/// angles), and the graphs agree as the agreement tests require.
#[test]
fn blinn_phong_exponents_from_1_to_1e6_at_grazing_angles_stay_finite() {
    let dir = Scratch::new("grazing");
    for ns in ["1", "1000", "1000000"] {
        for height in ["0.001", "3"] {
            let path = write_scene(&dir.0, &lights_of("1 1 1"), BOX_CORNER, GREY);
            let mtl = std::fs::read_to_string(dir.0.join("room.mtl")).expect("mtl");
            std::fs::write(
                dir.0.join("room.mtl"),
                mtl.replace("Ns 20", &format!("Ns {ns}")),
            )
            .expect("mtl");
            let text = std::fs::read_to_string(&path).expect("scene");
            std::fs::write(
                &path,
                text.replace("position 0 3 5", &format!("position 0 {height} 5")),
            )
            .expect("scene");
            let scene = weft_scene::load_scene(&path).expect("scene loads");
            let images = render_all(&scene, &format!("Ns {ns}, eye at {height}"));
            for (graph, image) in GRAPHS.iter().zip(&images).skip(1) {
                let d = agreement(image, &images[0]);
                println!("Ns {ns}, eye at {height}: {graph} against forward {d:?}");
                assert!(
                    d.mean <= 0.25 && d.p99 <= 1 && d.max <= 8,
                    "Ns {ns}, {height}, {graph}: {d:?}"
                );
            }
        }
    }
}

/// The animated scene at `time` in forward, 160×90, checked as
/// [`render_checked`] checks it.
fn animated_at(scene: &Scene, time: f64) -> RgbaImage {
    let settings = RenderSettings {
        graph: common::graph("forward.ron"),
        extent: Extent {
            width: 160,
            height: 90,
        },
        time,
        ..RenderSettings::default()
    };
    render_checked(scene, settings, &format!("at {time} s"))
}

/// The scene clock is f64 (issue 19, time): at a billion seconds, where f32
/// seconds are 64 apart, two frames 1/60 s apart still see the lights move,
/// as two frames at the start do. In f32 they were the same image.
#[test]
fn frames_a_sixtieth_of_a_second_apart_differ_at_a_billion_seconds() {
    let scene =
        weft_scene::load_scene(&common::root().join("scenes/animation.scene")).expect("loads");
    for start in [0.0, 1e9] {
        let a = animated_at(&scene, start);
        let b = animated_at(&scene, start + 1.0 / 60.0);
        let moved = a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count();
        assert!(
            moved > 0,
            "nothing moved between {start} s and 1/60 s later"
        );
    }
}
