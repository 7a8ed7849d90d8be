//! Step 7, passes: each running pass as the executor needs it — descriptor
//! bindings, shader defines for optional reads, the render pass (attachments with
//! load and store ops chosen from what later work needs), dispatch size, copy
//! endpoints and fixed-function state.

use super::cull::Roots;
use super::lifetimes::Lifetimes;
use super::order::Uses;
use super::CompileOptions;
use crate::id::{IdVec, IrPassId, PassId, ResourceId};
use crate::load::LoadedGraph;
use crate::plan::{
    AttachmentDesc, Barrier, Binding, BindingKind, IndirectDispatch, LoadOp, Location, PlanPass,
    PlanResource, RenderPassDesc, ResourceDesc, StoreOp,
};
use crate::resolve::{image_extent, Ir, IrDispatch, Usage};
use crate::schema::{LoadDecl, PassKind, StoreDecl};
use crate::spans::Seg;
use crate::vk::Layout;
use std::collections::BTreeSet;

/// What every pass description reads.
pub(crate) struct PassContext<'a> {
    pub graph: &'a LoadedGraph,
    pub ir: &'a Ir,
    pub uses: &'a Uses,
    pub lifetimes: &'a Lifetimes,
    pub roots: &'a Roots,
    pub resources: &'a IdVec<ResourceId, PlanResource>,
    pub options: &'a CompileOptions<'a>,
}

/// Describes the passes of `sequence`, each with the barriers recorded before
/// it and between its dispatches.
pub(crate) fn describe(
    cx: &PassContext,
    sequence: &[IrPassId],
    barriers: IdVec<PassId, Vec<Barrier>>,
    repeat_barriers: IdVec<PassId, Vec<Barrier>>,
) -> IdVec<PassId, PlanPass> {
    sequence
        .iter()
        .zip(barriers.into_iter().zip(repeat_barriers))
        .enumerate()
        .map(|(i, (&p, barriers))| plan_pass(cx, p, PassId::new(i), barriers))
        .collect()
}

/// One pass: bindings, defines, render pass, dispatch size and copy endpoints.
fn plan_pass(
    cx: &PassContext,
    p: IrPassId,
    i: PassId,
    (barriers, repeat_barriers): (Vec<Barrier>, Vec<Barrier>),
) -> PlanPass {
    let PassContext {
        graph,
        ir,
        uses: all_uses,
        lifetimes,
        roots,
        resources,
        options,
    } = *cx;
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
    let mut structure = None;
    let mut scratch = None;
    let mut defines: BTreeSet<String> = BTreeSet::new();
    for access in active_accesses() {
        let kind = match access.usage {
            Usage::Sampled => BindingKind::Sampled,
            Usage::StorageRead => BindingKind::StorageRead,
            Usage::StorageWrite => BindingKind::StorageWrite,
            _ => continue,
        };
        let r = lifetimes.plan_index(access.resource);
        if matches!(resources[r].desc, ResourceDesc::AccelerationStructure) {
            // Built, or traced through the scene's set: not bound in the pass's own.
            structure = Some(r);
            continue;
        }
        if pass.kind == PassKind::BuildAccelerationStructures {
            // The build's scratch, which it addresses: a build binds nothing.
            scratch = Some(r);
            continue;
        }
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
    for access in active_accesses() {
        if access.usage.is_color_output() && !access.conditions.is_empty() {
            defines.insert(format!(
                "HAS_{}",
                ir.resources[access.resource].name.to_ascii_uppercase()
            ));
        }
    }
    let mut model_defines = Vec::new();
    for define in &pass.defines {
        if super::conditions_hold(&define.enabled_if, &options.features) {
            let text = match &define.value {
                Some(crate::schema::ParamValue::Number(n)) => format!("{}={n}", define.name),
                _ => define.name.clone(),
            };
            match &define.draws {
                Some(model) => model_defines.push((model.0.clone(), text)),
                None => {
                    defines.insert(text);
                }
            }
        }
    }
    model_defines.sort();
    let render_pass = matches!(pass.kind, PassKind::Raster | PassKind::Fullscreen).then(|| {
        let mut attachments = Vec::new();
        let mut color = Vec::new();
        let mut resolve = Vec::new();
        let mut depth = None;
        let mut extent = options.extent;
        for access in active_accesses() {
            let (load, store, blend, read_only, is_depth) = match &access.usage {
                Usage::Color {
                    load, store, blend, ..
                } => (load, *store, *blend, false, false),
                Usage::Depth {
                    load,
                    store,
                    read_only,
                } => (load, *store, None, *read_only, true),
                _ => continue,
            };
            let r = lifetimes.plan_index(access.resource);
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
                && lifetimes
                    .timeline
                    .needed_later(ir, all_uses, i, access.resource, &roots.is_root)
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
            } else if access.usage.is_resolve_target() {
                // It follows the colour attachment it resolves.
                if let Some(last) = resolve.last_mut() {
                    *last = Some(index);
                }
            } else {
                color.push(index);
                resolve.push(None);
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
            resolve,
            depth,
        }
    });
    let dispatch = pass.dispatch.and_then(|d| match d {
        IrDispatch::Groups(x, y, z) => Some([x, y, z]),
        IrDispatch::Output(x, y) => Some([
            options.extent.width.div_ceil(x.max(1)),
            options.extent.height.div_ceil(y.max(1)),
            1,
        ]),
        IrDispatch::Image(r, x, y) => {
            let e = image_extent(ir, r, options.extent).unwrap_or(options.extent);
            Some([e.width.div_ceil(x.max(1)), e.height.div_ceil(y.max(1)), 1])
        }
        IrDispatch::Indirect(..) => None,
    });
    let indirect = pass.dispatch.and_then(|d| match d {
        IrDispatch::Indirect(r, stride) => Some(IndirectDispatch {
            buffer: lifetimes.plan_index(r),
            stride,
        }),
        _ => None,
    });
    let transfer = if matches!(pass.kind, PassKind::Copy | PassKind::Blit) {
        let find = |want: fn(&Usage) -> bool| {
            pass.accesses
                .iter()
                .find(|a| want(&a.usage))
                .map(|a| lifetimes.plan_index(a.resource))
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
        indirect,
        repeat: pass.repeat,
        repeat_barriers,
        params: pass.params.clone(),
        defines: defines.into_iter().collect(),
        model_defines,
        variants: crate::resolve::variant_count(pass.variant_bits()),
        barriers,
        render_pass,
        bindings,
        transfer,
        raster: pass.raster,
        derive: pass.derive.clone(),
        structure,
        scratch,
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::CHAIN;
    use super::super::tests::plan_of;
    use super::*;

    #[test]
    fn stores_are_kept_only_for_contents_read_later() {
        let plan = plan_of(CHAIN, &[]);
        let ops = |pass: usize| {
            let rp = plan.passes[PassId::new(pass)]
                .render_pass
                .as_ref()
                .expect("fullscreen");
            let a = &rp.attachments[0];
            (a.load, a.store, a.final_layout)
        };
        assert_eq!(
            ops(0),
            (
                LoadOp::Clear,
                StoreOp::Store,
                Layout::ColorAttachmentOptimal
            )
        );
        assert_eq!(plan.passes[PassId::new(1)].bindings.len(), 1);
        assert_eq!(
            plan.passes[PassId::new(1)].bindings[0].kind,
            BindingKind::Sampled
        );
        assert_eq!(
            ops(1),
            (
                LoadOp::DontCare,
                StoreOp::Store,
                Layout::ColorAttachmentOptimal
            )
        );
    }

    #[test]
    fn a_conditional_read_defines_has_name() {
        let text = CHAIN.replace(
            r#"sampled: ["x"]"#,
            r#"sampled: ["x", (name: "x", enabled_if: ["extra"])]"#,
        );
        let plain = plan_of(&text, &[]);
        assert!(plain.passes[PassId::new(1)].defines.is_empty());
        let text = text.replace(r#"sampled: ["x", "#, "sampled: [");
        let with = plan_of(&text, &["extra"]);
        let b = with.passes.iter().find(|p| p.name == "b").expect("b runs");
        assert_eq!(b.defines, ["HAS_X"]);
    }

    #[test]
    fn declared_defines_follow_their_features() {
        let text = CHAIN.replace(
            r#"sampled: ["x"], color: [(image: "out")]"#,
            r#"sampled: ["x"], color: [(image: "out")],
                 defines: [(name: "ALWAYS"), (name: "WITH_EXTRA", enabled_if: ["extra"]),
                           (name: "WITHOUT_EXTRA", enabled_if: ["!extra"])]"#,
        );
        let b = |features: &[&str]| {
            let plan = plan_of(&text, features);
            let b = plan.passes.iter().find(|p| p.name == "b").expect("b runs");
            b.defines.clone()
        };
        assert_eq!(b(&[]), ["ALWAYS", "WITHOUT_EXTRA"]);
        assert_eq!(b(&["extra"]), ["ALWAYS", "WITH_EXTRA"]);
        let (_, ir) = super::super::fixture::resolved(&text);
        assert!(crate::resolve::feature_names(&ir).contains("extra"));
    }

    #[test]
    fn a_conditional_colour_attachment_is_attached_only_when_its_features_hold() {
        let text = CHAIN
            .replace(
                r#"color: [(image: "x", load: Clear([0.0, 0.0, 0.0, 0.0]))]),"#,
                r#"color: [(image: "x", load: Clear([0.0, 0.0, 0.0, 0.0])),
                         (image: "tint", enabled_if: ["extra"])]),"#,
            )
            .replace(
                r#"Image(name: "out", format: R8G8B8A8_UNORM),"#,
                r#"Image(name: "out", format: R8G8B8A8_UNORM),
            Image(name: "tint", format: R8G8B8A8_UNORM),"#,
            )
            .replace(
                r#"sampled: ["x"], color: [(image: "out")]"#,
                r#"sampled: ["x", (name: "tint", enabled_if: ["extra"])], color: [(image: "out")]"#,
            );
        let a = |features: &[&str]| {
            let plan = plan_of(&text, features);
            let a = plan
                .passes
                .iter()
                .find(|p| p.name == "a")
                .expect("a runs")
                .clone();
            a
        };
        let plain = a(&[]);
        assert_eq!(plain.render_pass.as_ref().map(|rp| rp.color.len()), Some(1));
        assert!(plain.defines.is_empty());
        let extra = a(&["extra"]);
        assert_eq!(extra.render_pass.as_ref().map(|rp| rp.color.len()), Some(2));
        assert_eq!(extra.defines, ["HAS_TINT"]);
    }

    #[test]
    fn a_define_with_a_value_is_name_equals_the_parameter_it_names() {
        let text = CHAIN
            .replacen("Graph(", r#"Graph(params: { "choice": 2 },"#, 1)
            .replace(
                r#"sampled: ["x"], color: [(image: "out")]"#,
                r#"sampled: ["x"], color: [(image: "out")],
                 defines: [(name: "CHOICE", value: "$choice"), (name: "TWELVE", value: 12),
                           (name: "PLAIN", enabled_if: ["plain"])]"#,
            );
        let b = |features: &[&str]| {
            let plan = plan_of(&text, features);
            let b = plan.passes.iter().find(|p| p.name == "b").expect("b runs");
            b.defines.clone()
        };
        assert_eq!(b(&[]), ["CHOICE=2", "TWELVE=12"]);
        assert_eq!(b(&["plain"]), ["CHOICE=2", "PLAIN", "TWELVE=12"]);
    }

    #[test]
    fn model_defines_group_mesh_draws_by_shading_model() {
        let text = CHAIN
            .replace(
                r#"Pass(name: "b", kind: Fullscreen, shaders: (fragment: "b.frag"),"#,
                r#"Pass(name: "b", kind: Raster, shaders: (vertex: "b.vert", fragment: "b.frag"),
                 draw: Meshes(All),"#,
            )
            .replace(
                r#"sampled: ["x"], color: [(image: "out")]"#,
                r#"sampled: ["x"], color: [(image: "out")],
                 defines: [(name: "ALWAYS"),
                           (name: "PHONG", enabled_if: ["phong"], draws: BlinnPhong),
                           (name: "PBR", draws: MetallicRoughness)]"#,
            );
        let plan = plan_of(&text, &["phong"]);
        let b = plan.passes.iter().find(|p| p.name == "b").expect("b runs");
        assert_eq!(b.defines, ["ALWAYS"]);
        assert!(b.groups_by_model());
        assert_eq!(b.defines_for("BlinnPhong"), ["ALWAYS", "PHONG"]);
        assert_eq!(b.defines_for("MetallicRoughness"), ["ALWAYS", "PBR"]);
        let plan = plan_of(&text, &[]);
        let b = plan.passes.iter().find(|p| p.name == "b").expect("b runs");
        assert_eq!(
            b.model_defines,
            [("MetallicRoughness".to_string(), "PBR".to_string())]
        );
        assert_eq!(b.defines_for("BlinnPhong"), ["ALWAYS"]);
    }
}
