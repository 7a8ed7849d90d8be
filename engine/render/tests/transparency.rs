//! Transparent materials, in forward's pass that draws every mesh and in
//! deferred's transparent pass after lighting: blended over what lies behind them
//! with their opacity (MTL `d`), in linear HDR.

use std::path::Path;
use weft_gpu::{Gpu, GpuOptions, Pixels};
use weft_graph::plan::Extent;
use weft_render::{render, RenderSettings};

/// Writes a scene with one white quad facing the camera, lit head-on by a white
/// sun, with dissolve `d`, and returns the HDR value at the centre.
fn centre_hdr(dir: &Path, graph: &str, d: f32) -> [f32; 4] {
    std::fs::create_dir_all(dir).expect("temp dir");
    std::fs::write(
        dir.join("quad.obj"),
        "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvn 0 0 1\nusemtl glass\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\n",
    )
    .expect("obj");
    std::fs::write(
        dir.join("quad.mtl"),
        format!("newmtl glass\nKd 1 1 1\nKs 0 0 0\nd {d}\n"),
    )
    .expect("mtl");
    std::fs::write(
        dir.join("quad.scene"),
        "model\n{\n\tfile \"quad.obj\"\n}\nsunlight\n{\n\tdirection 0 0 -1\n\tcolor 1 1 1\n\tambient 0\n}\ncamera \"front\"\n{\n\tposition 0 0 3\n\ttarget 0 0 0\n\tfov_deg 40\n}\n",
    )
    .expect("scene");
    let scene = weft_scene::load_scene(&dir.join("quad.scene")).expect("scene loads");
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
    [values[at], values[at + 1], values[at + 2], values[at + 3]]
}

#[test]
fn a_half_transparent_quad_lets_half_the_background_through() {
    let dir = std::env::temp_dir().join(format!("weft-transparency-{}", std::process::id()));
    for graph in ["forward.ron", "deferred.ron"] {
        let opaque = centre_hdr(&dir.join("opaque"), graph, 1.0);
        let glass = centre_hdr(&dir.join("glass"), graph, 0.5);
        // Kd 1 lit head-on by a unit sun: 1.0; half of it over the black clear colour:
        // 0.5 (R16G16B16A16_SFLOAT stores both exactly).
        assert_eq!(opaque[..3], [1.0, 1.0, 1.0], "{graph}");
        assert_eq!(glass[..3], [0.5, 0.5, 0.5], "{graph}");
    }
    std::fs::remove_dir_all(&dir).expect("clean up");
}
