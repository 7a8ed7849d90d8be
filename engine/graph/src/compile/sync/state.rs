//! Synchronization: walks the passes in order keeping, per resource, the last write,
//! the reads since, the layout and which scopes the last write is already visible
//! to, and emits the fewest synchronization2 barriers that order every access after
//! the previous conflicting one with the layout it needs.

use crate::id::ResourceId;
use crate::plan::Barrier;
use crate::schema::PassKind;
use crate::vk::{Access, Aspect, Layout, Stage};

/// One access as the GPU sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GpuAccess {
    pub stage: Stage,
    pub access: Access,
    pub layout: Layout,
    /// Whether older contents may be thrown away (layout transition from UNDEFINED).
    pub discards: bool,
}

impl GpuAccess {
    fn writes(&self) -> bool {
        self.access.is_write()
    }
}

/// The shader stages a pass kind runs.
pub fn shader_stages(kind: PassKind) -> Stage {
    match kind {
        PassKind::Raster => Stage::VERTEX_SHADER | Stage::FRAGMENT_SHADER,
        PassKind::Fullscreen => Stage::FRAGMENT_SHADER,
        PassKind::Compute => Stage::COMPUTE_SHADER,
        PassKind::Copy => Stage::COPY,
        PassKind::Blit => Stage::BLIT,
        PassKind::BuildAccelerationStructures => Stage::ACCELERATION_STRUCTURE_BUILD,
    }
}

/// What the last frame left behind, or what a new resource starts as.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ResourceState {
    pub layout: Layout,
    /// Stage and access of the last write (a layout transition is a write with no access bits).
    pub write: Option<(Stage, Access)>,
    /// Stages that read since the last write.
    pub reads: Stage,
    /// Scopes the last write has been made visible to.
    pub visible: Vec<(Stage, Access)>,
    /// Whether the resource is an image (buffers have no layouts).
    pub image: bool,
}

impl ResourceState {
    /// A resource nothing has touched yet.
    pub fn fresh(image: bool) -> Self {
        ResourceState {
            layout: if image {
                Layout::Undefined
            } else {
                Layout::General
            },
            write: None,
            reads: Stage::empty(),
            visible: Vec::new(),
            image,
        }
    }

    /// Treats earlier accesses to the same memory (aliased images and buffers) as if they were this resource's.
    pub fn inherit(&mut self, stages: Stage, access: Access) {
        if !stages.is_empty() {
            let (s, a) = self.write.unwrap_or_default();
            self.write = Some((s | stages, a | access));
        }
    }

    fn covered(&self, a: &GpuAccess) -> bool {
        self.visible
            .iter()
            .any(|(s, acc)| s.contains(a.stage) && acc.contains(a.access))
    }

    /// Records `a` and returns the barrier it needs first, if any. For a read,
    /// `scope` may widen the barrier's destination to cover the reads that follow in
    /// the same layout, so they need no barrier of their own.
    pub fn access(
        &mut self,
        resource: ResourceId,
        a: GpuAccess,
        scope: (Stage, Access),
    ) -> Option<Barrier> {
        let (scope_stage, scope_access) = if a.writes() {
            (a.stage, a.access)
        } else {
            scope
        };
        let layout_change = self.image && self.layout != a.layout;
        if a.writes() || layout_change {
            let (write_stage, write_access) = self.write.unwrap_or_default();
            let src_stage = write_stage | self.reads;
            let only_transition_since = self.reads.is_empty() && write_access.is_empty();
            let redundant = !layout_change && only_transition_since && self.covered(&a);
            let needed = layout_change || (!src_stage.is_empty() && !redundant);
            let old = if a.discards {
                Layout::Undefined
            } else {
                self.layout
            };
            let barrier = needed.then_some(Barrier {
                resource,
                src_stage,
                src_access: write_access,
                dst_stage: scope_stage,
                dst_access: scope_access,
                layouts: self.image.then_some((old, a.layout)),
            });
            if a.writes() {
                // This write is visible to no one yet, the writer's own
                // scope included: a later pass reading in that same scope
                // still needs a barrier.
                self.write = Some((a.stage, a.access & Access::WRITES));
                self.reads = Stage::empty();
                self.visible = Vec::new();
            } else {
                // A layout transition: the barrier made it visible to `scope`.
                self.write = Some((scope_stage, Access::empty()));
                self.reads = a.stage;
                self.visible = vec![(scope_stage, scope_access)];
            }
            self.layout = a.layout;
            barrier
        } else {
            let barrier = match self.write {
                Some((stage, access)) if !self.covered(&a) => {
                    self.visible.push((scope_stage, scope_access));
                    Some(Barrier {
                        resource,
                        src_stage: stage,
                        src_access: access,
                        dst_stage: scope_stage,
                        dst_access: scope_access,
                        layouts: self.image.then_some((self.layout, self.layout)),
                    })
                }
                _ => None,
            };
            self.reads |= a.stage;
            barrier
        }
    }

    /// The stages and access of everything since the last completed dependency,
    /// for handing memory over to an aliased image or the next frame.
    pub fn pending(&self) -> (Stage, Access) {
        let (s, a) = self.write.unwrap_or_default();
        (s | self.reads, a)
    }
}

/// The layout for sampling an image of an aspect.
pub fn sampled_layout(aspect: Aspect) -> Layout {
    match aspect {
        Aspect::Color => Layout::ShaderReadOnlyOptimal,
        Aspect::Depth | Aspect::DepthStencil => Layout::DepthStencilReadOnlyOptimal,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const R: ResourceId = ResourceId::new(0);

    const COLOR_WRITE: GpuAccess = GpuAccess {
        stage: Stage::COLOR_ATTACHMENT_OUTPUT,
        access: Access::COLOR_ATTACHMENT_WRITE,
        layout: Layout::ColorAttachmentOptimal,
        discards: true,
    };
    const FRAG_SAMPLE: GpuAccess = GpuAccess {
        stage: Stage::FRAGMENT_SHADER,
        access: Access::SHADER_SAMPLED_READ,
        layout: Layout::ShaderReadOnlyOptimal,
        discards: false,
    };
    const COMPUTE_SAMPLE: GpuAccess = GpuAccess {
        stage: Stage::COMPUTE_SHADER,
        ..FRAG_SAMPLE
    };

    fn own(a: GpuAccess) -> (Stage, Access) {
        (a.stage, a.access)
    }

    #[test]
    fn a_widened_scope_covers_later_reads_in_the_same_layout() {
        let mut s = ResourceState::fresh(true);
        s.access(R, COLOR_WRITE, own(COLOR_WRITE));
        let both = (
            Stage::FRAGMENT_SHADER | Stage::COMPUTE_SHADER,
            Access::SHADER_SAMPLED_READ,
        );
        let b = s.access(R, FRAG_SAMPLE, both).expect("RAW barrier");
        assert_eq!((b.dst_stage, b.dst_access), both);
        assert_eq!(s.access(R, COMPUTE_SAMPLE, own(COMPUTE_SAMPLE)), None);
    }

    #[test]
    fn write_then_two_reads_in_one_stage_needs_one_barrier() {
        let mut s = ResourceState::fresh(true);
        let first = s
            .access(R, COLOR_WRITE, own(COLOR_WRITE))
            .expect("initial transition");
        assert_eq!(
            first.layouts,
            Some((Layout::Undefined, Layout::ColorAttachmentOptimal))
        );
        assert_eq!(first.src_stage, Stage::empty());
        let b = s
            .access(R, FRAG_SAMPLE, own(FRAG_SAMPLE))
            .expect("RAW barrier");
        assert_eq!(b.src_stage, Stage::COLOR_ATTACHMENT_OUTPUT);
        assert_eq!(b.src_access, Access::COLOR_ATTACHMENT_WRITE);
        assert_eq!(
            b.layouts,
            Some((
                Layout::ColorAttachmentOptimal,
                Layout::ShaderReadOnlyOptimal
            ))
        );
        assert_eq!(s.access(R, FRAG_SAMPLE, own(FRAG_SAMPLE)), None);
    }

    #[test]
    fn a_read_in_a_new_stage_chains_after_the_transition() {
        let mut s = ResourceState::fresh(true);
        s.access(R, COLOR_WRITE, own(COLOR_WRITE));
        s.access(R, FRAG_SAMPLE, own(FRAG_SAMPLE));
        let b = s
            .access(R, COMPUTE_SAMPLE, own(COMPUTE_SAMPLE))
            .expect("new stage needs a barrier");
        assert_eq!(b.src_stage, Stage::FRAGMENT_SHADER);
        assert_eq!(b.dst_stage, Stage::COMPUTE_SHADER);
        assert_eq!(
            b.layouts,
            Some((Layout::ShaderReadOnlyOptimal, Layout::ShaderReadOnlyOptimal))
        );
    }

    #[test]
    fn write_after_reads_waits_for_the_readers() {
        let mut s = ResourceState::fresh(true);
        s.access(R, COLOR_WRITE, own(COLOR_WRITE));
        s.access(R, FRAG_SAMPLE, own(FRAG_SAMPLE));
        s.access(R, COMPUTE_SAMPLE, own(COMPUTE_SAMPLE));
        let b = s
            .access(R, COLOR_WRITE, own(COLOR_WRITE))
            .expect("WAR barrier");
        assert_eq!(b.src_stage, Stage::FRAGMENT_SHADER | Stage::COMPUTE_SHADER);
        assert_eq!(b.src_access, Access::empty());
        assert_eq!(
            b.layouts,
            Some((Layout::Undefined, Layout::ColorAttachmentOptimal))
        );
    }

    #[test]
    fn buffers_get_no_barrier_before_their_first_write() {
        let mut s = ResourceState::fresh(false);
        let write = GpuAccess {
            stage: Stage::COMPUTE_SHADER,
            access: Access::SHADER_STORAGE_WRITE,
            layout: Layout::General,
            discards: false,
        };
        assert_eq!(s.access(ResourceId::new(1), write, own(write)), None);
        let b = s
            .access(ResourceId::new(1), write, own(write))
            .expect("WAW barrier");
        assert_eq!(b.layouts, None);
        assert_eq!(b.src_access, Access::SHADER_STORAGE_WRITE);
    }
}
