//! Images besides the output read back after the frame (`CompileOptions::readback`),
//! as EXR output of the HDR buffer needs.

use crate::common;

use weft_gpu::{memory_requirements, Renderer};
use weft_graph::plan::Extent;
use weft_graph::CompileOptions;

#[test]
fn intermediate_images_are_read_back_with_the_output() {
    let gpu = common::gpu();
    let loaded = weft_graph::load(&common::graph("mixed.ron"));
    let memory = memory_requirements(&gpu);
    let options = CompileOptions {
        extent: Extent {
            width: 8,
            height: 8,
        },
        memory: &memory,
        readback: vec!["half".into(), "inverted".into()],
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&loaded, &options).expect("compiles");
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let report = weft_testkit::one_frame(&mut renderer, &plan).expect("frame");
    let names: Vec<&str> = report.readbacks.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names, ["half", "inverted"]);
    let (half, inverted) = (&report.readbacks[0].1, &report.readbacks[1].1);
    assert_eq!((half.width, half.height), (8, 8));
    let mut distinct = std::collections::BTreeSet::new();
    for y in 0..8 {
        for x in 0..8 {
            let h = half.rgba8_at(x, y);
            let i = inverted.rgba8_at(x, y);
            assert_eq!(
                i,
                [255 - h[0], 255 - h[1], 255 - h[2], 255],
                "pixel ({x}, {y})"
            );
            distinct.insert(h);
        }
    }
    assert!(distinct.len() > 8, "the blitted pattern varies");
    assert!(report.output.is_some());
    drop(renderer);
    let counts = gpu.validation_counts();
    assert_eq!(
        (counts.errors, counts.warnings),
        (0, 0),
        "{:?}",
        gpu.validation().messages()
    );
}
