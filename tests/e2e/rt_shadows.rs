//! Ray-traced shadows (feature `rt_shadows`: the lighting passes of the
//! forward, deferred and tiled graphs trace shadow rays through the path
//! tracer's BVH instead of looking up the shadow map). A box floats over a
//! white Lambertian floor. Hard shadows: for a sun, a point light and a spot,
//! in each graph, every floor pixel's visibility (the image over the same
//! scene's without the box) equals a CPU ray cast from the point the pixel's
//! centre ray meets the floor, except where moving that point by 1e-3 units
//! changes the cast (the shadow's edge runs through the pixel centre). With
//! `footprint_rays` spread over each pixel, a sun's shadow edge is the
//! fraction of the pixel's floor the CPU finds lit. Soft shadows: under a rectangular area light, the shaded floor converges to the
//! path tracer's direct light (`max_depth=2`), far closer than the shadow
//! map's estimated penumbra.

use glam::{Vec2, Vec3};
use std::path::{Path, PathBuf};
use weft_compare::{hdr_flip, LinearImage};
use weft_testkit::raytrace::Bvh;
use weft_tests::TempDir;

const SIZE: u32 = 96;

/// A 16 x 16 floor at y = 0 and, with `box_on`, a unit box floating at
/// y 1..2, white and Lambertian, lit by `lights` (scene blocks) alone.
fn write_scene(dir: &Path, name: &str, lights: &str, box_on: bool) -> PathBuf {
    let mut obj = String::from(
        "mtllib white.mtl\nusemtl white\nv -8 0 -8\nv 8 0 -8\nv 8 0 8\nv -8 0 8\nf 1 4 3\nf 1 3 2\n",
    );
    if box_on {
        for i in 0..8 {
            let x = if i & 1 == 0 { -0.5 } else { 0.5 };
            let y = if i & 2 == 0 { 1.0 } else { 2.0 };
            let z = if i & 4 == 0 { -0.5 } else { 0.5 };
            obj += &format!("v {x} {y} {z}\n");
        }
        for [a, b, c, d] in [
            [1, 3, 7, 5],
            [2, 6, 8, 4],
            [1, 5, 6, 2],
            [3, 4, 8, 7],
            [1, 2, 4, 3],
            [5, 7, 8, 6],
        ] {
            let (a, b, c, d) = (a + 4, b + 4, c + 4, d + 4);
            obj += &format!("f {a} {b} {c}\nf {a} {c} {d}\n");
        }
    }
    let model = format!("{name}.obj");
    std::fs::write(dir.join(&model), obj).expect("obj");
    std::fs::write(dir.join("white.mtl"), "newmtl white\nKd 1 1 1\nKs 0 0 0\n").expect("mtl");
    let path = dir.join(format!("{name}.scene"));
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"{model}\"\n}}\n{lights}camera\n{{\n\tposition 0 9 5\n\ttarget 0 0 0.5\n\tfov_deg 45\n}}\n"
        ),
    )
    .expect("scene");
    path
}

/// The HDR image of `scene` through shipped `graph`, validated, bloom off.
fn render(
    scene: &Path,
    graph: &str,
    samples: Option<u64>,
    params: &[(&str, f64)],
    features: &[&str],
) -> Vec<[f32; 3]> {
    let settings =
        weft_tests::render::square_settings_without_bloom(graph, SIZE, samples, params, features);
    weft_tests::render::linear_image_validated(scene, settings, "hdr").pixels
}

/// A light the hard-shadow test casts towards from a floor point: the unit
/// direction towards it and its distance.
enum Punctual {
    Sun(Vec3),
    At(Vec3),
}

impl Punctual {
    fn towards(&self, p: Vec3) -> (Vec3, f32) {
        match self {
            Punctual::Sun(travel) => (-travel.normalize(), f32::MAX),
            Punctual::At(q) => ((*q - p).normalize(), (*q - p).length()),
        }
    }
}

/// Where pixel (x, y)'s centre ray meets the floor, when the floor is what
/// it meets first.
fn floor_point(bvh: &Bvh, inverse: &glam::Mat4, x: u32, y: u32) -> Option<Vec3> {
    floor_point_at(bvh, inverse, Vec2::new(x as f32, y as f32) + 0.5)
}

/// [`floor_point`] for the ray through `at`, in pixels.
fn floor_point_at(bvh: &Bvh, inverse: &glam::Mat4, at: Vec2) -> Option<Vec3> {
    let ndc = at / SIZE as f32 * 2.0 - 1.0;
    let near = inverse.project_point3(ndc.extend(1.0));
    let far = inverse.project_point3(ndc.extend(0.5));
    let dir = (far - near).normalize();
    let hit = bvh.closest(near, dir, f32::MAX)?;
    let p = near + dir * hit.t;
    (hit.normal.y.abs() > 0.999 && p.y.abs() < 1e-3).then_some(Vec3::new(p.x, 0.0, p.z))
}

/// The CPU's visibility of `light` from floor point `p`, with the shader's
/// ray offset (`leave`) and shortening.
fn cpu_visible(bvh: &Bvh, light: &Punctual, p: Vec3) -> bool {
    let (l, d) = light.towards(p);
    let scale = p.abs().max_element().max(1.0);
    let origin = p + Vec3::Y * (1e-4 * scale);
    let t_max = if d == f32::MAX {
        3.0e38
    } else {
        d * (1.0 - 1e-4)
    };
    !bvh.occluded(origin, l, t_max)
}

/// With 64 rays over each pixel's footprint, the sun's visibility in each
/// floor pixel is the lit fraction of a 16 x 16 grid of CPU casts from the
/// floor points the pixel covers: within 0.12 at every pixel (the GPU's 64
/// jittered rays against the CPU's 256) and within 0.035 on average over the
/// edge's pixels, and no pixel more than two rays off where all 256 casts
/// agree.
fn footprints_are_box_filtered(
    bvh: &Bvh,
    inverse: &glam::Mat4,
    light: &Punctual,
    unshadowed: &[[f32; 3]],
    scene: &Path,
) {
    let image = render(
        scene,
        "deferred.ron",
        None,
        &[("footprint_rays", 64.0)],
        &["rt_shadows"],
    );
    let (mut edge, mut edge_error, mut worst) = (0, 0.0f32, 0.0f32);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = (y * SIZE + x) as usize;
            let Some(_) = floor_point(bvh, inverse, x, y) else {
                continue;
            };
            let mut casts = Vec::new();
            for k in 0..256 {
                let at = Vec2::new(x as f32, y as f32)
                    + (Vec2::new((k % 16) as f32, (k / 16) as f32) + 0.5) / 16.0;
                if let Some(p) = floor_point_at(bvh, inverse, at) {
                    casts.push(cpu_visible(bvh, light, p));
                }
            }
            if casts.len() < 256 {
                continue; // the box's silhouette crosses the pixel
            }
            let expected = casts.iter().filter(|v| **v).count() as f32 / 256.0;
            let seen = image[i][0] / unshadowed[i][0];
            let error = (seen - expected).abs();
            if expected > 0.0 && expected < 1.0 {
                edge += 1;
                edge_error += error;
                worst = worst.max(error);
            } else {
                // A jittered ray may still find an edge in the sliver
                // between the CPU's grid and the pixel's border.
                assert!(
                    error < 2.0 / 64.0 + 1e-3,
                    "({x}, {y}): {seen} where every cast gives {expected}"
                );
            }
        }
    }
    let mean = edge_error / edge as f32;
    assert!(
        edge > 40 && worst < 0.12 && mean < 0.035,
        "{edge} edge pixels: mean error {mean}, worst {worst}"
    );
    eprintln!("footprint: {edge} edge pixels, mean error {mean:.4}, worst {worst:.4}");
}

#[test]
fn hard_shadows_equal_cpu_ray_casts_for_sun_point_and_spot_in_every_raster_graph() {
    let dir = TempDir::new("rt-shadows-hard");
    let lights = [
        (
            "sun",
            "sunlight\n{\n\tdirection 0.45 -1 0.3\n\tcolor 1 1 1\n\tambient 0\n}\n",
            Punctual::Sun(Vec3::new(0.45, -1.0, 0.3)),
        ),
        (
            "point",
            "pointlight\n{\n\tposition 1.5 4 1\n\tcolor 4 4 4\n\tattenuation 1 0 0\n}\n",
            Punctual::At(Vec3::new(1.5, 4.0, 1.0)),
        ),
        (
            "spot",
            "spotlight\n{\n\tposition -1.2 5 -1\n\tdirection 0.35 -1 0.35\n\tcolor 4 4 4\n\texponent 0\n\tangle 60\n\tattenuation 1 0 0\n}\n",
            Punctual::At(Vec3::new(-1.2, 5.0, -1.0)),
        ),
    ];
    let mut report = Vec::new();
    for (name, block, light) in &lights {
        let boxed = write_scene(&dir.0, name, block, true);
        let open = write_scene(&dir.0, &format!("{name}_open"), block, false);
        let scene = weft_scene::load_scene(&boxed).expect("scene");
        let inverse = scene.cameras[0].view_projection(0.0, 1.0).inverse();
        let bvh = Bvh::from_scene(&scene, |_, _| true);
        let unshadowed = render(&open, "forward.ron", None, &[], &[]);
        if *name == "sun" {
            footprints_are_box_filtered(&bvh, &inverse, light, &unshadowed, &boxed);
        }
        for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
            let image = render(&boxed, graph, None, &[], &["rt_shadows"]);
            let (mut lit, mut shadowed, mut edge, mut wrong) = (0, 0, 0, Vec::new());
            for y in 0..SIZE {
                for x in 0..SIZE {
                    let Some(p) = floor_point(&bvh, &inverse, x, y) else {
                        continue;
                    };
                    let i = (y * SIZE + x) as usize;
                    let full = unshadowed[i][0];
                    if full < 1e-3 {
                        continue; // outside the spot's cone
                    }
                    let expected = cpu_visible(&bvh, light, p);
                    let nudged = [Vec3::X, -Vec3::X, Vec3::Z, -Vec3::Z]
                        .iter()
                        .any(|d| cpu_visible(&bvh, light, p + *d * 1e-3) != expected);
                    if nudged {
                        edge += 1;
                        continue;
                    }
                    let seen = image[i][0] / full;
                    let want = if expected { 1.0 } else { 0.0 };
                    if expected {
                        lit += 1;
                    } else {
                        shadowed += 1;
                    }
                    if (seen - want).abs() > 0.01 {
                        wrong.push(format!("({x}, {y}): {seen} for {want}"));
                    }
                }
            }
            report.push(format!(
                "{name} through {graph}: {lit} lit, {shadowed} shadowed, {edge} on the edge"
            ));
            assert!(
                wrong.is_empty(),
                "{name} through {graph}: {} pixel(s) differ from the CPU's ray casts: {}",
                wrong.len(),
                wrong.iter().take(8).cloned().collect::<Vec<_>>().join(", ")
            );
            assert!(
                shadowed > 100 && lit > 1000 && edge * 20 < shadowed,
                "{name} through {graph}: the shadow must be there and its edge thin: {lit} lit, {shadowed} shadowed, {edge} on the edge"
            );
        }
    }
    eprintln!("{}", report.join("\n"));
}

/// `image` with the pixels `keep` leaves out set to black.
fn masked(image: &[[f32; 3]], keep: &[bool]) -> LinearImage {
    LinearImage {
        width: SIZE,
        height: SIZE,
        pixels: image
            .iter()
            .zip(keep)
            .map(|(p, k)| if *k { *p } else { [0.0; 3] })
            .collect(),
    }
}

fn mean(image: &LinearImage) -> f64 {
    image.pixels.iter().map(|p| f64::from(p[0])).sum::<f64>() / image.pixels.len() as f64
}

#[test]
fn area_light_shadows_converge_to_the_path_tracers_direct_light() {
    let dir = TempDir::new("rt-shadows-area");
    // A 1.6 x 1.6 panel 4 units up, off to the side, facing down.
    let (centre, half) = (Vec3::new(1.2, 4.0, 0.8), 0.8);
    let light = format!(
        "arealight\n{{\n\tshape rect\n\tsize {s} {s}\n\tposition {} {} {}\n\tdirection 0 -1 0\n\temission 4 4 4\n}}\n",
        centre.x,
        centre.y,
        centre.z,
        s = 2.0 * half
    );
    let path = write_scene(&dir.0, "area", &light, true);
    let scene = weft_scene::load_scene(&path).expect("scene");
    let inverse = scene.cameras[0].view_projection(0.0, 1.0).inverse();
    let bvh = Bvh::from_scene(&scene, |_, _| true);
    // The floor, where the camera does not see the panel in front of it
    // (the panel, not the floor's shadow, is what those pixels show).
    let keep: Vec<bool> = (0..SIZE * SIZE)
        .map(|i| {
            let (x, y) = (i % SIZE, i / SIZE);
            let ndc = (Vec2::new(x as f32, y as f32) + 0.5) / SIZE as f32 * 2.0 - 1.0;
            let near = inverse.project_point3(ndc.extend(1.0));
            let far = inverse.project_point3(ndc.extend(0.5));
            let t = (centre.y - near.y) / (far.y - near.y);
            let at = near + (far - near) * t;
            let under_panel = t > 0.0
                && (at.x - centre.x).abs() <= half + 0.05
                && (at.z - centre.z).abs() <= half + 0.05;
            !under_panel && floor_point(&bvh, &inverse, x, y).is_some()
        })
        .collect();
    let reference = masked(
        &render(
            &path,
            "pathtrace.ron",
            Some(1024),
            &[("max_depth", 2.0)],
            &[],
        ),
        &keep,
    );
    // The yardstick: how far a 1,024-spp path tracer with independent
    // random numbers lies from the reference (whose Sobol numbers leave it
    // several times less noisy, so this is mostly the independent one's
    // noise).
    let again = masked(
        &render(
            &path,
            "pathtrace.ron",
            Some(1024),
            &[("max_depth", 2.0), ("seed", 7.0)],
            &["independent_sampler"],
        ),
        &keep,
    );
    let noise = hdr_flip(&reference, &again).mean;
    let mut report = vec![format!(
        "independently sampled path tracer against the reference: {noise:.4}"
    )];
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        let mapped = masked(&render(&path, graph, None, &[], &[]), &keep);
        let traced = masked(
            &render(
                &path,
                graph,
                None,
                &[("shadow_rays", 256.0)],
                &["rt_shadows"],
            ),
            &keep,
        );
        let (flip_mapped, flip_traced) = (
            hdr_flip(&reference, &mapped).mean,
            hdr_flip(&reference, &traced).mean,
        );
        let ratio = mean(&traced) / mean(&reference);
        report.push(format!(
            "{graph}: HDR-FLIP shadow map {flip_mapped:.4}, rt_shadows {flip_traced:.4}; mean ratio {ratio:.4}"
        ));
        // Measured: the independently sampled path tracer 0.0062; shadow map
        // 0.028-0.029, rt_shadows 0.0035 in each graph, mean ratio 1.0002.
        // (Against an independently sampled reference, its own noise 0.0079,
        // rt_shadows measured 0.0070.)
        assert!(
            flip_traced <= noise && (ratio - 1.0).abs() < 0.01 && flip_mapped > 3.0 * flip_traced,
            "rt_shadows must be as close to the reference as a 1,024-spp independently sampled path tracer, \
             and well below the shadow map's error:\n{}",
            report.join("\n")
        );
    }
    eprintln!("{}", report.join("\n"));
}

/// Point lights' cube shadow maps (`point_shadows`, graphs/shadows.ron): the
/// floor's visibility equals CPU ray casts in every raster graph, away from
/// the shadow's edge (where moving the point by 0.1 units, about two shadow
/// texels plus the PCF kernel, changes the cast). The light sits over the
/// box's corner, so the shadow spans the cube's −y face and its neighbours.
#[test]
fn point_light_shadow_maps_equal_cpu_ray_casts_away_from_edges_in_every_raster_graph() {
    let dir = TempDir::new("point-shadow-maps");
    let block = "pointlight\n{\n\tposition 0.9 3.2 0.7\n\tcolor 4 4 4\n\tattenuation 1 0 0\n}\n";
    let light = Punctual::At(Vec3::new(0.9, 3.2, 0.7));
    let boxed = write_scene(&dir.0, "point", block, true);
    let open = write_scene(&dir.0, "point_open", block, false);
    let scene = weft_scene::load_scene(&boxed).expect("scene");
    let inverse = scene.cameras[0].view_projection(0.0, 1.0).inverse();
    let bvh = Bvh::from_scene(&scene, |_, _| true);
    let unshadowed = render(&open, "forward.ron", None, &[], &[]);
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        let image = render(&boxed, graph, None, &[], &[]);
        let (mut lit, mut shadowed, mut wrong) = (0, 0, Vec::new());
        for y in 0..SIZE {
            for x in 0..SIZE {
                let Some(p) = floor_point(&bvh, &inverse, x, y) else {
                    continue;
                };
                let i = (y * SIZE + x) as usize;
                let expected = cpu_visible(&bvh, &light, p);
                let near_edge = (0..8).any(|k| {
                    let a = k as f32 * std::f32::consts::FRAC_PI_4;
                    cpu_visible(&bvh, &light, p + Vec3::new(a.cos(), 0.0, a.sin()) * 0.1)
                        != expected
                });
                if near_edge {
                    continue;
                }
                let seen = image[i][0] / unshadowed[i][0];
                if expected {
                    lit += 1;
                } else {
                    shadowed += 1;
                }
                if (seen - if expected { 1.0 } else { 0.0 }).abs() > 0.02 {
                    wrong.push(format!("({x}, {y}): {seen} for {expected}"));
                }
            }
        }
        assert!(
            wrong.is_empty(),
            "{graph}: {} pixel(s) differ from the CPU's ray casts: {}",
            wrong.len(),
            wrong.iter().take(8).cloned().collect::<Vec<_>>().join(", ")
        );
        assert!(
            shadowed > 300 && lit > 3000,
            "{graph}: {lit} lit, {shadowed} shadowed"
        );
    }
    // Without a budget the point light casts nothing on the floor.
    let image = render(
        &boxed,
        "forward.ron",
        None,
        &[("shadows.point_shadows", 0.0)],
        &[],
    );
    let darker = (0..SIZE * SIZE)
        .filter(|&i| floor_point(&bvh, &inverse, i % SIZE, i / SIZE).is_some())
        .filter(|&i| image[i as usize][0] < unshadowed[i as usize][0] * 0.99)
        .count();
    assert_eq!(darker, 0, "floor pixels darkened with point_shadows 0");
}
