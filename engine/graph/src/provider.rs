//! Value providers, as the graph sees them: a pass names a provider and gives
//! its arguments (`derive: [Gaussian(sigma: "$sigma", radius: 21)]`); the
//! renderer registers what each provider is called, which arguments it takes
//! and their ranges ([`ProviderSpec`]), and computes the values. This module
//! knows no provider: it holds a graph to whatever registry it is given, with
//! located errors and hints, so a misspelled name or an argument out of range
//! is an error, never a silent default or clamp.

use crate::diagnostic::{nearest, Diagnostic};
use crate::load::{resolve_value, LoadedGraph};
use crate::schema::{ParamValue, PassKind, ProviderDecl};
use crate::spans::Seg;
use std::collections::BTreeMap;

/// What a provider is called, what it takes and what it supplies.
#[derive(Debug, Clone, Copy)]
pub struct ProviderSpec {
    pub name: &'static str,
    /// One line for messages and docs.
    pub summary: &'static str,
    /// The pass kinds it can serve.
    pub kinds: &'static [PassKind],
    pub args: &'static [ArgSpec],
    /// Push-constant members (or other shader inputs) it fills, so interface
    /// checks know they are not missing parameters.
    pub supplies: &'static [&'static str],
}

/// One argument of a provider.
#[derive(Debug, Clone, Copy)]
pub struct ArgSpec {
    pub name: &'static str,
    pub kind: ArgKind,
    /// The value when the argument is left out; `None`: it is required.
    pub default: Option<ArgDefault>,
}

/// An argument's type and accepted range (both ends included).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArgKind {
    Integer { min: i64, max: i64 },
    Number { min: f64, max: f64 },
    Bool,
}

/// A default value of an argument.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArgDefault {
    Number(f64),
    Bool(bool),
}

impl ArgKind {
    /// Why `value` is not acceptable, if it is not.
    fn problem(&self, value: &ParamValue) -> Option<String> {
        match (self, value) {
            (ArgKind::Bool, ParamValue::Bool(_)) => None,
            (ArgKind::Bool, other) => {
                Some(format!("expected true or false, found {}", show(other)))
            }
            (ArgKind::Integer { min, max }, ParamValue::Number(n)) => {
                if n.fract() != 0.0 {
                    Some(format!(
                        "expected a whole number in {min}..={max}, found {n}"
                    ))
                } else if *n < *min as f64 || *n > *max as f64 {
                    Some(format!("{n} is out of range {min}..={max}"))
                } else {
                    None
                }
            }
            (ArgKind::Number { min, max }, ParamValue::Number(n)) => {
                (!(n >= min && n <= max)).then(|| format!("{n} is out of range {min}..={max}"))
            }
            (ArgKind::Integer { min, max }, other) => Some(format!(
                "expected a whole number in {min}..={max}, found {}",
                show(other)
            )),
            (ArgKind::Number { min, max }, other) => Some(format!(
                "expected a number in {min}..={max}, found {}",
                show(other)
            )),
        }
    }
}

fn show(value: &ParamValue) -> String {
    match value {
        ParamValue::Bool(b) => b.to_string(),
        ParamValue::Number(n) => n.to_string(),
        ParamValue::Vector(v) => format!("a vector of {}", v.len()),
        ParamValue::Reference(r) => format!("\"{r}\""),
    }
}

impl ProviderSpec {
    /// The arguments of a checked call with defaults filled in.
    pub fn arguments(&self, call: &ProviderDecl) -> BTreeMap<String, ParamValue> {
        let mut args = call.args.clone();
        for a in self.args {
            if let (false, Some(d)) = (args.contains_key(a.name), a.default) {
                let value = match d {
                    ArgDefault::Number(n) => ParamValue::Number(n),
                    ArgDefault::Bool(b) => ParamValue::Bool(b),
                };
                args.insert(a.name.to_string(), value);
            }
        }
        args
    }
}

/// The spec a call names, if the registry has it.
pub fn find<'r>(registry: &'r [ProviderSpec], name: &str) -> Option<&'r ProviderSpec> {
    registry.iter().find(|s| s.name == name)
}

/// Every problem with the graph's provider uses against `registry`: unknown
/// providers and arguments (with the nearest name as a hint), missing required
/// arguments, wrong types and values out of range, a provider on a pass kind
/// it cannot serve, and one provider named twice in a pass.
pub fn check_providers(graph: &LoadedGraph, registry: &[ProviderSpec]) -> Vec<Diagnostic> {
    let mut diags = Vec::new();
    for pass in &graph.passes {
        let params = &graph.sources[pass.source].params;
        for (k, call) in pass.item.derive.iter().enumerate() {
            let at = |rest: &[Seg]| {
                let mut path = vec![
                    Seg::Field("passes"),
                    Seg::Index(pass.index),
                    Seg::Field("derive"),
                    Seg::Index(k),
                ];
                path.extend_from_slice(rest);
                graph.locate(pass.source, &path)
            };
            let Some(spec) = find(registry, &call.name) else {
                let (file, pos) = at(&[]);
                let names: Vec<&str> = registry.iter().map(|s| s.name).collect();
                let d = Diagnostic::error(file, pos, format!("unknown provider `{}`", call.name));
                diags.push(match nearest(&call.name, names.iter().copied()) {
                    Some(n) => d.with_hint(format!("did you mean `{n}`?")),
                    None => d.with_hint(format!("the providers are: {}", names.join(", "))),
                });
                continue;
            };
            if pass.item.derive[..k].iter().any(|c| c.name == call.name) {
                let (file, pos) = at(&[]);
                diags.push(Diagnostic::error(
                    file,
                    pos,
                    format!("provider `{}` is named twice in one pass", call.name),
                ));
            }
            if !spec.kinds.contains(&pass.item.kind) {
                let (file, pos) = at(&[]);
                let kinds: Vec<String> = spec.kinds.iter().map(|k| format!("{k:?}")).collect();
                diags.push(
                    Diagnostic::error(
                        file,
                        pos,
                        format!(
                            "provider `{}` cannot serve a {:?} pass",
                            spec.name, pass.item.kind
                        ),
                    )
                    .with_hint(format!("it serves {} passes", kinds.join(" and "))),
                );
            }
            for (name, value) in &call.args {
                let (file, pos) = at(&[Seg::Field(name)]);
                let Some(arg) = spec.args.iter().find(|a| a.name == name) else {
                    let names: Vec<&str> = spec.args.iter().map(|a| a.name).collect();
                    let d = Diagnostic::error(
                        file,
                        pos,
                        format!("provider `{}` has no argument `{name}`", spec.name),
                    );
                    diags.push(match nearest(name, names.iter().copied()) {
                        Some(n) => d.with_hint(format!("did you mean `{n}`?")),
                        None => d.with_hint(format!("its arguments are: {}", names.join(", "))),
                    });
                    continue;
                };
                // Unknown `$references` are reported where all references are resolved.
                let Ok(value) = resolve_value(params, value) else {
                    continue;
                };
                if let Some(problem) = arg.kind.problem(&value) {
                    diags.push(Diagnostic::error(
                        file,
                        pos,
                        format!("`{}` argument `{name}`: {problem}", spec.name),
                    ));
                }
            }
            for arg in spec.args.iter().filter(|a| a.default.is_none()) {
                if !call.args.contains_key(arg.name) {
                    let (file, pos) = at(&[]);
                    diags.push(Diagnostic::error(
                        file,
                        pos,
                        format!("provider `{}` needs argument `{}`", spec.name, arg.name),
                    ));
                }
            }
        }
    }
    diags
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::load::load_with;
    use std::path::Path;

    const BLUR: ProviderSpec = ProviderSpec {
        name: "Blur",
        summary: "a test provider",
        kinds: &[PassKind::Fullscreen],
        args: &[
            ArgSpec {
                name: "radius",
                kind: ArgKind::Integer { min: 0, max: 8 },
                default: None,
            },
            ArgSpec {
                name: "sigma",
                kind: ArgKind::Number {
                    min: 0.1,
                    max: 100.0,
                },
                default: Some(ArgDefault::Number(2.0)),
            },
        ],
        supplies: &["blur_weights"],
    };

    fn problems(derive: &str) -> Vec<(u32, String, Option<String>)> {
        let text = format!(
            r#"Graph(
    params: {{ "r": 3, "big": 12 }},
    output: "out",
    resources: [Image(name: "out", format: R8G8B8A8_UNORM)],
    passes: [
        Pass(name: "p", kind: Fullscreen, shaders: (fragment: "p.frag"), color: [(image: "out")],
             derive: [{derive}]),
    ],
)"#
        );
        let root = Path::new("/t/g.ron");
        let graph = load_with(root, &|_: &Path| Ok(text.clone()));
        assert!(!graph.has_errors(), "{:#?}", graph.diagnostics);
        check_providers(&graph, &[BLUR])
            .into_iter()
            .map(|d| (d.pos.line, d.message, d.hint))
            .collect()
    }

    #[test]
    fn a_call_within_the_registry_is_clean_and_gets_its_defaults() {
        assert_eq!(problems(r#"Blur(radius: "$r")"#), []);
        let call = ProviderDecl {
            name: "Blur".into(),
            args: [("radius".to_string(), ParamValue::Number(3.0))].into(),
        };
        assert_eq!(
            BLUR.arguments(&call)["sigma"],
            ParamValue::Number(2.0),
            "the default fills a missing argument"
        );
    }

    #[test]
    fn misspellings_are_errors_with_the_nearest_name() {
        assert_eq!(
            problems("Blurr(radius: 1)"),
            [(
                7,
                "unknown provider `Blurr`".to_string(),
                Some("did you mean `Blur`?".to_string())
            )]
        );
        assert_eq!(
            problems("Blur(radius: 1, sigmaa: 2.0)"),
            [(
                7,
                "provider `Blur` has no argument `sigmaa`".to_string(),
                Some("did you mean `sigma`?".to_string())
            )]
        );
    }

    #[test]
    fn out_of_range_and_wrong_types_are_errors_not_clamps() {
        let messages: Vec<String> = [
            r#"Blur(radius: "$big")"#,
            "Blur(radius: 2.5)",
            "Blur(radius: 1, sigma: 0.0)",
            "Blur(radius: true)",
            "Blur(sigma: 1.0)",
            "Blur(radius: 1), Blur(radius: 2)",
        ]
        .iter()
        .flat_map(|d| problems(d))
        .map(|(_, m, _)| m)
        .collect();
        assert_eq!(
            messages,
            [
                "`Blur` argument `radius`: 12 is out of range 0..=8",
                "`Blur` argument `radius`: expected a whole number in 0..=8, found 2.5",
                "`Blur` argument `sigma`: 0 is out of range 0.1..=100",
                "`Blur` argument `radius`: expected a whole number in 0..=8, found true",
                "provider `Blur` needs argument `radius`",
                "provider `Blur` is named twice in one pass",
            ]
        );
    }
}
