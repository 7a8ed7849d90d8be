//! The wavefront path tracer (graphs/pathtrace_wavefront.ron) traces the
//! megakernel's paths (graphs/pathtrace.ron) a segment per dispatch, with the
//! same path_segment, random numbers and running mean: for the same seed the
//! two images are the same, bit for bit. The scenes cover every part of the
//! state the queue carries between segments: area lights and MIS weights
//! (Cornell), glass with Snell-bent NEE and lights chosen by power
//! (caustics), punctual lights chosen through the light tree with BSDF
//! sampling alone and Russian roulette from the third segment (demo, `rr_depth` 2), and a medium's absorption carried across
//! up to 16 segments (the Beer slab).

use super::*;

/// A scene's name, its file and the parameters both graphs render it with.
type Case = (&'static str, PathBuf, &'static [(&'static str, f64)]);

#[test]
fn the_wavefront_traces_the_megakernels_paths_bit_for_bit() {
    const SIZE: u32 = 32;
    let repo = weft_tests::repo();
    let cases: [Case; 4] = [
        ("cornell", repo.join("scenes/cornell.scene"), &[]),
        (
            "caustics",
            repo.join("scenes/caustics.scene"),
            &[("nee_through_glass", 1.0), ("light_choice", 1.0)],
        ),
        (
            "demo",
            repo.join("scenes/demo.scene"),
            &[
                ("sampling", 2.0),
                ("rr_depth", 2.0),
                ("seed", 3.0),
                ("light_choice", 2.0),
            ],
        ),
        (
            "slab",
            super::glass::absorbing_slab_scene(),
            &[("max_depth", 16.0)],
        ),
    ];
    for (name, scene, params) in cases {
        let megakernel = render_hdr(&scene, "pathtrace.ron", SIZE, Some(3), params, &[]);
        let wavefront = render_hdr(
            &scene,
            "pathtrace_wavefront.ron",
            SIZE,
            Some(3),
            params,
            &[],
        );
        let lit = megakernel.lit_pixels();
        let differing = megakernel.pixels_differing_from(&wavefront);
        println!("{name}: {lit} lit pixels, {differing} differ");
        assert!(lit > (SIZE * SIZE / 4) as usize, "{name}: {lit} lit pixels");
        assert_eq!(differing, 0, "{name}: pixels that differ");
    }
}
