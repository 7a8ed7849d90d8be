//! Layout tracking through a compiled plan's barriers (no device needed).

use std::path::Path;
use weft_gpu::layouts::layout_at;
use weft_graph::plan::Extent;
use weft_graph::vk::Layout;
use weft_graph::CompileOptions;

#[test]
fn layouts_follow_the_plan_barriers() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/graphs/mixed.ron");
    let loaded = weft_graph::load(&path);
    let options = CompileOptions {
        extent: Extent {
            width: 8,
            height: 8,
        },
        ..CompileOptions::default()
    };
    let plan = weft_graph::compile(&loaded, &options).expect("compiles");
    let pass = |name: &str| plan.passes.position(|p| p.name == name).expect("pass");
    let inverted = plan.resource("inverted").expect("inverted");
    let half = plan.resource("half").expect("half");
    assert_eq!(layout_at(&plan, pass("fill"), inverted), Layout::Undefined);
    assert_eq!(layout_at(&plan, pass("invert"), inverted), Layout::General);
    assert_eq!(
        layout_at(&plan, pass("combine"), inverted),
        Layout::ShaderReadOnlyOptimal
    );
    assert_eq!(
        layout_at(&plan, pass("shrink"), half),
        Layout::TransferDstOptimal
    );
    assert_eq!(layout_at(&plan, pass("invert"), half), Layout::General);
}
