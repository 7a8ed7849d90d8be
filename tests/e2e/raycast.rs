//! The ray tracer's scene data on the GPU: a compute pass that declares
//! `derive: [RayTracing()]` casts one camera ray per pixel through the BVH
//! (`shaders/include/trace.glsl`), and every pixel's hit distance, triangle,
//! interpolated normal and UV, and material match the CPU traversal
//! (`weft_render::WideBvh`, the walk the shader takes) of the same ray over the same triangles
//! (`SceneGeometry::trace_mesh`, the order the GPU buffers use). The CPU
//! traces the very ray the GPU traced (read back), so only traversal and
//! surface interpolation are compared.
//! Tolerance: distances within 1e-4 relative, normals and UVs within 1e-3,
//! and no pixel may disagree. Measured on both scenes: distances and UVs
//! exactly equal, normals within 9e-8 (printed by the test).

use glam::Vec3;
use weft_gpu::Pixels;
use weft_graph::plan::Extent;
use weft_render::SceneGeometry;
use weft_render::{render, RenderSettings};
use weft_render::{Bvh, WideBvh};
use weft_tests::render as common;

const WIDTH: u32 = 64;
const HEIGHT: u32 = 48;

#[test]
fn gpu_bvh_traversal_matches_the_cpu_on_every_pixel_of_the_demo_scene() {
    traced_pixels_match_the_cpu(&common::demo_scene(), false);
}

#[test]
fn gpu_surfaces_match_the_cpu_on_a_textured_gltf_model() {
    traced_pixels_match_the_cpu(&common::gltf_scene(), true);
}

/// Casts the fixture's rays on `scene` and compares every pixel with the CPU;
/// `textured`: the scene's meshes have UVs, so some must be non-zero.
fn traced_pixels_match_the_cpu(scene: &std::path::Path, textured: bool) {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: weft_tests::graph("raycast.ron"),
        extent: Extent {
            width: WIDTH,
            height: HEIGHT,
        },
        extra_readback: vec!["surface".into(), "ray".into()],
        // The CPU mirror is the software walk's, step for step.
        trace_backend: weft_render::TraceBackend::Software,
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).unwrap_or_else(|e| panic!("render: {e}"));
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let output = rendered.report.output.expect("read back");
    let Pixels::RgbaF32(texels) = &output.pixels else {
        panic!("hit is a float image");
    };
    let image = |name: &str| -> &Vec<f32> {
        let readback = &rendered
            .report
            .readbacks
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name} read back"))
            .1;
        match &readback.pixels {
            Pixels::RgbaF32(texels) => texels,
            _ => panic!("{name} is an RGBA float image"),
        }
    };
    let (surfaces, rays) = (image("surface"), image("ray"));

    let mesh = SceneGeometry::new(&scene).trace_mesh();
    let triangles = &mesh.corners;
    // The shader walks the wide form; its CPU mirror finds the same hits.
    let bvh = WideBvh::collapse(&Bvh::build(triangles), triangles);
    let eye = scene.cameras[0].pose_at(0.0).0;
    let (mut hits, mut disagree) = (0, 0);
    let (mut worst, mut worst_normal, mut worst_uv) = (0.0f32, 0.0f32, 0.0f32);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let at = ((y * WIDTH + x) * 4) as usize;
            let dir = Vec3::new(rays[at], rays[at + 1], rays[at + 2]);
            assert!(dir.is_normalized(), "pixel ({x}, {y}) traced {dir}");
            let cpu = bvh.closest_hit(eye, dir, 1e30);
            let gpu_t = texels[at];
            match (cpu, gpu_t >= 0.0) {
                (Some((t, tri)), true) => {
                    hits += 1;
                    let relative = (t - gpu_t).abs() / t.max(1e-3);
                    worst = worst.max(relative);
                    let (normal, uv) = interpolated(&mesh, tri as usize, eye + t * dir);
                    let gpu_uv = glam::Vec2::new(texels[at + 2], texels[at + 3]);
                    worst_uv = worst_uv.max((uv - gpu_uv).length());
                    let gpu_normal = Vec3::new(surfaces[at], surfaces[at + 1], surfaces[at + 2]);
                    worst_normal = worst_normal.max((normal - gpu_normal).length());
                    let same = relative <= 1e-4
                        && texels[at + 1] == tri as f32
                        && surfaces[at + 3] == mesh.materials[tri as usize] as f32
                        && (normal - gpu_normal).length() <= 1e-3
                        && (uv - gpu_uv).length() <= 1e-3;
                    if !same {
                        disagree += 1;
                    }
                }
                (None, false) => {}
                _ => disagree += 1,
            }
        }
    }
    let pixels = (WIDTH * HEIGHT) as usize;
    eprintln!(
        "{hits} of {pixels} rays hit; {disagree} disagree; worst relative distance error {worst:e}, worst normal error {worst_normal:e}, worst UV error {worst_uv:e}"
    );
    assert!(
        hits > pixels / 8,
        "the camera looks at the scene: {hits} hits"
    );
    assert_eq!(disagree, 0, "{disagree} of {pixels} pixels disagree");
    assert_eq!(
        texels
            .chunks_exact(4)
            .any(|t| t[0] >= 0.0 && (t[2] != 0.0 || t[3] != 0.0)),
        textured,
        "UVs are interpolated where the meshes have them"
    );
}

/// The normal and UV at `p` on triangle `tri`, interpolated from its corners
/// by barycentric weights (the CPU side of `trace_surface`).
fn interpolated(mesh: &weft_render::TraceMesh, tri: usize, p: Vec3) -> (Vec3, glam::Vec2) {
    let [a, b, c] = mesh.corners[tri];
    let (e1, e2, d) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (d20, d21) = (d.dot(e1), d.dot(e2));
    let denom = d00 * d11 - d01 * d01;
    let u = (d11 * d20 - d01 * d21) / denom;
    let v = (d00 * d21 - d01 * d20) / denom;
    let [na, nb, nc] = mesh.normals[tri];
    let n = (1.0 - u - v) * na + u * nb + v * nc;
    let [ta, tb, tc] = mesh.uvs[tri];
    (
        n.try_normalize().unwrap_or((e1.cross(e2)).normalize()),
        (1.0 - u - v) * ta + u * tb + v * tc,
    )
}

#[test]
fn ray_tracing_data_needs_the_provider_declared() {
    let path = weft_tests::graph("raycast.ron");
    let text = std::fs::read_to_string(&path).expect("fixture");
    let undeclared = text.replace("            derive: [RayTracing()],\n", "");
    assert_ne!(undeclared, text);
    let graph = weft_graph::load_with(&path, &|p: &std::path::Path| {
        if p == path {
            Ok(undeclared.clone())
        } else {
            std::fs::read_to_string(p)
        }
    });
    let target = weft_render::ShaderTarget::of(&weft_tests::gpu());
    let diagnostics = weft_render::check_graph_and_shaders(&graph, &target).expect("shaderc");
    let messages: Vec<&str> = diagnostics.iter().map(|d| d.message.as_str()).collect();
    assert!(
        messages.iter().any(|m| m.contains(
            "shader binding `bvh_nodes` (set 1 binding 6) is ray-tracing scene data, which the engine feeds only to passes that declare `derive: [RayTracing()]`"
        )),
        "{messages:#?}"
    );
    let declared = weft_graph::load(&path);
    let clean = weft_render::check_graph_and_shaders(&declared, &target).expect("shaderc");
    assert!(clean.iter().all(|d| !d.is_error()), "{clean:#?}");
}

/// Hardware tracing, asked for (`--backend hardware`) or insisted on
/// (`RayTracing(hardware: true)`), on this binary's device: where it has no
/// ray queries (lavapipe before Mesa 24.1, the system driver tools/setup
/// leaves in place), each is refused at the tracing pass of the graph, naming
/// the missing extensions; where it has them, both render clean.
#[test]
fn hardware_tracing_is_refused_at_the_pass_on_a_device_without_ray_queries() {
    let gpu = weft_tests::gpu();
    let offered = gpu.info().shaders.ray_query;
    let scene =
        weft_scene::load_scene(&common::root().join("scenes/cornell.scene")).expect("loads");
    let path = weft_tests::graph("ray_set.ron");
    let text = std::fs::read_to_string(&path).expect("fixture");
    let insisting = text.replace(
        "derive: [RayTracing()]",
        "derive: [RayTracing(hardware: true)]",
    );
    assert_ne!(insisting, text);
    let graph = weft_graph::load_with(&path, &|p: &std::path::Path| {
        if p == path {
            Ok(insisting.clone())
        } else {
            std::fs::read_to_string(p)
        }
    });
    let prepared = weft_graph::Prepared::new(graph).expect("the graph loads");
    let settings = RenderSettings {
        graph: path.clone(),
        extent: Extent {
            width: 8,
            height: 8,
        },
        ..RenderSettings::default()
    };
    let insisted =
        weft_render::render_with_progress(&gpu, &scene, &prepared, &settings, &mut |_| {});
    let asked = render(
        &gpu,
        &scene,
        &RenderSettings {
            trace_backend: weft_render::TraceBackend::Hardware,
            ..settings.clone()
        },
    );
    let log = gpu.validation();
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    if offered {
        assert!(
            insisted.is_ok() && asked.is_ok(),
            "a device with ray queries renders both"
        );
        return;
    }
    // A pass is located at its name.
    let pass_line = text
        .lines()
        .position(|l| l.trim() == "name: \"cast\",")
        .expect("the fixture's pass")
        + 1;
    let at = format!("{}:{pass_line}:", path.display());
    let insisted = insisted.err().expect("refused").to_string();
    assert!(
        insisted.starts_with(&at)
            && insisted.contains(
                "pass \"cast\" traces with `RayTracing(hardware: true)`, which needs \
                 VK_KHR_acceleration_structure and VK_KHR_ray_query: the device `llvmpipe"
            ),
        "{insisted}"
    );
    let asked = asked.err().expect("refused").to_string();
    assert!(
        asked.starts_with(&at)
            && asked.contains("--backend hardware: pass \"cast\" would trace with ray queries"),
        "{asked}"
    );
}
