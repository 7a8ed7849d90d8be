//! The graphs' `emissive_boost` parameter scales material emission (MTL `Ke`)
//! in linear HDR, the same in forward, deferred and tiled, and only emission.

use weft_tests::render as common;

use std::collections::BTreeMap;
use std::path::PathBuf;
use weft_graph::schema::ParamValue;

/// A folder removed when the test ends.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

#[test]
fn emissive_boost_scales_emission_alone_in_every_graph() {
    let dir = TempDir(std::env::temp_dir().join(format!("weft-emissive-{}", std::process::id())));
    // Diffuse Kd = 0.5 lit head-on by the unit sun, plus emission Ke.
    let scene = common::write_quad_scene(&dir.0, "Kd 0.5 0.5 0.5\nKs 0 0 0\nKe 0.25 0.5 1\n");
    let boost = |b: f64| BTreeMap::from([("emissive_boost".to_string(), ParamValue::Number(b))]);
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        // Exact in RGBA16F.
        let plain = common::centre_hdr(&scene, graph, BTreeMap::new());
        assert_eq!(plain[..3], [0.75, 1.0, 1.5], "{graph}");
        let boosted = common::centre_hdr(&scene, graph, boost(4.0));
        assert_eq!(
            boosted[..3],
            [1.5, 2.5, 4.5],
            "{graph} with emissive_boost 4"
        );
    }
}
