//! Copies the executor can record: a `Copy` between images copies texel for
//! texel, so its source and destination must be one size at the output size
//! compiled for (a `Blit` scales). `weft graph check` compiles at two output
//! sizes, so a rule that agrees at one size only (an `Absolute` size beside
//! an output-relative one) is refused before a render meets it.

use crate::diagnostic::Diagnostic;
use crate::id::{IdVec, PassId, ResourceId};
use crate::plan::{Extent, PlanPass, PlanResource, ResourceDesc};
use crate::schema::PassKind;

/// An error for each image `Copy` among `passes` whose images differ in size.
pub(super) fn check(
    passes: &IdVec<PassId, PlanPass>,
    resources: &IdVec<ResourceId, PlanResource>,
    output: Extent,
) -> Result<(), Vec<Diagnostic>> {
    let mut errors = Vec::new();
    for pass in passes.iter().filter(|p| p.kind == PassKind::Copy) {
        let Some((src, dst)) = pass.transfer else {
            continue;
        };
        let (s, d) = (&resources[src], &resources[dst]);
        if let (ResourceDesc::Image(si), ResourceDesc::Image(di)) = (&s.desc, &d.desc) {
            if si.extent != di.extent {
                errors.push(Diagnostic::error(
                    pass.declared_at.file.clone(),
                    pass.declared_at.pos,
                    format!(
                        "copy pass \"{}\": `{}` is {}x{} and `{}` {}x{} at output size {}x{}; a copy needs equal sizes (a Blit scales)",
                        pass.name,
                        s.name,
                        si.extent.width,
                        si.extent.height,
                        d.name,
                        di.extent.width,
                        di.extent.height,
                        output.width,
                        output.height
                    ),
                ));
            }
        }
    }
    if errors.is_empty() {
        Ok(())
    } else {
        Err(errors)
    }
}
