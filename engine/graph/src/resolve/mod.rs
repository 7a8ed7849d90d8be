//! Turns a loaded graph into an index-based intermediate form, checking every name,
//! format, parameter and per-pass rule that does not depend on execution order.
//! All problems are collected; none stops the others from being found.

mod attachments;
mod features;
mod ir;
mod multisample;
mod passes;
mod resources;
mod rules;
mod structures;
mod values;

pub use features::{feature_names, pass_feature_names};
pub use ir::*;
pub use rules::{access_path, usage_name};
pub(crate) use values::oversized_image;
pub use values::{
    expression_vars, image_extent, scene_value_vars, INDIRECT_RECORD_BYTES, MAX_BUFFER_BYTES,
    MAX_IMAGE_DIMENSION, MAX_REPEAT, MAX_SAMPLES_PER_FRAME, MAX_WORKGROUP_COUNT,
};

use crate::diagnostic::Diagnostic;
use crate::id::{IdVec, IrPassId, IrResourceId};
use crate::load::LoadedGraph;
use crate::plan::Extent;
use crate::schema::ResourceDecl;
use crate::spans::Seg;
use std::collections::HashMap;

/// An attachment's extent and sample count at one probe size (`None` when unknown).
type SizeAtProbe = Option<(Extent, u32)>;

/// Output sizes at which attachment sizes are compared, so that sizes which only
/// coincide at one output size are still reported.
/// The formats a summarised view may read: counts and measures, one channel.
pub const VIEW_FORMATS: [&str; 2] = ["R32_UINT", "R32_SFLOAT"];

const PROBE_SIZES: [Extent; 3] = [
    Extent {
        width: 1920,
        height: 1080,
    },
    Extent {
        width: 1280,
        height: 720,
    },
    Extent {
        width: 641,
        height: 359,
    },
];

/// Resolves and checks a loaded graph; returns the IR (possibly partial) and diagnostics.
pub fn resolve(graph: &LoadedGraph) -> (Ir, Vec<Diagnostic>) {
    let mut r = Resolver {
        graph,
        diags: Vec::new(),
        resource_index: HashMap::new(),
        pass_index: HashMap::new(),
    };
    let ir = r.run();
    (ir, r.diags)
}

struct Resolver<'a> {
    graph: &'a LoadedGraph,
    diags: Vec<Diagnostic>,
    resource_index: HashMap<&'a str, IrResourceId>,
    pass_index: HashMap<&'a str, IrPassId>,
}

fn pass_path<'p>(index: usize, rest: &[Seg<'p>]) -> Vec<Seg<'p>> {
    let mut path = vec![Seg::Field("passes"), Seg::Index(index)];
    path.extend_from_slice(rest);
    path
}

pub(crate) fn resource_path<'p>(index: usize, rest: &[Seg<'p>]) -> Vec<Seg<'p>> {
    let mut path = vec![Seg::Field("resources"), Seg::Index(index)];
    path.extend_from_slice(rest);
    path
}

impl<'a> Resolver<'a> {
    fn error(&mut self, source: usize, path: &[Seg], message: String) -> &mut Diagnostic {
        let (file, pos) = self.graph.locate(source, path);
        self.diags.push(Diagnostic::error(file, pos, message));
        self.diags.last_mut().expect("just pushed")
    }

    fn resource_names(&self) -> Vec<&'a str> {
        self.graph
            .resources
            .iter()
            .map(|r| resource_name(&r.item))
            .collect()
    }

    fn run(&mut self) -> Ir {
        let graph = self.graph;
        for (i, r) in graph.resources.iter().enumerate() {
            let name = resource_name(&r.item);
            if self
                .resource_index
                .insert(name, IrResourceId::new(i))
                .is_some()
            {
                self.error(
                    r.source,
                    &resource_path(r.index, &[Seg::Field("name")]),
                    format!("resource \"{name}\" is declared twice"),
                )
                .hint = Some("resource names are shared by a graph and its includes".into());
            }
        }
        for (i, p) in graph.passes.iter().enumerate() {
            if self
                .pass_index
                .insert(p.item.name.as_str(), IrPassId::new(i))
                .is_some()
            {
                let name = p.item.name.clone();
                self.error(
                    p.source,
                    &pass_path(p.index, &[Seg::Field("name")]),
                    format!("pass \"{name}\" is declared twice"),
                );
            }
        }
        let mut resources: IdVec<IrResourceId, IrResource> = graph
            .resources
            .iter()
            .map(|r| self.resolve_resource(r))
            .collect();
        for (source, names) in graph.inputs.iter().enumerate() {
            for (k, name) in names.iter().enumerate() {
                if self.resource_index.contains_key(name.as_str()) {
                    continue;
                }
                if source == 0 && graph.is_fragment {
                    let id = resources.push(IrResource {
                        name: name.clone(),
                        source,
                        index: k,
                        kind: IrKind::External,
                        history: false,
                        persistent: false,
                    });
                    self.resource_index.insert(name, id);
                } else {
                    let fragment = graph.sources[source].file.display().to_string();
                    self.error(source, &[Seg::Field("inputs"), Seg::Index(k)], format!(
                        "fragment \"{fragment}\" needs resource \"{name}\", which the including graph does not declare"))
                        .hint = Some(format!("declare \"{name}\" in the graph that includes this fragment"));
                }
            }
        }
        let passes: IdVec<IrPassId, IrPass> = graph
            .passes
            .iter()
            .map(|p| self.resolve_pass(p, &resources))
            .collect();
        let output = self.resolve_output(&resources);
        self.check_readback(&resources);
        let samples_per_frame = self.resolve_progressive();
        let views = self.resolve_views(&resources);
        let ir = Ir {
            resources,
            passes,
            output,
            samples_per_frame,
            views,
        };
        self.check_usages(&ir);
        self.check_structure_uses(&ir);
        self.check_multisampling(&ir);
        self.check_extents(&ir);
        self.check_caveats();
        self.check_jitter();
        self.check_define_sets();
        ir
    }

    /// Every define set's names are preprocessor names of the graph's own,
    /// and no set is declared twice (a fragment included twice declares its
    /// sets once).
    fn check_define_sets(&mut self) {
        let sets = self.graph.define_sets.clone();
        for (n, (source, name, defines)) in sets.iter().enumerate() {
            let earlier = sets[..n].iter().find(|(_, other, _)| other == name);
            if let Some((first, _, _)) = earlier {
                let same_file = self.graph.sources[*first].file == self.graph.sources[*source].file;
                if !same_file {
                    let at = self
                        .graph
                        .locate(*first, &[Seg::Field("define_sets"), Seg::Key(name)]);
                    self.error(
                        *source,
                        &[Seg::Field("define_sets"), Seg::Key(name)],
                        format!("define set \"{name}\" is declared twice"),
                    )
                    .hint = Some(format!("first at {}:{}", at.0.display(), at.1.line));
                }
                continue;
            }
            for (k, define) in defines.iter().enumerate() {
                if let Some((message, hint)) = passes::define_name_problem(&define.name) {
                    let path = [
                        Seg::Field("define_sets"),
                        Seg::Key(name),
                        Seg::Index(k),
                        Seg::Field("name"),
                    ];
                    self.error(*source, &path, message).hint = hint;
                }
            }
        }
    }

    /// Every caveat says something, and its conditions are well formed
    /// (whether they name features scenes set is the scene vocabulary's
    /// check, `crate::vocabulary::check_vocabulary`).
    fn check_caveats(&mut self) {
        let caveats = &self.graph.caveats;
        for (k, (source, caveat)) in caveats.iter().enumerate() {
            let index = caveats[..k].iter().filter(|(s, _)| s == source).count();
            let path = |field| [Seg::Field("caveats"), Seg::Index(index), Seg::Field(field)];
            if caveat.note.trim().is_empty() {
                self.error(*source, &path("note"), "a caveat's note is empty".into())
                    .hint = Some("say what differs from the reference and why".into());
            }
            self.check_malformed_conditions(*source, &path("enabled_if"), &caveat.enabled_if);
        }
    }

    /// The camera jitter's conditions are well formed.
    fn check_jitter(&mut self) {
        let jitter = &self.graph.jitter;
        for (k, (source, decl)) in jitter.iter().enumerate() {
            let index = jitter[..k].iter().filter(|(s, _)| s == source).count();
            let path = [
                Seg::Field("jitter"),
                Seg::Index(index),
                Seg::Field("enabled_if"),
            ];
            self.check_malformed_conditions(*source, &path, &decl.enabled_if);
        }
    }

    /// Each of a declaration's `enabled_if` conditions is well formed.
    fn check_malformed_conditions(&mut self, source: usize, path: &[Seg], conditions: &[String]) {
        for condition in conditions {
            if let Some(problem) = crate::condition::malformed(condition) {
                self.error(source, path, problem);
            }
        }
    }

    /// Every image fits [`MAX_IMAGE_DIMENSION`] at each size `check` tries
    /// (images within it keep every output-sized dispatch within
    /// [`MAX_WORKGROUP_COUNT`] groups).
    fn check_extents(&mut self, ir: &Ir) {
        for (r, res) in ir.resources.iter_enumerated() {
            if !matches!(res.kind, IrKind::Image { .. }) {
                continue;
            }
            let too_large = PROBE_SIZES.iter().find_map(|out| {
                image_extent(ir, r, *out)
                    .filter(|e| e.width > MAX_IMAGE_DIMENSION || e.height > MAX_IMAGE_DIMENSION)
                    .map(|e| (*out, e))
            });
            if let Some((out, e)) = too_large {
                self.error(
                    res.source,
                    &resource_path(res.index, &[Seg::Field("size")]),
                    oversized_image(&res.name, e, out),
                );
            }
        }
    }

    /// A progressive graph's samples per frame: a whole number from 1 to
    /// [`MAX_SAMPLES_PER_FRAME`].
    fn resolve_progressive(&mut self) -> Option<u32> {
        let progressive = self.graph.progressive.as_ref()?;
        let path = [Seg::Field("progressive"), Seg::Field("samples_per_frame")];
        Some(self.count(
            0,
            &path,
            &progressive.samples_per_frame,
            "samples_per_frame",
            MAX_SAMPLES_PER_FRAME,
        ))
    }

    /// Each view names a single-channel `R32_UINT` or `R32_SFLOAT` image the
    /// summary can read, under a name no other view takes.
    fn resolve_views(&mut self, resources: &IdVec<IrResourceId, IrResource>) -> Vec<IrView> {
        let mut views: Vec<IrView> = Vec::new();
        for (k, (source, decl)) in self.graph.views.iter().enumerate() {
            let index = self.graph.views[..k]
                .iter()
                .filter(|(s, _)| s == source)
                .count();
            let path = |field| [Seg::Field("views"), Seg::Index(index), Seg::Field(field)];
            if views.iter().any(|v| v.name == decl.name) {
                self.error(
                    *source,
                    &path("name"),
                    format!("view \"{}\" is declared twice", decl.name),
                );
                continue;
            }
            if !decl.threshold.is_finite() {
                self.error(
                    *source,
                    &path("threshold"),
                    format!(
                        "threshold must be a finite number, found {}",
                        decl.threshold
                    ),
                );
                continue;
            }
            let Some(&image) = self.resource_index.get(decl.image.as_str()) else {
                let names = self.resource_names();
                self.error(
                    *source,
                    &path("image"),
                    format!("unknown resource \"{}\"", decl.image),
                )
                .hint = crate::diagnostic::nearest(&decl.image, names)
                    .map(|n| format!("did you mean \"{n}\"?"));
                continue;
            };
            match &resources[image].kind {
                IrKind::Image { format, .. } if VIEW_FORMATS.contains(&format.name) => {
                    views.push(IrView {
                        name: decl.name.clone(),
                        image,
                        threshold: decl.threshold,
                        enabled_if: decl.enabled_if.clone(),
                    });
                }
                IrKind::Image { format, .. } => {
                    self.error(
                        *source,
                        &path("image"),
                        format!(
                            "view \"{}\" reads image \"{}\" of format {}; views summarise {}",
                            decl.name,
                            decl.image,
                            format.name,
                            VIEW_FORMATS.join(" or ")
                        ),
                    );
                }
                _ => {
                    self.error(
                        *source,
                        &path("image"),
                        format!(
                            "view \"{}\" names \"{}\", which is not an image",
                            decl.name, decl.image
                        ),
                    );
                }
            }
        }
        views
    }

    /// Every name in the graph's `readback` list is one of its images.
    fn check_readback(&mut self, resources: &IdVec<IrResourceId, IrResource>) {
        let names = self.graph.readback_names();
        for (i, name) in names.iter().enumerate() {
            let path = [Seg::Field("readback"), Seg::Index(i)];
            match self.resource_index.get(name.as_str()) {
                Some(&r) if matches!(resources[r].kind, IrKind::Buffer { .. }) => {
                    self.error(
                        0,
                        &path,
                        format!("readback \"{name}\" is a buffer; only images are read back"),
                    );
                }
                Some(_) => {}
                None => {
                    let names = self.resource_names();
                    self.error(0, &path, format!("unknown resource \"{name}\""))
                        .hint = crate::diagnostic::nearest(name, names)
                        .map(|n| format!("did you mean \"{n}\"?"));
                }
            }
        }
    }

    fn resolve_output(
        &mut self,
        resources: &IdVec<IrResourceId, IrResource>,
    ) -> Option<IrResourceId> {
        let graph = self.graph;
        if graph.is_fragment {
            return None;
        }
        let Some(name) = &graph.output else {
            let names: Vec<&str> = self.resource_names();
            let mut d = Diagnostic::error(
                graph
                    .sources
                    .first()
                    .map(|s| s.file.clone())
                    .unwrap_or_default(),
                crate::spans::Pos { line: 1, col: 1 },
                "the graph has no output",
            );
            d.hint = Some(match names.last() {
                Some(last) => format!("add `output: \"{last}\"` naming the image to present"),
                None => "add `output: \"name\"` naming the image to present".into(),
            });
            if !graph.sources.is_empty() {
                self.diags.push(d);
            }
            return None;
        };
        match self.resource_index.get(name.as_str()) {
            Some(&i) => {
                if matches!(resources[i].kind, IrKind::Buffer { .. }) {
                    self.error(
                        0,
                        &[Seg::Field("output")],
                        format!("output \"{name}\" is a buffer"),
                    )
                    .hint = Some("the output must be an image".into());
                }
                Some(i)
            }
            None => {
                let names = self.resource_names();
                self.error(
                    0,
                    &[Seg::Field("output")],
                    format!("unknown output \"{name}\""),
                )
                .hint = crate::diagnostic::nearest(name, names)
                    .map(|n| format!("did you mean \"{n}\"?"));
                None
            }
        }
    }

    fn lookup(&mut self, source: usize, path: &[Seg], name: &str) -> Option<IrResourceId> {
        match self.resource_index.get(name) {
            Some(&i) => Some(i),
            None => {
                let names = self.resource_names();
                let hint = crate::diagnostic::nearest(name, names.iter().copied())
                    .map(|n| format!("did you mean \"{n}\"?"))
                    .or_else(|| Some("declare it under `resources`".into()));
                self.error(source, path, format!("unknown resource \"{name}\""))
                    .hint = hint;
                None
            }
        }
    }
}

fn resource_name(r: &ResourceDecl) -> &str {
    match r {
        ResourceDecl::Image(i) => &i.name,
        ResourceDecl::Buffer(b) => &b.name,
        ResourceDecl::AccelerationStructure(a) => &a.name,
    }
}
