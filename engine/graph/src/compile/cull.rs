//! Step 2, cull: the roots (the output and the images read back after the frame)
//! and the passes that contribute to them; every other pass is culled, with the
//! reason recorded in the plan and a warning when it is live but useless.

use super::order::{Order, Ordered, Uses};
use super::{conditions_hold, locate, root_file};
use crate::diagnostic::{Diagnostic, Severity};
use crate::id::{IdVec, IrPassId, IrResourceId};
use crate::load::LoadedGraph;
use crate::plan::CulledPass;
use crate::resolve::{Ir, IrKind};
use crate::schema::PassKind;
use crate::spans::{Pos, Seg};
use std::collections::BTreeSet;

/// The resources that must hold valid contents when the frame ends.
pub(crate) struct Roots {
    /// The output first, then the read-back images in the order asked for.
    pub list: Vec<IrResourceId>,
    /// Per IR resource: whether it is a root.
    pub is_root: IdVec<IrResourceId, bool>,
}

/// The output and the images named in `readback`, each of which some live pass writes.
pub(crate) fn roots(
    graph: &LoadedGraph,
    ir: &Ir,
    output: IrResourceId,
    readback: &[String],
    ordered: &Ordered,
) -> Result<Roots, Vec<Diagnostic>> {
    let mut list = vec![output];
    for name in readback {
        match ir
            .resources
            .position(|r| r.name == *name && matches!(r.kind, IrKind::Image { .. }))
        {
            Some(r) if !list.contains(&r) => list.push(r),
            Some(_) => {}
            None => {
                let names = ir.resources.iter().map(|r| r.name.as_str());
                return Err(vec![Diagnostic::error(
                    root_file(graph),
                    Pos { line: 1, col: 1 },
                    format!("cannot read back \"{name}\": the graph has no image of that name"),
                )
                .suggest(name, names)]);
            }
        }
    }
    if let Some(&unwritten) = list.iter().find(|&&r| ordered.order.writers[r].is_empty()) {
        let (file, pos) = graph.locate(0, &[Seg::Field("output")]);
        return Err(vec![Diagnostic::error(
            file,
            pos,
            format!(
                "no pass writes \"{}\", which is read back after the frame",
                ir.resources[unwritten].name
            ),
        )
        .with_hint(
            "the passes that write it may be disabled by `enabled_if` for these features",
        )]);
    }
    let mut is_root = IdVec::filled(false, ir.resources.len());
    for &r in &list {
        is_root[r] = true;
    }
    Ok(Roots { list, is_root })
}

/// The passes that run, in order, and those that do not, with why.
pub(crate) struct Culled {
    /// The passes that run, in execution order.
    pub sequence: Vec<IrPassId>,
    pub culled: Vec<CulledPass>,
    /// A warning for each live pass that contributes nothing.
    pub warnings: Vec<Diagnostic>,
}

/// Why a live pass is culled when nothing it writes reaches a root.
pub(crate) const UNNEEDED: &str = "contributes nothing to the output";

/// Why a live build pass is culled when no live pass reads what it builds.
pub(crate) const NOTHING_TRACES: &str = "no pass that runs traces against what it builds";

/// The warning for live pass `name` culled for [`UNNEEDED`].
pub(crate) fn unneeded_warning(name: &str) -> String {
    format!("pass \"{name}\" is culled: it {UNNEEDED}")
}

/// Keeps the live passes that contribute to a root.
pub(crate) fn cull(
    graph: &LoadedGraph,
    ir: &Ir,
    ordered: &Ordered,
    roots: &Roots,
    features: &BTreeSet<String>,
) -> Culled {
    let needed = contributing(ir, &ordered.order, &ordered.uses, &roots.list);
    let mut culled = Vec::new();
    let mut warnings = Vec::new();
    for (p, pass) in ir.passes.iter_enumerated() {
        let reason = if !ordered.live[p] {
            let failing: Vec<&str> = pass
                .enabled_if
                .iter()
                .filter(|c| !conditions_hold(std::slice::from_ref(c), features))
                .map(String::as_str)
                .collect();
            format!("enabled_if [{}] is false", failing.join(", "))
        } else if !needed[p] && pass.kind == PassKind::BuildAccelerationStructures {
            // It serves whichever passes trace; with none live, it has no work.
            NOTHING_TRACES.to_string()
        } else if !needed[p] {
            let mut d = locate(graph, ir, p, &[Seg::Field("name")]);
            d.severity = Severity::Warning;
            d.message = unneeded_warning(&pass.name);
            warnings.push(d);
            UNNEEDED.to_string()
        } else {
            continue;
        };
        culled.push(CulledPass {
            name: pass.name.clone(),
            reason,
        });
    }
    let sequence = ordered
        .order
        .sequence
        .iter()
        .copied()
        .filter(|&p| needed[p])
        .collect();
    Culled {
        sequence,
        culled,
        warnings,
    }
}

/// Passes that contribute to the roots (the output and images read back): their writers, and transitively the writers
/// of everything a contributing pass reads (history resources: all their writers,
/// since the next frame reads them).
fn contributing(
    ir: &Ir,
    order: &Order,
    uses: &Uses,
    roots: &[IrResourceId],
) -> IdVec<IrPassId, bool> {
    let position = &order.position;
    let mut needed = IdVec::filled(false, ir.passes.len());
    let mut stack: Vec<IrPassId> = roots
        .iter()
        .flat_map(|&r| order.writers[r].iter().copied())
        .collect();
    while let Some(p) = stack.pop() {
        if needed[p] {
            continue;
        }
        needed[p] = true;
        for u in &uses[p] {
            if !u.reads_previous {
                continue;
            }
            let history = ir.resources[u.resource].history;
            for &w in &order.writers[u.resource] {
                if w != p && (history || position[w] < position[p]) {
                    stack.push(w);
                }
            }
        }
    }
    needed
}

#[cfg(test)]
mod tests {
    use super::super::fixture::{ordered, pass, resource, CHAIN};
    use super::*;

    #[test]
    fn passes_that_feed_no_root_are_culled_with_a_warning() {
        let (graph, ir, o) = ordered(CHAIN, &[]);
        let roots = roots(&graph, &ir, resource(&ir, "out"), &[], &o).expect("roots");
        let culled = cull(&graph, &ir, &o, &roots, &BTreeSet::new());
        assert_eq!(culled.sequence, vec![pass(&ir, "a"), pass(&ir, "b")]);
        let reasons: Vec<(&str, &str)> = culled
            .culled
            .iter()
            .map(|c| (c.name.as_str(), c.reason.as_str()))
            .collect();
        assert_eq!(
            reasons,
            [
                ("c", "contributes nothing to the output"),
                ("d", "enabled_if [extra] is false")
            ]
        );
        assert_eq!(culled.warnings.len(), 1);
        assert_eq!(culled.warnings[0].severity, Severity::Warning);
    }

    #[test]
    fn a_read_back_image_is_a_root_and_keeps_its_writer() {
        let (graph, ir, o) = ordered(CHAIN, &[]);
        let out = resource(&ir, "out");
        let roots = roots(&graph, &ir, out, &["unused".into()], &o).expect("roots");
        assert_eq!(roots.list, vec![out, resource(&ir, "unused")]);
        let culled = cull(&graph, &ir, &o, &roots, &BTreeSet::new());
        assert_eq!(culled.sequence, ir.passes.ids().take(3).collect::<Vec<_>>());
        assert!(culled.warnings.is_empty());
    }

    #[test]
    fn an_unknown_read_back_name_is_an_error_with_a_suggestion() {
        let (graph, ir, o) = ordered(CHAIN, &[]);
        let Err(errors) = roots(&graph, &ir, resource(&ir, "out"), &["unsed".into()], &o) else {
            panic!("no image called unsed");
        };
        assert!(errors[0].message.contains("cannot read back \"unsed\""));
        assert_eq!(errors[0].hint.as_deref(), Some("did you mean \"unused\"?"));
    }
}
