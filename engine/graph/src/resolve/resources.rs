//! Resolving resource declarations: formats, sizes, mips, layers, samples.

use super::{
    expression_vars, resource_path, BufferSize, IrKind, IrResource, Resolver, SizeSpec,
    MAX_BUFFER_BYTES,
};
use crate::diagnostic::Diagnostic;
use crate::load::Located;
use crate::plan::Extent;
use crate::schema::{Expr, ResourceDecl, SizeDecl};
use crate::spans::Seg;
use crate::vk::{format_by_name, FORMATS};

impl Resolver<'_> {
    pub(super) fn resolve_resource(&mut self, r: &Located<ResourceDecl>) -> IrResource {
        let (source, index) = (r.source, r.index);
        match &r.item {
            ResourceDecl::Image(img) => {
                if img.history && img.persistent {
                    self.error(
                        source,
                        &resource_path(index, &[Seg::Field("persistent")]),
                        format!(
                            "\"{}\" is both `history` (read before this frame writes it) and `persistent` (written, then read); choose one",
                            img.name
                        ),
                    );
                }
                let Some(format) = format_by_name(&img.format.0) else {
                    let (file, pos) = self
                        .graph
                        .locate(source, &resource_path(index, &[Seg::Field("format")]));
                    let d = Diagnostic::error(
                        file,
                        pos,
                        format!("unknown format \"{}\"", img.format.0),
                    )
                    .suggest(&img.format.0, FORMATS.iter().map(|f| f.name));
                    let d = if d.hint.is_none() {
                        d.with_hint(
                            "use a Vulkan format name such as R16G16B16A16_SFLOAT or D32_SFLOAT",
                        )
                    } else {
                        d
                    };
                    self.diags.push(d);
                    // Checked no further, so one typo gives one error.
                    return IrResource {
                        name: img.name.clone(),
                        source,
                        index,
                        kind: IrKind::External,
                        history: img.history,
                        persistent: img.persistent,
                    };
                };
                let size_path = resource_path(index, &[Seg::Field("size")]);
                let size = match &img.size {
                    SizeDecl::Output => SizeSpec::Output,
                    SizeDecl::Scale(x, y) => {
                        let (sx, sy) = self.scale_pair(source, &size_path, x, y);
                        SizeSpec::Scale(sx, sy)
                    }
                    SizeDecl::Absolute(w, h) => {
                        let w = self.count(source, &size_path, w, "a width", 16384);
                        let h = self.count(source, &size_path, h, "a height", 16384);
                        SizeSpec::Absolute(w, h)
                    }
                    SizeDecl::Like(other, x, y) => {
                        let (sx, sy) = self.scale_pair(source, &size_path, x, y);
                        match self.resource_index.get(other.as_str()) {
                            Some(&i) => SizeSpec::Like(i, sx, sy),
                            None => {
                                let names = self.resource_names();
                                self.error(
                                    source,
                                    &size_path,
                                    format!("unknown resource \"{other}\""),
                                )
                                .hint = crate::diagnostic::nearest(other, names)
                                    .map(|n| format!("did you mean \"{n}\"?"));
                                SizeSpec::Output
                            }
                        }
                    }
                };
                let mips = self.count(
                    source,
                    &resource_path(index, &[Seg::Field("mips")]),
                    &img.mips,
                    "mips",
                    15,
                );
                let layers = self.count(
                    source,
                    &resource_path(index, &[Seg::Field("layers")]),
                    &img.layers,
                    "layers",
                    2048,
                );
                let samples_path = resource_path(index, &[Seg::Field("samples")]);
                let samples = self.count(source, &samples_path, &img.samples, "samples", 64);
                if !samples.is_power_of_two() {
                    self.error(
                        source,
                        &samples_path,
                        format!("samples must be 1, 2, 4, 8, 16, 32 or 64, found {samples}"),
                    );
                }
                IrResource {
                    name: img.name.clone(),
                    source,
                    index,
                    kind: IrKind::Image {
                        format,
                        size,
                        mips,
                        layers,
                        samples,
                    },
                    history: img.history,
                    persistent: img.persistent,
                }
            }
            ResourceDecl::Buffer(buf) => {
                let size_path = resource_path(index, &[Seg::Field("size")]);
                let size = match &buf.size {
                    Expr::Number(n)
                        if *n >= 1.0 && n.fract() == 0.0 && *n <= MAX_BUFFER_BYTES as f64 =>
                    {
                        BufferSize::Bytes(*n as u64)
                    }
                    Expr::Number(n) => {
                        self.error(
                            source,
                            &size_path,
                            format!(
                                "buffer size must be a whole number of bytes from 1 to 2^48, found {n}"
                            ),
                        );
                        BufferSize::Bytes(1)
                    }
                    Expr::Text(text) => {
                        // Any value stands for a scene's here: only names are checked.
                        let scene = super::scene_value_vars(self.graph, |_| Some(1.0));
                        let vars = expression_vars(
                            &self.graph.sources[source].params,
                            Extent {
                                width: 1920,
                                height: 1080,
                            },
                            &scene,
                        );
                        if let Err(e) = crate::expr::eval(text, &vars) {
                            let mut names: Vec<String> = vars.keys().cloned().collect();
                            names.sort();
                            self.error(
                                source,
                                &size_path,
                                format!(
                                    "in size expression \"{text}\" at character {}: {}",
                                    e.offset + 1,
                                    e.message
                                ),
                            )
                            .hint = Some(format!("variables: {}", names.join(", ")));
                        }
                        BufferSize::Expression(text.clone())
                    }
                };
                IrResource {
                    name: buf.name.clone(),
                    source,
                    index,
                    kind: IrKind::Buffer { size },
                    history: buf.history,
                    persistent: false,
                }
            }
            // Built each frame before it is traced; the scene keeps it.
            ResourceDecl::AccelerationStructure(decl) => IrResource {
                name: decl.name.clone(),
                source,
                index,
                kind: IrKind::AccelerationStructure,
                history: false,
                persistent: true,
            },
        }
    }
}
