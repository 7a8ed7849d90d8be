//! The feature names a graph's conditions mention (those the engine sets
//! from what a scene holds are the scene vocabulary's, `crate::vocabulary`).

use super::{Ir, IrPass};
use std::collections::BTreeSet;

/// Every feature name a graph's conditions mention.
pub fn feature_names(ir: &Ir) -> BTreeSet<String> {
    ir.passes
        .iter()
        .flat_map(|p| pass_feature_names(p, true))
        .collect()
}

/// The feature names one pass's conditions mention: whether it runs, what
/// it reads and writes, and (with `defines`) its defines.
pub fn pass_feature_names(pass: &IrPass, defines: bool) -> BTreeSet<String> {
    let define_conditions = pass
        .defines
        .iter()
        .filter(|_| defines)
        .flat_map(|d| d.enabled_if.iter());
    let conditions = pass
        .enabled_if
        .iter()
        .chain(pass.accesses.iter().flat_map(|a| a.conditions.iter()))
        .chain(define_conditions);
    conditions
        .flat_map(|c| crate::condition::names(c))
        .filter(|name| !name.is_empty())
        .map(str::to_string)
        .collect()
}
