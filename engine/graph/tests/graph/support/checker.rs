//! An independent checker of compiled plans. It re-derives every access a pass
//! makes from the plan's render passes, bindings and transfers, replays two frames
//! (plus the executor's read-back of the output) against a per-resource model of
//! Vulkan execution and memory dependencies, and reports the first access that is
//! not ordered after the previous conflicting one, reads undefined contents, or
//! finds the image in the wrong layout. It shares no code with the compiler's
//! synchronization pass.

use std::collections::BTreeMap;
use weft_graph::id::{PassId, ResourceId};
use weft_graph::plan::{BindingKind, LoadOp, Plan, Residency, ResourceDesc};
use weft_graph::schema::PassKind;
use weft_graph::vk::{Access, Aspect, Layout, Stage};

#[derive(Clone, Debug)]
struct Write {
    stage: Stage,
    access: Access,
    synced: Vec<(Stage, Access)>,
}

#[derive(Clone, Debug)]
struct Read {
    stage: Stage,
    synced: Stage,
}

#[derive(Clone, Debug)]
struct Model {
    layout: Layout,
    defined: bool,
    write: Option<Write>,
    reads: Vec<Read>,
}

impl Model {
    fn fresh() -> Self {
        Model {
            layout: Layout::Undefined,
            defined: false,
            write: None,
            reads: Vec::new(),
        }
    }

    fn write_covered_by(&self, src_stage: Stage, src_access: Access) -> bool {
        match &self.write {
            None => true,
            Some(w) => {
                (src_stage.contains(w.stage) && src_access.contains(w.access))
                    || w.synced.iter().any(|(s, _)| s.intersects(src_stage))
            }
        }
    }

    /// What follows `b` (a layout transition or a hand-over of memory) must
    /// be inside its destination scope, as after a write there.
    fn start_at(&mut self, b: &weft_graph::plan::Barrier) {
        self.write = Some(Write {
            stage: b.dst_stage,
            access: Access::empty(),
            synced: vec![(b.dst_stage, b.dst_access)],
        });
        self.reads.clear();
    }

    /// Whether anything used the resource since its memory was last taken over.
    fn touched(&self) -> bool {
        self.write.is_some() || !self.reads.is_empty()
    }

    fn read_covered_by(r: &Read, src_stage: Stage) -> bool {
        src_stage.contains(r.stage) || r.synced.intersects(src_stage)
    }
}

#[derive(Clone, Copy, Debug)]
struct Use {
    stage: Stage,
    access: Access,
    layout: Layout,
    needs_contents: bool,
}

fn shader_stage(kind: PassKind, image: bool) -> Stage {
    match kind {
        PassKind::Raster if image => Stage::FRAGMENT_SHADER,
        PassKind::Raster => Stage::VERTEX_SHADER | Stage::FRAGMENT_SHADER,
        PassKind::Fullscreen => Stage::FRAGMENT_SHADER,
        PassKind::Compute => Stage::COMPUTE_SHADER,
        PassKind::Copy => Stage::COPY,
        PassKind::Blit => Stage::BLIT,
        PassKind::BuildAccelerationStructures => Stage::ACCELERATION_STRUCTURE_BUILD,
    }
}

/// Every access of one pass, derived from the plan's description of it.
fn uses_of(plan: &Plan, pass: usize) -> Vec<(usize, Use)> {
    let p = &plan.passes[PassId::new(pass)];
    let mut out = Vec::new();
    if let Some(rp) = &p.render_pass {
        for (i, a) in rp.attachments.iter().enumerate() {
            let depth = rp.depth == Some(i);
            let load = a.load == LoadOp::Load;
            let u = if depth && a.read_only {
                Use {
                    stage: Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS,
                    access: Access::DEPTH_STENCIL_ATTACHMENT_READ,
                    layout: Layout::DepthStencilReadOnlyOptimal,
                    needs_contents: true,
                }
            } else if depth {
                Use {
                    stage: Stage::EARLY_FRAGMENT_TESTS | Stage::LATE_FRAGMENT_TESTS,
                    access: Access::DEPTH_STENCIL_ATTACHMENT_READ
                        | Access::DEPTH_STENCIL_ATTACHMENT_WRITE,
                    layout: Layout::DepthStencilAttachmentOptimal,
                    needs_contents: load,
                }
            } else {
                let read = if load {
                    Access::COLOR_ATTACHMENT_READ
                } else {
                    Access::empty()
                };
                Use {
                    stage: Stage::COLOR_ATTACHMENT_OUTPUT,
                    access: Access::COLOR_ATTACHMENT_WRITE | read,
                    layout: Layout::ColorAttachmentOptimal,
                    needs_contents: load,
                }
            };
            assert_eq!(a.layout, u.layout, "attachment layout of pass {}", p.name);
            assert_eq!((a.initial_layout, a.final_layout), (a.layout, a.layout));
            out.push((a.resource.index(), u));
        }
    }
    for b in &p.bindings {
        let (image, aspect) = match &plan.resources[b.resource].desc {
            ResourceDesc::Image(i) => (true, Some(i.aspect)),
            ResourceDesc::Buffer(_) | ResourceDesc::AccelerationStructure => (false, None),
        };
        let stage = shader_stage(p.kind, image);
        let (access, layout, needs_contents) = match b.kind {
            BindingKind::Sampled => match aspect {
                Some(Aspect::Color) => (
                    Access::SHADER_SAMPLED_READ,
                    Layout::ShaderReadOnlyOptimal,
                    true,
                ),
                Some(_) => (
                    Access::SHADER_SAMPLED_READ,
                    Layout::DepthStencilReadOnlyOptimal,
                    true,
                ),
                None => (Access::UNIFORM_READ, Layout::General, true),
            },
            BindingKind::StorageRead => (Access::SHADER_STORAGE_READ, Layout::General, true),
            BindingKind::StorageWrite => (Access::SHADER_STORAGE_WRITE, Layout::General, false),
            BindingKind::StorageReadWrite => (
                Access::SHADER_STORAGE_READ | Access::SHADER_STORAGE_WRITE,
                Layout::General,
                true,
            ),
        };
        out.push((
            b.resource.index(),
            Use {
                stage: if image {
                    stage
                } else {
                    shader_stage(p.kind, false)
                },
                access,
                layout,
                needs_contents,
            },
        ));
    }
    if let Some(structure) = p.structure {
        // Built (a refit reads what it rewrites), or read by ray queries.
        let access = if p.kind == PassKind::BuildAccelerationStructures {
            Access::ACCELERATION_STRUCTURE_READ | Access::ACCELERATION_STRUCTURE_WRITE
        } else {
            Access::ACCELERATION_STRUCTURE_READ
        };
        out.push((
            structure.index(),
            Use {
                stage: shader_stage(p.kind, false),
                access,
                layout: Layout::General,
                needs_contents: true,
            },
        ));
    }
    if let Some(scratch) = p.scratch {
        // The build's scratch: written and read at the build stage, its
        // old contents never needed.
        out.push((
            scratch.index(),
            Use {
                stage: Stage::ACCELERATION_STRUCTURE_BUILD,
                access: Access::ACCELERATION_STRUCTURE_READ | Access::ACCELERATION_STRUCTURE_WRITE,
                layout: Layout::General,
                needs_contents: false,
            },
        ));
    }
    if let Some((src, dst)) = p.transfer {
        let stage = shader_stage(p.kind, true);
        out.push((
            src.index(),
            Use {
                stage,
                access: Access::TRANSFER_READ,
                layout: Layout::TransferSrcOptimal,
                needs_contents: true,
            },
        ));
        out.push((
            dst.index(),
            Use {
                stage,
                access: Access::TRANSFER_WRITE,
                layout: Layout::TransferDstOptimal,
                needs_contents: false,
            },
        ));
    }
    out
}

fn is_image(plan: &Plan, r: usize) -> bool {
    matches!(
        plan.resources[ResourceId::new(r)].desc,
        ResourceDesc::Image(_)
    )
}

fn overlapping(plan: &Plan, r: usize) -> Vec<usize> {
    let Some(a) = plan.resources[ResourceId::new(r)].placement else {
        return Vec::new();
    };
    (0..plan.resources.len())
        .filter(|&j| j != r)
        .filter(|&j| {
            plan.resources[ResourceId::new(j)]
                .placement
                .is_some_and(|b| {
                    a.block == b.block
                        && a.offset < b.offset + b.size
                        && b.offset < a.offset + a.size
                })
        })
        .collect()
}

fn apply_barrier(
    plan: &Plan,
    models: &mut [Model],
    b: &weft_graph::plan::Barrier,
    at: &str,
) -> Result<(), String> {
    let name = &plan.resources[b.resource].name;
    let transition = match b.layouts {
        Some((old, new)) => old != new || old == Layout::Undefined,
        None => false,
    };
    if transition {
        let (old, new) = b.layouts.expect("transition has layouts");
        if old == Layout::Undefined {
            take_over(plan, models, b, at)?;
        }
        let m = &mut models[b.resource.index()];
        if old != Layout::Undefined && old != m.layout {
            return Err(format!(
                "{at}: barrier on \"{name}\" says old layout {old:?} but it is in {:?}",
                m.layout
            ));
        }
        if !m.write_covered_by(b.src_stage, b.src_access) {
            return Err(format!(
                "{at}: layout transition of \"{name}\" is not ordered after its last write"
            ));
        }
        if !m
            .reads
            .iter()
            .all(|r| Model::read_covered_by(r, b.src_stage))
        {
            return Err(format!(
                "{at}: layout transition of \"{name}\" is not ordered after its reads"
            ));
        }
        if old == Layout::Undefined {
            m.defined = false;
        }
        m.layout = new;
        m.start_at(b);
        return Ok(());
    }
    if b.layouts.is_none() && take_over(plan, models, b, at)? {
        // A buffer has no layout to discard: any of its barriers may be the
        // one that takes its memory over, and what it held is gone; what
        // follows must be inside the barrier's destination scope.
        let m = &mut models[b.resource.index()];
        m.defined = false;
        m.start_at(b);
        return Ok(());
    }
    let m = &mut models[b.resource.index()];
    if let Some((old, _)) = b.layouts {
        if old != m.layout {
            return Err(format!(
                "{at}: barrier on \"{name}\" expects {old:?} but it is in {:?}",
                m.layout
            ));
        }
    }
    let covers = m.write_covered_by(b.src_stage, b.src_access);
    if let Some(w) = &mut m.write {
        if covers {
            w.synced.push((b.dst_stage, b.dst_access));
        }
    }
    for r in &mut m.reads {
        if Model::read_covered_by(r, b.src_stage) {
            r.synced |= b.dst_stage;
        }
    }
    Ok(())
}

/// Memory `b`'s resource shares with others (images or buffers): everything
/// they did since must be finished before the barrier, and is then over.
/// Whether any had done something since.
fn take_over(
    plan: &Plan,
    models: &mut [Model],
    b: &weft_graph::plan::Barrier,
    at: &str,
) -> Result<bool, String> {
    let name = &plan.resources[b.resource].name;
    let mut took = false;
    for j in overlapping(plan, b.resource.index()) {
        let m = &models[j];
        if !m.touched() {
            continue;
        }
        if !m.write_covered_by(b.src_stage, b.src_access)
            || !m
                .reads
                .iter()
                .all(|r| Model::read_covered_by(r, b.src_stage))
        {
            return Err(format!(
                "{at}: \"{name}\" takes over memory of \"{}\" without waiting for its last use",
                plan.resources[ResourceId::new(j)].name
            ));
        }
        models[j] = Model::fresh();
        took = true;
    }
    Ok(took)
}

fn check_use(plan: &Plan, models: &[Model], r: usize, u: &Use, at: &str) -> Result<(), String> {
    let name = &plan.resources[ResourceId::new(r)].name;
    let m = &models[r];
    if let Some(j) = overlapping(plan, r)
        .into_iter()
        .find(|&j| models[j].touched())
    {
        return Err(format!(
            "{at}: \"{name}\" is used in memory \"{}\" used since, with no barrier taking it over",
            plan.resources[ResourceId::new(j)].name
        ));
    }
    if is_image(plan, r) && m.layout != u.layout {
        return Err(format!(
            "{at}: \"{name}\" is in {:?} but the access needs {:?}",
            m.layout, u.layout
        ));
    }
    if u.needs_contents && !m.defined {
        return Err(format!(
            "{at}: \"{name}\" is read but its contents are undefined"
        ));
    }
    if let Some(w) = &m.write {
        if !w
            .synced
            .iter()
            .any(|(s, a)| s.contains(u.stage) && a.contains(u.access))
        {
            return Err(format!(
                "{at}: access {:?}/{:?} to \"{name}\" is not ordered after the previous write {:?}/{:?}",
                u.stage, u.access, w.stage, w.access
            ));
        }
    }
    if u.access.is_write() {
        for read in &m.reads {
            if !read.synced.contains(u.stage) {
                return Err(format!(
                    "{at}: write to \"{name}\" is not ordered after a read at {:?}",
                    read.stage
                ));
            }
        }
    }
    Ok(())
}

fn record(models: &mut [Model], r: usize, stage: Stage, access: Access) {
    let m = &mut models[r];
    if access.is_write() {
        m.write = Some(Write {
            stage,
            access: access & Access::WRITES,
            synced: Vec::new(),
        });
        m.reads.clear();
        m.defined = true;
    } else {
        m.reads.push(Read {
            stage,
            synced: Stage::empty(),
        });
    }
}

/// Replays `frames` frames of a plan; `Err` names the first unsynchronized or invalid access.
pub fn check_plan(plan: &Plan, frames: usize) -> Result<(), String> {
    let mut models: Vec<Model> = plan
        .resources
        .iter()
        .map(|r| {
            let mut m = Model::fresh();
            if r.residency != Residency::Transient {
                m.layout = if matches!(r.desc, ResourceDesc::Image(_)) {
                    r.frame_start_layout
                } else {
                    Layout::General
                };
                m.defined = r.residency == Residency::History;
            } else if matches!(r.desc, ResourceDesc::Buffer(_)) {
                m.layout = Layout::General;
            }
            m
        })
        .collect();
    for frame in 0..frames {
        for (i, pass) in plan.passes.iter().enumerate() {
            let at = format!("frame {frame}, pass {i} \"{}\"", pass.name);
            for b in &pass.barriers {
                apply_barrier(plan, &mut models, b, &at)?;
            }
            let mut merged: BTreeMap<usize, (Stage, Access)> = BTreeMap::new();
            for (r, u) in uses_of(plan, i) {
                check_use(plan, &models, r, &u, &at)?;
                let e = merged.entry(r).or_default();
                e.0 |= u.stage;
                e.1 |= u.access;
            }
            for (r, (stage, access)) in merged {
                record(&mut models, r, stage, access);
            }
        }
        let at = format!("frame {frame}, epilogue");
        for b in &plan.epilogue {
            apply_barrier(plan, &mut models, b, &at)?;
        }
        let readback = Use {
            stage: Stage::COPY,
            access: Access::TRANSFER_READ,
            layout: Layout::TransferSrcOptimal,
            needs_contents: true,
        };
        check_use(
            plan,
            &models,
            plan.output.index(),
            &readback,
            &format!("frame {frame}, read-back"),
        )?;
        record(
            &mut models,
            plan.output.index(),
            Stage::COPY,
            Access::TRANSFER_READ,
        );
    }
    Ok(())
}

/// Transient images whose memory overlaps must never be alive at the same time.
pub fn check_aliasing(plan: &Plan) -> Result<(), String> {
    for (i, a) in plan.resources.iter().enumerate() {
        for j in overlapping(plan, i) {
            let b = &plan.resources[ResourceId::new(j)];
            if a.lifetime.0 <= b.lifetime.1 && b.lifetime.0 <= a.lifetime.1 {
                return Err(format!(
                    "\"{}\" and \"{}\" share memory while both alive",
                    a.name, b.name
                ));
            }
        }
    }
    Ok(())
}
