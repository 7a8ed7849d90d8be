//! Rules across a pass: what each kind must declare, format capabilities,
//! attachment sizes, and accesses that conflict inside one pass.

use super::{
    image_extent, pass_path, resource_path, Ir, IrAccess, IrKind, IrPass, IrResource, Resolver,
    SizeAtProbe, SizeSpec, Usage, PROBE_SIZES,
};
use crate::id::{IdVec, IrResourceId};
use crate::plan::Extent;
use crate::schema::{LoadDecl, PassDecl, PassKind};
use crate::spans::Seg;
use crate::vk::{Aspect, FormatFeatures, FORMATS};
use std::collections::HashMap;

impl Resolver<'_> {
    /// Rules about what each pass kind must declare.
    pub(super) fn check_pass_shape(
        &mut self,
        pass: &IrPass,
        decl: &PassDecl,
        resources: &IdVec<IrResourceId, IrResource>,
    ) {
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
            PassKind::BuildAccelerationStructures => {
                self.check_build_pass(pass, decl, resources);
                return;
            }
        }
        if decl.repeat.is_some() && pass.kind != PassKind::Compute {
            self.error(
                source,
                &pass_path(index, &[Seg::Field("repeat")]),
                format!(
                    "only compute passes repeat; pass \"{name}\" is {:?}",
                    pass.kind
                ),
            );
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
                PassKind::Copy | PassKind::Blit | PassKind::BuildAccelerationStructures => false,
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
    pub(super) fn check_usages(&mut self, ir: &Ir) {
        for pass in &ir.passes {
            let (source, index) = (pass.source, pass.index);
            let mut seen: HashMap<IrResourceId, &IrAccess> = HashMap::new();
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
                    IrKind::External | IrKind::AccelerationStructure => {}
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
                        if access.usage == Usage::IndirectRead {
                            self.error(
                                source,
                                &path,
                                format!("an indirect dispatch reads its group counts from a buffer; \"{rname}\" is an image"),
                            );
                            continue;
                        }
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
                            Usage::TransferSrc | Usage::TransferDst | Usage::IndirectRead => {
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
                        if attachment && !access.usage.is_resolve_target() {
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
        for (i, r) in ir.resources.iter_enumerated() {
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
        ref u if u.is_resolve_target() => path.push(Seg::Field("resolve")),
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
                Usage::IndirectRead,
                Usage::StorageRead | Usage::StorageWrite
            )
            | (
                Usage::StorageRead | Usage::StorageWrite,
                Usage::IndirectRead
            )
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
        Usage::IndirectRead => "an indirect dispatch's group counts",
    }
}
