//! Step 3, lifetimes: for each resource, the plan passes that touch it, which
//! resources the plan keeps, and the checks that need both (a write nothing reads,
//! a `store: DontCare` whose contents are needed later).

use super::cull::Roots;
use super::order::Uses;
use crate::diagnostic::Diagnostic;
use crate::id::{IdVec, IrPassId, IrResourceId, PassId, ResourceId};
use crate::load::LoadedGraph;
use crate::resolve::{access_path, Ir, Usage};
use crate::schema::StoreDecl;
use crate::spans::Seg;

/// What the running passes do to each resource, and which resources the plan keeps.
pub(crate) struct Lifetimes {
    pub timeline: Timeline,
    /// IR resources the plan keeps, in declaration order; the plan's index of a
    /// resource is its position here.
    pub kept: IdVec<ResourceId, IrResourceId>,
    /// Per IR resource: its plan id, when kept.
    plan_index: IdVec<IrResourceId, Option<ResourceId>>,
}

impl Lifetimes {
    /// The resources the passes in `sequence` use, and the roots.
    pub fn new(ir: &Ir, sequence: &[IrPassId], uses: &Uses, roots: &Roots) -> Self {
        let timeline = Timeline::new(ir, sequence, uses);
        let mut kept = IdVec::new();
        let mut plan_index = IdVec::filled(None, ir.resources.len());
        for (r, index) in plan_index.iter_enumerated_mut() {
            if roots.is_root[r] || !timeline.per_resource[r].is_empty() {
                *index = Some(kept.push(r));
            }
        }
        Lifetimes {
            timeline,
            kept,
            plan_index,
        }
    }

    /// The plan id of an IR resource the plan uses.
    pub fn plan_index(&self, r: IrResourceId) -> ResourceId {
        self.plan_index[r].expect("every resource a running pass uses is kept")
    }

    /// Warns about writes nothing reads; errors on discarded contents that are needed.
    pub fn check(
        &self,
        graph: &LoadedGraph,
        ir: &Ir,
        sequence: &[IrPassId],
        uses: &Uses,
        roots: &Roots,
        warnings: &mut Vec<Diagnostic>,
    ) -> Result<(), Vec<Diagnostic>> {
        warn_unread(graph, ir, &self.timeline, uses, &roots.is_root, warnings);
        check_discarding_stores(graph, ir, sequence, &self.timeline, uses, &roots.is_root)
    }
}

/// For each resource, the passes that use it in plan order, so per-resource questions
/// cost the resource's uses, not the whole plan.
pub(crate) struct Timeline {
    /// `(plan pass, IR pass, index into that pass's uses)` per resource.
    pub per_resource: IdVec<IrResourceId, Vec<(PassId, IrPassId, usize)>>,
}

impl Timeline {
    fn new(ir: &Ir, sequence: &[IrPassId], uses: &Uses) -> Self {
        let mut per_resource = IdVec::filled(Vec::new(), ir.resources.len());
        for (i, &p) in sequence.iter().enumerate() {
            for (k, u) in uses[p].iter().enumerate() {
                per_resource[u.resource].push((PassId::new(i), p, k));
            }
        }
        Timeline { per_resource }
    }

    /// Whether anything after plan pass `i` needs what it left in resource `r`.
    pub fn needed_later(
        &self,
        ir: &Ir,
        uses: &Uses,
        i: PassId,
        r: IrResourceId,
        is_root: &IdVec<IrResourceId, bool>,
    ) -> bool {
        let touches = &self.per_resource[r];
        let next = touches.partition_point(|t| t.0 <= i);
        match touches.get(next) {
            Some(&(_, p, k)) => uses[p][k].reads_previous || !uses[p][k].discards,
            None => is_root[r] || ir.resources[r].kept_across_frames(),
        }
    }
}

/// Warns about each resource that is written and never read.
fn warn_unread(
    graph: &LoadedGraph,
    ir: &Ir,
    timeline: &Timeline,
    uses: &Uses,
    is_root: &IdVec<IrResourceId, bool>,
    warnings: &mut Vec<Diagnostic>,
) {
    for (r, res) in ir.resources.iter_enumerated() {
        if is_root[r] || res.kept_across_frames() {
            continue;
        }
        let touches = &timeline.per_resource[r];
        let written = touches.iter().any(|&(_, p, k)| uses[p][k].writes);
        // A depth attachment is read by its own depth test, a colour
        // attachment with a resolve target (the access after it) by the
        // resolve, a build's scratch by the build.
        let read = touches.iter().any(|&(_, p, k)| {
            let u = &uses[p][k];
            let accesses = &ir.passes[p].accesses;
            if ir.passes[p].kind == crate::schema::PassKind::BuildAccelerationStructures {
                return true;
            }
            let resolved = |a: usize| {
                accesses[a].usage.is_color_output()
                    && accesses
                        .get(a + 1)
                        .is_some_and(|next| next.usage.is_resolve_target())
            };
            u.reads_previous
                || u.accesses
                    .iter()
                    .any(|&a| matches!(accesses[a].usage, Usage::Depth { .. }) || resolved(a))
        });
        if written && !read {
            let (file, pos) = graph.locate(
                res.source,
                &[
                    Seg::Field("resources"),
                    Seg::Index(res.index),
                    Seg::Field("name"),
                ],
            );
            warnings.push(Diagnostic::warning(
                file,
                pos,
                format!("resource \"{}\" is written and never read", res.name),
            ));
        }
    }
}

/// A declared `store: DontCare` whose contents a later pass needs is an error.
fn check_discarding_stores(
    graph: &LoadedGraph,
    ir: &Ir,
    sequence: &[IrPassId],
    timeline: &Timeline,
    uses: &Uses,
    is_root: &IdVec<IrResourceId, bool>,
) -> Result<(), Vec<Diagnostic>> {
    let mut errors = Vec::new();
    for (i, &p) in sequence.iter().enumerate() {
        let i = PassId::new(i);
        for access in &ir.passes[p].accesses {
            let store = match &access.usage {
                Usage::Color { store, .. }
                | Usage::Depth {
                    store,
                    read_only: false,
                    ..
                } => *store,
                _ => continue,
            };
            if store == StoreDecl::DontCare
                && timeline.needed_later(ir, uses, i, access.resource, is_root)
            {
                let mut path = access_path(ir.passes[p].index, access);
                path.pop();
                path.push(Seg::Field("store"));
                let (file, pos) = graph.locate(ir.passes[p].source, &path);
                errors.push(
                    Diagnostic::error(file, pos, format!(
                        "pass \"{}\" discards \"{}\" with `store: DontCare` but later work needs it",
                        ir.passes[p].name, ir.resources[access.resource].name))
                    .with_hint("use `store: Store` (the compiler already drops stores nothing reads)"),
                );
            }
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}

#[cfg(test)]
mod tests {
    use super::super::cull::{cull, roots};
    use super::super::fixture::{ordered, resource, CHAIN};
    use super::*;
    use std::collections::BTreeSet;

    fn lifetimes_of(text: &str) -> (LoadedGraph, Ir, Lifetimes, Vec<IrPassId>, Roots) {
        let (graph, ir, o) = ordered(text, &[]);
        let roots = roots(&graph, &ir, resource(&ir, "out"), &[], &o).expect("roots");
        let sequence = cull(&graph, &ir, &o, &roots, &BTreeSet::new()).sequence;
        let lifetimes = Lifetimes::new(&ir, &sequence, &o.uses, &roots);
        (graph, ir, lifetimes, sequence, roots)
    }

    #[test]
    fn only_resources_running_passes_use_are_kept_in_declaration_order() {
        let (_, ir, l, _, _) = lifetimes_of(CHAIN);
        assert_eq!(
            l.kept.as_slice(),
            [resource(&ir, "x"), resource(&ir, "out")]
        );
        assert_eq!(l.plan_index(resource(&ir, "out")), ResourceId::new(1));
        let x = &l.timeline.per_resource[resource(&ir, "x")];
        assert_eq!(x.iter().map(|t| t.0.index()).collect::<Vec<_>>(), [0, 1]);
    }

    #[test]
    fn contents_are_needed_later_only_when_a_later_pass_reads_them() {
        let (_, ir, l, _, roots) = lifetimes_of(CHAIN);
        let (x, out) = (resource(&ir, "x"), resource(&ir, "out"));
        let o = ordered(CHAIN, &[]).2;
        assert!(l
            .timeline
            .needed_later(&ir, &o.uses, PassId::new(0), x, &roots.is_root));
        assert!(!l
            .timeline
            .needed_later(&ir, &o.uses, PassId::new(1), x, &roots.is_root));
        assert!(l
            .timeline
            .needed_later(&ir, &o.uses, PassId::new(1), out, &roots.is_root));
    }

    #[test]
    fn discarding_a_needed_image_is_an_error_at_its_store() {
        let text = CHAIN.replace(
            r#"load: Clear([0.0, 0.0, 0.0, 0.0]))"#,
            r#"load: Clear([0.0, 0.0, 0.0, 0.0]), store: DontCare)"#,
        );
        let (graph, ir, l, sequence, roots) = lifetimes_of(&text);
        let o = ordered(&text, &[]).2;
        let mut warnings = Vec::new();
        let errors = l
            .check(&graph, &ir, &sequence, &o.uses, &roots, &mut warnings)
            .expect_err("x is sampled after a DontCare store");
        assert!(errors[0]
            .message
            .contains("pass \"a\" discards \"x\" with `store: DontCare`"));
        assert_eq!(errors[0].pos.line, 10);
    }
}
