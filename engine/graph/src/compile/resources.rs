//! Step 4, resources: a description of each kept resource — its residency
//! (transient, history, output), the plan passes it lives through, and the
//! format, extent and usage flags an image or buffer is created with.

use super::cull::Roots;
use super::lifetimes::Lifetimes;
use super::order::Uses;
use super::CompileOptions;
use crate::diagnostic::Diagnostic;
use crate::id::{IdVec, IrResourceId, PassId, ResourceId};
use crate::load::LoadedGraph;
use crate::plan::{BufferDesc, Extent, ImageDesc, PlanResource, Residency, ResourceDesc};
use crate::resolve::{
    expression_vars, image_extent, oversized_image, resource_path, scene_value_vars, BufferSize,
    Ir, IrKind, Usage, MAX_BUFFER_BYTES, MAX_IMAGE_DIMENSION,
};
use crate::schema::PassKind;
use crate::spans::Seg;
use crate::vk::{BufferUsage, ImageUsage, Layout};

/// Describes every kept resource, after checking that every image fits the device limit.
pub(crate) fn describe(
    graph: &LoadedGraph,
    ir: &Ir,
    uses: &Uses,
    lifetimes: &Lifetimes,
    roots: &Roots,
    passes: usize,
    options: &CompileOptions,
) -> Result<IdVec<ResourceId, PlanResource>, Vec<Diagnostic>> {
    check_image_sizes(graph, ir, &lifetimes.kept, options.extent)?;
    let mut resources = IdVec::new();
    let mut errors = Vec::new();
    for &r in &lifetimes.kept {
        let res = &ir.resources[r];
        let residency = if roots.is_root[r] {
            Residency::Output
        } else if res.kept_across_frames() {
            Residency::History
        } else {
            Residency::Transient
        };
        let touches = &lifetimes.timeline.per_resource[r];
        let final_pass = passes.saturating_sub(1);
        let first = touches
            .first()
            .map_or(final_pass, |t| t.0.index())
            .min(final_pass);
        let last = touches.last().map_or(0, |t| t.0.index());
        let accesses = || {
            touches.iter().flat_map(|&(_, p, k)| {
                uses[p][k]
                    .accesses
                    .iter()
                    .map(move |&a| &ir.passes[p].accesses[a].usage)
            })
        };
        // A build pass's buffer is its scratch, which builds address.
        let built_in = || {
            touches
                .iter()
                .any(|&(_, p, _)| ir.passes[p].kind == PassKind::BuildAccelerationStructures)
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
                        // Refused by validation: images hold no dispatch records.
                        Usage::IndirectRead => ImageUsage::empty(),
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
            IrKind::AccelerationStructure => ResourceDesc::AccelerationStructure,
            IrKind::External => unreachable!(
                "only fragments have external resources, and fragments are not compiled"
            ),
            IrKind::Buffer { size } => {
                let bytes = match buffer_bytes(graph, res, size, options) {
                    Ok(bytes) => bytes,
                    Err(error) => {
                        errors.push(error);
                        1
                    }
                };
                let mut usage = BufferUsage::empty();
                if built_in() {
                    usage |= BufferUsage::STORAGE | BufferUsage::SHADER_DEVICE_ADDRESS;
                }
                for u in accesses() {
                    usage |= match u {
                        Usage::Sampled => BufferUsage::UNIFORM,
                        Usage::TransferSrc => BufferUsage::TRANSFER_SRC,
                        Usage::TransferDst => BufferUsage::TRANSFER_DST,
                        Usage::IndirectRead => BufferUsage::INDIRECT,
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
            lifetime: (PassId::new(first), PassId::new(last)),
            placement: None,
            frame_start_layout: Layout::Undefined,
        });
    }
    if !errors.is_empty() {
        return Err(errors);
    }
    Ok(resources)
}

/// A buffer's bytes at this output size, with the scene values the renderer
/// measured (0 for one it did not), or an error at its size when the
/// expression gives no byte count (infinite, say, dividing by a scene value
/// of 0) or more than [`MAX_BUFFER_BYTES`].
fn buffer_bytes(
    graph: &LoadedGraph,
    res: &crate::resolve::IrResource,
    size: &BufferSize,
    options: &CompileOptions,
) -> Result<u64, Diagnostic> {
    let text = match size {
        BufferSize::Bytes(b) => return Ok(*b),
        BufferSize::Expression(text) => text,
    };
    let vars = expression_vars(
        &graph.sources[res.source].params,
        options.extent,
        &scene_value_vars(graph, |name| options.scene_values.get(name).copied()),
    );
    // Resolving checked the expression's syntax and names; its value may
    // still be no byte count (a division by a scene value of 0).
    let problem = match crate::expr::eval(text, &vars) {
        Ok(value) if (0.0..=MAX_BUFFER_BYTES as f64).contains(&value) => {
            return Ok(value.max(1.0).ceil() as u64)
        }
        Ok(value) => format!("gives {value} bytes"),
        Err(e) => format!(
            "cannot be evaluated ({} at character {})",
            e.message,
            e.offset + 1
        ),
    };
    let (file, pos) = graph.locate(res.source, &resource_path(res.index, &[Seg::Field("size")]));
    let values: Vec<String> =
        scene_value_vars(graph, |name| options.scene_values.get(name).copied())
            .iter()
            .map(|(k, v)| format!("{k} = {v}"))
            .collect();
    let d = Diagnostic::error(
        file,
        pos,
        format!(
            "buffer \"{}\" size \"{text}\" {problem} at {}x{}: a size is a byte count up to \
             2^48",
            res.name, options.extent.width, options.extent.height
        ),
    );
    Err(if values.is_empty() {
        d
    } else {
        d.with_hint(format!(
            "the graph's scene values here (0 where none was measured): {}",
            values.join(", ")
        ))
    })
}

/// Every image the plan creates fits [`MAX_IMAGE_DIMENSION`] at this output size
/// (`check` tries a few sizes; a command line can ask for another).
fn check_image_sizes(
    graph: &LoadedGraph,
    ir: &Ir,
    kept: &IdVec<ResourceId, IrResourceId>,
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

#[cfg(test)]
mod tests {
    use super::super::fixture::CHAIN;
    use super::super::tests::plan_of;
    use super::*;

    #[test]
    fn usage_flags_and_residency_come_from_the_accesses() {
        let plan = plan_of(CHAIN, &[]);
        let image = |name: &str| {
            let r = plan.resource(name).expect("kept");
            match &plan.resources[r].desc {
                ResourceDesc::Image(d) => (d.usage, plan.resources[r].residency),
                _ => panic!("{name} is an image"),
            }
        };
        assert_eq!(
            image("x"),
            (
                ImageUsage::COLOR_ATTACHMENT | ImageUsage::SAMPLED,
                Residency::Transient
            )
        );
        assert_eq!(
            image("out"),
            (
                ImageUsage::COLOR_ATTACHMENT | ImageUsage::TRANSFER_SRC,
                Residency::Output
            )
        );
        assert_eq!(
            plan.resources[ResourceId::new(0)].lifetime,
            (PassId::new(0), PassId::new(1))
        );
    }

    #[test]
    fn an_image_over_the_device_limit_is_an_error_at_its_size() {
        let text = CHAIN.replace("size: Scale(0.5, 0.5)", "size: Scale(8.0, 1.0)");
        let (graph, ir) = super::super::fixture::resolved(&text);
        let options = CompileOptions {
            readback: vec!["unused".into()],
            extent: Extent {
                width: 2100,
                height: 100,
            },
            ..CompileOptions::default()
        };
        let errors =
            super::super::compile_ir(&graph, &ir, &options).expect_err("8 x 2100 texels wide");
        assert_eq!(
            errors[0].message,
            oversized_image(
                "unused",
                Extent {
                    width: 16800,
                    height: 100
                },
                options.extent
            )
        );
        assert_eq!(errors[0].pos.line, 6);
    }
}
