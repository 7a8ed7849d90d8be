//! Shading measured in linear HDR against the CPU reference: a glTF
//! metallic-roughness quad under a sun (factors, a metallicRoughness texture read
//! as B = metallic, G = roughness, a normal map with a scale) equals
//! `weft_testkit::brdf::cook_torrance`
//! within 0.2% (measured at most 0.086%: half-float storage), and a diffuse quad
//! under a rectangle and a two-sided disc area light equals a brute-force
//! integral: analytically (the default, `area_samples` 0: exact for the
//! rectangle, the disc a 12-gon of its area) within 0.5%, and by 8 x 8
//! quadrature (`area_samples` 8) within 1% and the CPU copy of that quadrature
//! within 0.2%, through forward and deferred, with zero validation messages.

use glam::Vec3;
use std::f32::consts::PI;
use std::path::{Path, PathBuf};
use weft_graph::plan::Extent;
use weft_render::area_shape;
use weft_render::RenderSettings;
use weft_scene::Light;
use weft_testkit::brdf::{cook_torrance, AreaGeometry, AreaIrradiance};
use weft_tests::gltf::{write_gltf_quad, Texel};

/// Image size: odd, so the centre pixel looks straight down the camera axis.
const SIZE: u32 = 33;
/// The camera sits at (0, 0, CAMERA_Z) looking at the origin with this vertical field of view.
const CAMERA_Z: f32 = 3.0;
const FOV_DEG: f32 = 40.0;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-shading-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// The camera block every test scene uses.
fn camera_block() -> String {
    format!("camera \"front\"\n{{\n\tposition 0 0 {CAMERA_Z}\n\ttarget 0 0 0\n\tfov_deg {FOV_DEG}\n}}\n")
}

/// Renders `scene` through `graph` with validation and returns the HDR image as RGBA floats.
fn render_hdr(scene: &Path, graph: &str) -> Vec<f32> {
    render_hdr_with(scene, graph, &[])
}

/// [`render_hdr`] with graph parameters set.
fn render_hdr_with(scene: &Path, graph: &str, params: &[(&str, f64)]) -> Vec<f32> {
    let settings = RenderSettings {
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), weft_graph::schema::ParamValue::Number(*v)))
            .collect(),
        graph: weft_tests::shipped(graph),
        extent: Extent {
            width: SIZE,
            height: SIZE,
        },
        features: vec!["!bloom".into()],
        ..RenderSettings::default()
    };
    weft_tests::render::render_hdr_validated(scene, settings).1
}

fn pixel(values: &[f32], x: u32, y: u32) -> Vec3 {
    let at = ((y * SIZE + x) * 4) as usize;
    Vec3::new(values[at], values[at + 1], values[at + 2])
}

/// Where the centre of pixel `x` on the middle row hits the plane z = 0.
fn on_plane(x: u32) -> Vec3 {
    on_plane_at(x, SIZE / 2)
}

/// Where the centre of pixel (`x`, `y`) hits the plane z = 0 (row 0 at the top, +Y).
fn on_plane_at(x: u32, y: u32) -> Vec3 {
    let ndc = |i: u32| (i as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0;
    let half = CAMERA_Z * (FOV_DEG / 2.0).to_radians().tan();
    Vec3::new(ndc(x) * half, -ndc(y) * half, 0.0)
}

fn assert_relative(got: Vec3, want: Vec3, tolerance: f32, what: &str) {
    let error = ((got - want).abs() / want.max(Vec3::splat(1e-6))).max_element();
    eprintln!("{what}: relative error {error:.5}");
    assert!(
        error <= tolerance,
        "{what}: got {got}, want {want} (relative error {error})"
    );
}

/// 8-bit rounding, as the shaders apply to metallic and roughness.
fn unorm8(v: f32) -> f32 {
    (v * 255.0).round() / 255.0
}

#[test]
fn gltf_metallic_roughness_matches_the_cpu_brdf_in_both_paths() {
    let sun = Vec3::new(-0.6, -0.4, -0.7); // L = (0.6, 0.4, 0.7), normalised
    let base = Vec3::new(0.8, 0.5, 0.2);
    let mr = |rgb| Texel {
        rgb,
        normal_scale: None,
    };
    // A normal-map texel bending the normal towards +X (u) and +Y (up in the image),
    // at half strength: the expected normal in world space (tangent +X, bitangent +Y).
    let bent = Texel {
        rgb: [204, 160, 230],
        normal_scale: Some(0.5),
    };
    let decode = |c: u8| f32::from(c) / 255.0 * 2.0 - 1.0;
    let bent_normal = Vec3::new(0.5 * decode(204), 0.5 * decode(160), decode(230)).normalize();
    // (name, pbrMetallicRoughness factors, textures, metallic, roughness, normal).
    let cases = [
        (
            "factors",
            r#""baseColorFactor": [0.8, 0.5, 0.2, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6"#,
            vec![],
            0.0,
            unorm8(0.6),
            Vec3::Z,
        ),
        (
            "textured",
            r#""baseColorFactor": [0.8, 0.5, 0.2, 1.0], "metallicFactor": 1.0, "roughnessFactor": 1.0"#,
            vec![mr([0u8, 100, 255])],
            1.0,
            100.0 / 255.0,
            Vec3::Z,
        ),
        (
            "textured_scaled",
            r#""baseColorFactor": [0.8, 0.5, 0.2, 1.0], "metallicFactor": 0.5, "roughnessFactor": 0.5"#,
            vec![mr([0u8, 200, 102])],
            unorm8(0.5 * 0.4),
            unorm8(0.5 * 200.0 / 255.0),
            Vec3::Z,
        ),
        (
            "normal_mapped",
            r#""baseColorFactor": [0.8, 0.5, 0.2, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6"#,
            vec![bent],
            0.0,
            unorm8(0.6),
            bent_normal,
        ),
    ];
    for (name, factors, textures, metallic, roughness, normal) in cases {
        let dir = temp_dir(name);
        write_gltf_quad(&dir, factors, &textures);
        std::fs::write(
            dir.join("quad.scene"),
            format!(
                "model\n{{\n\tfile \"quad.gltf\"\n}}\nsunlight\n{{\n\tdirection {} {} {}\n\tcolor 2 2 2\n\tambient 0\n}}\n{}",
                sun.x,
                sun.y,
                sun.z,
                camera_block()
            ),
        )
        .expect("scene");
        let l = -sun.normalize();
        for graph in ["forward.ron", "deferred.ron"] {
            let hdr = render_hdr(&dir.join("quad.scene"), graph);
            for x in [4, 16, 28] {
                let p = on_plane(x);
                let v = (Vec3::Z * CAMERA_Z - p).normalize();
                // A sun of colour C gives irradiance pi C (scenes/FORMAT.md, "Units").
                let want = 2.0 * PI * cook_torrance(base, metallic, roughness, normal, v, l);
                let got = pixel(&hdr, x, SIZE / 2);
                assert_relative(got, want, 0.002, &format!("{name} {graph} pixel {x}"));
            }
        }
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}

#[test]
fn area_lights_match_a_brute_force_integral_in_both_paths() {
    let dir = temp_dir("area");
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -2 -2 0\nv 2 -2 0\nv 2 2 0\nv -2 2 0\nvn 0 0 1\nusemtl white\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("obj");
    std::fs::write(dir.join("quad.mtl"), "newmtl white\nKd 1 1 1\nKs 0 0 0\n").expect("mtl");
    // A 1 x 0.5 panel facing the quad, and a disc facing away from it that glows on
    // both faces; the camera sees their panels in front of parts of the quad.
    std::fs::write(
        dir.join("quad.scene"),
        format!(
            "model\n{{\n\tfile \"quad.obj\"\n}}\n\
             arealight\n{{\n\tshape rect\n\tsize 1 0.5\n\tposition 0.3 0 1\n\tdirection 0 0 -1\n\temission 2 1 0.5\n}}\n\
             arealight\n{{\n\tshape disc\n\tradius 0.3\n\tposition -0.5 0.2 0.6\n\tdirection 0 0 1\n\temission 0 1 3\n\ttwo_sided 1\n}}\n{}",
            camera_block()
        ),
    )
    .expect("scene");
    let scene = weft_scene::load_scene(&dir.join("quad.scene")).expect("scene loads");
    let lights: Vec<(AreaGeometry, Vec3)> = scene
        .lights
        .iter()
        .filter_map(|l| match l {
            Light::Area(a) => Some((area_shape(a).expect("usable"), a.emission)),
            _ => None,
        })
        .collect();
    assert_eq!(lights.len(), 2);
    for graph in ["forward.ron", "deferred.ron"] {
        let analytic = render_hdr(&dir.join("quad.scene"), graph);
        let quadrature = render_hdr_with(&dir.join("quad.scene"), graph, &[("area_samples", 8.0)]);
        // Row 29 (y = -0.86 on the quad) passes below both lights' panels, which
        // the camera sees in front of the middle rows (scenes/FORMAT.md "Units").
        const ROW: u32 = 29;
        for x in [2, 10, 16, 22, 30] {
            let p = on_plane_at(x, ROW);
            // A white Lambert surface shows the irradiance over pi.
            let estimate: Vec3 = lights
                .iter()
                .map(|(shape, emission)| *emission * shape.irradiance(p, Vec3::Z) / PI)
                .sum();
            let reference: Vec3 = lights
                .iter()
                .map(|(shape, emission)| {
                    *emission * shape.irradiance_brute_force(p, Vec3::Z, 1000) as f32 / PI
                })
                .sum();
            assert_relative(
                pixel(&analytic, x, ROW),
                reference,
                0.005,
                &format!("{graph} pixel {x}, analytic, vs brute force"),
            );
            let got = pixel(&quadrature, x, ROW);
            assert_relative(
                got,
                estimate,
                0.002,
                &format!("{graph} pixel {x}, 8 x 8 quadrature, vs its CPU copy"),
            );
            assert_relative(
                got,
                reference,
                0.01,
                &format!("{graph} pixel {x}, 8 x 8 quadrature, vs brute force"),
            );
        }
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
