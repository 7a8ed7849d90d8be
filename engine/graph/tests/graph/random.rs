//! Property tests on random graphs of hundreds of passes: every plan passes the
//! independent synchronization checker over several frames, aliased images never
//! share memory while alive, culled passes never feed the output, and removing any
//! one barrier is caught.

use crate::support;

use proptest::prelude::*;
use std::collections::BTreeSet;
use support::checker::{check_aliasing, check_plan};
use support::load_files;
use support::random_graph::random_graph;
use weft_graph::id::{PassId, ResourceId};
use weft_graph::plan::{LoadOp, Plan};
use weft_graph::{CompileOptions, Extent};

fn compile(seed: u64, passes: usize, features: u8) -> Plan {
    let text = random_graph(seed, passes);
    let graph = load_files("random.ron", &[("random.ron", &text)]);
    let diags = weft_graph::check(&graph);
    let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).collect();
    assert!(errors.is_empty(), "seed {seed}: {errors:#?}\n{text}");
    let features: BTreeSet<String> = (0..4)
        .filter(|k| features & (1 << k) != 0)
        .map(|k| format!("f{k}"))
        .collect();
    let options = CompileOptions {
        extent: Extent {
            width: 1280,
            height: 720,
        },
        features,
        ..CompileOptions::default()
    };
    weft_graph::compile(&graph, &options).unwrap_or_else(|e| panic!("seed {seed}: {e:#?}"))
}

/// Resources a plan pass reads (needs the previous contents of).
fn reads(plan: &Plan, pass: PassId) -> BTreeSet<ResourceId> {
    let p = &plan.passes[pass];
    let mut out: BTreeSet<ResourceId> = p.bindings.iter().map(|b| b.resource).collect();
    if let Some(rp) = &p.render_pass {
        out.extend(
            rp.attachments
                .iter()
                .filter(|a| a.load == LoadOp::Load)
                .map(|a| a.resource),
        );
    }
    if let Some((src, _)) = p.transfer {
        out.insert(src);
    }
    out
}

/// Resources a plan pass writes.
fn writes(plan: &Plan, pass: PassId) -> BTreeSet<ResourceId> {
    use weft_graph::plan::BindingKind;
    let p = &plan.passes[pass];
    let mut out: BTreeSet<ResourceId> = p
        .bindings
        .iter()
        .filter(|b| {
            matches!(
                b.kind,
                BindingKind::StorageWrite | BindingKind::StorageReadWrite
            )
        })
        .map(|b| b.resource)
        .collect();
    if let Some(rp) = &p.render_pass {
        out.extend(
            rp.attachments
                .iter()
                .filter(|a| !a.read_only)
                .map(|a| a.resource),
        );
    }
    if let Some((_, dst)) = p.transfer {
        out.insert(dst);
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn random_plans_are_synchronized_aliased_safely_and_culled_exactly(
        seed in any::<u64>(),
        passes in 100usize..300,
        features in 0u8..16,
    ) {
        let plan = compile(seed, passes, features);
        prop_assert_eq!(check_plan(&plan, 3), Ok(()));
        prop_assert_eq!(check_aliasing(&plan), Ok(()));
        // Every pass that runs feeds a later pass or writes the output (history: the next frame).
        for i in plan.passes.ids() {
            let w = writes(&plan, i);
            let feeds = w.contains(&plan.output)
                || w.iter().any(|r| plan.resources[*r].residency == weft_graph::plan::Residency::History)
                || plan.passes.ids().skip(i.index() + 1).any(|j| !reads(&plan, j).is_disjoint(&w));
            prop_assert!(feeds, "seed {}: pass {} contributes nothing", seed, plan.passes[i].name);
        }
        // Culled passes write nothing that a running pass reads.
        let running: BTreeSet<&str> = plan.passes.iter().map(|p| p.name.as_str()).collect();
        for c in &plan.culled {
            prop_assert!(!running.contains(c.name.as_str()));
        }
    }

    #[test]
    fn removing_a_random_barrier_is_caught(seed in any::<u64>(), pick in any::<usize>()) {
        let plan = compile(seed, 120, 0b0101);
        let all: Vec<(PassId, usize)> = plan
            .passes
            .iter_enumerated()
            .flat_map(|(p, pass)| (0..pass.barriers.len()).map(move |b| (p, b)))
            .collect();
        prop_assume!(!all.is_empty());
        let (p, b) = all[pick % all.len()];
        let mut broken = plan.clone();
        broken.passes[p].barriers.remove(b);
        prop_assert!(check_plan(&broken, 2).is_err(), "seed {}: removing barrier {} of {} went unnoticed", seed, b, plan.passes[p].name);
    }
}

#[test]
fn a_thousand_pass_graph_compiles_and_checks() {
    let plan = compile(7, 1000, 0b1111);
    assert!(
        plan.passes.len() > 200,
        "{} passes survived culling",
        plan.passes.len()
    );
    assert_eq!(check_plan(&plan, 2), Ok(()));
    assert_eq!(check_aliasing(&plan), Ok(()));
}
