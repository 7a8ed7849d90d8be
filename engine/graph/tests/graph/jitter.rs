//! The camera jitter a graph declares (`jitter` in the file): it holds only
//! under its features, and the plan text says so.

use crate::support::repo_root;
use weft_graph::CompileOptions;

/// forward.ron jitters the camera under `taa` (taa.ron's `jitter`) and
/// only then, and its plan text says so.
#[test]
fn the_camera_is_jittered_only_under_the_features_that_ask_for_it() {
    let graph = weft_graph::load(&repo_root().join("graphs/forward.ron"));
    let plan = |toggles: &[&str]| {
        let options = CompileOptions {
            features: graph.features(toggles),
            ..CompileOptions::default()
        };
        weft_graph::compile(&graph, &options).expect("compiles")
    };
    assert!(!plan(&[]).camera_jitter);
    let jittered = plan(&["taa"]);
    assert!(jittered.camera_jitter);
    assert!(weft_graph::text::render(&jittered)
        .contains("\ncamera jittered each frame by a sub-pixel Halton (2, 3) offset\n"));
}
