//! Compile-time benchmarks (`make bench`): the shipped deferred graph with shadows
//! and bloom, and a random 1,000-pass graph: compiling a validated graph (what a
//! resize or feature toggle costs), validation plus compilation, and for the
//! deferred graph also loading (RON parsing) plus both.

#[path = "../tests/graph/support/random_graph.rs"]
mod random_graph;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use std::path::{Path, PathBuf};
use weft_graph::{CompileOptions, Extent};

fn deferred() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../graphs/deferred.ron")
}

fn bench(c: &mut Criterion) {
    let graph = weft_graph::load(&deferred());
    let options = CompileOptions {
        extent: Extent {
            width: 1920,
            height: 1080,
        },
        features: graph.features(&["shadow_casters", "point_lights", "spot_lights"]),
        ..CompileOptions::default()
    };
    let prepared = weft_graph::Prepared::new(graph.clone()).expect("valid");
    c.bench_function("compile deferred+shadows+bloom 1920x1080", |b| {
        b.iter(|| black_box(&prepared).compile(&options).expect("compiles"))
    });
    c.bench_function("validate+compile deferred+shadows+bloom 1920x1080", |b| {
        b.iter(|| weft_graph::compile(black_box(&graph), &options).expect("compiles"))
    });
    c.bench_function("load+compile deferred+shadows+bloom 1920x1080", |b| {
        b.iter(|| {
            let g = weft_graph::load(&deferred());
            weft_graph::compile(&g, &options).expect("compiles")
        })
    });

    let text = random_graph::random_graph(7, 1000);
    let read = move |_: &Path| Ok(text.clone());
    let random = weft_graph::load_with(Path::new("random.ron"), &read);
    let random_options = CompileOptions {
        features: ["f0", "f1", "f2", "f3"]
            .iter()
            .map(|s| s.to_string())
            .collect(),
        ..CompileOptions::default()
    };
    let prepared = weft_graph::Prepared::new(random.clone()).expect("valid");
    c.bench_function("compile random 1000-pass graph", |b| {
        b.iter(|| {
            black_box(&prepared)
                .compile(&random_options)
                .expect("compiles")
        })
    });
    c.bench_function("validate+compile random 1000-pass graph", |b| {
        b.iter(|| weft_graph::compile(black_box(&random), &random_options).expect("compiles"))
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
