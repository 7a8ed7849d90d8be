//! Russian roulette counts as Mitsuba's `path` does: it applies at the
//! `rr_depth`-th surface a path meets and after, so segment `rr_depth + 1` is
//! the first it may cut (docs/pathtrace.md, "Paths"). With `rr_depth` equal to
//! `max_depth` no segment can be cut, and the image is bit for bit the one
//! without roulette; one less, and the last segment may be cut. At
//! `max_depth` 4 that segment only looks for light (its BSDF-sampled ray
//! finding the ceiling light), so it changes the few pixels where a sample's
//! fourth ray found the light: at 16 spp, 32x32, some tens.

use super::*;

#[test]
fn russian_roulette_first_cuts_segment_rr_depth_plus_one() {
    const SIZE: u32 = 32;
    let scene = weft_tests::repo().join("scenes/cornell.scene");
    let render = |rr_depth: f64| {
        render_hdr(
            &scene,
            "pathtrace.ron",
            SIZE,
            Some(16),
            &[("max_depth", 4.0), ("rr_depth", rr_depth)],
            &[],
        )
    };
    let without = render(100.0);
    let at_max_depth = render(4.0);
    let one_less = render(3.0);
    let lit = without.lit_pixels();
    let cut = without.pixels_differing_from(&one_less);
    println!("{lit} lit pixels; rr_depth 3 changes {cut}");
    assert!(lit > (SIZE * SIZE / 2) as usize, "{lit} lit pixels");
    assert_eq!(
        without.pixels_differing_from(&at_max_depth),
        0,
        "rr_depth = max_depth cut a segment"
    );
    assert!(cut > 0, "rr_depth 3 cut no fourth segment");
}
