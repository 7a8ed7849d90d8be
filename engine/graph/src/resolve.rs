//! Turns a loaded graph into an index-based intermediate form, checking every name,
//! format, parameter and per-pass rule that does not depend on execution order.
//! All problems are collected; none stops the others from being found.

use crate::diagnostic::Diagnostic;
use crate::load::{LoadedGraph, Located};
use crate::plan::{Extent, ShaderFiles};
use crate::schema::{
    AttachmentDecl, Blend, Dim, Dispatch, Draw, Expr, LoadDecl, ParamValue, PassDecl, PassKind,
    RasterState, ReadDecl, ResourceDecl, SizeDecl, StoreDecl,
};
use crate::spans::Seg;
use crate::vk::{format_by_name, Aspect, FormatFeatures, FormatInfo, FORMATS};
use std::collections::{BTreeMap, HashMap};

/// A graph with names resolved to indices.
#[derive(Debug, Clone)]
pub struct Ir {
    pub resources: Vec<IrResource>,
    pub passes: Vec<IrPass>,
    pub output: Option<usize>,
}

/// A resolved resource.
#[derive(Debug, Clone)]
pub struct IrResource {
    pub name: String,
    pub source: usize,
    pub index: usize,
    pub kind: IrKind,
    pub history: bool,
}

/// Image or buffer specifics.
#[derive(Debug, Clone)]
pub enum IrKind {
    Image {
        format: &'static FormatInfo,
        size: SizeSpec,
        mips: u32,
        layers: u32,
        samples: u32,
    },
    Buffer {
        size: BufferSize,
    },
    /// A fragment's input when the fragment is checked on its own, or an image
    /// whose format is unknown: names resolve, but nothing more is checked.
    External,
}

/// An image size with parameters resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SizeSpec {
    Output,
    Scale(f64, f64),
    Absolute(u32, u32),
    Like(usize, f64, f64),
}

/// A buffer size: fixed, or an expression evaluated per compile.
#[derive(Debug, Clone, PartialEq)]
pub enum BufferSize {
    Bytes(u64),
    Expression(String),
}

/// A resolved pass.
#[derive(Debug, Clone)]
pub struct IrPass {
    pub name: String,
    pub source: usize,
    pub index: usize,
    pub kind: PassKind,
    pub shaders: ShaderFiles,
    pub draw: Option<Draw>,
    pub dispatch: Option<IrDispatch>,
    pub params: BTreeMap<String, ParamValue>,
    pub accesses: Vec<IrAccess>,
    pub after: Vec<usize>,
    pub enabled_if: Vec<String>,
    /// Fixed-function state of a raster pass.
    pub raster: RasterState,
}

/// How many compute work groups, resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IrDispatch {
    Output(u32, u32),
    Image(usize, u32, u32),
    Groups(u32, u32, u32),
}

/// One use of a resource by a pass.
#[derive(Debug, Clone)]
pub struct IrAccess {
    pub resource: usize,
    pub usage: Usage,
    /// Features that must hold for this access to happen.
    pub conditions: Vec<String>,
    /// The field and index in the pass declaration, for diagnostics.
    pub field: &'static str,
    pub item: Option<usize>,
}

/// How a pass uses a resource.
#[derive(Debug, Clone, PartialEq)]
pub enum Usage {
    Sampled,
    StorageRead,
    StorageWrite,
    Color {
        load: LoadDecl,
        store: StoreDecl,
        blend: Option<Blend>,
    },
    Depth {
        load: LoadDecl,
        store: StoreDecl,
        read_only: bool,
    },
    TransferSrc,
    TransferDst,
}

impl Usage {
    /// Whether the access needs what earlier passes left in the resource.
    pub fn reads_previous(&self) -> bool {
        match self {
            Usage::Sampled | Usage::StorageRead | Usage::TransferSrc => true,
            Usage::Color { load, .. } => *load == LoadDecl::Load,
            Usage::Depth {
                load, read_only, ..
            } => *load == LoadDecl::Load || *read_only,
            Usage::StorageWrite | Usage::TransferDst => false,
        }
    }

    /// Whether the access changes the resource.
    pub fn writes(&self) -> bool {
        match self {
            Usage::Sampled | Usage::StorageRead | Usage::TransferSrc => false,
            Usage::Depth { read_only, .. } => !read_only,
            Usage::Color { .. } | Usage::StorageWrite | Usage::TransferDst => true,
        }
    }

    /// Whether the access overwrites every texel without reading, so older contents may be discarded.
    pub fn discards(&self) -> bool {
        match self {
            Usage::Color { load, .. } => *load != LoadDecl::Load,
            Usage::Depth {
                load, read_only, ..
            } => *load != LoadDecl::Load && !read_only,
            Usage::TransferDst => true,
            _ => false,
        }
    }
}

/// An attachment's extent and sample count at one probe size (`None` when unknown).
type SizeAtProbe = Option<(Extent, u32)>;

/// Output sizes at which attachment sizes are compared, so that sizes which only
/// coincide at one output size are still reported.
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
    resource_index: HashMap<&'a str, usize>,
    pass_index: HashMap<&'a str, usize>,
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
            if self.resource_index.insert(name, i).is_some() {
                self.error(
                    r.source,
                    &resource_path(r.index, &[Seg::Field("name")]),
                    format!("resource \"{name}\" is declared twice"),
                )
                .hint = Some("resource names are shared by a graph and its includes".into());
            }
        }
        for (i, p) in graph.passes.iter().enumerate() {
            if self.pass_index.insert(p.item.name.as_str(), i).is_some() {
                let name = p.item.name.clone();
                self.error(
                    p.source,
                    &pass_path(p.index, &[Seg::Field("name")]),
                    format!("pass \"{name}\" is declared twice"),
                );
            }
        }
        let mut resources: Vec<IrResource> = graph
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
                    self.resource_index.insert(name, resources.len());
                    resources.push(IrResource {
                        name: name.clone(),
                        source,
                        index: k,
                        kind: IrKind::External,
                        history: false,
                    });
                } else {
                    let fragment = graph.sources[source].file.display().to_string();
                    self.error(source, &[Seg::Field("inputs"), Seg::Index(k)], format!(
                        "fragment \"{fragment}\" needs resource \"{name}\", which the including graph does not declare"))
                        .hint = Some(format!("declare \"{name}\" in the graph that includes this fragment"));
                }
            }
        }
        let passes: Vec<IrPass> = graph
            .passes
            .iter()
            .map(|p| self.resolve_pass(p, &resources))
            .collect();
        let output = self.resolve_output(&resources);
        self.check_readback(&resources);
        let ir = Ir {
            resources,
            passes,
            output,
        };
        self.check_usages(&ir);
        self.check_extents(&ir);
        ir
    }

    /// Every image fits [`MAX_IMAGE_DIMENSION`] at each size `check` tries
    /// (images within it keep every output-sized dispatch within
    /// [`MAX_WORKGROUP_COUNT`] groups).
    fn check_extents(&mut self, ir: &Ir) {
        for (r, res) in ir.resources.iter().enumerate() {
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

    /// Every name in the graph's `readback` list is one of its images.
    fn check_readback(&mut self, resources: &[IrResource]) {
        for (i, name) in self.graph.readback.iter().enumerate() {
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

    fn resolve_output(&mut self, resources: &[IrResource]) -> Option<usize> {
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

    /// A number from the graph or a parameter; NaN and infinity are errors.
    fn dim(&mut self, source: usize, path: &[Seg], dim: &Dim, what: &str) -> Option<f64> {
        let value = self.dim_value(source, path, dim, what)?;
        if value.is_finite() {
            return Some(value);
        }
        self.error(
            source,
            path,
            format!("{what} must be a finite number, found {value}"),
        );
        None
    }

    fn dim_value(&mut self, source: usize, path: &[Seg], dim: &Dim, what: &str) -> Option<f64> {
        match dim {
            Dim::Number(n) => Some(*n),
            Dim::Reference(text) => {
                let params = &self.graph.sources[source].params;
                let name = text.strip_prefix('$').unwrap_or(text);
                match params.get(name) {
                    Some(ParamValue::Number(n)) => Some(*n),
                    Some(other) => {
                        self.error(
                            source,
                            path,
                            format!(
                                "parameter \"${name}\" used as {what} is {other:?}, not a number"
                            ),
                        );
                        None
                    }
                    None => {
                        let names: Vec<&str> = params.keys().map(String::as_str).collect();
                        let hint = crate::diagnostic::nearest(name, names)
                            .map(|n| format!("did you mean \"${n}\"?"))
                            .or(Some("declare it in the file's `params`".into()));
                        self.error(source, path, format!("unknown parameter \"{text}\""))
                            .hint = hint;
                        None
                    }
                }
            }
        }
    }

    /// A size's two scale factors, each in (0, 16].
    fn scale_pair(&mut self, source: usize, path: &[Seg], x: &Dim, y: &Dim) -> (f64, f64) {
        let sx = self.dim(source, path, x, "a scale").unwrap_or(1.0);
        let sy = self.dim(source, path, y, "a scale").unwrap_or(1.0);
        if !(sx > 0.0 && sy > 0.0 && sx <= 16.0 && sy <= 16.0) {
            self.error(
                source,
                path,
                format!("scale ({sx}, {sy}) must be in (0, 16]"),
            );
            return (1.0, 1.0);
        }
        (sx, sy)
    }

    fn count(&mut self, source: usize, path: &[Seg], dim: &Dim, what: &str, max: u32) -> u32 {
        match self.dim(source, path, dim, what) {
            Some(n) if n >= 1.0 && n.fract() == 0.0 && n <= max as f64 => n as u32,
            Some(n) => {
                self.error(
                    source,
                    path,
                    format!("{what} must be a whole number from 1 to {max}, found {n}"),
                );
                1
            }
            None => 1,
        }
    }

    fn resolve_resource(&mut self, r: &Located<ResourceDecl>) -> IrResource {
        let (source, index) = (r.source, r.index);
        match &r.item {
            ResourceDecl::Image(img) => {
                let Some(format) = format_by_name(&img.format.0) else {
                    let (file, pos) = self
                        .graph
                        .locate(source, &resource_path(index, &[Seg::Field("format")]));
                    let d = Diagnostic::error(
                        file,
                        pos,
                        format!("unknown format \"{}\"", img.format.0),
                    )
                    .suggest(&img.format.0, FORMATS.iter().map(|f| f.name));
                    let d = if d.hint.is_none() {
                        d.with_hint(
                            "use a Vulkan format name such as R16G16B16A16_SFLOAT or D32_SFLOAT",
                        )
                    } else {
                        d
                    };
                    self.diags.push(d);
                    // Checked no further, so one typo gives one error.
                    return IrResource {
                        name: img.name.clone(),
                        source,
                        index,
                        kind: IrKind::External,
                        history: img.history,
                    };
                };
                let size_path = resource_path(index, &[Seg::Field("size")]);
                let size = match &img.size {
                    SizeDecl::Output => SizeSpec::Output,
                    SizeDecl::Scale(x, y) => {
                        let (sx, sy) = self.scale_pair(source, &size_path, x, y);
                        SizeSpec::Scale(sx, sy)
                    }
                    SizeDecl::Absolute(w, h) => {
                        let w = self.count(source, &size_path, w, "a width", 16384);
                        let h = self.count(source, &size_path, h, "a height", 16384);
                        SizeSpec::Absolute(w, h)
                    }
                    SizeDecl::Like(other, x, y) => {
                        let (sx, sy) = self.scale_pair(source, &size_path, x, y);
                        match self.resource_index.get(other.as_str()) {
                            Some(&i) => SizeSpec::Like(i, sx, sy),
                            None => {
                                let names = self.resource_names();
                                self.error(
                                    source,
                                    &size_path,
                                    format!("unknown resource \"{other}\""),
                                )
                                .hint = crate::diagnostic::nearest(other, names)
                                    .map(|n| format!("did you mean \"{n}\"?"));
                                SizeSpec::Output
                            }
                        }
                    }
                };
                let mips = self.count(
                    source,
                    &resource_path(index, &[Seg::Field("mips")]),
                    &img.mips,
                    "mips",
                    15,
                );
                let layers = self.count(
                    source,
                    &resource_path(index, &[Seg::Field("layers")]),
                    &img.layers,
                    "layers",
                    2048,
                );
                let samples_path = resource_path(index, &[Seg::Field("samples")]);
                let samples = self.count(source, &samples_path, &img.samples, "samples", 64);
                if !samples.is_power_of_two() {
                    self.error(
                        source,
                        &samples_path,
                        format!("samples must be 1, 2, 4, 8, 16, 32 or 64, found {samples}"),
                    );
                }
                IrResource {
                    name: img.name.clone(),
                    source,
                    index,
                    kind: IrKind::Image {
                        format,
                        size,
                        mips,
                        layers,
                        samples,
                    },
                    history: img.history,
                }
            }
            ResourceDecl::Buffer(buf) => {
                let size_path = resource_path(index, &[Seg::Field("size")]);
                let size = match &buf.size {
                    Expr::Number(n) if *n >= 1.0 && n.fract() == 0.0 => {
                        BufferSize::Bytes(*n as u64)
                    }
                    Expr::Number(n) => {
                        self.error(
                            source,
                            &size_path,
                            format!("buffer size must be a whole number of bytes >= 1, found {n}"),
                        );
                        BufferSize::Bytes(1)
                    }
                    Expr::Text(text) => {
                        let vars = expression_vars(
                            &self.graph.sources[source].params,
                            Extent {
                                width: 1920,
                                height: 1080,
                            },
                            1,
                        );
                        if let Err(e) = crate::expr::eval(text, &vars) {
                            let mut names: Vec<String> = vars.keys().cloned().collect();
                            names.sort();
                            self.error(
                                source,
                                &size_path,
                                format!(
                                    "in size expression \"{text}\" at character {}: {}",
                                    e.offset + 1,
                                    e.message
                                ),
                            )
                            .hint = Some(format!("variables: {}", names.join(", ")));
                        }
                        BufferSize::Expression(text.clone())
                    }
                };
                IrResource {
                    name: buf.name.clone(),
                    source,
                    index,
                    kind: IrKind::Buffer { size },
                    history: buf.history,
                }
            }
        }
    }

    fn lookup(&mut self, source: usize, path: &[Seg], name: &str) -> Option<usize> {
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

    fn resolve_pass(&mut self, p: &Located<PassDecl>, resources: &[IrResource]) -> IrPass {
        let (source, index) = (p.source, p.index);
        let decl = &p.item;
        let mut accesses = Vec::new();
        for (i, a) in decl.color.iter().enumerate() {
            let path = pass_path(
                index,
                &[Seg::Field("color"), Seg::Index(i), Seg::Field("image")],
            );
            if let Some(r) = self.lookup(source, &path, &a.image) {
                accesses.push(attachment_access(r, a, false, "color", Some(i)));
            }
        }
        if let Some(a) = &decl.depth {
            let path = pass_path(index, &[Seg::Field("depth"), Seg::Field("image")]);
            if let Some(r) = self.lookup(source, &path, &a.image) {
                accesses.push(attachment_access(r, a, true, "depth", None));
            }
        }
        let read_lists: [(&'static str, &Vec<ReadDecl>, Usage); 3] = [
            ("sampled", &decl.sampled, Usage::Sampled),
            ("storage_read", &decl.storage_read, Usage::StorageRead),
            ("storage_write", &decl.storage_write, Usage::StorageWrite),
        ];
        for (field, list, usage) in read_lists {
            for (i, read) in list.iter().enumerate() {
                let mut path = pass_path(index, &[Seg::Field(field), Seg::Index(i)]);
                if matches!(read, ReadDecl::Conditional(_)) {
                    path.push(Seg::Field("name"));
                }
                if let Some(r) = self.lookup(source, &path, read.name()) {
                    accesses.push(IrAccess {
                        resource: r,
                        usage: usage.clone(),
                        conditions: read.conditions().to_vec(),
                        field,
                        item: Some(i),
                    });
                }
            }
        }
        for (field, name, usage) in [
            ("src", &decl.src, Usage::TransferSrc),
            ("dst", &decl.dst, Usage::TransferDst),
        ] {
            if let Some(name) = name {
                let path = pass_path(index, &[Seg::Field(field)]);
                if let Some(r) = self.lookup(source, &path, name) {
                    accesses.push(IrAccess {
                        resource: r,
                        usage,
                        conditions: Vec::new(),
                        field,
                        item: None,
                    });
                }
            }
        }
        let mut after = Vec::new();
        for (i, name) in decl.after.iter().enumerate() {
            match self.pass_index.get(name.as_str()) {
                Some(&target) => after.push(target),
                None => {
                    let names: Vec<&str> = self
                        .graph
                        .passes
                        .iter()
                        .map(|p| p.item.name.as_str())
                        .collect();
                    let hint = crate::diagnostic::nearest(name, names)
                        .map(|n| format!("did you mean \"{n}\"?"));
                    self.error(
                        source,
                        &pass_path(index, &[Seg::Field("after"), Seg::Index(i)]),
                        format!("unknown pass \"{name}\""),
                    )
                    .hint = hint;
                }
            }
        }
        let mut params = BTreeMap::new();
        for (name, value) in &decl.params {
            match crate::load::resolve_value(&self.graph.sources[source].params, value) {
                Ok(v) => {
                    if let Some(bad) = crate::load::non_finite(&v) {
                        self.error(
                            source,
                            &pass_path(index, &[Seg::Field("params"), Seg::Key(name)]),
                            format!("parameter \"{name}\" must be finite, found {bad}"),
                        );
                    }
                    params.insert(name.clone(), v);
                }
                Err(missing) => {
                    let names: Vec<&str> = self.graph.sources[source]
                        .params
                        .keys()
                        .map(String::as_str)
                        .collect();
                    let hint = crate::diagnostic::nearest(&missing, names)
                        .map(|n| format!("did you mean \"${n}\"?"));
                    self.error(
                        source,
                        &pass_path(index, &[Seg::Field("params"), Seg::Key(name)]),
                        format!("unknown parameter \"${missing}\""),
                    )
                    .hint = hint;
                }
            }
        }
        self.check_dispatch(source, index, decl.dispatch.as_ref());
        let dispatch = match &decl.dispatch {
            None => None,
            Some(Dispatch::Output(x, y)) => Some(IrDispatch::Output(*x, *y)),
            Some(Dispatch::Groups(x, y, z)) => Some(IrDispatch::Groups(*x, *y, *z)),
            Some(Dispatch::Image(name, x, y)) => self
                .lookup(source, &pass_path(index, &[Seg::Field("dispatch")]), name)
                .map(|r| IrDispatch::Image(r, *x, *y)),
        };
        let dir = self.graph.sources[source]
            .file
            .parent()
            .map(|d| d.to_path_buf())
            .unwrap_or_default();
        let shaders = ShaderFiles {
            vertex: decl.shaders.vertex.as_ref().map(|s| dir.join(s)),
            fragment: decl.shaders.fragment.as_ref().map(|s| dir.join(s)),
            compute: decl.shaders.compute.as_ref().map(|s| dir.join(s)),
        };
        let pass = IrPass {
            name: decl.name.clone(),
            source,
            index,
            kind: decl.kind,
            shaders,
            draw: decl.draw.clone(),
            dispatch,
            params,
            accesses,
            after,
            enabled_if: decl.enabled_if.clone(),
            raster: self.raster_state(source, index, decl),
        };
        self.check_pass_shape(&pass, decl, resources);
        pass
    }

    /// A pass's declared fixed-function state, with bias parameters resolved;
    /// only raster passes have it, and depth state needs a depth attachment.
    fn raster_state(&mut self, source: usize, index: usize, decl: &PassDecl) -> RasterState {
        let Some(raster) = &decl.raster else {
            return RasterState::default();
        };
        let at = |field| pass_path(index, &[Seg::Field("raster"), Seg::Field(field)]);
        if decl.kind != PassKind::Raster {
            self.error(
                source,
                &pass_path(index, &[Seg::Field("raster")]),
                format!(
                    "a {:?} pass has no raster state (only Raster passes draw triangles with it)",
                    decl.kind
                ),
            );
        }
        let depth_state = raster.depth_compare.is_some() || raster.depth_bias.is_some();
        if depth_state && decl.depth.is_none() {
            let field = if raster.depth_compare.is_some() {
                "depth_compare"
            } else {
                "depth_bias"
            };
            self.error(
                source,
                &at(field),
                format!("`{field}` needs a depth attachment, and the pass has none"),
            );
        }
        let depth_bias = raster.depth_bias.as_ref().map(|(c, s)| {
            let path = at("depth_bias");
            let constant = self.dim(source, &path, c, "a depth bias").unwrap_or(0.0);
            let slope = self.dim(source, &path, s, "a depth bias").unwrap_or(0.0);
            (constant, slope)
        });
        RasterState {
            depth_compare: raster.depth_compare,
            depth_bias,
            cull: raster.cull.unwrap_or_default(),
        }
    }

    /// Work-group sizes of at least 1; fixed group counts within the count
    /// every Vulkan device supports.
    fn check_dispatch(&mut self, source: usize, index: usize, dispatch: Option<&Dispatch>) {
        let at = pass_path(index, &[Seg::Field("dispatch")]);
        let (values, what, max) = match dispatch {
            None => return,
            Some(Dispatch::Output(x, y) | Dispatch::Image(_, x, y)) => {
                (vec![*x, *y], "work-group sizes", u32::MAX)
            }
            Some(Dispatch::Groups(x, y, z)) => {
                (vec![*x, *y, *z], "group counts", MAX_WORKGROUP_COUNT)
            }
        };
        if let Some(bad) = values.iter().find(|v| !(1..=max).contains(*v)) {
            let range = if max == u32::MAX {
                "at least 1".to_string()
            } else {
                format!("from 1 to {max}")
            };
            self.error(source, &at, format!("{what} must be {range}, found {bad}"));
        }
    }

    /// Rules about what each pass kind must declare.
    fn check_pass_shape(&mut self, pass: &IrPass, decl: &PassDecl, resources: &[IrResource]) {
        let (source, index) = (pass.source, pass.index);
        let name = &pass.name;
        let here = pass_path(index, &[Seg::Field("kind")]);
        let need = |r: &mut Self, ok: bool, what: &str| {
            if !ok {
                r.error(
                    source,
                    &here,
                    format!("{:?} pass \"{name}\" needs {what}", pass.kind),
                );
            }
        };
        match pass.kind {
            PassKind::Raster => {
                need(self, decl.shaders.vertex.is_some(), "a vertex shader");
                need(
                    self,
                    decl.color.is_empty() || decl.shaders.fragment.is_some(),
                    "a fragment shader for its colour attachments",
                );
                need(self, decl.draw.is_some(), "a `draw`");
                need(
                    self,
                    !decl.color.is_empty() || decl.depth.is_some(),
                    "a colour or depth attachment",
                );
            }
            PassKind::Fullscreen => {
                need(self, decl.shaders.fragment.is_some(), "a fragment shader");
                need(self, !decl.color.is_empty(), "a colour attachment");
            }
            PassKind::Compute => {
                need(self, decl.shaders.compute.is_some(), "a compute shader");
                need(self, decl.dispatch.is_some(), "a `dispatch`");
            }
            PassKind::Copy | PassKind::Blit => {
                need(
                    self,
                    decl.src.is_some() && decl.dst.is_some(),
                    "`src` and `dst`",
                );
                let images = pass.accesses.iter().all(|a| {
                    matches!(
                        resources.get(a.resource).map(|r| &r.kind),
                        Some(IrKind::Image { .. })
                    )
                });
                if pass.kind == PassKind::Blit && !images {
                    self.error(
                        source,
                        &here,
                        format!("blit pass \"{name}\" works on images only"),
                    );
                }
            }
        }
        let shader_fields: [(&str, bool); 3] = [
            ("vertex", decl.shaders.vertex.is_some()),
            ("fragment", decl.shaders.fragment.is_some()),
            ("compute", decl.shaders.compute.is_some()),
        ];
        for (stage, present) in shader_fields {
            let allowed = match pass.kind {
                PassKind::Raster => stage != "compute",
                PassKind::Fullscreen => stage == "fragment",
                PassKind::Compute => stage == "compute",
                PassKind::Copy | PassKind::Blit => false,
            };
            if present && !allowed {
                self.error(
                    source,
                    &pass_path(index, &[Seg::Field("shaders"), Seg::Field(stage)]),
                    format!("a {:?} pass has no {stage} shader", pass.kind),
                );
            }
        }
        let attachment_kinds = !decl.color.is_empty() || decl.depth.is_some();
        if attachment_kinds
            && matches!(
                pass.kind,
                PassKind::Compute | PassKind::Copy | PassKind::Blit
            )
        {
            self.error(
                source,
                &here,
                format!("a {:?} pass cannot have attachments", pass.kind),
            );
        }
        for (i, a) in decl.color.iter().enumerate() {
            if let LoadDecl::Clear(v) = &a.load {
                let at = pass_path(
                    index,
                    &[Seg::Field("color"), Seg::Index(i), Seg::Field("load")],
                );
                if v.len() != 4 {
                    self.error(
                        source,
                        &at,
                        format!("a colour clear needs 4 values, found {}", v.len()),
                    );
                } else if let Some(bad) = v.iter().find(|x| !x.is_finite()) {
                    self.error(
                        source,
                        &at,
                        format!("clear values must be finite numbers, found {bad}"),
                    );
                }
            }
            if a.read_only {
                self.error(
                    source,
                    &pass_path(
                        index,
                        &[Seg::Field("color"), Seg::Index(i), Seg::Field("read_only")],
                    ),
                    "`read_only` applies to depth attachments only".to_string(),
                );
            }
        }
        if let Some(a) = &decl.depth {
            let at = pass_path(index, &[Seg::Field("depth"), Seg::Field("load")]);
            match &a.load {
                LoadDecl::Clear(v) if v.len() != 1 => {
                    self.error(
                        source,
                        &at,
                        format!("a depth clear needs 1 value, found {}", v.len()),
                    );
                }
                LoadDecl::Clear(v) if !(0.0..=1.0).contains(&v[0]) => {
                    self.error(
                        source,
                        &at,
                        format!("a depth clear must be in [0, 1], found {}", v[0]),
                    );
                }
                LoadDecl::Clear(_) | LoadDecl::DontCare if a.read_only => {
                    self.error(
                        source,
                        &at,
                        "a read-only depth attachment tests against earlier depth, so it needs `load: Load`".to_string(),
                    );
                }
                _ => {}
            }
            if a.blend.is_some() {
                self.error(
                    source,
                    &pass_path(index, &[Seg::Field("depth"), Seg::Field("blend")]),
                    "depth attachments do not blend".to_string(),
                );
            }
        }
    }

    /// Format capabilities, attachment kinds, sizes and in-pass conflicts.
    fn check_usages(&mut self, ir: &Ir) {
        for pass in &ir.passes {
            let (source, index) = (pass.source, pass.index);
            let mut seen: HashMap<usize, &IrAccess> = HashMap::new();
            let mut attachment_sizes: Vec<(&IrAccess, Vec<SizeAtProbe>)> = Vec::new();
            for access in &pass.accesses {
                let path = access_path(index, access);
                let resource = &ir.resources[access.resource];
                let rname = &resource.name;
                if let Some(prev) = seen.get(&access.resource) {
                    if !compatible_in_one_pass(&prev.usage, &access.usage) {
                        self.error(source, &path, format!("pass \"{}\" uses \"{rname}\" as {} and as {}", pass.name, usage_name(&prev.usage), usage_name(&access.usage)))
                            .hint = Some("an image cannot be read and written as an attachment in one pass; use a separate image".into());
                    }
                }
                seen.insert(access.resource, access);
                match &resource.kind {
                    IrKind::External => {}
                    IrKind::Buffer { .. } => {
                        if matches!(access.usage, Usage::Color { .. } | Usage::Depth { .. }) {
                            self.error(
                                source,
                                &path,
                                format!("buffer \"{rname}\" cannot be an attachment"),
                            );
                        }
                    }
                    IrKind::Image {
                        format, samples, ..
                    } => {
                        let (needed, what): (FormatFeatures, &str) = match &access.usage {
                            Usage::Sampled => (FormatFeatures::SAMPLED, "sampled"),
                            Usage::StorageRead | Usage::StorageWrite => {
                                (FormatFeatures::STORAGE, "a storage image")
                            }
                            Usage::Color { blend: Some(_), .. } => (
                                FormatFeatures::COLOR_ATTACHMENT | FormatFeatures::BLEND,
                                "a blended colour attachment",
                            ),
                            Usage::Color { .. } => {
                                (FormatFeatures::COLOR_ATTACHMENT, "a colour attachment")
                            }
                            Usage::Depth { .. } => {
                                (FormatFeatures::DEPTH_ATTACHMENT, "a depth attachment")
                            }
                            Usage::TransferSrc | Usage::TransferDst => {
                                (FormatFeatures::empty(), "")
                            }
                        };
                        let is_depth = format.aspect != Aspect::Color;
                        match (&access.usage, is_depth) {
                            (Usage::Color { .. }, true) => {
                                self.error(source, &path, format!("depth format {} of \"{rname}\" used as a colour attachment", format.name))
                                    .hint = Some("move it to `depth`, or give the image a colour format".into());
                            }
                            (Usage::Depth { .. }, false) => {
                                self.error(source, &path, format!("colour format {} of \"{rname}\" used as a depth attachment", format.name))
                                    .hint = Some("use a depth format such as D32_SFLOAT".into());
                            }
                            _ if !format.guaranteed.contains(needed) => {
                                let alternatives: Vec<&str> = FORMATS
                                    .iter()
                                    .filter(|f| {
                                        f.guaranteed.contains(needed) && f.aspect == format.aspect
                                    })
                                    .map(|f| f.name)
                                    .take(4)
                                    .collect();
                                self.error(source, &path, format!("format {} of \"{rname}\" cannot be used as {what}: Vulkan does not guarantee it", format.name))
                                    .hint = Some(format!("formats that can: {}", alternatives.join(", ")));
                            }
                            _ => {}
                        }
                        if matches!(access.usage, Usage::StorageRead | Usage::StorageWrite)
                            && *samples > 1
                        {
                            self.error(
                                source,
                                &path,
                                format!("multisampled image \"{rname}\" cannot be a storage image"),
                            );
                        }
                        let attachment =
                            matches!(access.usage, Usage::Color { .. } | Usage::Depth { .. });
                        if let (true, IrKind::Image { mips, layers, .. }) =
                            (attachment, &ir.resources[access.resource].kind)
                        {
                            if *mips > 1 || *layers > 1 {
                                self.error(
                                    source,
                                    &path,
                                    format!("\"{rname}\" has {mips} mip level(s) and {layers} layer(s), but attachments render to a single mip level and layer"),
                                )
                                .hint = Some("give the attachment image `mips: 1` and `layers: 1`".into());
                            }
                        }
                        if attachment {
                            let sizes = PROBE_SIZES
                                .iter()
                                .map(|out| {
                                    image_extent(ir, access.resource, *out).map(|e| (e, *samples))
                                })
                                .collect();
                            attachment_sizes.push((access, sizes));
                        }
                    }
                }
            }
            if let Some((first, first_sizes)) = attachment_sizes.first() {
                for (other, sizes) in &attachment_sizes[1..] {
                    if let Some(k) = (0..PROBE_SIZES.len()).find(|&k| sizes[k] != first_sizes[k]) {
                        let describe = |s: &Option<(Extent, u32)>| match s {
                            Some((e, n)) => format!("{}x{} ({n} sample(s))", e.width, e.height),
                            None => "unknown".into(),
                        };
                        let out = PROBE_SIZES[k];
                        let a = &ir.resources[first.resource].name;
                        let b = &ir.resources[other.resource].name;
                        self.error(source, &access_path(index, other), format!(
                            "attachments of pass \"{}\" differ in size: \"{a}\" is {} but \"{b}\" is {} at output {}x{}",
                            pass.name, describe(&first_sizes[k]), describe(&sizes[k]), out.width, out.height))
                            .hint = Some("give attachments of one pass the same `size` and `samples`".into());
                    }
                }
            }
        }
        for (i, r) in ir.resources.iter().enumerate() {
            if let IrKind::Image {
                size: SizeSpec::Like(..),
                ..
            } = r.kind
            {
                if image_extent(ir, i, PROBE_SIZES[0]).is_none() {
                    self.error(
                        r.source,
                        &resource_path(r.index, &[Seg::Field("size")]),
                        format!(
                            "the size of \"{}\" refers back to itself through `Like`",
                            r.name
                        ),
                    );
                }
            }
        }
    }
}

fn attachment_access(
    resource: usize,
    a: &AttachmentDecl,
    depth: bool,
    field: &'static str,
    item: Option<usize>,
) -> IrAccess {
    let usage = if depth {
        Usage::Depth {
            load: a.load.clone(),
            store: a.store,
            read_only: a.read_only,
        }
    } else {
        Usage::Color {
            load: a.load.clone(),
            store: a.store,
            blend: a.blend,
        }
    };
    IrAccess {
        resource,
        usage,
        conditions: Vec::new(),
        field,
        item,
    }
}

/// The path of an access inside its pass, for diagnostics.
pub fn access_path(pass_index: usize, access: &IrAccess) -> Vec<Seg<'static>> {
    let mut path = vec![
        Seg::Field("passes"),
        Seg::Index(pass_index),
        Seg::Field(access.field),
    ];
    if let Some(i) = access.item {
        path.push(Seg::Index(i));
    }
    match access.usage {
        Usage::Color { .. } | Usage::Depth { .. } => path.push(Seg::Field("image")),
        _ if !access.conditions.is_empty() => path.push(Seg::Field("name")),
        _ => {}
    }
    path
}

fn compatible_in_one_pass(a: &Usage, b: &Usage) -> bool {
    matches!(
        (a, b),
        (Usage::Sampled, Usage::Sampled)
            | (Usage::StorageRead, Usage::StorageWrite)
            | (Usage::StorageWrite, Usage::StorageRead)
            | (
                Usage::Depth {
                    read_only: true,
                    ..
                },
                Usage::Sampled
            )
            | (
                Usage::Sampled,
                Usage::Depth {
                    read_only: true,
                    ..
                }
            )
    )
}

/// Words for a usage in messages.
pub fn usage_name(u: &Usage) -> &'static str {
    match u {
        Usage::Sampled => "a sampled read",
        Usage::StorageRead => "a storage read",
        Usage::StorageWrite => "a storage write",
        Usage::Color { .. } => "a colour attachment",
        Usage::Depth {
            read_only: true, ..
        } => "a read-only depth attachment",
        Usage::Depth { .. } => "a depth attachment",
        Usage::TransferSrc => "a transfer source",
        Usage::TransferDst => "a transfer destination",
    }
}

fn resource_name(r: &ResourceDecl) -> &str {
    match r {
        ResourceDecl::Image(i) => &i.name,
        ResourceDecl::Buffer(b) => &b.name,
    }
}

/// The work-group count per dimension every Vulkan device supports
/// (`maxComputeWorkGroupCount`'s required minimum).
pub const MAX_WORKGROUP_COUNT: u32 = 65_535;

/// The largest image side weft creates: `maxImageDimension2D` on the devices
/// it targets, and the limit of `Absolute` sizes.
pub const MAX_IMAGE_DIMENSION: u32 = 16_384;

/// The error for an image side over [`MAX_IMAGE_DIMENSION`].
pub(crate) fn oversized_image(name: &str, size: Extent, output: Extent) -> String {
    format!(
        "\"{name}\" would be {}x{} at output size {}x{}, over the {MAX_IMAGE_DIMENSION} pixels an image side may have",
        size.width, size.height, output.width, output.height
    )
}

/// An image's size for a given output size; `None` for a `Like` cycle or a buffer.
pub fn image_extent(ir: &Ir, resource: usize, output: Extent) -> Option<Extent> {
    let scale = |v: u32, s: f64| ((v as f64 * s).floor() as u32).max(1);
    let mut current = resource;
    let (mut fx, mut fy) = (1.0, 1.0);
    for _ in 0..=ir.resources.len() {
        let IrKind::Image { size, .. } = ir.resources.get(current)?.kind else {
            return None;
        };
        match size {
            SizeSpec::Output => {
                return Some(Extent {
                    width: scale(output.width, fx),
                    height: scale(output.height, fy),
                })
            }
            SizeSpec::Scale(sx, sy) => {
                return Some(Extent {
                    width: scale(output.width, sx * fx),
                    height: scale(output.height, sy * fy),
                })
            }
            SizeSpec::Absolute(w, h) => {
                return Some(Extent {
                    width: scale(w, fx),
                    height: scale(h, fy),
                })
            }
            SizeSpec::Like(other, sx, sy) => {
                fx *= sx;
                fy *= sy;
                current = other;
            }
        }
    }
    None
}

/// Variables available to buffer size expressions.
pub fn expression_vars(
    params: &BTreeMap<String, ParamValue>,
    output: Extent,
    lights: u32,
) -> BTreeMap<String, f64> {
    let mut vars: BTreeMap<String, f64> = params
        .iter()
        .filter_map(|(k, v)| match v {
            ParamValue::Number(n) => Some((k.clone(), *n)),
            _ => None,
        })
        .collect();
    vars.insert("width".into(), output.width as f64);
    vars.insert("height".into(), output.height as f64);
    vars.insert("pixels".into(), output.width as f64 * output.height as f64);
    vars.insert("lights".into(), lights as f64);
    vars
}
