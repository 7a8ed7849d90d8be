//! The compiler, as a list of steps (read [`compile_ir`] top to bottom): features
//! decide which passes and reads are live and data decides their order (`order`),
//! the output and read-back images decide what is culled (`cull`), then each
//! resource's span of passes (`lifetimes`), its description (`resources`), shared
//! transient memory (`memory`), every barrier (`sync`) and the pass descriptions
//! with their render passes (`passes`), all for one output size.

pub(crate) mod cull;
mod lifetimes;
pub(crate) mod memory;
pub(crate) mod order;
mod passes;
mod recordable;
mod resources;
pub(crate) mod sync;

use crate::diagnostic::Diagnostic;
use crate::id::IrPassId;
use crate::load::LoadedGraph;
use crate::plan::{Extent, Plan, PlanView, ResourceDesc};
use crate::resolve::{feature_names, resolve, Ir, IrView};
use crate::spans::{Pos, Seg};
use memory::MemoryRequirements;
use std::collections::{BTreeMap, BTreeSet};

/// What to compile a graph for.
pub struct CompileOptions<'a> {
    pub extent: Extent,
    /// Scene features and user toggles that are on.
    pub features: BTreeSet<String>,
    /// Memory requirements of an image or a buffer; the executor passes the
    /// device's.
    pub memory: &'a dyn Fn(&ResourceDesc) -> MemoryRequirements,
    /// The scene values the renderer measured (`scene_values` a graph
    /// declares, for its buffer sizes); one missing is 0.
    pub scene_values: BTreeMap<String, f64>,
    /// Images to keep readable after the frame besides the output (e.g. the HDR
    /// buffer for EXR output): never aliased, left in `TRANSFER_SRC_OPTIMAL`.
    /// Those the graph lists as read back only under features (`(name:
    /// "denoised", enabled_if: ["denoise"])`) are dropped where the features
    /// do not hold, unless `readback_asked`.
    pub readback: Vec<String>,
    /// `readback` is what a user asked for by name (`--readback`), not the
    /// graph's own list: every name is kept, whatever the graph's conditions.
    pub readback_asked: bool,
}

impl Default for CompileOptions<'_> {
    fn default() -> Self {
        CompileOptions {
            extent: Extent {
                width: 1280,
                height: 720,
            },
            features: BTreeSet::new(),
            memory: &memory::estimate_requirements,
            scene_values: BTreeMap::new(),
            readback: Vec::new(),
            readback_asked: false,
        }
    }
}

/// A graph loaded and resolved once, owned: it passed the checks that do not
/// depend on features or size, and compiles many times (on resize, on a
/// feature toggle, for each scene) without being read or validated again.
/// Render, view, compare, sweep and hot reload keep one.
#[derive(Debug, Clone)]
pub struct Prepared {
    graph: LoadedGraph,
    ir: Ir,
}

impl Prepared {
    /// Validates names, formats, parameters and per-pass rules; returns every error found.
    pub fn new(graph: LoadedGraph) -> Result<Self, Vec<Diagnostic>> {
        let ir = resolve_checked(&graph)?;
        Ok(Prepared { graph, ir })
    }

    /// Loads the graph file at `path` with parameter `overrides` and
    /// prepares it.
    pub fn load(
        path: &std::path::Path,
        overrides: std::collections::BTreeMap<String, crate::schema::ParamValue>,
    ) -> Result<Self, Vec<Diagnostic>> {
        Self::new(crate::load::load_with_params(path, overrides))
    }

    /// The loaded graph (files, declarations, parameters, features).
    pub fn graph(&self) -> &LoadedGraph {
        &self.graph
    }

    /// The resolved graph.
    pub fn ir(&self) -> &Ir {
        &self.ir
    }

    /// The toggles of `requested` that name a feature of this graph, the
    /// rest dropped: the toggles meant for other graphs left out (a raster
    /// graph's `!bloom` given to the reference as well).
    pub fn known_toggles(&self, requested: &[String]) -> Vec<String> {
        requested
            .iter()
            .filter(|t| self.unknown_features(&[t.as_str()]).is_empty())
            .cloned()
            .collect()
    }

    /// The toggles a user typed (`name` on, `!name` off) that name no feature
    /// of this graph — neither one its passes test nor a default — each as a
    /// message with the nearest known name as a hint.
    pub fn unknown_features<S: AsRef<str>>(&self, requested: &[S]) -> Vec<String> {
        let mut known = feature_names(&self.ir);
        known.extend(self.graph.default_features.iter().cloned());
        let names: Vec<&str> = requested
            .iter()
            .map(|f| f.as_ref().trim())
            .map(|f| f.strip_prefix('!').unwrap_or(f))
            .collect();
        let mut problems = Vec::new();
        if names.iter().any(|f| f.is_empty()) {
            problems.push("an empty feature name (a stray comma, or `!` alone)".to_string());
        }
        for f in names.into_iter().filter(|f| !f.is_empty()) {
            if !known.contains(f) {
                let hint = crate::diagnostic::nearest(f, known.iter().map(String::as_str))
                    .map(|n| format!(" (did you mean \"{n}\"?)"))
                    .unwrap_or_default();
                let list = known.iter().cloned().collect::<Vec<_>>().join(", ");
                problems.push(format!(
                    "unknown feature \"{f}\"{hint}; this graph's features are: {list}"
                ));
            }
        }
        problems
    }

    /// Compiles for one size and feature set.
    pub fn compile(&self, options: &CompileOptions) -> Result<Plan, Vec<Diagnostic>> {
        compile_ir(&self.graph, &self.ir, options)
    }
}

/// Resolves a loaded graph after the checks that need no features or size:
/// load errors, a fragment compiled alone, resolve errors.
fn resolve_checked(graph: &LoadedGraph) -> Result<Ir, Vec<Diagnostic>> {
    if graph.has_errors() {
        return Err(graph.diagnostics.clone());
    }
    if graph.is_fragment {
        let file = root_file(graph);
        return Err(vec![Diagnostic::error(
            file,
            Pos { line: 1, col: 1 },
            "this file is a fragment (`fragment: true`) and cannot be compiled on its own",
        )
        .with_hint(
            "include it from a graph that declares its inputs and an output",
        )]);
    }
    let (ir, mut diags) = resolve(graph);
    if diags.iter().any(Diagnostic::is_error) {
        diags.retain(Diagnostic::is_error);
        return Err(diags);
    }
    Ok(ir)
}

/// Validates and compiles a loaded graph, or returns every error found.
pub fn compile(graph: &LoadedGraph, options: &CompileOptions) -> Result<Plan, Vec<Diagnostic>> {
    compile_ir(graph, &resolve_checked(graph)?, options)
}

/// Whether every condition (`"name"` on, `"!name"` off) holds.
/// The images asked for, less those the graph reads back only under
/// features that do not hold (names the graph does not list are kept).
fn readback_for(graph: &LoadedGraph, asked: &[String], features: &BTreeSet<String>) -> Vec<String> {
    asked
        .iter()
        .filter(|name| {
            graph.readback.iter().all(|r| match r {
                crate::schema::ReadDecl::Conditional(c) if &c.name == *name => {
                    conditions_hold(&c.enabled_if, features)
                }
                _ => true,
            })
        })
        .cloned()
        .collect()
}

pub fn conditions_hold(conditions: &[String], features: &BTreeSet<String>) -> bool {
    crate::condition::all_hold(conditions, features)
}

/// The notes of the graph's caveats whose features hold, each once (a note
/// may be declared under several conditions).
fn active_caveats(graph: &LoadedGraph, features: &BTreeSet<String>) -> Vec<String> {
    let mut notes: Vec<String> = Vec::new();
    for (_, caveat) in &graph.caveats {
        if conditions_hold(&caveat.enabled_if, features) && !notes.contains(&caveat.note) {
            notes.push(caveat.note.clone());
        }
    }
    notes
}

/// The file of the graph's root source, for errors about the graph as a whole.
fn root_file(graph: &LoadedGraph) -> std::path::PathBuf {
    graph
        .sources
        .first()
        .map(|s| s.file.clone())
        .unwrap_or_default()
}

/// An error (message left to the caller) located at a field of an IR pass.
fn locate(graph: &LoadedGraph, ir: &Ir, pass: IrPassId, rest: &[Seg]) -> Diagnostic {
    let p = &ir.passes[pass];
    let mut path = vec![Seg::Field("passes"), Seg::Index(p.index)];
    path.extend_from_slice(rest);
    let (file, pos) = graph.locate(p.source, &path);
    Diagnostic::error(file, pos, String::new())
}

/// Compiles a resolved graph for one feature set and size.
pub fn compile_ir(
    graph: &LoadedGraph,
    ir: &Ir,
    options: &CompileOptions,
) -> Result<Plan, Vec<Diagnostic>> {
    let Some(output) = ir.output else {
        return Err(vec![Diagnostic::error(
            root_file(graph),
            Pos { line: 1, col: 1 },
            "the graph has no output",
        )]);
    };
    let ordered = order::order_live(graph, ir, &options.features)?;
    let active_views: Vec<&IrView> = ir
        .views
        .iter()
        .filter(|v| conditions_hold(&v.enabled_if, &options.features))
        .collect();
    let mut readback = if options.readback_asked {
        options.readback.clone()
    } else {
        readback_for(graph, &options.readback, &options.features)
    };
    for view in &active_views {
        let name = &ir.resources[view.image].name;
        if !readback.contains(name) {
            readback.push(name.clone());
        }
    }
    let roots = cull::roots(graph, ir, output, &readback, &ordered)?;
    let cull::Culled {
        sequence,
        culled,
        mut warnings,
    } = cull::cull(graph, ir, &ordered, &roots, &options.features);
    let lifetimes = lifetimes::Lifetimes::new(ir, &sequence, &ordered.uses, &roots);
    lifetimes.check(graph, ir, &sequence, &ordered.uses, &roots, &mut warnings)?;
    let mut resources = resources::describe(
        graph,
        ir,
        &ordered.uses,
        &lifetimes,
        &roots,
        sequence.len(),
        options,
    )?;
    let memory = memory::alias(&mut resources, options.memory);
    let sync = sync::synchronize(ir, &sequence, &ordered.uses, &lifetimes, &mut resources);
    let passes = passes::describe(
        &passes::PassContext {
            graph,
            ir,
            uses: &ordered.uses,
            lifetimes: &lifetimes,
            roots: &roots,
            resources: &resources,
            options,
        },
        &sequence,
        sync.pass_barriers,
        sync.repeat_barriers,
    );
    recordable::check(&passes, &resources, options.extent)?;
    Ok(Plan {
        name: graph.name.clone(),
        file: root_file(graph),
        files: graph.files(),
        extent: options.extent,
        features: options.features.iter().cloned().collect(),
        scene_values: crate::resolve::scene_value_vars(graph, |name| {
            options.scene_values.get(name).copied()
        }),
        output: lifetimes.plan_index(output),
        readback: roots.list[1..]
            .iter()
            .map(|&r| lifetimes.plan_index(r))
            .collect(),
        samples_per_frame: ir.samples_per_frame,
        views: active_views
            .iter()
            .map(|v| PlanView {
                name: v.name.clone(),
                image: lifetimes.plan_index(v.image),
                threshold: v.threshold,
            })
            .collect(),
        caveats: active_caveats(graph, &options.features),
        camera_jitter: graph
            .jitter
            .iter()
            .any(|(_, j)| conditions_hold(&j.enabled_if, &options.features)),
        resources,
        passes,
        culled,
        memory,
        epilogue: sync.epilogue,
        warnings,
    })
}

/// Small graphs for the steps' unit tests.
#[cfg(test)]
pub(crate) mod fixture {
    use super::order::{order_live, Ordered};
    use crate::id::{IrPassId, IrResourceId};
    use crate::load::{load_with, LoadedGraph};
    use crate::resolve::{resolve, Ir};
    use std::collections::BTreeSet;
    use std::path::Path;

    /// `a` draws `x`; `b` samples `x` into `out` (the output); `c` draws `unused`,
    /// which nothing reads; `d`, enabled by feature `extra`, adds to `out` after `b`.
    pub const CHAIN: &str = r#"Graph(
        output: "out",
        resources: [
            Image(name: "x", format: R8G8B8A8_UNORM),
            Image(name: "out", format: R8G8B8A8_UNORM),
            Image(name: "unused", format: R8G8B8A8_UNORM, size: Scale(0.5, 0.5)),
        ],
        passes: [
            Pass(name: "a", kind: Fullscreen, shaders: (fragment: "a.frag"),
                 color: [(image: "x", load: Clear([0.0, 0.0, 0.0, 0.0]))]),
            Pass(name: "b", kind: Fullscreen, shaders: (fragment: "b.frag"),
                 sampled: ["x"], color: [(image: "out")]),
            Pass(name: "c", kind: Fullscreen, shaders: (fragment: "c.frag"),
                 color: [(image: "unused")]),
            Pass(name: "d", kind: Fullscreen, shaders: (fragment: "d.frag"),
                 color: [(image: "out", load: Load)], after: ["b"], enabled_if: ["extra"]),
        ],
    )"#;

    /// Loads and resolves graph text, which must resolve cleanly.
    pub fn resolved(text: &str) -> (LoadedGraph, Ir) {
        let root = Path::new("/fixture/graph.ron");
        let graph = load_with(root, &|p: &Path| {
            if p == root {
                Ok(text.to_string())
            } else {
                Err(std::io::ErrorKind::NotFound.into())
            }
        });
        assert!(!graph.has_errors(), "{:#?}", graph.diagnostics);
        let (ir, diags) = resolve(&graph);
        assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
        (graph, ir)
    }

    /// The live passes of `text` under `features`, ordered.
    pub fn ordered(text: &str, features: &[&str]) -> (LoadedGraph, Ir, Ordered) {
        let (graph, ir) = resolved(text);
        let features: BTreeSet<String> = features.iter().map(|f| f.to_string()).collect();
        let ordered = order_live(&graph, &ir, &features).expect("orders");
        (graph, ir, ordered)
    }

    /// A pass of the IR by name.
    pub fn pass(ir: &Ir, name: &str) -> IrPassId {
        ir.passes.position(|p| p.name == name).expect("pass")
    }

    /// A resource of the IR by name.
    pub fn resource(ir: &Ir, name: &str) -> IrResourceId {
        ir.resources.position(|r| r.name == name).expect("resource")
    }
}

#[cfg(test)]
mod tests {
    use super::fixture::{resolved, CHAIN};
    use super::*;

    /// Compiles graph text with `features` at the default size.
    pub(crate) fn plan_of(text: &str, features: &[&str]) -> Plan {
        let (graph, ir) = resolved(text);
        let options = CompileOptions {
            features: features.iter().map(|f| f.to_string()).collect(),
            ..CompileOptions::default()
        };
        compile_ir(&graph, &ir, &options).expect("compiles")
    }

    #[test]
    fn the_steps_together_make_a_plan_of_the_running_passes() {
        let plan = plan_of(CHAIN, &["extra"]);
        let names: Vec<&str> = plan.passes.iter().map(|p| p.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "d"]);
        assert_eq!(plan.features, ["extra"]);
        assert_eq!(plan.resources[plan.output].name, "out");
        assert_eq!(plan.culled.len(), 1);
    }
}
