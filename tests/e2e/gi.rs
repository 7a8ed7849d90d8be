//! Ray-traced one-bounce diffuse GI (graphs/gi.ron, feature `gi`): the
//! deferred and tiled graphs take what `gi.rays` cosine rays per pixel bring
//! back (the sky where they escape, the light a surface they meet reflects)
//! as the radiance of the surroundings. An open room of Lambertian walls
//! (red, green, white) under a low sun and an ambient sky: with `gi`, the
//! raster image is the path tracer's at `max_depth=3` (paths of at most
//! three segments) within the reference's noise, where without it the walls
//! and floor miss a large share of their light. On a floor alone every ray
//! escapes, so `gi` brings back exactly the ambient sky: the image is the
//! one without `gi`, bit for bit. Still frames average like more rays, and
//! the denoiser after the lighting (`denoise`) brings four frames of one
//! ray far closer to the converged image than averaging them does.

use std::path::{Path, PathBuf};
use weft_compare::{hdr_flip, luminance_ratio, rel_mse, LinearImage};
use weft_tests::TempDir;

const SIZE: u32 = 48;

/// Writes `obj` quads (each four corners, wound to face the camera side)
/// with their materials and a scene around them: a sun of colour `sun`
/// shining along (1, -2, -1) with ambient `ambient`, and a camera looking
/// into the room from the open front.
fn write_scene(dir: &Path, quads: &[(&str, [[f32; 3]; 4])], sun: f32, ambient: f32) -> PathBuf {
    std::fs::write(
        dir.join("room.mtl"),
        "newmtl white\nKd 0.8 0.8 0.8\nKs 0 0 0\n\
         newmtl red\nKd 0.8 0.1 0.1\nKs 0 0 0\n\
         newmtl green\nKd 0.1 0.8 0.1\nKs 0 0 0\n",
    )
    .expect("mtl");
    let mut obj = String::from("mtllib room.mtl\n");
    for (k, (material, corners)) in quads.iter().enumerate() {
        obj += &format!("usemtl {material}\n");
        for c in corners {
            obj += &format!("v {} {} {}\n", c[0], c[1], c[2]);
        }
        let v = 1 + 4 * k;
        obj += &format!("f {} {} {}\nf {} {} {}\n", v, v + 1, v + 2, v, v + 2, v + 3);
    }
    std::fs::write(dir.join("room.obj"), obj).expect("obj");
    let path = dir.join("room.scene");
    std::fs::write(
        &path,
        format!(
            "model\n{{\n\tfile \"room.obj\"\n}}\n\
             sunlight\n{{\n\tdirection 1 -2 -1\n\tcolor {sun} {sun} {sun}\n\tambient {ambient} {ambient} {ambient}\n}}\n\
             camera\n{{\n\tposition 0 2 7\n\ttarget 0 1.2 0\n\tfov_deg 55\n}}\n"
        ),
    )
    .expect("scene");
    path
}

/// A white floor, a red wall on the left, a green one on the right and a
/// white back wall; open at the top and the front, so the sun reaches in
/// and half the sky is seen from the floor.
fn room(dir: &Path) -> PathBuf {
    let floor = [
        [-2.0, 0.0, 2.0],
        [2.0, 0.0, 2.0],
        [2.0, 0.0, -2.0],
        [-2.0, 0.0, -2.0],
    ];
    let left = [
        [-2.0, 0.0, -2.0],
        [-2.0, 3.0, -2.0],
        [-2.0, 3.0, 2.0],
        [-2.0, 0.0, 2.0],
    ];
    let right = [
        [2.0, 0.0, 2.0],
        [2.0, 3.0, 2.0],
        [2.0, 3.0, -2.0],
        [2.0, 0.0, -2.0],
    ];
    let back = [
        [-2.0, 0.0, -2.0],
        [2.0, 0.0, -2.0],
        [2.0, 3.0, -2.0],
        [-2.0, 3.0, -2.0],
    ];
    write_scene(
        dir,
        &[
            ("white", floor),
            ("red", left),
            ("green", right),
            ("white", back),
        ],
        2.0,
        0.25,
    )
}

/// The HDR image of `scene` through shipped `graph` after `frames` frames at
/// one fixed time (denoised under `denoise`), validated, bloom off.
fn render(
    scene: &Path,
    graph: &str,
    samples: Option<u64>,
    frames: u32,
    params: &[(&str, f64)],
    features: &[&str],
) -> LinearImage {
    let mut settings =
        weft_tests::render::square_settings_without_bloom(graph, SIZE, samples, params, features);
    settings.frames = frames;
    settings.frame_time = 0.0;
    // The lit image, or the denoiser's output where it runs.
    let image = if features.contains(&"denoise") {
        "denoised"
    } else {
        "hdr"
    };
    weft_tests::render::linear_image_validated(scene, settings, image)
}

/// Mean of every channel over the pixels whose reference value is lit and
/// whose 3 x 3 neighbourhood in the reference holds no edge (no neighbour
/// differs by more than a quarter), so the raster graphs' unfiltered edges
/// do not count.
fn interior_mean(reference: &LinearImage, image: &LinearImage) -> (f64, f64) {
    let (w, h) = (reference.width, reference.height);
    let lum = |img: &LinearImage, i: usize| {
        let p = img.pixels[i];
        f64::from(p[0] + p[1] + p[2])
    };
    let (mut sum_ref, mut sum_img) = (0.0, 0.0);
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            let i = (y * w + x) as usize;
            if lum(reference, i) > 0.0 && weft_tests::render::flat_at(reference, x, y, 0.25) {
                sum_ref += lum(reference, i);
                sum_img += lum(image, i);
            }
        }
    }
    (sum_ref, sum_img)
}

#[test]
fn gi_makes_the_raster_image_the_references_at_three_segments() {
    let dir = TempDir::new("gi-room");
    let scene = room(&dir.0);
    let reference = render(
        &scene,
        "pathtrace.ron",
        Some(1024),
        1,
        &[("max_depth", 3.0)],
        &[],
    );
    let mut report = Vec::new();
    for graph in ["deferred.ron", "tiled.ron"] {
        // rt_shadows: the reference's exact sun shadows, so what differs is
        // the indirect light alone.
        let direct = render(&scene, graph, None, 1, &[], &["rt_shadows"]);
        let gi = render(
            &scene,
            graph,
            None,
            1,
            &[("gi.rays", 256.0)],
            &["rt_shadows", "gi"],
        );
        let (reference_sum, direct_sum) = interior_mean(&reference, &direct);
        let (_, gi_sum) = interior_mean(&reference, &gi);
        let (ratio_direct, ratio_gi) = (direct_sum / reference_sum, gi_sum / reference_sum);
        let (flip_direct, flip_gi) = (
            hdr_flip(&reference, &direct).mean,
            hdr_flip(&reference, &gi).mean,
        );
        report.push(format!(
            "{graph}: interior mean ratio {ratio_direct:.4} -> {ratio_gi:.4}, HDR-FLIP {flip_direct:.4} -> {flip_gi:.4}"
        ));
        assert!(ratio_direct < 0.9, "{report:#?}");
        assert!((ratio_gi - 1.0).abs() < 0.01, "{report:#?}");
        assert!(flip_gi < 0.6 * flip_direct, "{report:#?}");
    }
    println!("{report:#?}");
}

#[test]
fn gi_on_an_open_floor_is_the_ambient_sky_exactly() {
    let dir = TempDir::new("gi-floor");
    let floor = [
        [-8.0, 0.0, 8.0],
        [8.0, 0.0, 8.0],
        [8.0, 0.0, -8.0],
        [-8.0, 0.0, -8.0],
    ];
    // Ambient 1: any mean of rays that all escape is exactly 1.
    let scene = write_scene(&dir.0, &[("white", floor)], 2.0, 1.0);
    for graph in ["deferred.ron", "tiled.ron"] {
        let plain = render(&scene, graph, None, 1, &[], &[]);
        let gi = render(&scene, graph, None, 3, &[("gi.rays", 16.0)], &["gi"]);
        let lit = plain.pixels.iter().filter(|p| p[1] > 0.0).count();
        assert!(lit > plain.pixels.len() / 3, "{graph}: {lit} lit pixels");
        assert_eq!(plain.pixels, gi.pixels, "{graph}");
    }
}

fn rmse(a: &LinearImage, b: &LinearImage) -> f64 {
    weft_compare::rmse(&a.pixels, &b.pixels)
}

/// With `gi.frames` 8, eight still frames of 4 rays average like one frame
/// of 32: against 1,024 rays their error is that of 32 rays (within 25%);
/// with `frames` 1 the eighth frame is as noisy as the first.
#[test]
fn gi_accumulates_over_still_frames() {
    let dir = TempDir::new("gi-frames");
    let scene = room(&dir.0);
    let gi = |frames: u32, params: &[(&str, f64)]| {
        render(&scene, "deferred.ron", None, frames, params, &["gi"])
    };
    let truth = gi(1, &[("gi.rays", 1024.0)]);
    let one_of_4 = rmse(&gi(1, &[("gi.rays", 4.0)]), &truth);
    let one_of_32 = rmse(&gi(1, &[("gi.rays", 32.0)]), &truth);
    let eight_of_4 = rmse(&gi(8, &[("gi.rays", 4.0), ("gi.frames", 8.0)]), &truth);
    let eighth_alone = rmse(&gi(8, &[("gi.rays", 4.0), ("gi.frames", 1.0)]), &truth);
    let report = format!(
        "RMSE against 1,024 rays: 4 rays {one_of_4:.5}, 32 rays {one_of_32:.5}, 8 frames of 4 {eight_of_4:.5}, the 8th frame alone {eighth_alone:.5}"
    );
    println!("{report}");
    assert!((eight_of_4 / one_of_32 - 1.0).abs() < 0.25, "{report}");
    assert!(eight_of_4 < 0.5 * one_of_4, "{report}");
    assert!((eighth_alone / one_of_4 - 1.0).abs() < 0.25, "{report}");
}

/// Four still frames of one ray a pixel, through deferred with `gi` and
/// `rt_shadows`: averaged by gi's own history, and denoised (gi then keeps
/// each frame's rays and the SVGF-style denoiser filters the lit image).
/// Against the converged image (1,024 rays, no denoiser) the denoised
/// frame's relative MSE is under 0.3 of the averaged one's (measured
/// 0.03013 to 0.00794, 0.264; 0.257 with 5x5 taps in every à-trous step,
/// 0.249 while the denoiser's reprojection leaked a little of each
/// neighbour's history into still pixels, a blur of its own), and its light
/// within 1% of the converged image's.
#[test]
fn denoising_after_gi_cuts_its_error_and_keeps_the_light() {
    let dir = TempDir::new("gi-denoise");
    let scene = room(&dir.0);
    let converged = render(
        &scene,
        "deferred.ron",
        None,
        1,
        &[("gi.rays", 1024.0), ("gi.frames", 1.0)],
        &["rt_shadows", "gi"],
    );
    let averaged = render(&scene, "deferred.ron", None, 4, &[], &["rt_shadows", "gi"]);
    let denoised = render(
        &scene,
        "deferred.ron",
        None,
        4,
        &[],
        &["rt_shadows", "gi", "denoise"],
    );
    let (error_averaged, error_denoised) = (
        rel_mse(&averaged.pixels, &converged.pixels),
        rel_mse(&denoised.pixels, &converged.pixels),
    );
    let ratio = luminance_ratio(&denoised.pixels, &converged.pixels);
    let report = format!(
        "relative MSE against 1,024 rays: 4 frames averaged {error_averaged:.5}, denoised {error_denoised:.5}; denoised luminance ratio {ratio:.4}"
    );
    println!("{report}");
    assert!(error_denoised <= 0.3 * error_averaged, "{report}");
    assert!((ratio - 1.0).abs() < 0.01, "{report}");
}
