//! The ray tracer's scene data on the GPU: a compute pass that declares
//! `derive: [RayTracing()]` casts one camera ray per pixel through the BVH
//! (`shaders/include/trace.glsl`), and every pixel's hit distance matches the
//! CPU traversal (`weft_render::bvh`) of the same ray over the same triangles.
//! Tolerance: distances within 1e-4 relative; at most 0.5% of pixels may
//! disagree on hit or miss, for rays that graze a silhouette edge where the
//! GPU's and the CPU's float rounding can fall on different sides. Measured:
//! printed by the test.

use glam::Vec4;
use weft_gpu::Pixels;
use weft_graph::plan::Extent;
use weft_render::bvh::{scene_triangles, Bvh};
use weft_render::camera::{camera_position, view_projection};
use weft_render::{render, RenderSettings};
use weft_tests::render as common;

const WIDTH: u32 = 64;
const HEIGHT: u32 = 48;

#[test]
fn gpu_bvh_traversal_matches_the_cpu_on_every_pixel_of_the_demo_scene() {
    let scene = weft_scene::load_scene(&common::demo_scene()).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: weft_tests::graph("raycast.ron"),
        extent: Extent {
            width: WIDTH,
            height: HEIGHT,
        },
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).unwrap_or_else(|e| panic!("render: {e}"));
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let output = rendered.report.output.expect("read back");
    let Pixels::RgbaF32(texels) = &output.pixels else {
        panic!("hit is a float image");
    };

    let triangles = scene_triangles(&scene);
    let bvh = Bvh::build(&triangles);
    let camera = &scene.cameras[0];
    let inverse = view_projection(camera, 0.0, WIDTH as f32 / HEIGHT as f32).inverse();
    let eye = camera_position(camera, 0.0);
    let (mut hits, mut disagree, mut worst) = (0, 0, 0.0f32);
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let ndc_x = (x as f32 + 0.5) / WIDTH as f32 * 2.0 - 1.0;
            let ndc_y = (y as f32 + 0.5) / HEIGHT as f32 * 2.0 - 1.0;
            let on_near = inverse * Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
            let dir = (on_near.truncate() / on_near.w - eye).normalize();
            let cpu = bvh.closest_hit(&triangles, eye, dir, 1e30).map(|h| h.0);
            let gpu_t = texels[((y * WIDTH + x) * 4) as usize];
            match (cpu, gpu_t >= 0.0) {
                (Some(t), true) => {
                    hits += 1;
                    let relative = (t - gpu_t).abs() / t.max(1e-3);
                    worst = worst.max(relative);
                    if relative > 1e-4 {
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
        "{hits} of {pixels} rays hit; {disagree} disagree; worst relative distance error {worst:e}"
    );
    assert!(
        hits > pixels / 2,
        "the demo camera looks into the box: {hits} hits"
    );
    assert!(
        disagree * 200 <= pixels,
        "{disagree} of {pixels} pixels disagree"
    );
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
    let diagnostics = weft_render::check_graph_and_shaders(&graph).expect("shaderc");
    let messages: Vec<&str> = diagnostics.iter().map(|d| d.message.as_str()).collect();
    assert!(
        messages.iter().any(|m| m.contains(
            "shader binding `BvhNodes` (set 1 binding 6) is ray-tracing scene data, which the engine feeds only to passes that declare `derive: [RayTracing()]`"
        )),
        "{messages:#?}"
    );
    let declared = weft_graph::load(&path);
    let clean = weft_render::check_graph_and_shaders(&declared).expect("shaderc");
    assert!(clean.iter().all(|d| !d.is_error()), "{clean:#?}");
}
