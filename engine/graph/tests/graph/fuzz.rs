//! Mutated graph files never panic the loader, validator or compiler: they either
//! compile or produce located diagnostics.

use crate::support;

use proptest::prelude::*;
use std::path::Path;
use support::{fuzz_cases, repo_root};
use weft_graph::CompileOptions;

/// Applies byte-level edits (delete, duplicate, replace with RON punctuation) at
/// character boundaries.
fn mutate(text: &str, edits: &[(usize, u8, u8)]) -> String {
    const PIECES: &[&str] = &[
        "(",
        ")",
        "[",
        "]",
        "{",
        "}",
        ",",
        ":",
        "\"",
        "$",
        "-",
        "1e999",
        "NaN",
        "Load",
        "\"hdr\"",
        "Scale(0.0, -1.0)",
        "enabled_if: [\"!x\"]",
        "after: [\"tonemap\"]",
        "//",
        "/*",
        "r#\"",
    ];
    let mut chars: Vec<char> = text.chars().collect();
    for &(at, kind, piece) in edits {
        if chars.is_empty() {
            break;
        }
        let at = at % chars.len();
        match kind % 3 {
            0 => {
                let end = (at + 1 + piece as usize % 8).min(chars.len());
                chars.drain(at..end);
            }
            1 => {
                let end = (at + 1 + piece as usize % 16).min(chars.len());
                let copy: Vec<char> = chars[at..end].to_vec();
                chars.splice(at..at, copy);
            }
            _ => {
                let p = PIECES[piece as usize % PIECES.len()];
                chars.splice(at..at, p.chars());
            }
        }
    }
    chars.into_iter().collect()
}

/// Swaps string literals with other string literals of the same file (names,
/// paths, parameter references), so the text stays valid RON and the mistakes
/// reach validation and compilation.
fn swap_strings(text: &str, swaps: &[(usize, usize)]) -> String {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, c) in text.char_indices() {
        if c == '"' {
            match start.take() {
                Some(s) => spans.push((s, i + 1)),
                None => start = Some(i),
            }
        }
    }
    if spans.is_empty() {
        return text.to_string();
    }
    let literals: Vec<&str> = spans.iter().map(|&(a, b)| &text[a..b]).collect();
    let mut replaced: Vec<&str> = literals.clone();
    for &(target, source) in swaps {
        replaced[target % spans.len()] = literals[source % spans.len()];
    }
    let mut out = String::with_capacity(text.len());
    let mut at = 0;
    for (k, &(a, b)) in spans.iter().enumerate() {
        out.push_str(&text[at..a]);
        out.push_str(replaced[k]);
        at = b;
    }
    out.push_str(&text[at..]);
    out
}

fn run(root: &Path, text: String) {
    let read = |p: &Path| {
        if p == root {
            Ok(text.clone())
        } else {
            std::fs::read_to_string(p)
        }
    };
    let graph = weft_graph::load_with(root, &read);
    let diags = weft_graph::check(&graph);
    for d in &diags {
        assert!(d.pos.line >= 1 && d.pos.col >= 1, "unlocated: {d}");
    }
    let _ = weft_graph::compile(&graph, &CompileOptions::default());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: fuzz_cases(400), ..ProptestConfig::default() })]

    #[test]
    fn mutated_graphs_never_panic(
        which in 0usize..2,
        edits in proptest::collection::vec((any::<usize>(), any::<u8>(), any::<u8>()), 1..6),
    ) {
        let name = ["forward.ron", "deferred.ron"][which];
        let root = repo_root().join("graphs").join(name);
        let text = std::fs::read_to_string(&root).expect("shipped graph");
        run(&root, mutate(&text, &edits));
    }

    #[test]
    fn graphs_with_swapped_names_never_panic(
        which in 0usize..2,
        swaps in proptest::collection::vec((any::<usize>(), any::<usize>()), 1..4),
        features in proptest::collection::vec(prop_oneof![
            Just("shadow_casters"), Just("point_lights"), Just("spot_lights"), Just("depth_prepass"), Just("!bloom")
        ], 0..5),
    ) {
        let name = ["forward.ron", "deferred.ron"][which];
        let root = repo_root().join("graphs").join(name);
        let text = std::fs::read_to_string(&root).expect("shipped graph");
        let mutated = swap_strings(&text, &swaps);
        let read = |p: &Path| if p == root { Ok(mutated.clone()) } else { std::fs::read_to_string(p) };
        let graph = weft_graph::load_with(&root, &read);
        let diags = weft_graph::check(&graph);
        for d in &diags {
            prop_assert!(d.pos.line >= 1 && d.pos.col >= 1, "unlocated: {}", d);
        }
        let options = CompileOptions { features: graph.features(&features), ..CompileOptions::default() };
        // `check` tries every feature set of up to ten features and every pair of
        // them on and off beyond that, so a graph it passes compiles for the sets
        // drawn here, and one that fails to compile for one was reported by `check`.
        let checked_clean = !diags.iter().any(|d| d.is_error());
        match weft_graph::compile(&graph, &options) {
            Ok(_) => {}
            Err(errors) => {
                prop_assert!(!errors.is_empty());
                prop_assert!(!checked_clean, "check passed but compile failed: {:?}", errors);
            }
        }
    }
}
