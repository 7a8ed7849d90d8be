//! The compiler: features decide which passes and reads are live, data decides the
//! order, the output decides what is culled, and then resources, memory, barriers
//! and render passes are derived for one output size.

use crate::diagnostic::Diagnostic;
use crate::load::LoadedGraph;
use crate::memory::{place, MemoryRequirements, Transient};
use crate::order::{contributing, order, pass_uses, OrderError, PassUse};
use crate::plan::{
    AttachmentDesc, Barrier, Binding, BindingKind, BufferDesc, CulledPass, Extent, ImageDesc,
    LoadOp, Location, Plan, PlanPass, PlanResource, RenderPassDesc, Residency, ResourceDesc,
    StoreOp,
};
use crate::resolve::{
    access_path, expression_vars, image_extent, oversized_image, resolve, resource_path,
    BufferSize, Ir, IrDispatch, IrKind, Usage, MAX_IMAGE_DIMENSION,
};
use crate::schema::{LoadDecl, PassKind, StoreDecl};
use crate::spans::Seg;
use crate::sync::{sampled_layout, shader_stages, GpuAccess, ResourceState};
use crate::vk::{Access, BufferUsage, ImageUsage, Layout, Stage};
use std::collections::BTreeSet;

/// What to compile a graph for.
pub struct CompileOptions<'a> {
    pub extent: Extent,
    /// Scene features and user toggles that are on.
    pub features: BTreeSet<String>,
    /// Light count, for buffer size expressions.
    pub lights: u32,
    /// Memory requirements of an image; the executor passes the device's.
    pub memory: &'a dyn Fn(&ImageDesc) -> MemoryRequirements,
    /// Images to keep readable after the frame besides the output (e.g. the HDR
    /// buffer for EXR output): never aliased, left in `TRANSFER_SRC_OPTIMAL`.
    pub readback: Vec<String>,
}

impl Default for CompileOptions<'_> {
    fn default() -> Self {
        CompileOptions {
            extent: Extent {
                width: 1280,
                height: 720,
            },
            features: BTreeSet::new(),
            lights: 1,
            memory: &crate::memory::estimate_requirements,
            readback: Vec::new(),
        }
    }
}

/// A loaded graph that passed the checks that do not depend on features or size,
/// ready to compile many times (on resize, on a feature toggle) without re-validating.
pub struct Prepared<'g> {
    graph: &'g LoadedGraph,
    ir: Ir,
}

impl<'g> Prepared<'g> {
    /// Validates names, formats, parameters and per-pass rules; returns every error found.
    pub fn new(graph: &'g LoadedGraph) -> Result<Self, Vec<Diagnostic>> {
        if graph.has_errors() {
            return Err(graph.diagnostics.clone());
        }
        if graph.is_fragment {
            let file = graph
                .sources
                .first()
                .map(|s| s.file.clone())
                .unwrap_or_default();
            return Err(vec![Diagnostic::error(
                file,
                crate::spans::Pos { line: 1, col: 1 },
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
        Ok(Prepared { graph, ir })
    }

    /// The resolved graph.
    pub fn ir(&self) -> &Ir {
        &self.ir
    }

    /// The toggles a user typed (`name` on, `!name` off) that name no feature
    /// of this graph — neither one its passes test nor a default — each as a
    /// message with the nearest known name as a hint.
    pub fn unknown_features<S: AsRef<str>>(&self, requested: &[S]) -> Vec<String> {
        let mut known = feature_names(&self.ir);
        known.extend(self.graph.default_features.iter().cloned());
        requested
            .iter()
            .map(|f| f.as_ref().trim())
            .map(|f| f.strip_prefix('!').unwrap_or(f))
            .filter(|f| !f.is_empty() && !known.contains(*f))
            .map(|f| {
                let hint = crate::diagnostic::nearest(f, known.iter().map(String::as_str))
                    .map(|n| format!(" (did you mean \"{n}\"?)"))
                    .unwrap_or_default();
                let list = known.iter().cloned().collect::<Vec<_>>().join(", ");
                format!("unknown feature \"{f}\"{hint}; this graph's features are: {list}")
            })
            .collect()
    }

    /// Compiles for one size and feature set.
    pub fn compile(&self, options: &CompileOptions) -> Result<Plan, Vec<Diagnostic>> {
        compile_ir(self.graph, &self.ir, options)
    }
}

/// Validates and compiles a loaded graph, or returns every error found.
pub fn compile(graph: &LoadedGraph, options: &CompileOptions) -> Result<Plan, Vec<Diagnostic>> {
    Prepared::new(graph)?.compile(options)
}

/// Whether every condition (`"name"` on, `"!name"` off) holds.
pub fn conditions_hold(conditions: &[String], features: &BTreeSet<String>) -> bool {
    conditions.iter().all(|c| match c.strip_prefix('!') {
        Some(name) => !features.contains(name),
        None => features.contains(c),
    })
}

/// Every feature name a graph's conditions mention.
pub fn feature_names(ir: &Ir) -> BTreeSet<String> {
    let mut names = BTreeSet::new();
    for pass in &ir.passes {
        let conditions = pass
            .enabled_if
            .iter()
            .chain(pass.accesses.iter().flat_map(|a| a.conditions.iter()));
        for c in conditions {
            names.insert(c.trim_start_matches('!').to_string());
        }
    }
    names
}

/// Every image the plan creates fits [`MAX_IMAGE_DIMENSION`] at this output size
/// (`check` tries a few sizes; a command line can ask for another).
fn check_image_sizes(
    graph: &LoadedGraph,
    ir: &Ir,
    kept: &[usize],
    output: Extent,
) -> Result<(), Vec<Diagnostic>> {
    let errors: Vec<Diagnostic> = kept
        .iter()
        .filter_map(|&r| {
            let e = image_extent(ir, r, output)?;
            (e.width > MAX_IMAGE_DIMENSION || e.height > MAX_IMAGE_DIMENSION).then(|| {
                let res = &ir.resources[r];
                let (file, pos) =
                    graph.locate(res.source, &resource_path(res.index, &[Seg::Field("size")]));
                Diagnostic::error(file, pos, oversized_image(&res.name, e, output))
            })
        })
        .collect();
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}

fn locate(graph: &LoadedGraph, ir: &Ir, pass: usize, rest: &[Seg]) -> Diagnostic {
    let p = &ir.passes[pass];
    let mut path = vec![Seg::Field("passes"), Seg::Index(p.index)];
    path.extend_from_slice(rest);
    let (file, pos) = graph.locate(p.source, &path);
    Diagnostic::error(file, pos, String::new())
}

fn order_error(
    graph: &LoadedGraph,
    ir: &Ir,
    uses: &[Vec<PassUse>],
    e: &OrderError,
    disabled: &[usize],
) -> Diagnostic {
    let name = |p: usize| ir.passes[p].name.as_str();
    match e {
        OrderError::Cycle(cycle) => {
            let first = cycle.first().copied().unwrap_or(0);
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

/// Compiles a resolved graph for one feature set and size.
pub fn compile_ir(
    graph: &LoadedGraph,
    ir: &Ir,
    options: &CompileOptions,
) -> Result<Plan, Vec<Diagnostic>> {
    let features = &options.features;
    let Some(output) = ir.output else {
        return Err(vec![Diagnostic::error(
            graph
                .sources
                .first()
                .map(|s| s.file.clone())
                .unwrap_or_default(),
            crate::spans::Pos { line: 1, col: 1 },
            "the graph has no output",
        )]);
    };
    let n = ir.passes.len();
    let live: Vec<bool> = ir
        .passes
        .iter()
        .map(|p| conditions_hold(&p.enabled_if, features))
        .collect();
    let disabled: Vec<usize> = (0..n).filter(|&p| !live[p]).collect();
    let uses: Vec<Vec<PassUse>> = (0..n)
        .map(|p| {
            if live[p] {
                pass_uses(ir, p, |c| conditions_hold(c, features))
            } else {
                Vec::new()
            }
        })
        .collect();
    let order = order(ir, &live, &uses).map_err(|errors| {
        errors
            .iter()
            .map(|e| order_error(graph, ir, &uses, e, &disabled))
            .collect::<Vec<_>>()
    })?;
    let root_file = graph
        .sources
        .first()
        .map(|s| s.file.clone())
        .unwrap_or_default();
    let mut roots = vec![output];
    for name in &options.readback {
        match ir
            .resources
            .iter()
            .position(|r| r.name == *name && matches!(r.kind, IrKind::Image { .. }))
        {
            Some(r) if !roots.contains(&r) => roots.push(r),
            Some(_) => {}
            None => {
                let names = ir.resources.iter().map(|r| r.name.as_str());
                return Err(vec![Diagnostic::error(
                    root_file,
                    crate::spans::Pos { line: 1, col: 1 },
                    format!("cannot read back \"{name}\": the graph has no image of that name"),
                )
                .suggest(name, names)]);
            }
        }
    }
    let mut is_root = vec![false; ir.resources.len()];
    for &r in &roots {
        is_root[r] = true;
    }
    if let Some(&unwritten) = roots.iter().find(|&&r| order.writers[r].is_empty()) {
        let (file, pos) = graph.locate(0, &[Seg::Field("output")]);
        return Err(vec![Diagnostic::error(
            file,
            pos,
            format!(
                "no pass writes \"{}\", which is read back after the frame",
                ir.resources[unwritten].name
            ),
        )
        .with_hint(
            "the passes that write it may be disabled by `enabled_if` for these features",
        )]);
    }
    let needed = contributing(ir, &order, &uses, &roots);

    let mut culled = Vec::new();
    let mut warnings = Vec::new();
    for (p, pass) in ir.passes.iter().enumerate() {
        let reason = if !live[p] {
            let failing: Vec<&str> = pass
                .enabled_if
                .iter()
                .filter(|c| !conditions_hold(std::slice::from_ref(c), features))
                .map(String::as_str)
                .collect();
            format!("enabled_if [{}] is false", failing.join(", "))
        } else if !needed[p] {
            let mut d = locate(graph, ir, p, &[Seg::Field("name")]);
            d.severity = crate::diagnostic::Severity::Warning;
            d.message = format!(
                "pass \"{}\" is culled: it contributes nothing to the output",
                pass.name
            );
            warnings.push(d);
            "contributes nothing to the output".to_string()
        } else {
            continue;
        };
        culled.push(CulledPass {
            name: pass.name.clone(),
            reason,
        });
    }
    let sequence: Vec<usize> = order
        .sequence
        .iter()
        .copied()
        .filter(|&p| needed[p])
        .collect();

    let timeline = Timeline::new(ir, &sequence, &uses);
    // Resources used by the remaining passes, in declaration order.
    let mut used: Vec<bool> = timeline
        .per_resource
        .iter()
        .map(|t| !t.is_empty())
        .collect();
    for &r in &roots {
        used[r] = true;
    }
    let mut new_index = vec![usize::MAX; ir.resources.len()];
    let mut kept: Vec<usize> = Vec::new();
    for r in (0..ir.resources.len()).filter(|&r| used[r]) {
        new_index[r] = kept.len();
        kept.push(r);
    }
    warn_unread(graph, ir, &timeline, &uses, &is_root, &mut warnings);
    check_discarding_stores(graph, ir, &sequence, &timeline, &uses, &is_root)?;
    check_image_sizes(graph, ir, &kept, options.extent)?;

    let mut resources: Vec<PlanResource> = Vec::with_capacity(kept.len());
    for &r in &kept {
        let res = &ir.resources[r];
        let residency = if is_root[r] {
            Residency::Output
        } else if res.history {
            Residency::History
        } else {
            Residency::Transient
        };
        let touches = &timeline.per_resource[r];
        let first = touches.first().map_or(usize::MAX, |t| t.0);
        let last = touches.last().map_or(0, |t| t.0);
        let accesses = || {
            touches.iter().flat_map(|&(_, p, k)| {
                uses[p][k]
                    .accesses
                    .iter()
                    .map(move |&a| &ir.passes[p].accesses[a].usage)
            })
        };
        let desc = match &res.kind {
            IrKind::Image {
                format,
                mips,
                layers,
                samples,
                ..
            } => {
                let extent = image_extent(ir, r, options.extent).unwrap_or(options.extent);
                let mut usage = ImageUsage::empty();
                for u in accesses() {
                    usage |= match u {
                        Usage::Sampled => ImageUsage::SAMPLED,
                        Usage::StorageRead | Usage::StorageWrite => ImageUsage::STORAGE,
                        Usage::Color { .. } => ImageUsage::COLOR_ATTACHMENT,
                        Usage::Depth { .. } => ImageUsage::DEPTH_STENCIL_ATTACHMENT,
                        Usage::TransferSrc => ImageUsage::TRANSFER_SRC,
                        Usage::TransferDst => ImageUsage::TRANSFER_DST,
                    };
                }
                if residency == Residency::Output {
                    usage |= ImageUsage::TRANSFER_SRC;
                }
                ResourceDesc::Image(ImageDesc {
                    format: format.name.to_string(),
                    format_raw: format.raw,
                    aspect: format.aspect,
                    extent,
                    mips: *mips,
                    layers: *layers,
                    samples: *samples,
                    usage,
                    texel_bytes: format.bytes,
                })
            }
            IrKind::External => unreachable!(
                "only fragments have external resources, and fragments are not compiled"
            ),
            IrKind::Buffer { size } => {
                let bytes = match size {
                    BufferSize::Bytes(b) => *b,
                    BufferSize::Expression(text) => {
                        let vars = expression_vars(
                            &graph.sources[res.source].params,
                            options.extent,
                            options.lights,
                        );
                        crate::expr::eval(text, &vars)
                            .map(|v| v.max(1.0).ceil() as u64)
                            .unwrap_or(1)
                    }
                };
                let mut usage = BufferUsage::empty();
                for u in accesses() {
                    usage |= match u {
                        Usage::Sampled => BufferUsage::UNIFORM,
                        Usage::TransferSrc => BufferUsage::TRANSFER_SRC,
                        Usage::TransferDst => BufferUsage::TRANSFER_DST,
                        _ => BufferUsage::STORAGE,
                    };
                }
                ResourceDesc::Buffer(BufferDesc { size: bytes, usage })
            }
        };
        resources.push(PlanResource {
            name: res.name.clone(),
            desc,
            residency,
            lifetime: (first.min(sequence.len().saturating_sub(1)), last),
            placement: None,
            frame_start_layout: Layout::Undefined,
        });
    }

    // Transient images share memory.
    let transient: Vec<usize> = (0..resources.len())
        .filter(|&i| {
            resources[i].residency == Residency::Transient
                && matches!(resources[i].desc, ResourceDesc::Image(_))
        })
        .collect();
    let requests: Vec<Transient> = transient
        .iter()
        .map(|&i| match &resources[i].desc {
            ResourceDesc::Image(desc) => Transient {
                requirements: (options.memory)(desc),
                lifetime: resources[i].lifetime,
            },
            ResourceDesc::Buffer(_) => unreachable!("filtered to images"),
        })
        .collect();
    let (memory, placements) = place(&requests);
    for (k, &i) in transient.iter().enumerate() {
        resources[i].placement = Some(placements[k]);
    }

    // Per-pass GPU accesses, then barriers.
    let gpu_uses: Vec<Vec<(usize, GpuAccess)>> = sequence
        .iter()
        .map(|&p| {
            uses[p]
                .iter()
                .map(|u| (new_index[u.resource], gpu_access(ir, p, u)))
                .collect()
        })
        .collect();
    let scopes = read_scopes(&gpu_uses);
    let sharing = memory_sharing(&resources);
    let mut states: Vec<ResourceState> = resources
        .iter()
        .map(|r| ResourceState::fresh(matches!(r.desc, ResourceDesc::Image(_))))
        .collect();
    for (i, r) in resources.iter_mut().enumerate() {
        match r.residency {
            Residency::Transient => {}
            Residency::Output => {
                states[i].layout = Layout::TransferSrcOptimal;
                states[i].reads = Stage::COPY | Stage::BLIT;
                r.frame_start_layout = Layout::TransferSrcOptimal;
            }
            Residency::History => {
                if let Some((first, scope)) = first_access(&gpu_uses, &scopes, i) {
                    if states[i].image {
                        states[i].layout = first.layout;
                        r.frame_start_layout = first.layout;
                    }
                    states[i].write = Some((scope.0, Access::empty()));
                    states[i].visible = vec![scope];
                }
            }
        }
    }
    // The first frame starts from `states`; every later frame starts where the previous
    // one ended, so a transient image's first barrier must also wait for the previous
    // frame's last use of its memory. Simulate one frame to learn that, then record.
    let (_, end_of_frame) =
        record_barriers(&resources, &sharing, &gpu_uses, &scopes, states.clone());
    for (r, state) in states.iter_mut().enumerate() {
        if resources[r].residency == Residency::Transient {
            let (stage, access) = pending_of(&end_of_frame, sharing[r].iter().copied().chain([r]));
            state.inherit(stage, access);
        }
    }
    let (pass_barriers, states) = record_barriers(&resources, &sharing, &gpu_uses, &scopes, states);
    let passes: Vec<PlanPass> = sequence
        .iter()
        .zip(pass_barriers)
        .enumerate()
        .map(|(i, (&p, barriers))| {
            plan_pass(
                graph, ir, p, i, &uses, &new_index, &resources, &timeline, &is_root, barriers,
                options,
            )
        })
        .collect();
    let mut epilogue = Vec::new();
    for (i, r) in resources.iter().enumerate() {
        let target = match r.residency {
            Residency::Transient => continue,
            Residency::Output => GpuAccess {
                stage: Stage::COPY | Stage::BLIT,
                access: Access::TRANSFER_READ,
                layout: Layout::TransferSrcOptimal,
                discards: false,
            },
            Residency::History => match first_access(&gpu_uses, &scopes, i) {
                Some((first, (stage, access))) => GpuAccess {
                    stage,
                    access,
                    discards: false,
                    ..first
                },
                None => continue,
            },
        };
        let (src_stage, src_access) = states[i].pending();
        epilogue.push(Barrier {
            resource: i,
            src_stage,
            src_access,
            dst_stage: target.stage,
            dst_access: target.access,
            layouts: states[i].image.then_some((states[i].layout, target.layout)),
        });
    }

    let mut feature_list: Vec<String> = features.iter().cloned().collect();
    feature_list.sort();
    Ok(Plan {
        name: graph.name.clone(),
        file: graph
            .sources
            .first()
            .map(|s| s.file.clone())
            .unwrap_or_default(),
        files: graph.files(),
        extent: options.extent,
        features: feature_list,
        output: new_index[output],
        readback: roots[1..].iter().map(|&r| new_index[r]).collect(),
        resources,
        passes,
        culled,
        memory,
        epilogue,
        warnings,
    })
}

type Scope = (Stage, Access);

fn first_access(
    gpu_uses: &[Vec<(usize, GpuAccess)>],
    scopes: &[Vec<Scope>],
    r: usize,
) -> Option<(GpuAccess, Scope)> {
    gpu_uses
        .iter()
        .zip(scopes)
        .flat_map(|(u, s)| u.iter().zip(s))
        .find(|((i, _), _)| *i == r)
        .map(|((_, a), s)| (*a, *s))
}

/// For every access, the destination scope its barrier should have: its own, or for a
/// read, the union with the reads after it in the same layout up to the next write.
fn read_scopes(gpu_uses: &[Vec<(usize, GpuAccess)>]) -> Vec<Vec<Scope>> {
    let mut scopes: Vec<Vec<Scope>> = gpu_uses
        .iter()
        .map(|u| u.iter().map(|(_, a)| (a.stage, a.access)).collect())
        .collect();
    let mut run: std::collections::HashMap<usize, (Layout, Scope)> =
        std::collections::HashMap::new();
    for i in (0..gpu_uses.len()).rev() {
        for (k, &(r, a)) in gpu_uses[i].iter().enumerate() {
            if a.access.is_write() {
                run.remove(&r);
                continue;
            }
            let mut scope = (a.stage, a.access);
            if let Some((layout, later)) = run.get(&r) {
                if *layout == a.layout {
                    scope = (scope.0 | later.0, scope.1 | later.1);
                }
            }
            scopes[i][k] = scope;
            run.insert(r, (a.layout, scope));
        }
    }
    scopes
}

/// Walks the passes once, returning each pass's barriers and the final states.
fn record_barriers(
    resources: &[PlanResource],
    sharing: &[Vec<usize>],
    gpu_uses: &[Vec<(usize, GpuAccess)>],
    scopes: &[Vec<Scope>],
    mut states: Vec<ResourceState>,
) -> (Vec<Vec<Barrier>>, Vec<ResourceState>) {
    let mut all = Vec::with_capacity(gpu_uses.len());
    for (i, accesses) in gpu_uses.iter().enumerate() {
        let mut barriers = Vec::new();
        for (k, &(r, access)) in accesses.iter().enumerate() {
            if resources[r].lifetime.0 == i && resources[r].residency == Residency::Transient {
                let before = sharing[r]
                    .iter()
                    .copied()
                    .filter(|&j| resources[j].lifetime.1 < resources[r].lifetime.0);
                let (stage, acc) = pending_of(&states, before);
                states[r].inherit(stage, acc);
            }
            if let Some(b) = states[r].access(r, access, scopes[i][k]) {
                barriers.push(b);
            }
        }
        all.push(barriers);
    }
    (all, states)
}

/// For each resource, the other transient images whose memory overlaps its own.
fn memory_sharing(resources: &[PlanResource]) -> Vec<Vec<usize>> {
    let mut placed: Vec<(usize, u64, u64, usize)> = resources
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            r.placement
                .map(|p| (p.block, p.offset, p.offset + p.size, i))
        })
        .collect();
    placed.sort_unstable();
    let mut sharing = vec![Vec::new(); resources.len()];
    for (k, &(block, _, end, i)) in placed.iter().enumerate() {
        for &(other_block, start, _, j) in &placed[k + 1..] {
            if other_block != block || start >= end {
                break;
            }
            sharing[i].push(j);
            sharing[j].push(i);
        }
    }
    sharing
}

/// The union of the pending stages and accesses of some resources.
fn pending_of(states: &[ResourceState], which: impl Iterator<Item = usize>) -> (Stage, Access) {
    which.fold((Stage::empty(), Access::empty()), |(s, a), j| {
        let (js, ja) = states[j].pending();
        (s | js, a | ja)
    })
}

/// How the GPU sees a pass's merged use of a resource.
fn gpu_access(ir: &Ir, pass: usize, u: &PassUse) -> GpuAccess {
    let p = &ir.passes[pass];
    let aspect = match ir.resources[u.resource].kind {
        IrKind::Image { format, .. } => Some(format.aspect),
        IrKind::Buffer { .. } | IrKind::External => None,
    };
    let mut stage = Stage::empty();
    let mut access = Access::empty();
    let mut layout = Layout::General;
    for &a in &u.accesses {
        let (s, acc, l) = match &p.accesses[a].usage {
            Usage::Sampled => match aspect {
                Some(aspect) => (
                    image_read_stages(p.kind),
                    Access::SHADER_SAMPLED_READ,
                    sampled_layout(aspect),
                ),
                None => (shader_stages(p.kind), Access::UNIFORM_READ, Layout::General),
            },
            Usage::StorageRead => (
                shader_stages(p.kind),
                Access::SHADER_STORAGE_READ,
                Layout::General,
            ),
            Usage::StorageWrite => (
                shader_stages(p.kind),
                Access::SHADER_STORAGE_WRITE,
                Layout::General,
            ),
            Usage::Color { load, .. } => {
                let read = if *load == LoadDecl::Load {
                    Access::COLOR_ATTACHMENT_READ
                } else {
                    Access::empty()
                };
                (
                    Stage::COLOR_ATTACHMENT_OUTPUT,
                    Access::COLOR_ATTACHMENT_WRITE | read,
                    Layout::ColorAttachmentOptimal,
                )
            }
            Usage::Depth {
                read_only: true, ..
            } => (
                Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS,
                Access::DEPTH_STENCIL_ATTACHMENT_READ,
                Layout::DepthStencilReadOnlyOptimal,
            ),
            Usage::Depth { .. } => (
                Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS,
                Access::DEPTH_STENCIL_ATTACHMENT_READ | Access::DEPTH_STENCIL_ATTACHMENT_WRITE,
                Layout::DepthStencilAttachmentOptimal,
            ),
            Usage::TransferSrc => (
                shader_stages(p.kind),
                Access::TRANSFER_READ,
                Layout::TransferSrcOptimal,
            ),
            Usage::TransferDst => (
                shader_stages(p.kind),
                Access::TRANSFER_WRITE,
                Layout::TransferDstOptimal,
            ),
        };
        stage |= s;
        access |= acc;
        layout = l;
    }
    if aspect.is_none() {
        layout = Layout::General;
    }
    GpuAccess {
        stage,
        access,
        layout,
        discards: u.discards,
    }
}

/// Images are sampled in fragment shaders in raster passes (vertex shaders read buffers).
fn image_read_stages(kind: PassKind) -> Stage {
    match kind {
        PassKind::Raster => Stage::FRAGMENT_SHADER,
        other => shader_stages(other),
    }
}

/// For each resource, the passes that use it in plan order, so per-resource questions
/// cost the resource's uses, not the whole plan.
struct Timeline {
    /// `(plan index, IR pass, index into that pass's uses)` per resource.
    per_resource: Vec<Vec<(usize, usize, usize)>>,
}

impl Timeline {
    fn new(ir: &Ir, sequence: &[usize], uses: &[Vec<PassUse>]) -> Self {
        let mut per_resource = vec![Vec::new(); ir.resources.len()];
        for (i, &p) in sequence.iter().enumerate() {
            for (k, u) in uses[p].iter().enumerate() {
                per_resource[u.resource].push((i, p, k));
            }
        }
        Timeline { per_resource }
    }

    /// Whether anything after plan pass `i` needs what it left in resource `r`.
    fn needed_later(
        &self,
        ir: &Ir,
        uses: &[Vec<PassUse>],
        i: usize,
        r: usize,
        is_root: &[bool],
    ) -> bool {
        let touches = &self.per_resource[r];
        let next = touches.partition_point(|t| t.0 <= i);
        match touches.get(next) {
            Some(&(_, p, k)) => uses[p][k].reads_previous || !uses[p][k].discards,
            None => is_root[r] || ir.resources[r].history,
        }
    }
}

fn warn_unread(
    graph: &LoadedGraph,
    ir: &Ir,
    timeline: &Timeline,
    uses: &[Vec<PassUse>],
    is_root: &[bool],
    warnings: &mut Vec<Diagnostic>,
) {
    for (r, res) in ir.resources.iter().enumerate() {
        if is_root[r] || res.history {
            continue;
        }
        let touches = &timeline.per_resource[r];
        let written = touches.iter().any(|&(_, p, k)| uses[p][k].writes);
        // A depth attachment is read by its own depth test.
        let read = touches.iter().any(|&(_, p, k)| {
            let u = &uses[p][k];
            u.reads_previous
                || u.accesses
                    .iter()
                    .any(|&a| matches!(ir.passes[p].accesses[a].usage, Usage::Depth { .. }))
        });
        if written && !read {
            let (file, pos) = graph.locate(
                res.source,
                &[
                    Seg::Field("resources"),
                    Seg::Index(res.index),
                    Seg::Field("name"),
                ],
            );
            warnings.push(Diagnostic::warning(
                file,
                pos,
                format!("resource \"{}\" is written and never read", res.name),
            ));
        }
    }
}

/// A declared `store: DontCare` whose contents a later pass needs is an error.
fn check_discarding_stores(
    graph: &LoadedGraph,
    ir: &Ir,
    sequence: &[usize],
    timeline: &Timeline,
    uses: &[Vec<PassUse>],
    is_root: &[bool],
) -> Result<(), Vec<Diagnostic>> {
    let mut errors = Vec::new();
    for (i, &p) in sequence.iter().enumerate() {
        for access in &ir.passes[p].accesses {
            let store = match &access.usage {
                Usage::Color { store, .. }
                | Usage::Depth {
                    store,
                    read_only: false,
                    ..
                } => *store,
                _ => continue,
            };
            if store == StoreDecl::DontCare
                && timeline.needed_later(ir, uses, i, access.resource, is_root)
            {
                let mut path = access_path(ir.passes[p].index, access);
                path.pop();
                path.push(Seg::Field("store"));
                let (file, pos) = graph.locate(ir.passes[p].source, &path);
                errors.push(
                    Diagnostic::error(file, pos, format!(
                        "pass \"{}\" discards \"{}\" with `store: DontCare` but later work needs it",
                        ir.passes[p].name, ir.resources[access.resource].name))
                    .with_hint("use `store: Store` (the compiler already drops stores nothing reads)"),
                );
            }
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}

#[allow(clippy::too_many_arguments)]
fn plan_pass(
    graph: &LoadedGraph,
    ir: &Ir,
    p: usize,
    i: usize,
    all_uses: &[Vec<PassUse>],
    new_index: &[usize],
    resources: &[PlanResource],
    timeline: &Timeline,
    is_root: &[bool],
    barriers: Vec<Barrier>,
    options: &CompileOptions,
) -> PlanPass {
    let pass = &ir.passes[p];
    let uses = &all_uses[p];
    let mut is_active = vec![false; pass.accesses.len()];
    for u in uses {
        for &k in &u.accesses {
            is_active[k] = true;
        }
    }
    let active_accesses = || {
        pass.accesses
            .iter()
            .zip(&is_active)
            .filter(|(_, on)| **on)
            .map(|(a, _)| a)
    };
    let mut bindings = Vec::new();
    let mut defines: BTreeSet<String> = BTreeSet::new();
    for access in active_accesses() {
        let kind = match access.usage {
            Usage::Sampled => BindingKind::Sampled,
            Usage::StorageRead => BindingKind::StorageRead,
            Usage::StorageWrite => BindingKind::StorageWrite,
            _ => continue,
        };
        let r = new_index[access.resource];
        if let Some(existing) = bindings.iter_mut().find(|b: &&mut Binding| b.resource == r) {
            if matches!(
                (existing.kind, kind),
                (BindingKind::StorageRead, BindingKind::StorageWrite)
                    | (BindingKind::StorageWrite, BindingKind::StorageRead)
            ) {
                existing.kind = BindingKind::StorageReadWrite;
            }
            continue;
        }
        bindings.push(Binding { resource: r, kind });
        if !access.conditions.is_empty() {
            defines.insert(format!(
                "HAS_{}",
                ir.resources[access.resource].name.to_ascii_uppercase()
            ));
        }
    }
    let render_pass = matches!(pass.kind, PassKind::Raster | PassKind::Fullscreen).then(|| {
        let mut attachments = Vec::new();
        let mut color = Vec::new();
        let mut depth = None;
        let mut extent = options.extent;
        for access in active_accesses() {
            let (load, store, blend, read_only, is_depth) = match &access.usage {
                Usage::Color { load, store, blend } => (load, *store, *blend, false, false),
                Usage::Depth {
                    load,
                    store,
                    read_only,
                } => (load, *store, None, *read_only, true),
                _ => continue,
            };
            let r = new_index[access.resource];
            let ResourceDesc::Image(desc) = &resources[r].desc else {
                continue;
            };
            extent = desc.extent;
            let layout = if read_only {
                Layout::DepthStencilReadOnlyOptimal
            } else if is_depth {
                Layout::DepthStencilAttachmentOptimal
            } else {
                Layout::ColorAttachmentOptimal
            };
            let store = if read_only {
                StoreOp::None
            } else if store == StoreDecl::Store
                && timeline.needed_later(ir, all_uses, i, access.resource, is_root)
            {
                StoreOp::Store
            } else {
                StoreOp::DontCare
            };
            let (load, clear) = match load {
                LoadDecl::Load => (LoadOp::Load, Vec::new()),
                LoadDecl::Clear(v) => (LoadOp::Clear, v.clone()),
                LoadDecl::DontCare => (LoadOp::DontCare, Vec::new()),
            };
            let index = attachments.len();
            if is_depth {
                depth = Some(index);
            } else {
                color.push(index);
            }
            attachments.push(AttachmentDesc {
                resource: r,
                format_raw: desc.format_raw,
                samples: desc.samples,
                load,
                store,
                clear,
                initial_layout: layout,
                layout,
                final_layout: layout,
                blend,
                read_only,
            });
        }
        RenderPassDesc {
            extent,
            attachments,
            color,
            depth,
        }
    });
    let dispatch = pass.dispatch.map(|d| match d {
        IrDispatch::Groups(x, y, z) => [x, y, z],
        IrDispatch::Output(x, y) => [
            options.extent.width.div_ceil(x.max(1)),
            options.extent.height.div_ceil(y.max(1)),
            1,
        ],
        IrDispatch::Image(r, x, y) => {
            let e = image_extent(ir, r, options.extent).unwrap_or(options.extent);
            [e.width.div_ceil(x.max(1)), e.height.div_ceil(y.max(1)), 1]
        }
    });
    let transfer = if matches!(pass.kind, PassKind::Copy | PassKind::Blit) {
        let find = |want: fn(&Usage) -> bool| {
            pass.accesses
                .iter()
                .find(|a| want(&a.usage))
                .map(|a| new_index[a.resource])
        };
        find(|u| *u == Usage::TransferSrc).zip(find(|u| *u == Usage::TransferDst))
    } else {
        None
    };
    let (file, pos) = graph.locate(
        pass.source,
        &[
            Seg::Field("passes"),
            Seg::Index(pass.index),
            Seg::Field("name"),
        ],
    );
    PlanPass {
        name: pass.name.clone(),
        declared_at: Location { file, pos },
        kind: pass.kind,
        shaders: pass.shaders.clone(),
        draw: pass.draw.clone(),
        dispatch,
        params: pass.params.clone(),
        defines: defines.into_iter().collect(),
        barriers,
        render_pass,
        bindings,
        transfer,
        raster: pass.raster,
    }
}
