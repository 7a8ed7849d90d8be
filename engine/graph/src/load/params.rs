//! Graph parameters: the root's overrides split by include (`fragment.name`),
//! each file's declared parameters with include-site overrides applied and
//! `$references` resolved, and the declared ranges enforced.

use super::{file_name, include_stem, IncludeSite, LoadedGraph};
use crate::diagnostic::Diagnostic;
use crate::schema::{ParamRange, ParamValue};
use crate::spans::Seg;
use std::collections::BTreeMap;
use std::path::Path;

/// What a root-like graph does with the `--param` values it is given:
/// (its own, by include file stem those qualified as `fragment.name` for a
/// fragment it includes, and the rest to pass on to a whole graph it builds
/// on: names it does not declare, qualifiers that name no include of its).
type SplitOverrides = (
    BTreeMap<String, ParamValue>,
    BTreeMap<String, BTreeMap<String, ParamValue>>,
    BTreeMap<String, ParamValue>,
);

/// Splits a root-like graph's overrides ([`SplitOverrides`]).
pub(super) fn split_qualified(
    parsed: &crate::schema::GraphFile,
    overrides: BTreeMap<String, ParamValue>,
) -> SplitOverrides {
    let stems = include_stems(parsed);
    let mut own = BTreeMap::new();
    let mut qualified: BTreeMap<String, BTreeMap<String, ParamValue>> = BTreeMap::new();
    let mut passed_on = BTreeMap::new();
    for (name, value) in overrides {
        match name.split_once('.') {
            Some((fragment, param)) if stems.iter().any(|s| s == fragment) => {
                qualified
                    .entry(fragment.to_string())
                    .or_default()
                    .insert(param.to_string(), value);
            }
            None if parsed.params.contains_key(&name) => {
                own.insert(name, value);
            }
            _ => {
                passed_on.insert(name, value);
            }
        }
    }
    (own, qualified, passed_on)
}

fn include_stems(parsed: &crate::schema::GraphFile) -> Vec<String> {
    parsed
        .include
        .iter()
        .map(|i| include_stem(Path::new(&i.file)))
        .collect()
}

/// Reports the `--param` values a root-like graph passed on that no whole
/// graph it builds on took: a name it does not declare, or a qualifier that
/// names no fragment it includes, each with the nearest name.
pub(super) fn report_not_taken(
    graph: &mut LoadedGraph,
    source: usize,
    parsed: &crate::schema::GraphFile,
    not_taken: BTreeMap<String, ParamValue>,
) {
    let graph_file = file_name(&graph.sources[source].file);
    let stems = include_stems(parsed);
    for name in not_taken.into_keys() {
        let diagnostic = match name.split_once('.') {
            Some((fragment, _)) => {
                let (file, pos) = graph.locate(source, &[Seg::Field("include")]);
                Diagnostic::error(
                    file,
                    pos,
                    format!("parameter \"{name}\": \"{graph_file}\" includes no fragment \"{fragment}\""),
                )
                .suggest(fragment, stems.iter().map(String::as_str))
            }
            None => {
                let (file, pos) = graph.locate(source, &[Seg::Field("params")]);
                Diagnostic::error(
                    file,
                    pos,
                    format!("unknown parameter \"{name}\" for \"{graph_file}\""),
                )
                .suggest(&name, parsed.params.keys().map(String::as_str))
            }
        };
        graph.diagnostics.push(diagnostic);
    }
}

/// Applies include-site overrides to a file's declared parameters and resolves
/// `$references` between them; unknown overrides are reported at the include site.
pub(super) fn resolve_params(
    graph: &mut LoadedGraph,
    source: usize,
    (declared, ranges): (&BTreeMap<String, ParamValue>, &BTreeMap<String, ParamRange>),
    overrides: BTreeMap<String, ParamValue>,
    site: Option<&IncludeSite>,
) -> BTreeMap<String, ParamValue> {
    let mut params: BTreeMap<String, ParamValue> = declared.clone();
    check_ranges_name_params(graph, source, declared, ranges);
    for (name, value) in &params {
        if let Some(why) = refusal(ranges.get(name), declared.get(name), value) {
            let (file, pos) = graph.locate(source, &[Seg::Field("params"), Seg::Key(name)]);
            graph.diagnostics.push(Diagnostic::error(
                file,
                pos,
                format!("parameter \"{name}\": its default {why}"),
            ));
        }
    }
    for (name, value) in overrides {
        if let Some(slot) = params.get_mut(&name) {
            if let Some(why) = refusal(ranges.get(&name), declared.get(&name), &value) {
                let at = match site {
                    None => graph.locate(source, &[Seg::Field("params"), Seg::Key(&name)]),
                    Some(site) => graph.locate(
                        site.source,
                        &[
                            Seg::Field("include"),
                            Seg::Index(site.index),
                            Seg::Field("params"),
                            Seg::Key(&name),
                        ],
                    ),
                };
                graph.diagnostics.push(
                    Diagnostic::error(
                        at.0,
                        at.1,
                        format!(
                            "parameter \"{name}\" set to {}: it {why}",
                            value_text(&value)
                        ),
                    )
                    .with_hint(format!(
                        "see \"{name}\" in `params` and `param_ranges` of {}",
                        file_name(&graph.sources[source].file)
                    )),
                );
            }
            *slot = value;
        } else if site.is_none() {
            let (file, pos) = graph.locate(source, &[Seg::Field("params")]);
            let names: Vec<&str> = declared.keys().map(String::as_str).collect();
            let graph_file = file_name(&graph.sources[source].file);
            graph.diagnostics.push(
                Diagnostic::error(
                    file,
                    pos,
                    format!("unknown parameter \"{name}\" for \"{graph_file}\""),
                )
                .suggest(&name, names),
            );
        } else if let Some(site) = site {
            let (file, pos) = graph.locate(
                site.source,
                &[
                    Seg::Field("include"),
                    Seg::Index(site.index),
                    Seg::Field("params"),
                    Seg::KeyOf(&name),
                ],
            );
            let names: Vec<&str> = declared.keys().map(String::as_str).collect();
            let fragment = file_name(&graph.sources[source].file);
            graph.diagnostics.push(
                Diagnostic::error(
                    file,
                    pos,
                    format!("unknown parameter \"{name}\" for \"{fragment}\""),
                )
                .suggest(&name, names),
            );
        }
    }
    for (name, value) in &params {
        if let Some(bad) = non_finite(value) {
            let (file, pos) = graph.locate(source, &[Seg::Field("params"), Seg::Key(name)]);
            graph
                .diagnostics
                .push(Diagnostic::error(file, pos, not_f32(name, bad)));
        }
    }
    let snapshot = params.clone();
    for (name, value) in params.iter_mut() {
        if let Err(missing) = resolve_value(&snapshot, value).map(|v| *value = v) {
            let (file, pos) = graph.locate(source, &[Seg::Field("params"), Seg::Key(name)]);
            let names: Vec<&str> = snapshot.keys().map(String::as_str).collect();
            graph.diagnostics.push(
                Diagnostic::error(file, pos, format!("unknown parameter \"${missing}\""))
                    .suggest(&missing, names),
            );
        }
    }
    params
}

/// The first number in a parameter value that a shader's 32-bit float
/// cannot hold (NaN, infinite, or beyond ±3.4e38, which would arrive as
/// infinity), if any.
pub(crate) fn non_finite(value: &ParamValue) -> Option<f64> {
    let bad = |n: &f64| !(n.is_finite() && n.abs() <= f64::from(f32::MAX));
    match value {
        ParamValue::Number(n) => Some(*n).filter(bad),
        ParamValue::Vector(v) => v.iter().copied().find(bad),
        ParamValue::Bool(_) | ParamValue::Reference(_) => None,
    }
}

/// The error for parameter `name` whose value holds `bad` ([`non_finite`]).
pub(crate) fn not_f32(name: &str, bad: f64) -> String {
    let shown = if bad.is_finite() {
        format!("{bad:e}")
    } else {
        format!("{bad}")
    };
    format!("parameter \"{name}\" must be a finite 32-bit float (at most 3.4e38 in size), found {shown}")
}

/// Resolves a `"$name"` reference (one level; parameters may not chain) to its value.
pub fn resolve_value(
    params: &BTreeMap<String, ParamValue>,
    value: &ParamValue,
) -> Result<ParamValue, String> {
    match value {
        ParamValue::Reference(text) => match text.strip_prefix('$') {
            Some(name) => match params.get(name) {
                Some(ParamValue::Reference(inner)) if inner.starts_with('$') => {
                    Err(name.to_string())
                }
                Some(v) => Ok(v.clone()),
                None => Err(name.to_string()),
            },
            None => Ok(value.clone()),
        },
        other => Ok(other.clone()),
    }
}

/// Every `param_ranges` entry names a declared parameter, and its bounds agree.
fn check_ranges_name_params(
    graph: &mut LoadedGraph,
    source: usize,
    declared: &BTreeMap<String, ParamValue>,
    ranges: &BTreeMap<String, ParamRange>,
) {
    for (name, range) in ranges {
        let (file, pos) = graph.locate(source, &[Seg::Field("param_ranges"), Seg::KeyOf(name)]);
        if !declared.contains_key(name) {
            let names: Vec<&str> = declared.keys().map(String::as_str).collect();
            graph.diagnostics.push(
                Diagnostic::error(
                    file,
                    pos,
                    format!("`param_ranges` names \"{name}\", which `params` does not declare"),
                )
                .suggest(name, names),
            );
        } else if let Some(bad) = [range.min, range.max]
            .into_iter()
            .flatten()
            .chain(range.one_of.iter().copied())
            .find(|b| b.is_nan())
        {
            graph.diagnostics.push(Diagnostic::error(
                file,
                pos,
                format!("the range of \"{name}\" has a bound of {bad}: bounds are numbers"),
            ));
        } else if range.min.zip(range.max).is_some_and(|(min, max)| min > max) {
            graph.diagnostics.push(Diagnostic::error(
                file,
                pos,
                format!("the range of \"{name}\" has min above max"),
            ));
        }
    }
}

/// Why `value` cannot be parameter whose default is `default` and whose
/// range is `range`: another kind of value than the default, or a number
/// outside the range. References (`"$x"`) are checked where they resolve.
fn refusal(
    range: Option<&ParamRange>,
    default: Option<&ParamValue>,
    value: &ParamValue,
) -> Option<String> {
    let kind = |v: &ParamValue| match v {
        ParamValue::Bool(_) => Some("true or false"),
        ParamValue::Number(_) => Some("a number"),
        ParamValue::Vector(_) => Some("a vector"),
        ParamValue::Reference(_) => None,
    };
    if let (Some(expected), Some(found)) = (default.and_then(kind), kind(value)) {
        if expected != found {
            return Some(format!("must be {expected}, like its default"));
        }
    }
    match (range, value) {
        (Some(range), ParamValue::Number(n)) => range.refuses(*n),
        _ => None,
    }
}

/// A value as a user would type it.
pub(crate) fn value_text(value: &ParamValue) -> String {
    match value {
        ParamValue::Bool(b) => b.to_string(),
        ParamValue::Number(n) => format!("{n}"),
        ParamValue::Vector(v) => format!("{v:?}"),
        ParamValue::Reference(r) => r.clone(),
    }
}
