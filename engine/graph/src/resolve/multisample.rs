//! Rules for multisampled images: only attachments draw into them, and a
//! colour attachment's resolve target is a single-sample image of its size
//! and format that the attachment itself is multisampled for.

use super::rules::access_path;
use super::{image_extent, Ir, IrAccess, IrKind, Resolver, Usage, PROBE_SIZES};
use crate::vk::FormatInfo;

impl Resolver<'_> {
    /// Multisampled images are neither sampled nor copied (shaders and
    /// transfers see one sample per texel), and every resolve target fits
    /// the attachment it resolves.
    pub(super) fn check_multisampling(&mut self, ir: &Ir) {
        for pass in &ir.passes {
            let (source, index) = (pass.source, pass.index);
            for (k, access) in pass.accesses.iter().enumerate() {
                let Some((format, samples)) = image_of(ir, access) else {
                    continue;
                };
                let name = &ir.resources[access.resource].name;
                let path = access_path(index, access);
                let how = match access.usage {
                    Usage::Sampled => Some("sampled"),
                    Usage::TransferSrc | Usage::TransferDst => Some("copied or blitted"),
                    _ => None,
                };
                if let (Some(how), true) = (how, samples > 1) {
                    self.error(source, &path, format!(
                        "multisampled image \"{name}\" ({samples} samples) cannot be {how}: shaders and transfers see one sample per texel"))
                        .hint = Some(format!("give the attachment that draws \"{name}\" `resolve: \"{name}_resolved\"` (a single-sample image) and read that"));
                }
                // The attachment a resolve target resolves is the access
                // just before it.
                let Some(attachment) = k
                    .checked_sub(1)
                    .filter(|_| access.usage.is_resolve_target())
                    .map(|j| &pass.accesses[j])
                else {
                    continue;
                };
                let Some((from_format, from_samples)) = image_of(ir, attachment) else {
                    continue;
                };
                let from = &ir.resources[attachment.resource].name;
                let problem = if from_samples == 1 {
                    Some(format!("colour attachment \"{from}\" has 1 sample, so there is nothing to resolve into \"{name}\""))
                } else if samples != 1 {
                    Some(format!(
                        "resolve target \"{name}\" has {samples} samples; a resolve target has 1"
                    ))
                } else if from_format.name != format.name {
                    Some(format!("resolve target \"{name}\" is {} but colour attachment \"{from}\" is {}: a resolve keeps the format", format.name, from_format.name))
                } else {
                    PROBE_SIZES.iter().find_map(|&out| {
                        let (a, b) = (
                            image_extent(ir, attachment.resource, out)?,
                            image_extent(ir, access.resource, out)?,
                        );
                        (a != b).then(|| format!(
                            "resolve target \"{name}\" is {}x{} but colour attachment \"{from}\" is {}x{} at output {}x{}",
                            b.width, b.height, a.width, a.height, out.width, out.height))
                    })
                };
                if let Some(problem) = problem {
                    self.error(source, &path, problem).hint = Some(
                        "resolve a multisampled colour attachment into a single-sample image of its size and format".into(),
                    );
                }
            }
        }
    }
}

/// The format and sample count of the image an access touches, when it
/// is an image the graph declares.
fn image_of(ir: &Ir, access: &IrAccess) -> Option<(&'static FormatInfo, u32)> {
    match &ir.resources[access.resource].kind {
        IrKind::Image {
            format, samples, ..
        } => Some((*format, *samples)),
        _ => None,
    }
}
