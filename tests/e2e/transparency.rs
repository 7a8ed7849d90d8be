//! Transparent materials, in forward's pass that draws every mesh and in
//! deferred's transparent pass after lighting: blended over what lies behind them
//! with their opacity (MTL `d`), in linear HDR.

use weft_tests::render as common;

use std::collections::BTreeMap;

#[test]
fn a_half_transparent_quad_lets_half_the_background_through() {
    let dir = std::env::temp_dir().join(format!("weft-transparency-{}", std::process::id()));
    for graph in ["forward.ron", "deferred.ron"] {
        let quad = |name: &str, d: f32| {
            let scene =
                common::write_quad_scene(&dir.join(name), &format!("Kd 1 1 1\nKs 0 0 0\nd {d}\n"));
            common::centre_hdr(&scene, graph, BTreeMap::new())
        };
        let opaque = quad("opaque", 1.0);
        let glass = quad("glass", 0.5);
        // Kd 1 lit head-on by a unit sun: 1.0; half of it over the black clear colour:
        // 0.5 (R16G16B16A16_SFLOAT stores both exactly).
        assert_eq!(opaque[..3], [1.0, 1.0, 1.0], "{graph}");
        assert_eq!(glass[..3], [0.5, 0.5, 0.5], "{graph}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
