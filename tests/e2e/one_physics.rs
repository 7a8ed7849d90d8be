//! One physics for raster graphs and the path tracer (scenes/FORMAT.md,
//! "Units"): an emissive quad lights a floor as a rectangle area light of the
//! same shape and radiance does, in every raster graph; and a light lying in
//! the plane of the surface it would light gives that surface exactly nothing,
//! in every raster graph and in the path tracer, however bright it is.

use glam::Vec3;
use std::path::{Path, PathBuf};
use weft_tests::TempDir;

const SIZE: u32 = 48;

/// The HDR image of `scene` through shipped graph `graph` (validated, bloom
/// off), RGB per pixel.
fn render(scene: &Path, graph: &str, samples: Option<u64>, params: &[(&str, f64)]) -> Vec<Vec3> {
    render_with(scene, graph, samples, params, &["!bloom"])
}

/// Forward without shadows (and bloom): every light unoccluded.
fn unshadowed(scene: &Path) -> Vec<Vec3> {
    render_with(
        scene,
        "forward.ron",
        None,
        &[],
        &["!bloom", "!shadow_casters"],
    )
}

/// As `render`, with `features`.
fn render_with(
    scene: &Path,
    graph: &str,
    samples: Option<u64>,
    params: &[(&str, f64)],
    features: &[&str],
) -> Vec<Vec3> {
    let settings = weft_tests::render::square_settings(graph, SIZE, samples, params, features);
    let (_, values) = weft_tests::render::render_hdr_validated(scene, settings);
    values
        .chunks(4)
        .map(|p| Vec3::new(p[0], p[1], p[2]))
        .collect()
}

/// A 6 x 6 white Lambert floor at y = 0 (Kd 0.8), the camera above it looking
/// down, `extra_obj` appended to the floor's OBJ (with material `glow`,
/// emitting `Ke 3 2 1`) and `lights` as `.scene` blocks.
fn floor_scene(dir: &Path, extra_obj: &str, lights: &str) -> PathBuf {
    std::fs::write(
        dir.join("floor.obj"),
        format!(
            "mtllib floor.mtl\nv -3 0 -3\nv 3 0 -3\nv 3 0 3\nv -3 0 3\nvn 0 1 0\nusemtl white\n\
             f 1//1 3//1 2//1\nf 1//1 4//1 3//1\n{extra_obj}"
        ),
    )
    .expect("obj");
    std::fs::write(
        dir.join("floor.mtl"),
        "newmtl white\nKd 0.8 0.8 0.8\nKs 0 0 0\nnewmtl glow\nKd 0 0 0\nKs 0 0 0\nKe 3 2 1\n",
    )
    .expect("mtl");
    let scene = dir.join("floor.scene");
    std::fs::write(
        &scene,
        format!(
            "model\n{{\n\tfile \"floor.obj\"\n}}\n{lights}\
             camera\n{{\n\tposition 0 4 0.01\n\ttarget 0 0 0\n\tfov_deg 60\n}}\n"
        ),
    )
    .expect("scene");
    scene
}

fn mean(image: &[Vec3]) -> Vec3 {
    image.iter().copied().sum::<Vec3>() / image.len() as f32
}

/// The mean of the floor around the panel of the emissive-quad tests (more
/// than 9 pixels from the centre either way): the panel itself shows
/// differently as a mesh and as a light.
fn floor_around_panel(image: &[Vec3]) -> Vec3 {
    let around: Vec<Vec3> = (0..SIZE * SIZE)
        .filter(|i| (i % SIZE).abs_diff(SIZE / 2) > 9 || (i / SIZE).abs_diff(SIZE / 2) > 9)
        .map(|i| image[i as usize])
        .collect();
    mean(&around)
}

#[test]
fn an_emissive_quad_lights_the_floor_as_the_same_rect_area_light() {
    // A 1 x 0.6 panel at height 1, emitting (3, 2, 1) downwards: once as two
    // emissive triangles, once as an `arealight`, seen from above.
    let quad = TempDir::new("emissive-quad");
    let quad_scene = floor_scene(
        &quad.0,
        "v -0.5 1 -0.3\nv 0.5 1 -0.3\nv 0.5 1 0.3\nv -0.5 1 0.3\nvn 0 -1 0\nusemtl glow\n\
         f 5//2 6//2 7//2\nf 5//2 7//2 8//2\n",
        "",
    );
    let rect = TempDir::new("rect-light");
    let rect_scene = floor_scene(
        &rect.0,
        "",
        "arealight\n{\n\tshape rect\n\tsize 1 0.6\n\tposition 0 1 0\n\tdirection 0 -1 0\n\temission 3 2 1\n}\n",
    );
    // The panel (about 7 x 4 pixels each way of the centre) shows differently:
    // an emissive mesh's back is culled, an area light's back is drawn black.
    // The floor around it is compared.
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        let from_quad = floor_around_panel(&render(&quad_scene, graph, None, &[]));
        let from_rect = floor_around_panel(&render(&rect_scene, graph, None, &[]));
        assert!(
            from_rect.min_element() > 0.01,
            "{graph}: the floor is lit: {from_rect}"
        );
        let ratio = from_quad / from_rect;
        assert!(
            (ratio - Vec3::ONE).abs().max_element() < 0.01,
            "{graph}: emissive quad {from_quad} vs rect light {from_rect}"
        );
    }
}

#[test]
fn a_light_in_the_plane_of_a_surface_gives_it_nothing_in_every_graph() {
    // A rectangle light of radiance 1e30 lying in the floor's plane, facing up:
    // every floor point is in its plane, so its cosine is 0 there. The camera
    // sees the light's panel (clamped) and, around it, a floor that must be
    // exactly black; rounding once lit it with sparkles of 1e18.
    let dir = TempDir::new("coplanar-light");
    let scene = floor_scene(
        &dir.0,
        "",
        "arealight\n{\n\tshape rect\n\tsize 1 1\n\tposition 0 0 0\n\tdirection 0 1 0\n\temission 1e30 1e30 1e30\n}\n",
    );
    // The panel covers the middle; pixels 8 or more from the centre column and
    // row on both axes see only floor (the panel spans about 7 pixels each way).
    let floor_only = |x: u32, y: u32| x.abs_diff(SIZE / 2) >= 8 || y.abs_diff(SIZE / 2) >= 8;
    for (graph, samples, params) in [
        ("forward.ron", None, vec![]),
        ("deferred.ron", None, vec![]),
        ("tiled.ron", None, vec![]),
        ("forward.ron", None, vec![("area_samples", 8.0)]),
        ("pathtrace.ron", Some(16), vec![("max_depth", 2.0)]),
    ] {
        let image = render(&scene, graph, samples, &params);
        let lit: Vec<(u32, u32, Vec3)> = (0..SIZE * SIZE)
            .map(|i| (i % SIZE, i / SIZE, image[i as usize]))
            .filter(|&(x, y, c)| floor_only(x, y) && c != Vec3::ZERO)
            .collect();
        assert!(
            lit.is_empty(),
            "{graph} {params:?}: {} floor pixels lit, e.g. {:?}",
            lit.len(),
            lit.first()
        );
        // The panel itself is seen, bright, in every graph.
        let centre = image[(SIZE / 2 * SIZE + SIZE / 2) as usize];
        assert!(
            centre.min_element() > 1000.0,
            "{graph}: the panel shows {centre}"
        );
    }
}

#[test]
fn area_lights_cast_soft_shadows_as_the_tracer_sees_them() {
    // The 1 x 0.6 emissive panel at height 1 over the floor, and a 0.4 x 0.4
    // square blocker at height 0.4 off to the side: its shadow falls further
    // out, soft (the panel is larger than the blocker's distance to the
    // floor allows a hard edge). Raster graphs shadow area lights with
    // PCSS in a view from the light's centre; the path tracer traces the
    // visibility of every point of the panel. Compared on the band of floor
    // beside the blocker where the shadow falls, which the camera above sees.
    let dir = TempDir::new("area-shadow");
    let scene = floor_scene(
        &dir.0,
        "v -0.5 1 -0.3\nv 0.5 1 -0.3\nv 0.5 1 0.3\nv -0.5 1 0.3\nvn 0 -1 0\nusemtl glow\n\
         f 5//2 6//2 7//2\nf 5//2 7//2 8//2\n\
         v 0.6 0.4 -0.2\nv 1.0 0.4 -0.2\nv 1.0 0.4 0.2\nv 0.6 0.4 0.2\nusemtl white\n\
         f 9//1 11//1 10//1\nf 9//1 12//1 11//1\n",
        "",
    );
    // Image x grows with world x (2.31 world units either side at the floor
    // plane); the shadow spans about x 1.1 to 2.3 and |z| < 0.6.
    let band = |image: &[Vec3]| -> Vec<f32> {
        let (mut values, half) = (Vec::new(), SIZE as f32 / 2.0);
        for y in 0..SIZE {
            for x in 0..SIZE {
                let world =
                    (Vec3::new(x as f32 + 0.5 - half, 0.0, y as f32 + 0.5 - half)) / half * 2.31;
                if (1.15..2.2).contains(&world.x) && world.z.abs() < 0.5 {
                    values.push(image[(y * SIZE + x) as usize].x);
                }
            }
        }
        values
    };
    let reference = band(&render(
        &scene,
        "pathtrace.ron",
        Some(512),
        &[("max_depth", 2.0)],
    ));
    // Relative L1 error over the band, and the band's mean over the reference's.
    let error = |image: &[f32]| {
        image
            .iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .sum::<f32>()
            / reference.iter().sum::<f32>()
    };
    let ratio = |image: &[f32]| image.iter().sum::<f32>() / reference.iter().sum::<f32>();
    let unshadowed = band(&unshadowed(&scene));
    println!(
        "unshadowed: error {:.3}, ratio {:.3}",
        error(&unshadowed),
        ratio(&unshadowed)
    );
    assert!(
        error(&unshadowed) > 0.5,
        "the blocker's shadow is there to find"
    );
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        let shadowed = band(&render(&scene, graph, None, &[]));
        println!(
            "{graph}: error {:.3}, ratio {:.3}",
            error(&shadowed),
            ratio(&shadowed)
        );
        assert!(
            error(&shadowed) < 0.16 && (ratio(&shadowed) - 1.0).abs() < 0.08,
            "{graph}: error {}, ratio {}",
            error(&shadowed),
            ratio(&shadowed)
        );
    }
}

/// An `arealight` panel under an emissive quad blocks the quad's light, in
/// the raster graph's shadow views as in the path tracer (whose panels are
/// opaque to every ray): a 1 x 1 quad emitting (3, 2, 1) at height 2, a
/// 1.2 x 1.2 panel emitting (1, 1, 1) downwards at height 1 beneath it. On
/// the floor around them, which the panel half hides from the quad, forward
/// is within 6% of the tracer's direct light (measured 1.035); without
/// shadows it counts all of the quad's light (measured 1.265), as it did
/// before panels were casters.
#[test]
fn an_area_light_panel_blocks_the_light_behind_it() {
    let dir = TempDir::new("panel-occludes");
    let scene = floor_scene(
        &dir.0,
        "v -0.5 2 -0.5\nv 0.5 2 -0.5\nv 0.5 2 0.5\nv -0.5 2 0.5\nvn 0 -1 0\nusemtl glow\n\
         f 5//2 6//2 7//2\nf 5//2 7//2 8//2\n",
        "arealight\n{\n\tshape rect\n\tsize 1.2 1.2\n\tposition 0 1 0\n\tdirection 0 -1 0\n\temission 1 1 1\n}\n",
    );
    // The floor around the panel, 0.9 to 1.6 from the centre, which the
    // camera above sees (2.31 units either side) and the panel half hides
    // from the quad.
    let under = |image: &[Vec3]| -> f32 {
        let half = SIZE as f32 / 2.0;
        let (mut sum, mut count) = (0.0, 0.0);
        for y in 0..SIZE {
            for x in 0..SIZE {
                let (wx, wz) = (
                    (x as f32 + 0.5 - half) / half * 2.31,
                    (y as f32 + 0.5 - half) / half * 2.31,
                );
                if (0.9..1.6).contains(&wx.abs().max(wz.abs())) {
                    sum += image[(y * SIZE + x) as usize].y;
                    count += 1.0;
                }
            }
        }
        sum / count
    };
    let traced = under(&render(
        &scene,
        "pathtrace.ron",
        Some(256),
        &[("max_depth", 2.0)],
    ));
    let raster = under(&render(&scene, "forward.ron", None, &[]));
    let (ratio, unshadowed_ratio) = (raster / traced, under(&unshadowed(&scene)) / traced);
    println!("forward over the tracer around the panel: {ratio:.3}; without shadows {unshadowed_ratio:.3}");
    assert!(
        (ratio - 1.0).abs() < 0.06,
        "forward {ratio} of the tracer's"
    );
    assert!(unshadowed_ratio > 1.2, "without shadows {unshadowed_ratio}");
}

#[test]
fn an_emissive_texture_lights_the_floor_with_its_mean_in_every_raster_graph_and_the_tracer() {
    // The panel of the first test, its emission `Ke 3 2 1` times a uniform
    // sRGB texture of (128, 192, 160), against the same panel emitting the
    // texture's linear value times Ke untextured.
    let textured = TempDir::new("emissive-texture");
    image::RgbaImage::from_pixel(4, 4, image::Rgba([128, 192, 160, 255]))
        .save(textured.0.join("glow.png"))
        .expect("texture");
    let panel = "v -0.5 1 -0.3\nv 0.5 1 -0.3\nv 0.5 1 0.3\nv -0.5 1 0.3\nvn 0 -1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl glow\n\
                 f 5/1/2 6/2/2 7/3/2\nf 5/1/2 7/3/2 8/4/2\n";
    let textured_scene = floor_scene(&textured.0, panel, "");
    let mtl = textured.0.join("floor.mtl");
    let text = std::fs::read_to_string(&mtl).expect("mtl");
    std::fs::write(
        &mtl,
        text.replace("Ke 3 2 1\n", "Ke 3 2 1\nmap_Ke glow.png\n"),
    )
    .expect("mtl");
    let linear = [128.0f32, 192.0, 160.0].map(|v| weft_gpu::readback::srgb_to_linear(v / 255.0));
    let plain = TempDir::new("emissive-plain");
    let plain_scene = floor_scene(&plain.0, panel, "");
    let mtl = plain.0.join("floor.mtl");
    let text = std::fs::read_to_string(&mtl).expect("mtl");
    let ke = format!("Ke {} {} {}\n", 3.0 * linear[0], 2.0 * linear[1], linear[2]);
    std::fs::write(&mtl, text.replace("Ke 3 2 1\n", &ke)).expect("mtl");
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        let lit = floor_around_panel(&render(&textured_scene, graph, None, &[]));
        let expected = floor_around_panel(&render(&plain_scene, graph, None, &[]));
        assert!(expected.min_element() > 0.002, "{graph}: {expected}");
        let ratio = lit / expected;
        assert!(
            (ratio - Vec3::ONE).abs().max_element() < 0.005,
            "{graph}: textured {lit} against untextured {expected}"
        );
    }
    let traced = floor_around_panel(&render(
        &textured_scene,
        "pathtrace.ron",
        Some(64),
        &[("max_depth", 2.0)],
    ));
    let raster = floor_around_panel(&render(&textured_scene, "forward.ron", None, &[]));
    let ratio = raster / traced;
    assert!(
        (ratio - Vec3::ONE).abs().max_element() < 0.05,
        "forward {raster} against the tracer's {traced}"
    );
}
