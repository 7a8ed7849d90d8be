//! Resolving a pass's attachments: colour attachments (conditional ones
//! last), the single-sample images multisampled ones resolve into, and the
//! depth attachment, each an access of the pass.

use super::{pass_path, IrAccess, Resolver, Usage};
use crate::id::IrResourceId;
use crate::load::Located;
use crate::schema::{AttachmentDecl, LoadDecl, PassDecl, StoreDecl};
use crate::spans::Seg;

impl Resolver<'_> {
    /// The accesses of `p`'s attachments, in order: each colour attachment
    /// followed by its resolve target, if it names one, then the depth
    /// attachment.
    pub(super) fn resolve_attachments(&mut self, p: &Located<PassDecl>) -> Vec<IrAccess> {
        let (source, index) = (p.source, p.index);
        let decl = &p.item;
        let mut accesses = Vec::new();
        let mut conditional_before = None;
        for (i, a) in decl.color.iter().enumerate() {
            let path = pass_path(
                index,
                &[Seg::Field("color"), Seg::Index(i), Seg::Field("image")],
            );
            if let Some(r) = self.lookup(source, &path, &a.image) {
                accesses.push(attachment_access(r, a, false, "color", Some(i)));
                if let Some(target) = &a.resolve {
                    let at = pass_path(
                        index,
                        &[Seg::Field("color"), Seg::Index(i), Seg::Field("resolve")],
                    );
                    if let Some(t) = self.lookup(source, &at, target) {
                        accesses.push(resolve_access(t, a, i));
                    }
                }
            }
            match (&conditional_before, a.enabled_if.is_empty()) {
                (None, false) => conditional_before = Some(a.image.clone()),
                (Some(earlier), true) => {
                    self.error(
                        source,
                        &path,
                        format!(
                            "colour attachment \"{}\" follows the conditional attachment \"{earlier}\": its fragment output location would depend on features",
                            a.image
                        ),
                    )
                    .hint = Some("list conditional colour attachments last".into());
                }
                _ => {}
            }
        }
        if let Some(a) = &decl.depth {
            let path = pass_path(index, &[Seg::Field("depth"), Seg::Field("image")]);
            if !a.enabled_if.is_empty() {
                let at = pass_path(index, &[Seg::Field("depth"), Seg::Field("enabled_if")]);
                self.error(
                    source,
                    &at,
                    "a depth attachment cannot be conditional: make the pass conditional instead"
                        .to_string(),
                );
            }
            if a.resolve.is_some() {
                let at = pass_path(index, &[Seg::Field("depth"), Seg::Field("resolve")]);
                self.error(
                    source,
                    &at,
                    "a depth attachment cannot resolve (Vulkan 1.0 render passes resolve colour only)".to_string(),
                )
                .hint = Some("write the depth a later pass needs from a single-sample pass".into());
            }
            if let Some(r) = self.lookup(source, &path, &a.image) {
                accesses.push(attachment_access(r, a, true, "depth", None));
            }
        }
        accesses
    }
}

fn attachment_access(
    resource: IrResourceId,
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
            resolve_target: false,
        }
    };
    IrAccess {
        resource,
        usage,
        conditions: a.enabled_if.clone(),
        field,
        item,
    }
}

/// The write of the `item`-th colour attachment `a`'s resolve target: every
/// texel replaced at the end of the pass, under the attachment's conditions.
fn resolve_access(resource: IrResourceId, a: &AttachmentDecl, item: usize) -> IrAccess {
    IrAccess {
        resource,
        usage: Usage::Color {
            load: LoadDecl::DontCare,
            store: StoreDecl::Store,
            blend: None,
            resolve_target: true,
        },
        conditions: a.enabled_if.clone(),
        field: "color",
        item: Some(item),
    }
}
