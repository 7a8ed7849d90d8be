//! Graphviz output for `weft graph dot`: passes as boxes, resources as ellipses,
//! edges labelled with the usage, culled passes greyed out.

use crate::compile::conditions_hold;
use crate::load::LoadedGraph;
use crate::plan::Plan;
use crate::resolve::{resolve, usage_name};
use std::fmt::Write;

fn quote(s: &str) -> String {
    let escaped = s
        .replace('\\', "\\\\")
        .replace('"', "\\\"")
        .replace('\n', "\\n");
    format!("\"{escaped}\"")
}

/// DOT text for a graph; passes absent from `plan` are drawn as culled.
pub fn render(graph: &LoadedGraph, plan: &Plan) -> String {
    let (ir, _) = resolve(graph);
    let features = plan.features.iter().cloned().collect();
    let mut out = String::new();
    let w = &mut out;
    let _ = writeln!(w, "digraph {} {{", quote(&plan.name));
    let _ = writeln!(w, "  rankdir=LR;");
    let _ = writeln!(w, "  node [fontname=\"Helvetica\"];");
    for r in &ir.resources {
        let style = if plan.resource(&r.name).is_some() {
            ""
        } else {
            ", color=grey, fontcolor=grey"
        };
        let shape = if r.history {
            "doubleoctagon"
        } else {
            "ellipse"
        };
        let _ = writeln!(
            w,
            "  {} [shape={shape}{style}];",
            quote(&format!("res:{}", r.name))
        );
    }
    for p in &ir.passes {
        let culled = plan.culled.iter().find(|c| c.name == p.name);
        let (style, label) = match culled {
            Some(c) => (
                ", style=\"filled,dashed\", fillcolor=\"#eeeeee\", color=grey, fontcolor=grey",
                format!("{}\n(culled: {})", p.name, c.reason),
            ),
            None => (", style=filled, fillcolor=\"#dde8ff\"", p.name.clone()),
        };
        let _ = writeln!(
            w,
            "  {} [shape=box, label={}{style}];",
            quote(&format!("pass:{}", p.name)),
            quote(&label)
        );
        for a in &p.accesses {
            let res = quote(&format!("res:{}", ir.resources[a.resource].name));
            let pass = quote(&format!("pass:{}", p.name));
            let inactive = culled.is_some() || !conditions_hold(&a.conditions, &features);
            let grey = if inactive {
                ", color=grey, fontcolor=grey, style=dashed"
            } else {
                ""
            };
            let label = quote(
                usage_name(&a.usage)
                    .trim_start_matches("a ")
                    .trim_start_matches("an "),
            );
            if a.usage.writes() {
                let _ = writeln!(w, "  {pass} -> {res} [label={label}{grey}];");
            } else {
                let _ = writeln!(w, "  {res} -> {pass} [label={label}{grey}];");
            }
        }
        for &after in &p.after {
            let _ = writeln!(
                w,
                "  {} -> {} [style=dotted, label=\"after\"];",
                quote(&format!("pass:{}", ir.passes[after].name)),
                quote(&format!("pass:{}", p.name))
            );
        }
    }
    let _ = writeln!(w, "}}");
    out
}
