//! Many lights: a generated 1,000-light scene (`weft_render::light_scene`, seed
//! 1) rendered at 320x180 through forward, deferred (light volumes) and tiled
//! shading under validation and synchronization validation (zero messages).
//! RGB channel differences in 8-bit units: forward vs deferred and tiled vs
//! deferred each within mean <= 0.25 and 99th percentile <= 1; tiled also
//! against its golden image. The light heat map (`light_heatmap`) is checked
//! exactly: per-tile counts read back against the CPU mirror of the culling test
//! (`weft_render::tiles`) on a scene of known lights, and the legend's pixels.

mod common;

use common::{agreement, graph, render_validated};
use std::path::{Path, PathBuf};

/// A fresh folder under the system temp folder for this test's scene files.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("weft-lights-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn golden(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/golden")
        .join(name)
}

#[test]
fn a_thousand_lights_agree_across_forward_deferred_and_tiled() {
    let dir = scratch("agree");
    let scene = weft_render::light_scene::write_light_scene(&dir, 1000, 1).unwrap();
    let forward = render_validated(&scene, &graph("forward.ron"), 320, 180, &["!bloom"]);
    let deferred = render_validated(&scene, &graph("deferred.ron"), 320, 180, &["!bloom"]);
    let tiled = render_validated(&scene, &graph("tiled.ron"), 320, 180, &["!bloom"]);
    std::fs::remove_dir_all(&dir).unwrap();
    for out in [&forward, &deferred, &tiled] {
        assert_eq!(out.messages, Vec::new());
    }
    assert_eq!(
        tiled.passes,
        ["gbuffer", "shadow_sun", "cull_lights", "shade", "tonemap"]
    );
    let fd = agreement(&forward.image, &deferred.image);
    let td = agreement(&tiled.image, &deferred.image);
    eprintln!("forward vs deferred {fd:?}; tiled vs deferred {td:?}");
    assert!(fd.mean <= 0.25 && fd.p99 <= 1, "forward vs deferred: {fd:?}");
    assert!(td.mean <= 0.25 && td.p99 <= 1, "tiled vs deferred: {td:?}");
    // The lights light the scene: not a comparison of two black images.
    let lit = tiled.image.pixels().filter(|p| p.0[0] > 32).count();
    assert!(lit > 320 * 180 / 4, "{lit} lit pixels");
    if let Err(e) = weft_gpu::check_golden(
        &tiled.image,
        &golden("lights1000_tiled_320x180.png"),
        &weft_gpu::Tolerance {
            per_channel: 12,
            mean: 0.5,
        },
    ) {
        panic!("{e}");
    }
}
