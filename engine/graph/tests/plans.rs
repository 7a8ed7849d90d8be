//! Every graph in `graphs/`: it checks clean, its text plans match the reviewed
//! snapshots in `tests/snapshots/` (insta: review a change with `cargo insta review`, or
//! accept it with `INSTA_UPDATE=always`),
//! and every plan passes the independent synchronization checker.

mod support;

use std::path::PathBuf;
use support::checker::{check_aliasing, check_plan};
use support::repo_root;
use weft_graph::{CompileOptions, Extent};

const FEATURE_SETS: &[(&str, &[&str])] = &[
    ("default", &[]),
    ("no-bloom", &["!bloom"]),
    (
        "all",
        &[
            "shadow_casters",
            "point_lights",
            "spot_lights",
            "area_lights",
            "depth_prepass",
            "transparent",
        ],
    ),
];

fn graph_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(repo_root().join("graphs"))
        .expect("graphs/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "ron"))
        .collect();
    files.sort();
    files
}

#[test]
fn every_shipped_graph_checks_clean() {
    let files = graph_files();
    assert!(
        files.len() >= 4,
        "expected the shipped graphs, found {files:?}"
    );
    for file in files {
        let diags = weft_graph::check(&weft_graph::load(&file));
        assert!(diags.is_empty(), "{}: {diags:#?}", file.display());
    }
}

#[test]
fn plans_match_snapshots_and_pass_the_checker() {
    let mut compared = 0;
    for file in graph_files() {
        let graph = weft_graph::load(&file);
        if graph.is_fragment {
            continue;
        }
        let stem = file
            .file_stem()
            .and_then(|s| s.to_str())
            .expect("utf-8 name");
        for (label, requested) in FEATURE_SETS {
            let options = CompileOptions {
                extent: Extent {
                    width: 1920,
                    height: 1080,
                },
                features: graph.features(requested),
                ..CompileOptions::default()
            };
            let plan = weft_graph::compile(&graph, &options)
                .unwrap_or_else(|e| panic!("{stem} {label}: {e:#?}"));
            check_plan(&plan, 3).unwrap_or_else(|e| panic!("{stem} {label}: {e}"));
            check_aliasing(&plan).unwrap_or_else(|e| panic!("{stem} {label}: {e}"));
            compared += 1;
            insta::with_settings!({ prepend_module_to_snapshot => false, omit_expression => true }, {
                insta::assert_snapshot!(format!("{stem}-{label}"), weft_graph::text::render(&plan));
            });
        }
    }
    assert_eq!(compared, 9);
}
