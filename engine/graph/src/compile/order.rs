//! Step 1, order: which passes and accesses the features make live, and their
//! execution order from data: edges from writers to readers (and from history
//! readers to this frame's writer), explicit `after`, a stable topological sort,
//! and the checks that need an order (cycles, unordered writers, reads of nothing)
//! as located diagnostics.

use super::{conditions_hold, locate};
use crate::diagnostic::Diagnostic;
use crate::id::{IdVec, IrPassId, IrResourceId};
use crate::load::LoadedGraph;
use crate::resolve::{access_path, Ir, IrKind, Usage};
use crate::spans::Seg;
use std::cmp::Reverse;
use std::collections::{BTreeSet, BinaryHeap};

/// Per IR pass, its merged active uses.
pub(crate) type Uses = IdVec<IrPassId, Vec<PassUse>>;

/// The live passes of one feature set, ordered, with what each does to each resource.
pub(crate) struct Ordered {
    /// Per IR pass: whether its `enabled_if` holds.
    pub live: IdVec<IrPassId, bool>,
    /// Per IR pass: its merged active uses (empty when not live).
    pub uses: Uses,
    pub order: Order,
}

/// Decides what is live under `features` and orders it, or reports every ordering error.
pub(crate) fn order_live(
    graph: &LoadedGraph,
    ir: &Ir,
    features: &BTreeSet<String>,
) -> Result<Ordered, Vec<Diagnostic>> {
    let live: IdVec<IrPassId, bool> = ir
        .passes
        .iter()
        .map(|p| conditions_hold(&p.enabled_if, features))
        .collect();
    let uses: Uses = ir
        .passes
        .ids()
        .map(|p| {
            if live[p] {
                pass_uses(ir, p, |c| conditions_hold(c, features))
            } else {
                Vec::new()
            }
        })
        .collect();
    match order(ir, &live, &uses) {
        Ok(order) => Ok(Ordered { live, uses, order }),
        Err(errors) => {
            let disabled: Vec<IrPassId> = live.ids().filter(|&p| !live[p]).collect();
            Err(errors
                .iter()
                .map(|e| order_error(graph, ir, &uses, e, &disabled))
                .collect())
        }
    }
}

/// What one live pass does to one resource, with all its accesses in the pass merged.
#[derive(Debug, Clone)]
pub struct PassUse {
    pub resource: IrResourceId,
    /// Indices into the pass's `accesses` that are active.
    pub accesses: Vec<usize>,
    pub reads_previous: bool,
    pub writes: bool,
    pub discards: bool,
}

/// Merges a pass's active accesses per resource, in first-use order.
pub fn pass_uses(ir: &Ir, pass: IrPassId, active: impl Fn(&[String]) -> bool) -> Vec<PassUse> {
    let mut uses: Vec<PassUse> = Vec::new();
    for (i, access) in ir.passes[pass].accesses.iter().enumerate() {
        if !active(&access.conditions) {
            continue;
        }
        let u = &access.usage;
        match uses.iter_mut().find(|x| x.resource == access.resource) {
            Some(x) => {
                x.accesses.push(i);
                x.reads_previous |= u.reads_previous();
                x.writes |= u.writes();
                x.discards &= u.discards();
            }
            None => uses.push(PassUse {
                resource: access.resource,
                accesses: vec![i],
                reads_previous: u.reads_previous(),
                writes: u.writes(),
                discards: u.discards(),
            }),
        }
    }
    for x in &mut uses {
        // A read-modify-write storage image keeps its contents even if one access discards.
        if x.reads_previous {
            x.discards = false;
        }
    }
    uses
}

/// An ordering problem, to be turned into a located diagnostic by the caller.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OrderError {
    /// Passes that form a cycle, in cycle order.
    Cycle(Vec<IrPassId>),
    /// Two writers of a resource with no order between them.
    UnorderedWriters {
        resource: IrResourceId,
        first: IrPassId,
        second: IrPassId,
    },
    /// A pass reads a resource that no earlier pass writes.
    ReadBeforeWrite {
        resource: IrResourceId,
        pass: IrPassId,
    },
}

/// The result of ordering the live passes.
#[derive(Debug, Clone)]
pub struct Order {
    /// Live passes in execution order.
    pub sequence: Vec<IrPassId>,
    /// For each resource, its live writers in execution order.
    pub writers: IdVec<IrResourceId, Vec<IrPassId>>,
    /// Each pass's index in `sequence` (`usize::MAX` when not live).
    pub position: IdVec<IrPassId, usize>,
}

/// Successors of each pass in the dependency graph.
type Edges = IdVec<IrPassId, Vec<IrPassId>>;

/// Orders the live passes. `uses[p]` holds the merged uses of pass `p` (empty when not live).
pub fn order(ir: &Ir, live: &IdVec<IrPassId, bool>, uses: &Uses) -> Result<Order, Vec<OrderError>> {
    let n = ir.passes.len();
    let mut succ: Edges = IdVec::filled(Vec::new(), n);
    let mut writers: IdVec<IrResourceId, Vec<IrPassId>> =
        IdVec::filled(Vec::new(), ir.resources.len());
    let mut readers: IdVec<IrResourceId, Vec<IrPassId>> =
        IdVec::filled(Vec::new(), ir.resources.len());
    for p in live.ids().filter(|&p| live[p]) {
        for u in &uses[p] {
            if u.writes {
                writers[u.resource].push(p);
            } else if u.reads_previous {
                readers[u.resource].push(p);
            }
        }
        for &a in &ir.passes[p].after {
            if live[a] && a != p {
                succ[a].push(p);
            }
        }
    }
    for (r, resource) in ir.resources.iter_enumerated() {
        for &w in &writers[r] {
            for &x in &readers[r] {
                if resource.history {
                    succ[x].push(w);
                } else {
                    succ[w].push(x);
                }
            }
        }
    }
    for s in succ.iter_mut() {
        s.sort_unstable();
        s.dedup();
    }

    let sequence = topological(live, &succ).map_err(|cycle| vec![OrderError::Cycle(cycle)])?;
    let mut position: IdVec<IrPassId, usize> = IdVec::filled(usize::MAX, n);
    for (i, &p) in sequence.iter().enumerate() {
        position[p] = i;
    }
    let reach = reachability(&sequence, &succ);

    let mut errors = Vec::new();
    for (r, resource) in ir.resources.iter_enumerated() {
        let w = &mut writers[r];
        w.sort_by_key(|&p| position[p]);
        for pair in w.windows(2) {
            if !reach[pair[0]].contains(pair[1]) {
                errors.push(OrderError::UnorderedWriters {
                    resource: r,
                    first: pair[0],
                    second: pair[1],
                });
            }
        }
        // An acceleration structure outlives the frame in the scene, but a
        // ray query needs this frame's build (or refit) before it.
        let built_each_frame = matches!(resource.kind, IrKind::AccelerationStructure);
        if resource.kept_across_frames() && !built_each_frame {
            continue;
        }
        match w.first() {
            None => {
                if let Some(&x) = readers[r].first() {
                    errors.push(OrderError::ReadBeforeWrite {
                        resource: r,
                        pass: x,
                    });
                }
            }
            Some(&first) => {
                let needs_previous = uses[first]
                    .iter()
                    .any(|u| u.resource == r && u.reads_previous);
                if needs_previous {
                    errors.push(OrderError::ReadBeforeWrite {
                        resource: r,
                        pass: first,
                    });
                }
            }
        }
    }
    if errors.is_empty() {
        Ok(Order {
            sequence,
            writers,
            position,
        })
    } else {
        Err(errors)
    }
}

/// Kahn's algorithm taking the lowest declaration index first, so the order is
/// stable under edits that do not change dependencies. On a cycle, returns one.
fn topological(live: &IdVec<IrPassId, bool>, succ: &Edges) -> Result<Vec<IrPassId>, Vec<IrPassId>> {
    let mut indegree: IdVec<IrPassId, usize> = IdVec::filled(0, live.len());
    for p in live.ids().filter(|&p| live[p]) {
        for &s in &succ[p] {
            indegree[s] += 1;
        }
    }
    let mut ready: BinaryHeap<Reverse<IrPassId>> = live
        .ids()
        .filter(|&p| live[p] && indegree[p] == 0)
        .map(Reverse)
        .collect();
    let mut sequence = Vec::with_capacity(live.len());
    while let Some(Reverse(p)) = ready.pop() {
        sequence.push(p);
        for &s in &succ[p] {
            indegree[s] -= 1;
            if indegree[s] == 0 {
                ready.push(Reverse(s));
            }
        }
    }
    let live_count = live.iter().filter(|&&l| l).count();
    if sequence.len() == live_count {
        return Ok(sequence);
    }
    Err(find_cycle(&indegree, succ))
}

/// Walks successors among the passes left with positive in-degree until one repeats.
fn find_cycle(indegree: &IdVec<IrPassId, usize>, succ: &Edges) -> Vec<IrPassId> {
    let Some(start) = indegree.ids().find(|&p| indegree[p] > 0) else {
        return Vec::new();
    };
    let mut seen_at: IdVec<IrPassId, Option<usize>> = IdVec::filled(None, indegree.len());
    let mut path = Vec::new();
    let mut current = start;
    loop {
        if let Some(at) = seen_at[current] {
            let mut cycle = path[at..].to_vec();
            let min = cycle
                .iter()
                .enumerate()
                .min_by_key(|(_, &p)| p)
                .map(|(i, _)| i)
                .unwrap_or(0);
            cycle.rotate_left(min);
            return cycle;
        }
        seen_at[current] = Some(path.len());
        path.push(current);
        match succ[current].iter().find(|&&s| indegree[s] > 0) {
            Some(&next) => current = next,
            None => return path,
        }
    }
}

/// A fixed-size set of passes.
#[derive(Debug, Clone)]
pub struct BitSet(Vec<u64>);

impl BitSet {
    fn new(n: usize) -> Self {
        BitSet(vec![0; n.div_ceil(64)])
    }
    fn insert(&mut self, p: IrPassId) {
        let i = p.index();
        self.0[i / 64] |= 1 << (i % 64);
    }
    /// Whether `p` is in the set.
    pub fn contains(&self, p: IrPassId) -> bool {
        let i = p.index();
        self.0[i / 64] & (1 << (i % 64)) != 0
    }
    fn union_with(&mut self, other: &BitSet) {
        for (a, b) in self.0.iter_mut().zip(&other.0) {
            *a |= b;
        }
    }
}

/// For each pass, the passes reachable from it, computed in reverse topological order.
fn reachability(sequence: &[IrPassId], succ: &Edges) -> IdVec<IrPassId, BitSet> {
    let n = succ.len();
    let mut reach: IdVec<IrPassId, BitSet> = IdVec::filled(BitSet::new(n), n);
    for &p in sequence.iter().rev() {
        let mut set = BitSet::new(n);
        for &s in &succ[p] {
            set.insert(s);
            set.union_with(&reach[s]);
        }
        reach[p] = set;
    }
    reach
}

/// The located diagnostic for one ordering problem.
fn order_error(
    graph: &LoadedGraph,
    ir: &Ir,
    uses: &Uses,
    e: &OrderError,
    disabled: &[IrPassId],
) -> Diagnostic {
    let name = |p: IrPassId| ir.passes[p].name.as_str();
    match e {
        OrderError::Cycle(cycle) => {
            let first = cycle.first().copied().unwrap_or(IrPassId::new(0));
            let mut names: Vec<&str> = cycle.iter().map(|&p| name(p)).collect();
            names.push(name(first));
            let mut d = locate(graph, ir, first, &[Seg::Field("name")]);
            d.message = format!("passes form a cycle: {}", names.join(" -> "));
            d.with_hint("break the cycle: remove an `after` or read a different resource")
        }
        OrderError::UnorderedWriters {
            resource,
            first,
            second,
        } => {
            let mut d = locate(graph, ir, *second, &[Seg::Field("name")]);
            d.message = format!(
                "passes \"{}\" and \"{}\" both write \"{}\" with no order between them",
                name(*first),
                name(*second),
                ir.resources[*resource].name
            );
            d.with_hint(format!(
                "add `after: [\"{}\"]` to \"{}\"",
                name(*first),
                name(*second)
            ))
        }
        OrderError::ReadBeforeWrite { resource, pass } => {
            let access = uses[*pass]
                .iter()
                .find(|u| u.resource == *resource)
                .and_then(|u| u.accesses.first())
                .map(|&i| &ir.passes[*pass].accesses[i]);
            let path = access
                .map(|a| access_path(ir.passes[*pass].index, a))
                .unwrap_or_default();
            let (file, pos) = graph.locate(ir.passes[*pass].source, &path);
            let rname = &ir.resources[*resource].name;
            let disabled_writers: Vec<&str> = disabled
                .iter()
                .filter(|&&p| {
                    ir.passes[p]
                        .accesses
                        .iter()
                        .any(|a| a.resource == *resource && a.usage.writes())
                })
                .map(|&p| name(p))
                .collect();
            let mut d = Diagnostic::error(
                file,
                pos,
                format!(
                    "pass \"{}\" reads \"{rname}\" before anything writes it",
                    name(*pass)
                ),
            );
            d.hint = Some(if let Some(w) = disabled_writers.first() {
                format!("its writer \"{w}\" is disabled by its `enabled_if`; make this read conditional with `(name: \"{rname}\", enabled_if: [...])`")
            } else if matches!(
                access.map(|a| &a.usage),
                Some(Usage::Color { .. } | Usage::Depth { .. })
            ) {
                "use `load: Clear(...)` or `load: DontCare` for the first pass that writes it"
                    .into()
            } else {
                "add a pass that writes it, or mark it `history: true` to read last frame's contents".into()
            });
            d
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::{ordered, pass, resolved, resource, CHAIN};
    use super::*;

    #[test]
    fn disabled_passes_are_not_live_and_have_no_uses() {
        let (_, ir, o) = ordered(CHAIN, &[]);
        let d = pass(&ir, "d");
        assert!(!o.live[d]);
        assert!(o.uses[d].is_empty());
        assert_eq!(
            o.order.sequence,
            ir.passes.ids().take(3).collect::<Vec<_>>()
        );
    }

    #[test]
    fn a_reader_runs_after_its_writer_whatever_the_declaration_order() {
        let a_decl = r#"Pass(name: "a", kind: Fullscreen, shaders: (fragment: "a.frag"),
                 color: [(image: "x", load: Clear([0.0, 0.0, 0.0, 0.0]))]),"#;
        assert!(CHAIN.contains(a_decl));
        let reader_first = CHAIN.replace(a_decl, "").replace(
            r#"Pass(name: "c""#,
            &format!("{a_decl}\n            Pass(name: \"c\""),
        );
        let (_, ir, o) = ordered(&reader_first, &["extra"]);
        let (a, b, d) = (pass(&ir, "a"), pass(&ir, "b"), pass(&ir, "d"));
        assert!(a > b, "a is declared after b");
        let at = |p| o.order.sequence.iter().position(|&q| q == p).unwrap();
        assert!(at(a) < at(b) && at(b) < at(d));
        assert_eq!(o.order.writers[resource(&ir, "out")], vec![b, d]);
    }

    #[test]
    fn cycles_are_reported_from_their_lowest_pass() {
        let ids = |list: &[usize]| list.iter().map(|&i| IrPassId::new(i)).collect::<Vec<_>>();
        let edges = |lists: &[&[usize]]| lists.iter().map(|l| ids(l)).collect::<Edges>();
        let live = IdVec::filled(true, 3);
        let cycle = edges(&[&[1], &[2], &[0]]);
        assert_eq!(topological(&live, &cycle), Err(ids(&[0, 1, 2])));
        let chain = edges(&[&[2], &[], &[1]]);
        assert_eq!(topological(&live, &chain), Ok(ids(&[0, 2, 1])));
    }

    #[test]
    fn ordering_errors_are_located_at_the_pass() {
        let two_writers = CHAIN.replace(r#"after: ["b"], "#, "");
        let (graph, ir) = resolved(&two_writers);
        let features = ["extra".to_string()].into_iter().collect();
        let Err(errors) = order_live(&graph, &ir, &features) else {
            panic!("two unordered writers of out");
        };
        assert_eq!(errors.len(), 1);
        assert!(errors[0]
            .message
            .contains("passes \"b\" and \"d\" both write \"out\""));
        assert_eq!(
            errors[0].hint.as_deref(),
            Some("add `after: [\"b\"]` to \"d\"")
        );
        assert_eq!((errors[0].pos.line, errors[0].pos.col), (15, 24));
    }
}
