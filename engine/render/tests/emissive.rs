//! The graphs' `emissive_boost` parameter scales material emission (MTL `Ke`)
//! in linear HDR, the same in forward, deferred and tiled, and only emission.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use weft_gpu::{Gpu, GpuOptions, Pixels};
use weft_graph::plan::Extent;
use weft_graph::schema::ParamValue;
use weft_render::{render, RenderSettings};

/// A folder removed when the test ends.
struct TempDir(PathBuf);

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Writes a quad facing the camera with emission Ke = (0.25, 0.5, 1) and a
/// diffuse Kd = 0.5 lit head-on by a unit sun, returning the scene file.
fn write_scene(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir).expect("temp dir");
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nusemtl glow\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("quad.mtl"),
        "newmtl glow\nKd 0.5 0.5 0.5\nKs 0 0 0\nKe 0.25 0.5 1\n",
    )
    .expect("mtl");
    let scene = dir.join("quad.scene");
    std::fs::write(
        &scene,
        "model\n{\n\tfile \"quad.obj\"\n}\nsunlight\n{\n\tdirection 0 0 -1\n\tcolor 1 1 1\n\tambient 0\n}\ncamera \"front\"\n{\n\tposition 0 0 3\n\ttarget 0 0 0\n\tfov_deg 40\n}\n",
    )
    .expect("scene");
    scene
}

/// The HDR value at the centre of a 16x16 render through `graph`.
fn centre_hdr(scene: &Path, graph: &str, boost: Option<f64>) -> [f32; 3] {
    let scene = weft_scene::load_scene(scene).expect("scene loads");
    let gpu = Gpu::new(&GpuOptions {
        validation: true,
        device: None,
    })
    .expect("device");
    let log = gpu.validation();
    let settings = RenderSettings {
        graph: Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../graphs")
            .join(graph),
        extent: Extent {
            width: 16,
            height: 16,
        },
        features: vec!["!bloom".into()],
        extra_readback: vec!["hdr".into()],
        params: boost
            .map(|b| BTreeMap::from([("emissive_boost".to_string(), ParamValue::Number(b))]))
            .unwrap_or_default(),
        ..RenderSettings::default()
    };
    let rendered = render(&gpu, &scene, &settings).expect("renders");
    drop(gpu);
    assert_eq!(log.messages(), Vec::new());
    let (_, hdr) = &rendered.report.readbacks[0];
    let Pixels::RgbaF32(values) = &hdr.pixels else {
        panic!("hdr is float");
    };
    let at = (8 * 16 + 8) * 4;
    [values[at], values[at + 1], values[at + 2]]
}

#[test]
fn emissive_boost_scales_emission_alone_in_every_graph() {
    let dir = TempDir(std::env::temp_dir().join(format!("weft-emissive-{}", std::process::id())));
    let scene = write_scene(&dir.0);
    for graph in ["forward.ron", "deferred.ron", "tiled.ron"] {
        // Diffuse 0.5 x unit sun head-on, plus Ke: exact in RGBA16F.
        assert_eq!(centre_hdr(&scene, graph, None), [0.75, 1.0, 1.5], "{graph}");
        assert_eq!(
            centre_hdr(&scene, graph, Some(4.0)),
            [1.5, 2.5, 4.5],
            "{graph} with emissive_boost 4"
        );
    }
}
