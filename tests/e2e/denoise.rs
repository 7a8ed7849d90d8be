//! The SVGF-style denoiser (graphs/denoise.ron) and the graph that runs it
//! after the path tracer (graphs/pathtrace_denoised.ron): a noise-free input
//! comes back unchanged once its frames' variance is known, reprojection
//! keeps every texel a pure camera translation, or a mesh's, keeps in view
//! and only those,
//! and on path-traced frames the error falls fourfold while the image's mean
//! holds. What makes it converge (no dot grid, no ghost of a switched-off
//! light, never worse than raw accumulation): `converges.rs`.

use std::path::{Path, PathBuf};
use weft_compare::{rel_mse, LinearImage};
use weft_gpu::Pixels;
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings};
use weft_tests::TempDir;

mod converges;
mod split;

const SIZE: u32 = 32;

/// A 20 x 20 grey plane at z = 0 (albedo 0.5) seen head-on from z = 5 with
/// a 90-degree field of view, so the view spans 10 units: 1 pixel is
/// 10 / 32 units. `keys`: camera `key` lines (time, position, target).
fn plane_scene(dir: &Path, keys: &str) -> PathBuf {
    std::fs::write(
        dir.join("grey.mtl"),
        "newmtl grey\nKd 0.5 0.5 0.5\nKs 0 0 0\n",
    )
    .expect("mtl");
    std::fs::write(
        dir.join("plane.obj"),
        "mtllib grey.mtl\nusemtl grey\nv -10 -10 0\nv 10 -10 0\nv 10 10 0\nv -10 10 0\nvn 0 0 1\n\
         f 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("obj");
    let path = dir.join("plane.scene");
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"plane.obj\"\n}}\n\
             sunlight\n{{\n\tdirection 0 0 -1\n\tcolor 1 1 1\n}}\n\
             camera\n{{\n\tposition 0 0 5\n\ttarget 0 0 0\n\tfov_deg 90\n{keys}}}\n"
        ),
    )
    .expect("scene");
    path
}

/// The fixture's images after `frames` frames one second apart, validated.
fn fixture(scene: &Path, frames: u32) -> Images {
    fixture_with(scene, frames, &[])
}

/// [`fixture`] with the fixture graph's parameters `params` set.
fn fixture_with(scene: &Path, frames: u32, params: &[(&str, f64)]) -> Images {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = weft_tests::gpu();
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: weft_tests::graph("denoise_check.ron"),
        extent: Extent {
            width: SIZE,
            height: SIZE,
        },
        frames,
        frame_time: 1.0,
        extra_readback: ["hdr", "albedo", "illumination", "moments"]
            .map(String::from)
            .to_vec(),
        params: params
            .iter()
            .map(|(k, v)| (k.to_string(), weft_graph::schema::ParamValue::Number(*v)))
            .collect(),
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).unwrap_or_else(|e| panic!("render: {e}"));
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let floats = |pixels: &Pixels| match pixels {
        Pixels::RgbaF32(v) => v.clone(),
        _ => panic!("a float image"),
    };
    let output = rendered.report.output.as_ref().expect("read back");
    let named = |name: &str| {
        let (_, image) = rendered
            .report
            .readbacks
            .iter()
            .find(|(n, _)| n == name)
            .unwrap_or_else(|| panic!("{name} read back"));
        floats(&image.pixels)
    };
    Images {
        denoised: floats(&output.pixels),
        hdr: named("hdr"),
        albedo: named("albedo"),
        illumination: named("illumination"),
        moments: named("moments"),
    }
}

/// RGBA floats, row by row.
struct Images {
    denoised: Vec<f32>,
    hdr: Vec<f32>,
    albedo: Vec<f32>,
    illumination: Vec<f32>,
    moments: Vec<f32>,
}

fn at(x: u32, y: u32, c: u32) -> usize {
    ((y * SIZE + x) * 4 + c) as usize
}

/// After four still frames the variance of a noise-free input is known to be
/// zero, so no neighbour's luminance is close enough to be mixed in: the
/// pattern (ramps with single-texel dots, every edge a step) comes back
/// within 1e-3. Before that, the variance is estimated from the
/// neighbourhood and the filter does blur (asserted too, so the first check
/// cannot pass by the filter doing nothing).
#[test]
fn a_noise_free_input_comes_back_once_its_variance_is_known() {
    let dir = TempDir::new("denoise-still");
    let scene = plane_scene(&dir.0, "");
    let first = fixture(&scene, 1);
    let worst = |images: &Images| {
        images
            .denoised
            .iter()
            .zip(&images.hdr)
            .enumerate()
            .filter(|(i, _)| i % 4 != 3)
            .map(|(_, (d, h))| (d - h).abs() / h.abs().max(1e-3))
            .fold(0.0f32, f32::max)
    };
    assert!(
        worst(&first) > 0.05,
        "one frame: the spatial variance estimate lets the filter blur ({})",
        worst(&first)
    );
    let settled = fixture(&scene, 6);
    assert_eq!(settled.moments[at(5, 5, 2)], 6.0, "six frames averaged");
    let error = worst(&settled);
    assert!(
        error <= 1e-3,
        "relative error {error} after six still frames"
    );
}

/// The camera moves 2 pixels to the right (0.625 units) between two
/// frames: every texel but the two columns entering on the right finds its
/// history 2 pixels to its right and averages it with this frame's value,
/// exactly; the entering ones start again.
#[test]
fn reprojection_keeps_what_a_pure_translation_keeps_in_view() {
    let dir = TempDir::new("denoise-moving");
    let scene = plane_scene(
        &dir.0,
        "\tkey 0  0 0 5   0 0 0\n\tkey 1  0.625 0 5   0.625 0 0\n",
    );
    assert_history_found_shifted(&fixture(&scene, 2), 2);
}

/// After two frames, every texel but the `shift.abs()` columns entering the
/// view (on the right for a positive shift, on the left for a negative one)
/// found its history `shift` pixels along x and averaged it with this
/// frame's value, exactly (within 1e-4 relative); the entering ones start
/// again with no history.
fn assert_history_found_shifted(images: &Images, shift: i32) {
    let mut worst = 0.0f32;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let frames = images.moments[at(x, y, 2)];
            let from = x as i32 + shift;
            if from < 0 || from >= SIZE as i32 {
                assert_eq!(frames, 1.0, "({x}, {y}) entered the view: no history");
                continue;
            }
            assert_eq!(frames, 2.0, "({x}, {y}) stayed in view");
            for c in 0..3 {
                let albedo = images.albedo[at(x, y, c)];
                let now = images.hdr[at(x, y, c)] / albedo;
                let before = images.hdr[at(from as u32, y, c)] / albedo;
                let expected = 0.5 * (now + before);
                let got = images.illumination[at(x, y, c)];
                worst = worst.max((got - expected).abs() / expected.abs().max(1e-3));
            }
        }
    }
    assert!(
        worst <= 1e-4,
        "reprojected history off by {worst} (relative)"
    );
}

/// The plane of `plane_scene` as a script moves it: 0.625 units (2 pixels)
/// to the right per second of scene time, the camera still.
fn moving_plane_scene(dir: &Path) -> PathBuf {
    plane_scene(dir, "");
    let path = dir.join("moving.rhai");
    std::fs::write(
        &path,
        "model(\"plane.obj\", #{});\n\
         camera(\"front\", #{ position: [0, 0, 5], target: [0, 0, 0], fov_deg: 90 });\n\
         sun_light(#{ direction: [0, 0, -1], color: [1, 1, 1] });\n\
         fn update(t, dt) { set_model_transform(0, #{ position: [0.625 * t, 0, 0] }); }\n",
    )
    .expect("script");
    path
}

/// The plane moves 2 pixels to the right between two frames under a still
/// camera: each pixel sees the plane's points where they are now, and
/// finds each point's history where it was, 2 pixels to its left (the
/// guides' motion vectors: its mesh's motion undone), averaging it with
/// this frame's value exactly; the two columns entering on the left start
/// again. Reprojecting by the camera alone would find the history at the
/// same pixel: the same world position, another point of the plane.
#[test]
fn reprojection_follows_a_moving_mesh() {
    let dir = TempDir::new("denoise-moving-mesh");
    let scene = moving_plane_scene(&dir.0);
    assert_history_found_shifted(&fixture(&scene, 2), -2);
}

/// `graph` (to `samples` per pixel where given) at 48 x 48 and `max_depth`
/// 3, after `frames` frames `frame_time` apart, with `features` and
/// `params`: the image `read`, validated.
fn traced(
    scene: &Path,
    (graph, samples): (&str, Option<u64>),
    (frames, frame_time): (u32, f64),
    (features, read): (&[&str], &str),
    params: &[(&str, f64)],
) -> LinearImage {
    let params: Vec<(&str, f64)> = [("max_depth", 3.0)]
        .into_iter()
        .chain(params.iter().copied())
        .collect();
    let mut settings = weft_tests::render::square_settings(graph, 48, samples, &params, features);
    settings.frames = frames;
    settings.frame_time = frame_time;
    weft_tests::render::linear_image_validated(scene, settings, read)
}

/// The path tracer's plain running mean of `samples` per pixel: the raw
/// accumulation the denoiser is measured against, or (at 512) a reference.
fn accumulated(scene: &Path, samples: u64) -> LinearImage {
    traced(
        scene,
        ("pathtrace.ron", Some(samples)),
        (1, 0.0),
        (&[], "hdr"),
        &[],
    )
}

/// The box on a floor under an ambient sky (tests/e2e/rt_ao.rs's scene),
/// path traced at one sample per pixel a frame, against a 512-spp
/// reference: the denoised frame's relative MSE is under half the raw
/// frame's on the first frame (measured 5.40e-2 to 2.69e-2) and under an
/// eighth on the fourth (4.49e-2 to 3.87e-3), and after four still frames
/// the image's mean is the reference's within 1% (measured 1.0009; the
/// first frame alone is 1.2% bright: a bias of filtering one sample). The
/// first frame's error is mostly the silhouette pixels' coverage of the
/// box, which the denoiser leaves to time (shaders/denoise/atrous.comp):
/// filtered among the background's pixels it was 1.29e-2, and a haze.
#[test]
fn on_path_traced_frames_the_error_falls_and_the_mean_holds() {
    let dir = TempDir::new("denoise-noisy");
    let scene = crate::rt_ao::scene(&dir.0);
    let image = |graph: &str, samples: Option<u64>, frames: u32, toggles_read| {
        traced(&scene, (graph, samples), (frames, 0.0), toggles_read, &[])
    };
    let reference = image("pathtrace.ron", Some(512), 1, (&[], "hdr"));
    let mean = |i: &LinearImage| i.pixels.iter().map(|p| f64::from(p[1])).sum::<f64>();
    for frames in [1, 4] {
        let raw = image(
            "pathtrace_denoised.ron",
            None,
            frames,
            (&["!denoise"], "hdr"),
        );
        let denoised = image("pathtrace_denoised.ron", None, frames, (&[], "denoised"));
        let (e_raw, e_denoised) = (
            rel_mse(&raw.pixels, &reference.pixels),
            rel_mse(&denoised.pixels, &reference.pixels),
        );
        let ratio = mean(&denoised) / mean(&reference);
        println!(
            "frame {frames}: relative MSE raw {e_raw:.4e}, denoised {e_denoised:.4e}; mean ratio {ratio:.4}"
        );
        let fall = if frames == 1 { 1.9 } else { 8.0 };
        assert!(
            e_denoised * fall <= e_raw,
            "frame {frames}: raw {e_raw}, denoised {e_denoised}"
        );
        if frames == 4 {
            assert!((ratio - 1.0).abs() <= 0.01, "mean ratio {ratio}");
        }
    }
}

/// The same box with the camera creeping sideways (1 mm a second): every
/// frame is a change, so `history_frames` is 0 each frame, yet each frame
/// path-traces new samples (numbered by the frame), so the denoiser sees
/// noise, and after six such frames the denoised image's relative MSE is
/// still a fourth of the raw frame's or less. With samples numbered from
/// the last change, every frame repeated the first one's samples, the
/// temporal variance was zero, and the noise passed through unfiltered.
#[test]
fn in_a_moving_scene_each_frame_draws_new_samples_and_is_denoised() {
    let dir = TempDir::new("denoise-creeping");
    crate::rt_ao::scene(&dir.0);
    let scene = dir.0.join("creeping.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"box.obj\"\n}\n\
         sunlight\n{\n\tdirection 0 -1 0\n\tcolor 0 0 0\n\tambient 1 1 1\n}\n\
         camera\n{\n\tposition 3 3.5 4\n\ttarget 0 0.5 0\n\tfov_deg 50\n\
         \tkey 0  3 3.5 4  0 0.5 0\n\tkey 10  3.01 3.5 4  0.01 0.5 0\n}\n",
    )
    .expect("scene");
    // The reference at one time; the denoised graph's frames 1/60 s apart.
    let image = |samples: Option<u64>, frames: u32, toggles_read| match samples {
        Some(_) => traced(
            &scene,
            ("pathtrace.ron", samples),
            (frames, 0.0),
            toggles_read,
            &[],
        ),
        None => traced(
            &scene,
            ("pathtrace_denoised.ron", None),
            (frames, 1.0 / 60.0),
            toggles_read,
            &[],
        ),
    };
    let reference = image(Some(512), 1, (&[], "hdr"));
    let first = image(None, 1, (&["!denoise"], "hdr"));
    let second = image(None, 2, (&["!denoise"], "hdr"));
    let denoised = image(None, 6, (&[], "denoised"));
    let raw = image(None, 6, (&["!denoise"], "hdr"));
    let noise = rel_mse(&first.pixels, &reference.pixels);
    let between = rel_mse(&second.pixels, &first.pixels);
    let (e_raw, e_denoised) = (
        rel_mse(&raw.pixels, &reference.pixels),
        rel_mse(&denoised.pixels, &reference.pixels),
    );
    let report = format!(
        "frame 1 against the reference {noise:.4e}, frame 2 against frame 1 {between:.4e}; sixth frame raw {e_raw:.4e}, denoised {e_denoised:.4e}"
    );
    println!("{report}");
    // Independent samples differ by about twice the noise's variance; the
    // same samples a camera 0.3 mm away would differ by next to nothing.
    assert!(between > noise, "{report}");
    assert!(e_denoised * 4.0 <= e_raw, "{report}");
}
