//! Execution order from data: edges from writers to readers (and from history
//! readers to this frame's writer), explicit `after`, a stable topological sort,
//! and the checks that need an order: cycles, unordered writers, reads of nothing.

use crate::resolve::Ir;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// What one live pass does to one resource, with all its accesses in the pass merged.
#[derive(Debug, Clone)]
pub struct PassUse {
    pub resource: usize,
    /// Indices into the pass's `accesses` that are active.
    pub accesses: Vec<usize>,
    pub reads_previous: bool,
    pub writes: bool,
    pub discards: bool,
}

/// Merges a pass's active accesses per resource, in first-use order.
pub fn pass_uses(ir: &Ir, pass: usize, active: impl Fn(&[String]) -> bool) -> Vec<PassUse> {
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
    /// Passes (indices into `Ir::passes`) that form a cycle, in cycle order.
    Cycle(Vec<usize>),
    /// Two writers of a resource with no order between them.
    UnorderedWriters {
        resource: usize,
        first: usize,
        second: usize,
    },
    /// A pass reads a resource that no earlier pass writes.
    ReadBeforeWrite { resource: usize, pass: usize },
}

/// The result of ordering the live passes.
#[derive(Debug, Clone)]
pub struct Order {
    /// Live pass indices (into `Ir::passes`) in execution order.
    pub sequence: Vec<usize>,
    /// For each resource, its live writers in execution order.
    pub writers: Vec<Vec<usize>>,
}

/// Orders the live passes. `uses[p]` holds the merged uses of pass `p` (empty when not live).
pub fn order(ir: &Ir, live: &[bool], uses: &[Vec<PassUse>]) -> Result<Order, Vec<OrderError>> {
    let n = ir.passes.len();
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); n];
    let mut writers: Vec<Vec<usize>> = vec![Vec::new(); ir.resources.len()];
    let mut readers: Vec<Vec<usize>> = vec![Vec::new(); ir.resources.len()];
    for p in (0..n).filter(|&p| live[p]) {
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
    for (r, resource) in ir.resources.iter().enumerate() {
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
    for s in &mut succ {
        s.sort_unstable();
        s.dedup();
    }

    let sequence = topological(n, live, &succ).map_err(|cycle| vec![OrderError::Cycle(cycle)])?;
    let mut position = vec![usize::MAX; n];
    for (i, &p) in sequence.iter().enumerate() {
        position[p] = i;
    }
    let reach = reachability(&sequence, &succ, n);

    let mut errors = Vec::new();
    for (r, resource) in ir.resources.iter().enumerate() {
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
        if resource.history {
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
        Ok(Order { sequence, writers })
    } else {
        Err(errors)
    }
}

/// Kahn's algorithm taking the lowest declaration index first, so the order is
/// stable under edits that do not change dependencies. On a cycle, returns one.
fn topological(n: usize, live: &[bool], succ: &[Vec<usize>]) -> Result<Vec<usize>, Vec<usize>> {
    let mut indegree = vec![0usize; n];
    for p in (0..n).filter(|&p| live[p]) {
        for &s in &succ[p] {
            indegree[s] += 1;
        }
    }
    let mut ready: BinaryHeap<Reverse<usize>> = (0..n)
        .filter(|&p| live[p] && indegree[p] == 0)
        .map(Reverse)
        .collect();
    let mut sequence = Vec::with_capacity(n);
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
    Err(find_cycle(n, &indegree, succ))
}

/// Walks successors among the passes left with positive in-degree until one repeats.
fn find_cycle(n: usize, indegree: &[usize], succ: &[Vec<usize>]) -> Vec<usize> {
    let Some(start) = (0..n).find(|&p| indegree[p] > 0) else {
        return Vec::new();
    };
    let mut seen_at = vec![usize::MAX; n];
    let mut path = Vec::new();
    let mut current = start;
    loop {
        if seen_at[current] != usize::MAX {
            let mut cycle = path[seen_at[current]..].to_vec();
            let min = cycle
                .iter()
                .enumerate()
                .min_by_key(|(_, &p)| p)
                .map(|(i, _)| i)
                .unwrap_or(0);
            cycle.rotate_left(min);
            return cycle;
        }
        seen_at[current] = path.len();
        path.push(current);
        match succ[current].iter().find(|&&s| indegree[s] > 0) {
            Some(&next) => current = next,
            None => return path,
        }
    }
}

/// A fixed-size set of pass indices.
#[derive(Debug, Clone)]
pub struct BitSet(Vec<u64>);

impl BitSet {
    fn new(n: usize) -> Self {
        BitSet(vec![0; n.div_ceil(64)])
    }
    fn insert(&mut self, i: usize) {
        self.0[i / 64] |= 1 << (i % 64);
    }
    /// Whether `i` is in the set.
    pub fn contains(&self, i: usize) -> bool {
        self.0[i / 64] & (1 << (i % 64)) != 0
    }
    fn union_with(&mut self, other: &BitSet) {
        for (a, b) in self.0.iter_mut().zip(&other.0) {
            *a |= b;
        }
    }
}

/// For each pass, the passes reachable from it, computed in reverse topological order.
pub fn reachability(sequence: &[usize], succ: &[Vec<usize>], n: usize) -> Vec<BitSet> {
    let mut reach = vec![BitSet::new(n); n];
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

/// Passes that contribute to the roots (the output and images read back): their writers, and transitively the writers
/// of everything a contributing pass reads (history resources: all their writers,
/// since the next frame reads them).
pub fn contributing(ir: &Ir, order: &Order, uses: &[Vec<PassUse>], roots: &[usize]) -> Vec<bool> {
    let n = ir.passes.len();
    let mut position = vec![usize::MAX; n];
    for (i, &p) in order.sequence.iter().enumerate() {
        position[p] = i;
    }
    let mut needed = vec![false; n];
    let mut stack: Vec<usize> = roots
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
