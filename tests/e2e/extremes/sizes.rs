//! Extreme sizes: one-pixel, one-column and one-row outputs, the largest
//! output and the smallest and largest shadow maps.

use super::*;

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
