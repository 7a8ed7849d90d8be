//! Image layouts as the plan's barriers leave them, so descriptors (the
//! executor's and a draw recorder's) name the layout an image is in during a pass.

use weft_graph::id::{IdVec, PassId, ResourceId};
use weft_graph::plan::{Plan, Residency};
use weft_graph::vk::Layout;

/// The layout of every resource at the start of a frame: persistent
/// resources in their frame-start layout, transient ones undefined.
pub fn frame_start(plan: &Plan) -> IdVec<ResourceId, Layout> {
    plan.resources
        .iter()
        .map(|r| match r.residency {
            Residency::Transient => Layout::Undefined,
            _ => r.frame_start_layout,
        })
        .collect()
}

/// Applies one pass's barriers to the tracked layouts.
pub fn apply_pass(plan: &Plan, pass: PassId, layouts: &mut IdVec<ResourceId, Layout>) {
    let Some(pass) = plan.passes.get(pass) else {
        return;
    };
    for b in &pass.barriers {
        if let Some((_, new)) = b.layouts {
            layouts[b.resource] = new;
        }
    }
}

/// The layout of `resource` while pass `pass` runs (after its barriers).
pub fn layout_at(plan: &Plan, pass: PassId, resource: ResourceId) -> Layout {
    let mut layouts = frame_start(plan);
    for p in plan.passes.ids().take(pass.index() + 1) {
        apply_pass(plan, p, &mut layouts);
    }
    layouts.get(resource).copied().unwrap_or(Layout::Undefined)
}
