//! Temporal anti-aliasing (graphs/taa.ron, forward's feature `taa`): a
//! still camera's frames converge to the supersampled image, a camera
//! translated by whole pixels finds every texel's history that stays in
//! view, so does a mesh a script moves, and what a moving occluder uncovers
//! starts again at once, with no trace of the occluder.

use std::path::{Path, PathBuf};
use weft_graph::plan::Extent;
use weft_graph::schema::ParamValue;
use weft_render::RenderSettings;
use weft_tests::render::render_image_validated;
use weft_tests::TempDir;

/// A grey plane (albedo 0.5) at z = 0, 20 units wide, under a sun straight
/// down its normal, and `extra` scene text; the camera at z = 5 looks at
/// the origin with a 90-degree field of view (10 units across), with
/// `keys` (camera `key` lines).
fn scene(dir: &Path, extra: &str, keys: &str) -> PathBuf {
    std::fs::write(
        dir.join("m.mtl"),
        "newmtl grey\nKd 0.5 0.5 0.5\nKs 0 0 0\nnewmtl white\nKd 1 0.2 0.1\nKs 0 0 0\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("plane.obj"),
        "mtllib m.mtl\nusemtl grey\nv -10 -10 0\nv 10 -10 0\nv 10 10 0\nv -10 10 0\nvn 0 0 1\n\
         f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("plane");
    // A 4 x 4 quad turned 20 degrees about z, 1 unit above the plane.
    let (s, c) = 20f32.to_radians().sin_cos();
    let corner =
        |x: f32, y: f32| format!("v {} {} 1\n", 2.0 * (c * x - s * y), 2.0 * (s * x + c * y));
    std::fs::write(
        dir.join("quad.obj"),
        format!(
            "mtllib m.mtl\nusemtl white\n{}{}{}{}vn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
            corner(-1.0, -1.0),
            corner(1.0, -1.0),
            corner(1.0, 1.0),
            corner(-1.0, 1.0)
        ),
    )
    .expect("quad");
    let path = dir.join("taa.scene");
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"plane.obj\"\n}}\n{extra}\
             sunlight\n{{\n\tdirection 0 0 -1\n\tcolor 1 1 1\n\tambient 0\n}}\n\
             camera\n{{\n\tposition 0 0 5\n\ttarget 0 0 0\n\tfov_deg 90\n{keys}}}\n"
        ),
    )
    .expect("scene");
    path
}

const QUAD: &str = "model\n{\n\tfile \"quad.obj\"\n}\n";

/// Forward at `size` x `size` for `frames` frames one second apart, bloom
/// off, with `features`; the float image `image` read back.
fn forward(scene: &Path, size: u32, frames: u32, features: &[&str], image: &str) -> Vec<f32> {
    forward_with(scene, size, frames, features, image, &[])
}

/// As `forward`, with graph parameters `params`.
fn forward_with(
    scene: &Path,
    size: u32,
    frames: u32,
    features: &[&str],
    image: &str,
    params: &[(&str, f64)],
) -> Vec<f32> {
    let settings = RenderSettings {
        graph: weft_tests::shipped("forward.ron"),
        extent: Extent {
            width: size,
            height: size,
        },
        frames,
        frame_time: 1.0,
        features: ["!bloom"]
            .iter()
            .chain(features)
            .map(|f| f.to_string())
            .collect(),
        params: params
            .iter()
            .map(|&(name, value)| (name.to_string(), ParamValue::Number(value)))
            .collect(),
        ..RenderSettings::default()
    };
    render_image_validated(scene, settings, image).1
}

/// RGB of an RGBA image averaged over `k` x `k` blocks: `size / k` square.
fn box_filtered(image: &[f32], size: usize, k: usize) -> Vec<f32> {
    let small = size / k;
    let mut out = vec![0.0f32; small * small * 3];
    for y in 0..size {
        for x in 0..size {
            for c in 0..3 {
                out[((y / k) * small + x / k) * 3 + c] +=
                    image[(y * size + x) * 4 + c] / (k * k) as f32;
            }
        }
    }
    out
}

/// The root-mean-square difference of two RGB images, over the second's mean.
fn relative_rms(a: &[f32], b: &[f32]) -> f64 {
    let n = a.len() as f64;
    let mse: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| f64::from(x - y).powi(2))
        .sum::<f64>()
        / n;
    let mean: f64 = b.iter().map(|&v| f64::from(v)).sum::<f64>() / n;
    mse.sqrt() / mean
}

/// 64 still frames of jittered samples (Halton 2, 3) average to the image
/// rendered at 16 x 16 the size and box-filtered: the quad's slanted edges
/// and its shadow's within 1% (relative RMS over the image, and the mean),
/// where one sample per pixel is off by more than 5 times that.
#[test]
fn a_still_camera_converges_to_the_supersampled_image() {
    let dir = TempDir::new("taa-still");
    let scene = scene(&dir.0, QUAD, "");
    let supersampled = box_filtered(&forward(&scene, 512, 1, &[], "hdr"), 512, 16);
    let rgb = |image: Vec<f32>| box_filtered(&image, 32, 1);
    let aliased = rgb(forward(&scene, 32, 1, &[], "hdr"));
    let antialiased = forward(&scene, 32, 64, &["taa"], "antialiased");
    assert!(
        antialiased.chunks(4).all(|p| p[3] == 64.0),
        "every pixel averaged 64 frames"
    );
    let antialiased = rgb(antialiased);
    let error = relative_rms(&antialiased, &supersampled);
    let before = relative_rms(&aliased, &supersampled);
    assert!(error <= 0.01, "TAA off the supersampled image by {error}");
    assert!(
        before > 5.0 * error,
        "one sample per pixel is off by {before}"
    );
    let mean = |v: &[f32]| v.iter().map(|&x| f64::from(x)).sum::<f64>() / v.len() as f64;
    let ratio = mean(&antialiased) / mean(&supersampled);
    assert!((ratio - 1.0).abs() <= 0.01, "means differ: ratio {ratio}");
}

/// The camera moves 2 pixels to the right (0.625 units at 32 pixels across
/// 10 units) a frame over the plane, lit by a point light to give it a
/// gradient: every texel but the two columns entering on the right found
/// its history (two frames averaged, within float rounding of the bilinear
/// weights), and that history is the texel 2 to its right's, not a
/// neighbour's; the entering ones start again.
#[test]
fn a_translating_camera_keeps_history_exactly() {
    let dir = TempDir::new("taa-moving");
    let scene = scene(
        &dir.0,
        "pointlight\n{\n\tposition -3 1 1\n\tcolor 4 4 4\n}\n",
        "\tkey 0  0 0 5   0 0 0\n\tkey 1  0.625 0 5   0.625 0 0\n",
    );
    let first = forward(&scene, 32, 1, &["taa"], "hdr");
    let now = forward(&scene, 32, 2, &["taa"], "hdr");
    let image = forward(&scene, 32, 2, &["taa"], "antialiased");
    let mut nearest = 0;
    for y in 0..32 {
        for x in 0..32 {
            let i = y * 32 + x;
            let frames = image[i * 4 + 3];
            let expected = if x >= 30 { 1.0 } else { 2.0 };
            assert!(
                (frames - expected).abs() <= 1e-4,
                "({x}, {y}) averaged {frames} frames, not {expected}"
            );
            if !(1..29).contains(&x) {
                continue;
            }
            // Which texel's history the average holds: 2 to the right
            // (this frame's sample is a third of a pixel from last
            // frame's, so the match is closest, not exact).
            let off =
                |from: usize| (0.5 * (first[(i + from) * 4] + now[i * 4]) - image[i * 4]).abs();
            if off(2) < off(1) && off(2) < off(3) {
                nearest += 1;
            }
        }
    }
    assert!(
        nearest >= 28 * 32 * 9 / 10,
        "{nearest} of {} texels hold the history 2 to their right",
        28 * 32
    );
}

/// A plane of stripes 4 pixels wide (1.25 units, grey and red in turn)
/// moves 2 pixels to the right between two frames under a still camera:
/// every texel but the two columns entering on the left finds its history
/// (two frames averaged), and where the stripes make it tell, that history
/// is the texel 2 to its left's (where the point was: the forward pass's
/// `taa_motion`), not the texel's own, which reprojecting by the camera
/// alone would take.
#[test]
fn a_moving_mesh_keeps_its_history() {
    let dir = TempDir::new("taa-moving-mesh");
    scene(&dir.0, "", ""); // the MTL file
    let mut obj = String::from("mtllib m.mtl\nvn 0 0 1\n");
    for k in 0..16 {
        let x = -10.0 + 1.25 * k as f32;
        let v = 4 * k + 1;
        obj += &format!(
            "usemtl {}\nv {x} -10 0\nv {} -10 0\nv {} 10 0\nv {x} 10 0\nf {v}//1 {}//1 {}//1\nf {v}//1 {}//1 {}//1\n",
            if k % 2 == 0 { "grey" } else { "white" },
            x + 1.25,
            x + 1.25,
            v + 1,
            v + 2,
            v + 2,
            v + 3
        );
    }
    std::fs::write(dir.0.join("stripes.obj"), obj).expect("stripes");
    let script = dir.0.join("stripes.rhai");
    std::fs::write(
        &script,
        "model(\"stripes.obj\", #{});\n\
         camera(\"front\", #{ position: [0, 0, 5], target: [0, 0, 0], fov_deg: 90 });\n\
         sun_light(#{ direction: [0, 0, -1], color: [1, 1, 1] });\n\
         fn update(t, dt) { set_model_transform(0, #{ position: [0.625 * t, 0, 0] }); }\n",
    )
    .expect("script");
    let first = forward(&script, 32, 1, &["taa"], "hdr");
    let now = forward(&script, 32, 2, &["taa"], "hdr");
    let image = forward(&script, 32, 2, &["taa"], "antialiased");
    let (mut telling, mut from_the_left) = (0, 0);
    for y in 0..32 {
        for x in 0..32 {
            let i = y * 32 + x;
            let frames = image[i * 4 + 3];
            let expected = if x < 2 { 1.0 } else { 2.0 };
            assert!(
                (frames - expected).abs() <= 1e-4,
                "({x}, {y}) averaged {frames} frames, not {expected}"
            );
            if x < 2 || (first[(i - 2) * 4 + 1] - first[i * 4 + 1]).abs() < 0.1 {
                continue;
            }
            telling += 1;
            let off = |from: usize| {
                (0.5 * (first[(i - from) * 4 + 1] + now[i * 4 + 1]) - image[i * 4 + 1]).abs()
            };
            if off(2) < off(0) {
                from_the_left += 1;
            }
        }
    }
    assert!(telling >= 32 * 10, "{telling} texels whose history tells");
    assert!(
        from_the_left >= telling * 9 / 10,
        "{from_the_left} of {telling} texels hold the history 2 to their left"
    );
}

/// The quad's soft shadow under a 2 x 2 area light 3 units above the
/// plane, ray-traced (`rt_shadows`) with one ray a pixel: under TAA the
/// rays' strata change every frame with the camera's jitter, so 32 still
/// frames average 32 rays a pixel and come within a third of the error
/// one frame has against 64 rays (relative RMS against the same graph at
/// 64 rays; measured 0.0099 against 0.0346). With the strata fixed per
/// pixel, as without TAA, the average kept almost all of one ray's error
/// (0.0317).
#[test]
fn taa_averages_one_shadow_ray_a_frame_over_frames() {
    let dir = TempDir::new("taa-shadow-rays");
    let scene = scene(
        &dir.0,
        &format!("{QUAD}arealight\n{{\n\tshape rect\n\tsize 2 2\n\tposition 0 0 3\n\tdirection 0 0 -1\n\temission 5 5 5\n}}\n"),
        "",
    );
    let still = |rays| {
        forward_with(
            &scene,
            64,
            1,
            &["rt_shadows"],
            "hdr",
            &[("shadow_rays", rays)],
        )
    };
    let averaged = |rays| {
        forward_with(
            &scene,
            64,
            32,
            &["rt_shadows", "taa"],
            "antialiased",
            &[("shadow_rays", rays)],
        )
    };
    let rgb =
        |image: Vec<f32>| -> Vec<f32> { image.chunks(4).flat_map(|p| p[..3].to_vec()).collect() };
    let one_frame = relative_rms(&rgb(still(1.0)), &rgb(still(64.0)));
    let over_frames = relative_rms(&rgb(averaged(1.0)), &rgb(averaged(64.0)));
    println!(
        "relative RMS against 64 rays: one frame {one_frame:.4}, 32 frames of TAA {over_frames:.4}"
    );
    assert!(one_frame > 0.02, "one ray's error {one_frame}");
    assert!(
        over_frames * 3.0 < one_frame,
        "one frame {one_frame}, 32 frames {over_frames}"
    );
}

/// The quad, 1 unit above the plane, moves 3.2 units (10 pixels) to the
/// right between two frames under a still camera: the plane it uncovers,
/// but for the pixels beside the quad's new place (whose neighbourhood
/// still shows it, so their history is kept for clipping), has no history
/// and shows the plane alone (not a trace of the quad's red), and the
/// plane it never covered keeps two frames.
#[test]
fn what_an_occluder_uncovers_starts_again_at_once() {
    let dir = TempDir::new("taa-disocclusion");
    scene(&dir.0, QUAD, ""); // the OBJ and MTL files the script loads
    let script = dir.0.join("moving.rhai");
    std::fs::write(
        &script,
        "model(\"plane.obj\", #{});\nmodel(\"quad.obj\", #{});\n\
         camera(\"front\", #{ position: [0, 0, 5], target: [0, 0, 0], fov_deg: 90 });\n\
         sun_light(#{ direction: [0, 0, -1], color: [1, 1, 1] });\n\
         fn update(t, dt) { set_model_transform(1, #{ position: [3.2 * t, 0, 0] }); }\n",
    )
    .expect("script");
    let first = forward(&script, 32, 1, &["taa"], "hdr");
    let second = forward(&script, 32, 2, &["taa"], "antialiased");
    let now = forward(&script, 32, 2, &["taa"], "hdr");
    let red = |image: &[f32], i: usize| image[i * 4] > 2.0 * image[i * 4 + 2];
    let (mut uncovered, mut kept) = (0, 0);
    for i in 0..32 * 32 {
        let frames = second[i * 4 + 3];
        let (x, y) = ((i % 32) as i32, (i / 32) as i32);
        let beside_the_quad = (-1..=1)
            .flat_map(|dy| (-1..=1).map(move |dx| (x + dx, y + dy)))
            .filter(|&(x, y)| (0..32).contains(&x) && (0..32).contains(&y))
            .any(|(x, y)| red(&now, (y * 32 + x) as usize));
        if red(&first, i) && !beside_the_quad {
            uncovered += 1;
            assert_eq!(frames, 1.0, "pixel {i}: uncovered, so no history");
            for c in 0..3 {
                let (got, plane) = (second[i * 4 + c], now[i * 4 + c]);
                assert!(
                    (got - plane).abs() <= 1e-6,
                    "pixel {i}: {got} where the plane is {plane}"
                );
            }
        } else if !red(&first, i) && !red(&now, i) && frames == 2.0 {
            kept += 1;
        }
    }
    assert!(uncovered >= 150, "the quad uncovered {uncovered} pixels");
    assert!(kept >= 500, "{kept} pixels of plane kept their history");
}

/// The debug view `history_length` counts the frames each pixel's average
/// holds: every pixel of a still camera's third frame holds three, and a
/// camera moving 2 pixels a frame leaves the two columns entering the view
/// at one.
#[test]
fn the_history_length_view_counts_the_frames_each_pixel_holds() {
    let (still_dir, moving_dir) = (
        TempDir::new("taa-history-still"),
        TempDir::new("taa-history-moving"),
    );
    let still = scene(&still_dir.0, QUAD, "");
    let moving = scene(
        &moving_dir.0,
        "",
        "\tkey 0  0 0 5   0 0 0\n\tkey 1  0.625 0 5   0.625 0 0\n",
    );
    let lengths = |scene: &Path, frames: u32| {
        let settings = RenderSettings {
            graph: weft_tests::shipped("forward.ron"),
            extent: Extent {
                width: 32,
                height: 32,
            },
            frames,
            frame_time: 1.0,
            features: vec!["!bloom".into(), "taa".into(), "history_length".into()],
            ..RenderSettings::default()
        };
        let (rendered, _) = render_image_validated(scene, settings, "antialiased");
        let (name, view) = &rendered.views[0];
        assert_eq!(name, "history_length");
        (view.pixels, view.total, view.max)
    };
    assert_eq!(lengths(&still, 3), (1024, 3.0 * 1024.0, 3.0));
    // 30 columns found their history: 2 frames; 2 entered: 1.
    assert_eq!(lengths(&moving, 2), (1024, (30.0 * 2.0 + 2.0) * 32.0, 2.0));
}
