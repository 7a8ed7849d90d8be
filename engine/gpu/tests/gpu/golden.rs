//! Golden-image tests: renderings compared with stored PNGs within a stated
//! tolerance (per channel 2/255, mean 0.5/255); a failure writes NAME.diff.png.

use crate::common;

use weft_gpu::Renderer;
use weft_testkit::{check_golden, Tolerance};

const TOLERANCE: Tolerance = Tolerance {
    per_channel: 2,
    mean: 0.5,
};

#[test]
fn mixed_graph_matches_its_golden_image() {
    let gpu = common::gpu();
    let plan = common::compile(&gpu, &common::graph("mixed.ron"), 32, 24);
    let mut renderer = Renderer::new(&gpu).expect("renderer");
    let report = weft_testkit::one_frame(&mut renderer, &plan).expect("frame");
    let image = report.output.expect("readback").to_rgba8();
    let golden =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/mixed_32x24.png");
    if let Err(e) = check_golden(&image, &golden, &TOLERANCE) {
        panic!("{e}");
    }
    drop(renderer);
    common::assert_no_validation_messages(gpu);
}
