//! Reading graph files: RON parsing with positions, includes resolved relative to
//! the including file, and parameters resolved per file with include-site overrides.

mod params;

pub use params::resolve_value;
pub(crate) use params::{non_finite, not_f32, value_text};
use params::{report_not_taken, resolve_params, split_qualified};

use crate::diagnostic::Diagnostic;
use crate::schema::{GraphFile, ParamValue, PassDecl, ResourceDecl};
use crate::spans::{Pos, Seg, SpanTree};
use ron::extensions::Extensions;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One file that contributed to a graph.
#[derive(Debug, Clone)]
pub struct Source {
    /// Path as given or as resolved from the including file.
    pub file: PathBuf,
    /// Positions of every value in the file.
    pub spans: SpanTree,
    /// The file's parameters after include-site overrides and `$reference` resolution.
    pub params: BTreeMap<String, ParamValue>,
    /// What values its parameters accept (`param_ranges`), for tools that
    /// offer them (the viewer's sliders).
    pub ranges: BTreeMap<String, crate::schema::ParamRange>,
    /// Its parameters the include site sets to a `$reference` of the
    /// includer's: they follow that parameter, and tools offer that one.
    pub follows: std::collections::BTreeSet<String>,
    /// The name `--param` reaches its parameters by from the root graph: empty
    /// for the root and a whole graph it builds on (hybrid.ron's deferred.ron),
    /// the file stem for a file either includes (`shadows` in
    /// `shadows.resolution`), `None` for files included deeper.
    pub qualifier: Option<String>,
    /// A whole graph (not a fragment) another includes, to build on it.
    pub built_on: bool,
}

/// An item declared in some source file, with where to point diagnostics.
#[derive(Debug, Clone)]
pub struct Located<T> {
    pub item: T,
    /// Index into [`LoadedGraph::sources`].
    pub source: usize,
    /// Index of the item in its file's list.
    pub index: usize,
}

/// A graph file and its includes, merged, before validation.
#[derive(Debug, Clone, Default)]
pub struct LoadedGraph {
    /// Source 0 is the root file; the rest are includes in the order met.
    pub sources: Vec<Source>,
    pub resources: Vec<Located<ResourceDecl>>,
    pub passes: Vec<Located<PassDecl>>,
    /// The output image name, from the root file.
    pub output: Option<String>,
    /// Images tools read back besides the output, from the root file (some
    /// only under features).
    pub readback: Vec<crate::schema::ReadDecl>,
    /// How the graph accumulates over frames, from the root file.
    pub progressive: Option<crate::schema::Progressive>,
    /// Summarised views from the graph and its fragments, with their source.
    pub views: Vec<(usize, crate::schema::ViewDecl)>,
    /// Known differences from the reference, from the graph and its
    /// fragments, with their source.
    pub caveats: Vec<(usize, crate::schema::CaveatDecl)>,
    /// When the camera is jittered, from the graph and its fragments, with
    /// their source.
    pub jitter: Vec<(usize, crate::schema::JitterDecl)>,
    /// Scene values (numbers the renderer measures from each scene) the graph
    /// and its fragments declare, with their source.
    pub scene_values: Vec<(usize, String)>,
    /// Define sets from the graph and its fragments: source, name, defines.
    pub define_sets: Vec<(usize, String, Vec<crate::schema::DefineDecl>)>,
    /// Human-readable name.
    pub name: String,
    /// Toggles declared on by default by the graph and its fragments.
    pub default_features: Vec<String>,
    /// Whether the root file is a fragment (checked alone, never compiled alone).
    pub is_fragment: bool,
    /// Per source: the resources it expects its includer to declare.
    pub inputs: Vec<Vec<String>>,
    /// Problems met while loading (syntax, includes, parameters).
    pub diagnostics: Vec<Diagnostic>,
}

impl LoadedGraph {
    /// The names of the images the graph reads back besides its output, as
    /// tools ask for them; entries under features the compile does not have
    /// are dropped by the compiler.
    pub fn readback_names(&self) -> Vec<String> {
        self.readback.iter().map(|r| r.name().to_string()).collect()
    }

    /// Where the value at `path` inside `source` is, as a file and position.
    pub fn locate(&self, source: usize, path: &[Seg]) -> (PathBuf, Pos) {
        match self.sources.get(source) {
            Some(s) => (s.file.clone(), s.spans.locate(path)),
            None => (PathBuf::new(), Pos::default()),
        }
    }

    /// The parameters `--param` reaches, in source order: each as its
    /// `--param` name (the root file's own, and as `stem.name` those of the
    /// files it includes directly), the file it is declared in, and its name
    /// there.
    pub fn settable(&self) -> impl Iterator<Item = (String, &Source, &str)> {
        self.sources
            .iter()
            .filter_map(|s| s.qualifier.as_ref().map(|q| (q, s)))
            .flat_map(|(q, s)| {
                s.params.keys().map(move |name| {
                    let key = if q.is_empty() {
                        name.clone()
                    } else {
                        format!("{q}.{name}")
                    };
                    (key, s, name.as_str())
                })
            })
    }

    /// The names of [`LoadedGraph::settable`].
    pub fn settable_params(&self) -> std::collections::BTreeSet<String> {
        self.settable().map(|(key, ..)| key).collect()
    }

    /// Every file the graph was built from, for hot reload.
    pub fn files(&self) -> Vec<PathBuf> {
        self.sources.iter().map(|s| s.file.clone()).collect()
    }

    /// The features to compile with: the graph's defaults, plus each requested
    /// name, minus each `!name`.
    pub fn features<S: AsRef<str>>(&self, requested: &[S]) -> std::collections::BTreeSet<String> {
        let mut on: std::collections::BTreeSet<String> =
            self.default_features.iter().cloned().collect();
        for f in requested
            .iter()
            .map(|f| f.as_ref().trim())
            .filter(|f| !f.is_empty())
        {
            match f.strip_prefix('!') {
                Some(off) => on.remove(off),
                None => on.insert(f.to_string()),
            };
        }
        on
    }

    /// Whether loading found any error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// Reads the contents of a file; tests substitute an in-memory file system.
pub type ReadFile<'a> = &'a dyn Fn(&Path) -> std::io::Result<String>;

/// Reads a graph file from disk through weft's one reader: regular files
/// only, at most [`weft_io::read::MAX_TEXT_BYTES`].
pub fn read_from_disk(path: &Path) -> std::io::Result<String> {
    weft_io::read_text(path, weft_io::read::MAX_TEXT_BYTES).map_err(weft_io::ReadError::into_io)
}

/// Loads a graph file from disk with its includes.
pub fn load(path: &Path) -> LoadedGraph {
    load_with(path, &read_from_disk)
}

/// Loads a graph with a custom file reader.
pub fn load_with(path: &Path, read: ReadFile) -> LoadedGraph {
    load_overridden(path, read, BTreeMap::new())
}

/// Loads a graph from disk with some of its top-level parameters set, as an
/// include site would set a fragment's (`weft render --param exposure=2`); a
/// name the graph does not declare is an error located at its `params`.
pub fn load_with_params(path: &Path, overrides: BTreeMap<String, ParamValue>) -> LoadedGraph {
    load_overridden(path, &read_from_disk, overrides)
}

fn load_overridden(
    path: &Path,
    read: ReadFile,
    overrides: BTreeMap<String, ParamValue>,
) -> LoadedGraph {
    let mut graph = LoadedGraph::default();
    let mut stack = Vec::new();
    load_file(&mut graph, read, path, overrides, None, &mut stack);
    if let Some(root) = graph.sources.first() {
        if graph.name.is_empty() {
            graph.name = root
                .file
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
        }
    }
    graph
}

/// Where an include was requested, for errors about the included file.
struct IncludeSite {
    source: usize,
    index: usize,
    /// Parameters the site sets to a `$reference` of the includer's.
    follows: std::collections::BTreeSet<String>,
    /// `--param` values the includer, the root or a graph built on like it,
    /// does not take itself (`name`, or `fragment.name` for a fragment it
    /// does not include): a whole graph included here takes them as a root
    /// would (hybrid.ron passes `gi.rays` to deferred.ron, whose fragment
    /// gi.ron it is); a fragment ignores them.
    passed_on: BTreeMap<String, ParamValue>,
}

fn ron_options() -> ron::Options {
    ron::Options::default()
        .with_default_extension(Extensions::IMPLICIT_SOME | Extensions::UNWRAP_VARIANT_NEWTYPES)
}

fn load_file(
    graph: &mut LoadedGraph,
    read: ReadFile,
    path: &Path,
    overrides: BTreeMap<String, ParamValue>,
    site: Option<IncludeSite>,
    stack: &mut Vec<PathBuf>,
) {
    let site_location = |graph: &LoadedGraph| match &site {
        Some(s) => graph.locate(
            s.source,
            &[
                Seg::Field("include"),
                Seg::Index(s.index),
                Seg::Field("file"),
            ],
        ),
        None => (path.to_path_buf(), Pos { line: 1, col: 1 }),
    };
    let canonical = std::fs::canonicalize(path).unwrap_or_else(|_| normalize(path));
    if let Some(first) = stack.iter().position(|p| *p == canonical) {
        let (file, pos) = site_location(graph);
        let chain: Vec<String> = stack[first..]
            .iter()
            .chain(std::iter::once(&canonical))
            .map(|p| file_name(p))
            .collect();
        graph.diagnostics.push(
            Diagnostic::error(
                file,
                pos,
                format!(
                    "\"{}\" includes itself: {}",
                    path.display(),
                    chain.join(" -> ")
                ),
            )
            .with_hint("remove one of the includes in this chain"),
        );
        return;
    }
    // An include outside the root graph's folder tree, or a system file, may be
    // anything (`/proc/self/environ`): errors about it name it, never show it.
    let private = match stack.first().and_then(|root| root.parent()) {
        Some(root) => !weft_io::paths::is_within(path, root) || weft_io::paths::is_system(path),
        None => weft_io::paths::is_system(path),
    };
    let text = match read(path) {
        Ok(text) => {
            if private {
                weft_io::sources::forget(path);
            } else {
                weft_io::sources::remember(path, &text);
            }
            text
        }
        Err(err) => {
            let (file, pos) = site_location(graph);
            let diagnostic = match &site {
                Some(_) => Diagnostic::error(
                    file,
                    pos,
                    format!("included file \"{}\" cannot be read: {err}", path.display()),
                )
                .with_hint("include paths are relative to the including file"),
                None if !path.exists() => Diagnostic::error(
                    file,
                    pos,
                    format!(
                        "cannot read graph file: no such file; looked in {}",
                        weft_io::home::looked_in(path)
                    ),
                )
                .with_hint("run weft from its repository, set WEFT_HOME to it, or `make install`"),
                None => Diagnostic::error(file, pos, format!("cannot read graph file: {err}")),
            };
            graph.diagnostics.push(diagnostic);
            return;
        }
    };
    let spans = SpanTree::parse(&text);
    let parsed: GraphFile = match ron_options().from_str(&text) {
        Ok(parsed) => parsed,
        Err(err) => {
            let pos = Pos {
                line: err.span.start.line as u32,
                col: err.span.start.col as u32,
            };
            let message = if private {
                "RON syntax error (the file is outside the graph's folder, so its content is not shown)".to_string()
            } else {
                format!("RON syntax: {}", err.code)
            };
            graph
                .diagnostics
                .push(Diagnostic::error(path, pos, message));
            return;
        }
    };
    let source = graph.sources.len();
    // The root, and a whole graph another root-like graph builds on, take
    // `--param` values as the root does: their own by name, their includes'
    // as `stem.name`.
    let includer_root_like = site
        .as_ref()
        .is_some_and(|s| graph.sources[s.source].qualifier.as_deref() == Some(""));
    let root_like = site.is_none() || (includer_root_like && !parsed.fragment);
    let qualifier = if root_like {
        Some(String::new())
    } else if includer_root_like {
        Some(include_stem(path))
    } else {
        None
    };
    graph.sources.push(Source {
        file: path.to_path_buf(),
        spans,
        params: BTreeMap::new(),
        ranges: parsed.param_ranges.clone(),
        follows: site.as_ref().map(|s| s.follows.clone()).unwrap_or_default(),
        qualifier,
        built_on: site.is_some() && !parsed.fragment,
    });
    graph.inputs.push(parsed.inputs.clone());
    if !parsed.fragment && !parsed.inputs.is_empty() {
        let (file, pos) = graph.locate(source, &[Seg::Field("inputs")]);
        graph.diagnostics.push(
            Diagnostic::error(file, pos, "`inputs` is only meaningful in a fragment")
                .with_hint("add `fragment: true`, or declare these resources here"),
        );
    }
    if site.is_none() {
        graph.output = parsed.output.clone();
        graph.readback = parsed.readback.clone();
        graph.progressive = parsed.progressive.clone();
        graph.name = parsed.name.clone().unwrap_or_default();
        graph.is_fragment = parsed.fragment;
    }
    if site.is_some() && !parsed.fragment {
        build_on(graph, source, &parsed);
    } else if parsed.fragment && parsed.output.is_some() {
        let (file, pos) = graph.locate(source, &[Seg::Field("output")]);
        graph.diagnostics.push(
            Diagnostic::warning(file, pos, "a fragment's output is ignored")
                .with_hint("only the including graph chooses the output"),
        );
    }

    graph
        .views
        .extend(parsed.views.iter().map(|v| (source, v.clone())));
    graph
        .caveats
        .extend(parsed.caveats.iter().map(|c| (source, c.clone())));
    graph
        .jitter
        .extend(parsed.jitter.iter().map(|j| (source, j.clone())));
    graph
        .scene_values
        .extend(parsed.scene_values.iter().map(|v| (source, v.clone())));
    graph.define_sets.extend(
        parsed
            .define_sets
            .iter()
            .map(|(name, defines)| (source, name.clone(), defines.clone())),
    );
    for feature in &parsed.features {
        if !graph.default_features.contains(feature) {
            graph.default_features.push(feature.clone());
        }
    }
    // At the root, `fragment.name` overrides (`--param shadows.resolution=1024`)
    // reach the parameter `name` of the include whose file stem is `fragment`;
    // what the root does not take is passed on to the whole graphs it
    // includes (build_on), which take it as a root would.
    let mut overrides = overrides;
    if root_like {
        if let Some(site) = &site {
            overrides.extend(site.passed_on.clone());
        }
    }
    let (overrides, mut qualified, mut passed_on) = if root_like {
        split_qualified(&parsed, overrides)
    } else {
        (overrides, BTreeMap::new(), BTreeMap::new())
    };
    let params = resolve_params(
        graph,
        source,
        (&parsed.params, &parsed.param_ranges),
        overrides,
        site.as_ref(),
    );
    graph.sources[source].params = params;

    stack.push(canonical);
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    for (index, include) in parsed.include.iter().enumerate() {
        let mut child_overrides = BTreeMap::new();
        for (name, value) in &include.params {
            match resolve_value(&graph.sources[source].params, value) {
                Ok(v) => {
                    child_overrides.insert(name.clone(), v);
                }
                Err(missing) => {
                    let (file, pos) = graph.locate(
                        source,
                        &[
                            Seg::Field("include"),
                            Seg::Index(index),
                            Seg::Field("params"),
                            Seg::Key(name),
                        ],
                    );
                    let names: Vec<&str> = graph.sources[source]
                        .params
                        .keys()
                        .map(String::as_str)
                        .collect();
                    graph.diagnostics.push(
                        Diagnostic::error(file, pos, format!("unknown parameter \"${missing}\""))
                            .suggest(&missing, names),
                    );
                }
            }
        }
        if let Some(given) = qualified.remove(&include_stem(Path::new(&include.file))) {
            child_overrides.extend(given);
        }
        let follows = include
            .params
            .iter()
            .filter(|(_, v)| matches!(v, ParamValue::Reference(_)))
            .map(|(name, _)| name.clone())
            .collect();
        let children = graph.sources.len();
        load_file(
            graph,
            read,
            &dir.join(&include.file),
            child_overrides,
            Some(IncludeSite {
                source,
                index,
                follows,
                passed_on: if root_like {
                    passed_on.clone()
                } else {
                    BTreeMap::new()
                },
            }),
            stack,
        );
        // A whole graph built on here took what was passed on (and reported
        // what it could not take).
        if graph
            .sources
            .get(children)
            .is_some_and(|child| child.built_on)
        {
            passed_on.clear();
        }
    }
    stack.pop();
    if root_like {
        report_not_taken(graph, source, &parsed, passed_on);
    }

    for (index, resource) in parsed.resources.into_iter().enumerate() {
        graph.resources.push(Located {
            item: resource,
            source,
            index,
        });
    }
    for (index, pass) in parsed.passes.into_iter().enumerate() {
        graph.passes.push(Located {
            item: pass,
            source,
            index,
        });
    }
}

/// A whole graph (not a fragment) included by another: the includer builds on
/// it, as the bench graphs add floor passes to a shipped graph, and takes its
/// name, output and accumulation where it declares none, and its read-backs
/// besides its own. An output other than the includer's is ignored, with a warning.
fn build_on(graph: &mut LoadedGraph, source: usize, parsed: &GraphFile) {
    if graph.name.is_empty() {
        graph.name = parsed.name.clone().unwrap_or_default();
    }
    match (&graph.output, &parsed.output) {
        (None, output) => graph.output = output.clone(),
        (Some(own), Some(other)) if own != other => {
            let (file, pos) = graph.locate(source, &[Seg::Field("output")]);
            graph.diagnostics.push(
                Diagnostic::warning(
                    file,
                    pos,
                    format!("this included graph's output \"{other}\" is ignored"),
                )
                .with_hint(format!("the including graph chooses \"{own}\"")),
            );
        }
        _ => {}
    }
    if graph.progressive.is_none() {
        graph.progressive = parsed.progressive.clone();
    }
    for read in &parsed.readback {
        if !graph.readback.iter().any(|r| r.name() == read.name()) {
            graph.readback.push(read.clone());
        }
    }
}

/// The name a fragment's parameters are qualified with: its file stem.
fn include_stem(file: &Path) -> String {
    file.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Lexically normalises a path (for files that do not exist, so cannot be canonicalised).
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for part in path.components() {
        match part {
            std::path::Component::ParentDir => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}
