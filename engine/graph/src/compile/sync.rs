//! Step 6, sync: all synchronization of a plan. Each pass's accesses as the GPU
//! sees them; the barriers before each pass, from the per-resource state walk in
//! `state`; the hand-over of aliased memory; the previous frame simulated so the
//! steady state is synchronized too; and the epilogue that leaves the output and
//! history images ready for the next frame.

mod access;
mod state;

use access::gpu_access;

use state::{GpuAccess, ResourceState};

use super::lifetimes::Lifetimes;
use super::order::Uses;
use crate::id::{IdVec, IrPassId, PassId, ResourceId};
use crate::plan::{Barrier, PlanResource, Residency, ResourceDesc};
use crate::resolve::Ir;
use crate::vk::{Access, Layout, Stage};

/// The barriers of a plan.
pub(crate) struct Synchronization {
    /// Per plan pass, the barriers recorded before it.
    pub pass_barriers: IdVec<PassId, Vec<Barrier>>,
    /// Per plan pass, the barriers between its dispatches when it repeats:
    /// each dispatch sees what the one before it wrote.
    pub repeat_barriers: IdVec<PassId, Vec<Barrier>>,
    /// Barriers after the last pass.
    pub epilogue: Vec<Barrier>,
}

type Resources = IdVec<ResourceId, PlanResource>;
type States = IdVec<ResourceId, ResourceState>;
/// Per resource, the other transient images and buffers whose memory overlaps its own.
type Sharing = IdVec<ResourceId, Vec<ResourceId>>;
/// Per plan pass, each resource it uses and how the GPU accesses it.
type GpuUses = IdVec<PassId, Vec<(ResourceId, GpuAccess)>>;
/// Per plan pass, the destination scope of each of its accesses' barriers.
type Scopes = IdVec<PassId, Vec<Scope>>;

/// Derives every barrier of the plan, and each output and history image's layout
/// at the start of a frame (set on `resources`).
pub(crate) fn synchronize(
    ir: &Ir,
    sequence: &[IrPassId],
    uses: &Uses,
    lifetimes: &Lifetimes,
    resources: &mut Resources,
) -> Synchronization {
    // Per-pass GPU accesses, then barriers.
    let gpu_uses = gpu_uses(ir, sequence, uses, lifetimes);
    let scopes = read_scopes(&gpu_uses);
    let sharing = memory_sharing(resources);
    let mut states = frame_start_states(resources, &gpu_uses, &scopes);
    inherit_previous_frame(resources, &sharing, &gpu_uses, &scopes, &mut states);
    let (pass_barriers, end_of_frame) =
        record_barriers(resources, &sharing, &gpu_uses, &scopes, states);
    let epilogue = epilogue(resources, &gpu_uses, &scopes, &end_of_frame);
    Synchronization {
        pass_barriers,
        repeat_barriers: repeat_barriers(ir, sequence, &gpu_uses, resources),
        epilogue,
    }
}

/// For each pass that repeats, a barrier per resource it writes, from its
/// own writes to its own accesses, so the next dispatch sees them; the layout
/// stays.
fn repeat_barriers(
    ir: &Ir,
    sequence: &[IrPassId],
    gpu_uses: &GpuUses,
    resources: &Resources,
) -> IdVec<PassId, Vec<Barrier>> {
    sequence
        .iter()
        .zip(gpu_uses.iter())
        .map(|(&p, accesses)| {
            if ir.passes[p].repeat < 2 {
                return Vec::new();
            }
            accesses
                .iter()
                .filter(|(_, a)| a.access.is_write())
                .map(|&(resource, a)| Barrier {
                    resource,
                    src_stage: a.stage,
                    src_access: a.access & Access::WRITES,
                    dst_stage: a.stage,
                    dst_access: a.access,
                    layouts: matches!(resources[resource].desc, ResourceDesc::Image(_))
                        .then_some((a.layout, a.layout)),
                })
                .collect()
        })
        .collect()
}

/// Per plan pass, each resource it uses (plan index) and how the GPU accesses it.
fn gpu_uses(ir: &Ir, sequence: &[IrPassId], uses: &Uses, lifetimes: &Lifetimes) -> GpuUses {
    sequence
        .iter()
        .map(|&p| {
            uses[p]
                .iter()
                .map(|u| (lifetimes.plan_index(u.resource), gpu_access(ir, p, u)))
                .collect()
        })
        .collect()
}

/// Each resource's state when a frame starts: transient ones fresh, the output as
/// the previous frame's copy left it, history images as their first reader needs
/// them (the epilogue puts them there). Sets `frame_start_layout` to match.
fn frame_start_states(resources: &mut Resources, gpu_uses: &GpuUses, scopes: &Scopes) -> States {
    let mut states: States = resources
        .iter()
        .map(|r| ResourceState::fresh(matches!(r.desc, ResourceDesc::Image(_))))
        .collect();
    for (i, r) in resources.iter_enumerated_mut() {
        match r.residency {
            Residency::Transient => {}
            Residency::Output => {
                states[i].layout = Layout::TransferSrcOptimal;
                states[i].reads = Stage::COPY | Stage::BLIT;
                r.frame_start_layout = Layout::TransferSrcOptimal;
            }
            Residency::History => {
                if let Some((first, scope)) = first_access(gpu_uses, scopes, i) {
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
    states
}

/// The first frame starts from `states`; every later frame starts where the previous
/// one ended, so a transient resource's first barrier must also wait for the previous
/// frame's last use of its memory. Simulates one frame to learn that.
fn inherit_previous_frame(
    resources: &Resources,
    sharing: &Sharing,
    gpu_uses: &GpuUses,
    scopes: &Scopes,
    states: &mut States,
) {
    let (_, end_of_frame) = record_barriers(resources, sharing, gpu_uses, scopes, states.clone());
    for (r, state) in states.iter_enumerated_mut() {
        if resources[r].residency == Residency::Transient {
            let (stage, access) = pending_of(&end_of_frame, sharing[r].iter().copied().chain([r]));
            state.inherit(stage, access);
        }
    }
}

/// Barriers after the last pass that bring the output to `TRANSFER_SRC_OPTIMAL`
/// and each history image to the state its first reader next frame expects.
fn epilogue(
    resources: &Resources,
    gpu_uses: &GpuUses,
    scopes: &Scopes,
    states: &States,
) -> Vec<Barrier> {
    let mut epilogue = Vec::new();
    for (i, r) in resources.iter_enumerated() {
        let target = match r.residency {
            Residency::Transient => continue,
            Residency::Output => GpuAccess {
                stage: Stage::COPY | Stage::BLIT,
                access: Access::TRANSFER_READ,
                layout: Layout::TransferSrcOptimal,
                discards: false,
            },
            Residency::History => match first_access(gpu_uses, scopes, i) {
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

    epilogue
}

type Scope = (Stage, Access);

fn first_access(gpu_uses: &GpuUses, scopes: &Scopes, r: ResourceId) -> Option<(GpuAccess, Scope)> {
    gpu_uses
        .iter()
        .zip(scopes)
        .flat_map(|(u, s)| u.iter().zip(s))
        .find(|((i, _), _)| *i == r)
        .map(|((_, a), s)| (*a, *s))
}

/// For every access, the destination scope its barrier should have: its own, or for a
/// read, the union with the reads after it in the same layout up to the next write.
fn read_scopes(gpu_uses: &GpuUses) -> Scopes {
    let mut scopes: Scopes = gpu_uses
        .iter()
        .map(|u| u.iter().map(|(_, a)| (a.stage, a.access)).collect())
        .collect();
    let mut run: std::collections::HashMap<ResourceId, (Layout, Scope)> =
        std::collections::HashMap::new();
    for i in gpu_uses.ids().rev() {
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
    resources: &Resources,
    sharing: &Sharing,
    gpu_uses: &GpuUses,
    scopes: &Scopes,
    mut states: States,
) -> (IdVec<PassId, Vec<Barrier>>, States) {
    let mut all = IdVec::new();
    for (i, accesses) in gpu_uses.iter_enumerated() {
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
fn memory_sharing(resources: &Resources) -> Sharing {
    let mut placed: Vec<(usize, u64, u64, ResourceId)> = resources
        .iter_enumerated()
        .filter_map(|(i, r)| {
            r.placement
                .map(|p| (p.block, p.offset, p.offset + p.size, i))
        })
        .collect();
    placed.sort_unstable();
    let mut sharing = IdVec::filled(Vec::new(), resources.len());
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
fn pending_of(states: &States, which: impl Iterator<Item = ResourceId>) -> (Stage, Access) {
    which.fold((Stage::empty(), Access::empty()), |(s, a), j| {
        let (js, ja) = states[j].pending();
        (s | js, a | ja)
    })
}

#[cfg(test)]
mod tests {
    use super::super::fixture::CHAIN;
    use super::super::tests::plan_of;
    use super::*;
    use crate::vk::BufferUsage;

    #[test]
    fn a_sampled_attachment_gets_one_barrier_and_the_output_an_epilogue() {
        let plan = plan_of(CHAIN, &[]);
        let x = plan.resource("x").expect("x");
        let before_b = &plan.passes[PassId::new(1)].barriers;
        let to_sampled = before_b
            .iter()
            .find(|b| b.resource == x)
            .expect("x barrier");
        assert_eq!(to_sampled.src_stage, Stage::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(to_sampled.src_access, Access::COLOR_ATTACHMENT_WRITE);
        assert_eq!(to_sampled.dst_stage, Stage::FRAGMENT_SHADER);
        assert_eq!(to_sampled.dst_access, Access::SHADER_SAMPLED_READ);
        assert_eq!(
            to_sampled.layouts,
            Some((
                Layout::ColorAttachmentOptimal,
                Layout::ShaderReadOnlyOptimal
            ))
        );
        let out = plan.resource("out").expect("out");
        assert_eq!(plan.epilogue.len(), 1);
        assert_eq!(plan.epilogue[0].resource, out);
        assert_eq!(
            plan.epilogue[0].layouts,
            Some((Layout::ColorAttachmentOptimal, Layout::TransferSrcOptimal))
        );
        assert_eq!(
            plan.resources[out].frame_start_layout,
            Layout::TransferSrcOptimal
        );
    }

    /// `accumulate` reads and writes a history image and writes the output;
    /// `params.reps` sets how often it repeats.
    fn repeating(reps: &str) -> String {
        format!(
            r#"Graph(
            output: "out",
            params: {{ "reps": {reps} }},
            resources: [
                Image(name: "acc", format: R32G32B32A32_SFLOAT, history: true),
                Image(name: "out", format: R32G32B32A32_SFLOAT),
            ],
            passes: [
                Pass(name: "accumulate", kind: Compute, shaders: (compute: "a.comp"),
                     storage_read: ["acc"], storage_write: ["acc", "out"],
                     dispatch: Output(8, 8), repeat: "$reps"),
            ],
        )"#
        )
    }

    #[test]
    fn a_repeating_pass_waits_for_its_own_writes_between_dispatches() {
        let plan = plan_of(&repeating("3"), &[]);
        let pass = &plan.passes[PassId::new(0)];
        assert_eq!(pass.repeat, 3);
        let acc = plan.resource("acc").expect("acc");
        let out = plan.resource("out").expect("out");
        let storage = Access::SHADER_STORAGE_READ | Access::SHADER_STORAGE_WRITE;
        assert_eq!(
            pass.repeat_barriers,
            [
                Barrier {
                    resource: acc,
                    src_stage: Stage::COMPUTE_SHADER,
                    src_access: Access::SHADER_STORAGE_WRITE,
                    dst_stage: Stage::COMPUTE_SHADER,
                    dst_access: storage,
                    layouts: Some((Layout::General, Layout::General)),
                },
                Barrier {
                    resource: out,
                    src_stage: Stage::COMPUTE_SHADER,
                    src_access: Access::SHADER_STORAGE_WRITE,
                    dst_stage: Stage::COMPUTE_SHADER,
                    dst_access: Access::SHADER_STORAGE_WRITE,
                    layouts: Some((Layout::General, Layout::General)),
                },
            ]
        );
        let once = plan_of(&repeating("1"), &[]);
        assert_eq!(once.passes[PassId::new(0)].repeat, 1);
        assert!(once.passes[PassId::new(0)].repeat_barriers.is_empty());
    }

    /// `count` writes the group counts `work` dispatches by, three times, and
    /// `work` rewrites them between its dispatches; `again` only dispatches
    /// by them.
    const INDIRECT: &str = r#"Graph(
        output: "out",
        resources: [
            Buffer(name: "counts", size: "48"),
            Image(name: "out", format: R32G32B32A32_SFLOAT),
        ],
        passes: [
            Pass(name: "count", kind: Compute, shaders: (compute: "c.comp"),
                 storage_write: ["counts"], dispatch: Groups(1, 1, 1)),
            Pass(name: "work", kind: Compute, shaders: (compute: "w.comp"),
                 storage_read: ["counts"], storage_write: ["counts", "out"],
                 dispatch: Indirect("counts", 16), repeat: 3, after: ["count"]),
            Pass(name: "again", kind: Compute, shaders: (compute: "a.comp"),
                 storage_read: ["out"], storage_write: ["out"],
                 dispatch: Indirect("counts", 16), after: ["work"]),
        ],
    )"#;

    #[test]
    fn an_indirect_dispatch_waits_for_its_counts_as_indirect_command_reads() {
        let plan = plan_of(INDIRECT, &[]);
        let counts = plan.resource("counts").expect("counts");
        let work = &plan.passes[PassId::new(1)];
        assert_eq!(work.dispatch, None);
        assert_eq!(
            work.indirect,
            Some(crate::plan::IndirectDispatch {
                buffer: counts,
                stride: 16
            })
        );
        let dst_stage = Stage::COMPUTE_SHADER | Stage::DRAW_INDIRECT;
        let dst_access = Access::SHADER_STORAGE_READ
            | Access::SHADER_STORAGE_WRITE
            | Access::INDIRECT_COMMAND_READ;
        let before = work
            .barriers
            .iter()
            .find(|b| b.resource == counts)
            .expect("a barrier on counts");
        assert_eq!(
            (before.src_stage, before.src_access),
            (Stage::COMPUTE_SHADER, Access::SHADER_STORAGE_WRITE)
        );
        assert_eq!(
            (before.dst_stage, before.dst_access),
            (dst_stage, dst_access)
        );
        let between = work
            .repeat_barriers
            .iter()
            .find(|b| b.resource == counts)
            .expect("a repeat barrier on counts");
        assert_eq!(
            (between.dst_stage, between.dst_access),
            (dst_stage, dst_access)
        );
        match &plan.resources[counts].desc {
            ResourceDesc::Buffer(b) => {
                assert_eq!(b.usage, BufferUsage::STORAGE | BufferUsage::INDIRECT)
            }
            other => panic!("counts is {other:?}"),
        }
        // The dispatch's read of the counts binds nothing: only storage
        // accesses do.
        let again = &plan.passes[PassId::new(2)];
        assert!(again.bindings.iter().all(|b| b.resource != counts));
        let before_again = again
            .barriers
            .iter()
            .find(|b| b.resource == counts)
            .expect("a barrier on counts before again");
        assert_eq!(
            (before_again.dst_stage, before_again.dst_access),
            (Stage::DRAW_INDIRECT, Access::INDIRECT_COMMAND_READ)
        );
    }

    /// A pass that reads and writes a buffer in one scope, then a pass that
    /// reads it in that scope: the write must still be made visible (the
    /// walk once took the writer's own scope as covering its write).
    #[test]
    fn a_read_after_a_read_write_in_the_same_scope_waits_for_the_write() {
        let plan = plan_of(
            r#"Graph(
            output: "out",
            resources: [
                Buffer(name: "buf", size: "64"),
                Image(name: "out", format: R32G32B32A32_SFLOAT),
            ],
            passes: [
                Pass(name: "clear", kind: Compute, shaders: (compute: "c.comp"),
                     storage_write: ["buf"], dispatch: Groups(1, 1, 1)),
                Pass(name: "update", kind: Compute, shaders: (compute: "u.comp"),
                     storage_read: ["buf"], storage_write: ["buf"], dispatch: Groups(1, 1, 1),
                     after: ["clear"]),
                Pass(name: "use", kind: Compute, shaders: (compute: "r.comp"),
                     storage_read: ["buf"], storage_write: ["out"], dispatch: Output(8, 8)),
            ],
        )"#,
            &[],
        );
        let buf = plan.resource("buf").expect("buf");
        let before_use = &plan.passes[PassId::new(2)].barriers;
        assert_eq!(
            before_use.iter().find(|b| b.resource == buf),
            Some(&Barrier {
                resource: buf,
                src_stage: Stage::COMPUTE_SHADER,
                src_access: Access::SHADER_STORAGE_WRITE,
                dst_stage: Stage::COMPUTE_SHADER,
                dst_access: Access::SHADER_STORAGE_READ,
                layouts: None,
            })
        );
    }
}
