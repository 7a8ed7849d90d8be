//! Where `weft bench` writes its figures.

use crate::harness::{command_in, repo};
use std::path::Path;

/// `weft bench pathtrace` at 8x8, 2 spp, max_depth 2, with `extra`
/// arguments, run in the repository with `cache` as the user cache: whether
/// it succeeded, and everything it said.
fn bench_pathtrace(extra: &[&str], cache: &Path) -> (bool, String) {
    let mut args = vec![
        "bench",
        "pathtrace",
        "--size",
        "8x8",
        "--spp",
        "2",
        "--max-depth",
        "2",
    ];
    args.extend_from_slice(extra);
    let output = command_in(&repo(), &args)
        .env("WEFT_CACHE_DIR", cache)
        .output()
        .expect("weft runs");
    let said = format!(
        "{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    (output.status.success(), said)
}

/// Without `--out-dir` a benchmark writes into the user cache and says so;
/// run inside the repository, it leaves the committed figures in `docs/` as
/// they are.
#[test]
fn bench_figures_go_to_the_user_cache_unless_an_out_dir_is_given() {
    let cache =
        crate::harness::scratch_path(&format!("weft-cli-bench-cache-{}", std::process::id()));
    let committed = repo().join("docs/pathtrace_bench.csv");
    let before = std::fs::read(&committed).expect("docs/pathtrace_bench.csv");
    let (succeeded, said) = bench_pathtrace(&[], &cache);
    assert!(succeeded, "{said}");
    let csv = cache.join("bench/pathtrace/pathtrace_bench.csv");
    let text =
        std::fs::read_to_string(&csv).unwrap_or_else(|e| panic!("{}: {e}\n{said}", csv.display()));
    assert!(
        text.starts_with("spp,seconds,samples_per_second,rel_mse\n2,"),
        "{text}"
    );
    assert!(said.contains(&csv.display().to_string()), "{said}");
    assert_eq!(std::fs::read(&committed).expect("docs csv"), before);
    std::fs::remove_dir_all(&cache).expect("remove the test's cache");
}

/// The wavefront path tracer takes one sample a frame and declares no
/// `samples_per_frame`: `weft bench pathtrace --graph` benchmarks it all the
/// same (the bench used to set that parameter on every graph, which the
/// wavefront graph refused).
#[test]
fn the_path_tracer_bench_takes_a_graph_without_samples_per_frame() {
    let out =
        crate::harness::scratch_path(&format!("weft-cli-bench-wavefront-{}", std::process::id()));
    let (succeeded, said) = bench_pathtrace(
        &[
            "--graph",
            "graphs/pathtrace_wavefront.ron",
            "--out-dir",
            out.to_str().expect("utf-8 path"),
        ],
        &out.join("cache"),
    );
    assert!(succeeded, "{said}");
    let text = std::fs::read_to_string(out.join("pathtrace_bench.csv")).expect("the csv");
    assert!(
        text.starts_with("spp,seconds,samples_per_second,rel_mse\n2,"),
        "{text}"
    );
    std::fs::remove_dir_all(&out).expect("remove the test's output");
}
