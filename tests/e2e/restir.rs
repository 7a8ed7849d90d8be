//! ReSTIR direct light (graphs/restir_di.ron, feature `restir_di` of the
//! deferred graph): its image's mean is the path tracer's direct light
//! (`max_depth` 2) on the Cornell box and under 400 point lights (there the
//! deferred graph's exact sum), with temporal reuse and with unbiased
//! spatial reuse (`restir_spatial`); the
//! biased spatial mode's darkening is measured and bounded; reuse across frames lowers the
//! error of the same candidates; a light switched off is gone from the very
//! frame it goes dark (no ghost in the reservoirs); and the path tracer
//! with ReSTIR at its first surface keeps the reference's mean. The
//! estimator's CPU model is tests/e2e/restir_model.rs.

use std::path::{Path, PathBuf};
use weft_compare::{rel_mse, LinearImage};
use weft_tests::TempDir;

const SIZE: u32 = 48;

/// The HDR image of `scene` through the deferred graph with `restir_di`
/// (and `features`) after `frames` still frames, or (graph `pathtrace.ron`)
/// the path tracer's direct light at 1,024 samples; validated, bloom off.
fn render(
    scene: &Path,
    graph: &str,
    frames: u32,
    params: &[(&str, f64)],
    features: &[&str],
) -> LinearImage {
    let reference = graph == "pathtrace.ron";
    let features: Vec<&str> = if reference {
        Vec::new()
    } else {
        ["restir_di"].iter().chain(features).copied().collect()
    };
    let samples = reference.then_some(1024);
    let mut settings =
        weft_tests::render::square_settings_without_bloom(graph, SIZE, samples, params, &features);
    settings.frames = frames;
    settings.frame_time = 0.0;
    weft_tests::render::linear_image_validated(scene, settings, "hdr")
}

/// Settings for `graph` with `restir_di` on and nothing else changed,
/// `frames` frames `frame_time` seconds apart, bloom off.
fn restir_settings(graph: &str, frames: u32, frame_time: f64) -> weft_render::RenderSettings {
    let mut settings =
        weft_tests::render::square_settings_without_bloom(graph, SIZE, None, &[], &["restir_di"]);
    settings.frames = frames;
    settings.frame_time = frame_time;
    settings
}

/// The deferred graph's own image: every point light summed exactly, with
/// the same G-buffer (and so the same filtered textures) ReSTIR shades.
fn raster(scene: &Path) -> LinearImage {
    let mut settings =
        weft_tests::render::square_settings_without_bloom("deferred.ron", SIZE, None, &[], &[]);
    settings.frame_time = 0.0;
    weft_tests::render::linear_image_validated(scene, settings, "hdr")
}

fn reference(scene: &Path) -> LinearImage {
    render(
        scene,
        "pathtrace.ron",
        1,
        &[("max_depth", 2.0), ("light_choice", 2.0)],
        &[],
    )
}

/// The image's mean over the pixels away from the reference's edges
/// (flat_at), over the reference's.
fn mean_ratio(reference: &LinearImage, image: &LinearImage) -> f64 {
    let (mut sum_ref, mut sum) = (0.0, 0.0);
    for y in 1..SIZE - 1 {
        for x in 1..SIZE - 1 {
            let p = (y * SIZE + x) as usize;
            if weft_tests::render::flat_at(reference, x, y, 0.25) {
                sum_ref += reference.pixels[p]
                    .iter()
                    .map(|&c| f64::from(c))
                    .sum::<f64>();
                sum += image.pixels[p].iter().map(|&c| f64::from(c)).sum::<f64>();
            }
        }
    }
    sum / sum_ref
}

/// A checkered floor under 400 point lights from one generator block
/// (scenes/many_lights.scene with fewer lights, higher up, still).
fn many_lights(dir: &Path) -> PathBuf {
    let floor = weft_tests::render::root().join("scenes/many_lights.scene");
    let text = std::fs::read_to_string(&floor).expect("many_lights.scene");
    let model =
        weft_tests::render::root().join("../shared/assets/462/scenes/models/checkered_floor.obj");
    let text = text
        .replace("count 10000", "count 400")
        .replace(
            "../../shared/assets/462/scenes/models/checkered_floor.obj",
            &model.display().to_string(),
        )
        .replace("velocity 0 0.5", "velocity 0 0")
        // Above the floor by more than a pixel's width (about 1), so each
        // light's highlight covers pixels: the reference's box-filtered
        // pixels and these pixel centres then average the same.
        .replace("min -20 0.2 -20", "min -20 2 -20")
        .replace("max 20 2 20", "max 20 4 20");
    let path = dir.join("lights.scene");
    std::fs::write(&path, text).expect("scene");
    path
}

#[test]
fn restir_is_the_path_tracers_direct_light_and_biased_spatial_reuse_a_little_darker() {
    let dir = TempDir::new("restir-mean");
    let cornell = weft_tests::render::root().join("scenes/cornell.scene");
    let lights = many_lights(&dir.0);
    let cornell_truth = reference(&cornell);
    // Textures: against the deferred graph's exact sum over its lights,
    // whose G-buffer texels ReSTIR's surfaces take (the path tracer's
    // box-filtered texels are another question: raster's mip-filtering).
    let lights_truth = raster(&lights);
    let spatial = |unbiased: f64| {
        let params = [("restir_di.unbiased", unbiased)];
        mean_ratio(
            &cornell_truth,
            &render(&cornell, "deferred.ron", 8, &params, &["restir_spatial"]),
        )
    };
    let temporal = mean_ratio(
        &cornell_truth,
        &render(&cornell, "deferred.ron", 8, &[], &[]),
    );
    let lights_temporal = mean_ratio(&lights_truth, &render(&lights, "deferred.ron", 8, &[], &[]));
    // Spatial reuse under 400 lights is noisy from frame to frame (the mean
    // ratio spans 0.971-1.025 over frames 4 to 16): the mean of four frames.
    let lights_unbiased = [6, 8, 10, 12]
        .iter()
        .map(|&frames| {
            let params = [("restir_di.unbiased", 1.0)];
            mean_ratio(
                &lights_truth,
                &render(
                    &lights,
                    "deferred.ron",
                    frames,
                    &params,
                    &["restir_spatial"],
                ),
            )
        })
        .sum::<f64>()
        / 4.0;
    let (unbiased, biased) = (spatial(1.0), spatial(0.0));
    let report = format!(
        "mean over the reference's: Cornell box, temporal reuse {temporal:.4}, spatial unbiased \
         {unbiased:.4}, spatial biased {biased:.4}; 400 point lights against the deferred graph's sum, temporal {lights_temporal:.4}, spatial unbiased {lights_unbiased:.4} (frames 6, 8, 10, 12)"
    );
    println!("{report}");
    for ratio in [temporal, unbiased, lights_temporal, lights_unbiased] {
        assert!((ratio - 1.0).abs() < 0.02, "{report}");
    }
    assert!(biased < unbiased + 0.005 && biased > 0.95, "{report}");
}

/// The path tracer with `restir_di` (graphs/path_tracer.ron): the direct
/// light at each pixel's first surface is ReSTIR's and the paths bring the
/// rest, so the raw frames' mean is the reference's, at direct light only
/// (`max_depth` 2: the paths add only what the camera sees of the light) and
/// with every bounce; with the feature off the same frames agree as well.
#[test]
fn the_path_tracer_with_restir_at_its_first_surface_keeps_the_references_mean() {
    let cornell = weft_tests::render::root().join("scenes/cornell.scene");
    let mut report = String::new();
    for depth in [2.0, 8.0] {
        let truth = render(&cornell, "pathtrace.ron", 1, &[("max_depth", depth)], &[]);
        let frames = |features: &[&str]| {
            let params = [("max_depth", depth), ("samples_per_frame", 16.0)];
            let mut settings = weft_tests::render::square_settings(
                "pathtrace_denoised.ron",
                SIZE,
                None,
                &params,
                features,
            );
            settings.frames = 8;
            settings.frame_time = 0.0;
            mean_ratio(
                &truth,
                &weft_tests::render::linear_image_validated(&cornell, settings, "hdr"),
            )
        };
        let (restir, nee) = (frames(&["!denoise", "restir_di"]), frames(&["!denoise"]));
        report += &format!("max_depth {depth}: with restir_di {restir:.4}, without {nee:.4}; ");
        for ratio in [restir, nee] {
            assert!((ratio - 1.0).abs() < 0.02, "{report}");
        }
    }
    println!("{report}");
}

#[test]
fn temporal_reuse_lowers_the_error_of_the_same_candidates() {
    let dir = TempDir::new("restir-reuse");
    let scene = many_lights(&dir.0);
    let truth = reference(&scene);
    let error = |frames: u32, history_cap: f64| {
        let params = [("restir_di.history_cap", history_cap)];
        rel_mse(
            &truth.pixels,
            &render(&scene, "deferred.ron", frames, &params, &[]).pixels,
        )
    };
    let alone = error(1, 0.0);
    let eighth_alone = error(8, 0.0);
    let eight = error(8, 20.0);
    let report = format!(
        "relative MSE: one frame's candidates {alone:.4}, the 8th frame's alone {eighth_alone:.4}, 8 frames reused {eight:.4}"
    );
    println!("{report}");
    assert!((eighth_alone / alone - 1.0).abs() < 0.25, "{report}");
    assert!(eight < 0.6 * alone, "{report}");
}

/// The tiled graph takes ReSTIR's light as the deferred graph does: the same
/// passes over the same G-buffer, so the same image.
#[test]
fn tiled_and_deferred_shade_the_same_restir_light() {
    let dir = TempDir::new("restir-tiled");
    let scene = many_lights(&dir.0);
    let image = |graph: &str| {
        let settings = restir_settings(graph, 3, 0.0);
        weft_tests::render::linear_image_validated(&scene, settings, "hdr")
    };
    let (tiled, deferred) = (image("tiled.ron"), image("deferred.ron"));
    let worst = tiled
        .pixels
        .iter()
        .zip(&deferred.pixels)
        .flat_map(|(a, b)| (0..3).map(move |c| (a[c] - b[c]).abs() / b[c].abs().max(1e-3)))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "worst relative difference {worst}");
    assert!(lit_pixels(&deferred) > (SIZE * SIZE / 4) as usize);
}

fn lit_pixels(image: &LinearImage) -> usize {
    image.pixels.iter().filter(|p| p[1] > 0.0).count()
}

/// A wall facing the camera with a box before it, lit by a sun; the scene's
/// script moves the camera sideways after t = 0.125 s (the ninth frame of
/// frames 1/60 s apart) by exactly two pixels' width at the wall.
fn wall_and_box(dir: &Path) -> PathBuf {
    std::fs::write(
        dir.join("wall.mtl"),
        "newmtl white\nKd 0.8 0.8 0.8\nKs 0 0 0\n",
    )
    .expect("mtl");
    let quads: [[[f32; 3]; 4]; 2] = [
        // The wall, z = 0, facing +z.
        [
            [-4.0, -3.0, 0.0],
            [4.0, -3.0, 0.0],
            [4.0, 5.0, 0.0],
            [-4.0, 5.0, 0.0],
        ],
        // The box's front, z = 2.5.
        [
            [-0.5, 0.5, 2.5],
            [0.5, 0.5, 2.5],
            [0.5, 1.5, 2.5],
            [-0.5, 1.5, 2.5],
        ],
    ];
    let mut obj = String::from("mtllib wall.mtl\nusemtl white\n");
    for (k, q) in quads.iter().enumerate() {
        for c in q {
            obj += &format!("v {} {} {}\n", c[0], c[1], c[2]);
        }
        let v = 1 + 4 * k;
        obj += &format!("f {} {} {}\nf {} {} {}\n", v, v + 1, v + 2, v, v + 2, v + 3);
    }
    std::fs::write(dir.join("wall.obj"), obj).expect("obj");
    // Two pixels at the wall, 5 away, through a 60-degree view SIZE across.
    let step = 2.0 * 5.0 * (30.0f64.to_radians()).tan() / (f64::from(SIZE) / 2.0);
    std::fs::write(
        dir.join("pan.rhai"),
        format!(
            "fn update(t, dt) {{\n    if t > 0.125 {{\n        set_camera(\"main\", #{{ position: [{step}, 1.0, 5.0], target: [{step}, 1.0, 0.0] }});\n    }}\n}}\n"
        ),
    )
    .expect("script");
    let path = dir.join("wall.scene");
    std::fs::write(
        &path,
        "model\n{\n\tfile \"wall.obj\"\n}\n\
         sunlight\n{\n\tdirection 0.2 -0.3 -1\n\tcolor 1 1 1\n\tambient 0 0 0\n}\n\
         camera \"main\"\n{\n\tposition 0 1 5\n\ttarget 0 1 0\n\tfov_deg 60\n}\n\
         script \"pan.rhai\"\n",
    )
    .expect("scene");
    path
}

/// Temporal reuse under a camera moved two pixels: every pixel whose surface
/// the last frame saw keeps its reservoir (its count grows by this frame's
/// 2 candidates), the two columns the move uncovered start again (2), and so
/// do the wall pixels the box uncovered, which lie beside its edge.
#[test]
fn a_camera_moved_two_pixels_keeps_reservoirs_where_the_surface_stays() {
    let dir = TempDir::new("restir-pan");
    let scene = wall_and_box(&dir.0);
    // Component `c` of image `image` (RGBA floats) after `frames` frames.
    let read = |frames: u32, image: &str, c: usize| -> Vec<f32> {
        let settings = restir_settings("deferred.ron", frames, 1.0 / 60.0);
        let (_, texels) = weft_tests::render::render_image_validated(&scene, settings, image);
        texels.chunks(4).map(|texel| texel[c]).collect()
    };
    // The reservoirs' counts before and after the move, and which pixels
    // see the box after it (its front is at z = 2.5, the wall at 0).
    let (still, moved) = (read(8, "restir_state", 2), read(9, "restir_state", 2));
    let on_box: Vec<bool> = read(9, "restir_surface", 2)
        .iter()
        .map(|&z| z > 1.0)
        .collect();
    // 2 candidates a frame, the history's count below its cap (20 frames'):
    // 16 after eight frames, 18 after nine where history was kept.
    let (steady, kept_count) = (16.0, 18.0);
    let at = |x: u32, y: u32| (y * SIZE + x) as usize;
    let pixels = || (0..SIZE).flat_map(|y| (0..SIZE).map(move |x| (x, y)));
    let near_box = |x: u32, y: u32| {
        pixels().any(|(bx, by)| on_box[at(bx, by)] && bx.abs_diff(x) <= 3 && by.abs_diff(y) <= 3)
    };
    let restarted: Vec<(u32, u32)> = pixels().filter(|&(x, y)| moved[at(x, y)] == 2.0).collect();
    let whole: Vec<u32> = (0..SIZE)
        .filter(|&x| (0..SIZE).all(|y| moved[at(x, y)] == 2.0))
        .collect();
    let report = format!(
        "still: {} of {} pixels at the count {steady}; after the move {} restarted, whole columns {whole:?}",
        still.iter().filter(|&&m| m == steady).count(),
        SIZE * SIZE,
        restarted.len()
    );
    println!("{report}");
    assert!(still.iter().all(|&m| m == steady), "{report}");
    // The two columns the move uncovered, at one edge.
    assert!(whole == [0, 1] || whole == [SIZE - 2, SIZE - 1], "{report}");
    let mut uncovered = 0;
    for (x, y) in pixels().filter(|(x, _)| !whole.contains(x)) {
        let kept = moved[at(x, y)] == kept_count;
        if on_box[at(x, y)] || !near_box(x, y) {
            assert!(kept, "({x}, {y}) lost its history: {report}");
        } else if !kept {
            assert_eq!(moved[at(x, y)], 2.0, "({x}, {y}): {report}");
            uncovered += 1;
        }
    }
    // The wall the box uncovered: a strip two pixels wide (the box, half as
    // far, moved four) down every row it covers.
    let rows = (0..SIZE)
        .filter(|&y| (0..SIZE).any(|x| on_box[at(x, y)]))
        .count();
    assert_eq!(
        uncovered,
        2 * rows,
        "wall pixels restarted beside the box's {rows} rows: {report}"
    );
}

/// A white floor under two point lights, the second switched off by the
/// scene's script after t = 0.125 s when `switch` (frames 1/60 s apart: the
/// ninth frame is the first without it), or left out of the scene.
fn two_lights(dir: &Path, name: &str, second: bool, switch: bool) -> PathBuf {
    std::fs::write(
        dir.join("floor.mtl"),
        "newmtl white\nKd 0.8 0.8 0.8\nKs 0 0 0\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("floor.obj"),
        "mtllib floor.mtl\nusemtl white\nv -4 0 4\nv 4 0 4\nv 4 0 -4\nv -4 0 -4\nf 1 2 3\nf 1 3 4\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("switch.rhai"),
        "fn update(t, dt) {\n    if t > 0.125 {\n        set_light_on(1, false);\n    }\n}\n",
    )
    .expect("script");
    let mut text = String::from(
        "model\n{\n\tfile \"floor.obj\"\n}\n\
         pointlight\n{\n\tposition -1.5 1 0\n\tcolor 2 2 2\n\tattenuation 0 0 1\n}\n\
         camera\n{\n\tposition 0 6 5\n\ttarget 0 0 0\n\tfov_deg 60\n}\n",
    );
    if second {
        text += "pointlight\n{\n\tposition 1.5 1 0\n\tcolor 2 2 2\n\tattenuation 0 0 1\n}\n";
    }
    if switch {
        text += "script \"switch.rhai\"\n";
    }
    let path = dir.join(name);
    std::fs::write(&path, text).expect("scene");
    path
}

#[test]
fn a_light_switched_off_is_gone_from_the_frame_it_goes_dark() {
    let dir = TempDir::new("restir-switch");
    let image = |scene: &Path, frames: u32| {
        let settings = restir_settings("deferred.ron", frames, 1.0 / 60.0);
        weft_tests::render::linear_image_validated(scene, settings, "hdr")
    };
    let switched = two_lights(&dir.0, "switched.scene", true, true);
    let one = two_lights(&dir.0, "one.scene", false, false);
    let both = two_lights(&dir.0, "both.scene", true, false);
    let lit = |image: &LinearImage| -> f64 {
        image
            .pixels
            .iter()
            .map(|p| f64::from(p[0] + p[1] + p[2]))
            .sum()
    };
    // Eight frames with both lights; the ninth is the first without.
    let before = lit(&image(&switched, 8));
    let after = lit(&image(&switched, 9));
    let (one, both) = (lit(&image(&one, 9)), lit(&image(&both, 9)));
    let report = format!(
        "light summed over the image: both lights {both:.1}, frame 8 {before:.1}; one light {one:.1}, frame 9 {after:.1}"
    );
    println!("{report}");
    assert!((before / both - 1.0).abs() < 0.03, "{report}");
    assert!((after / one - 1.0).abs() < 0.03, "{report}");
}
