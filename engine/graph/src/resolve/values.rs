//! Numbers in a graph: dimensions, scales and counts from literals or parameters,
//! checked for range, and the sizes and expression variables derived from them.

use super::{Ir, IrKind, Resolver, SizeSpec};
use crate::id::IrResourceId;
use crate::plan::Extent;
use crate::schema::{Dim, ParamValue};
use crate::spans::Seg;
use std::collections::BTreeMap;

impl Resolver<'_> {
    /// A number from the graph or a parameter; NaN and infinity are errors.
    pub(super) fn dim(
        &mut self,
        source: usize,
        path: &[Seg],
        dim: &Dim,
        what: &str,
    ) -> Option<f64> {
        let value = self.dim_value(source, path, dim, what)?;
        if value.is_finite() {
            return Some(value);
        }
        self.error(
            source,
            path,
            format!("{what} must be a finite number, found {value}"),
        );
        None
    }

    pub(super) fn dim_value(
        &mut self,
        source: usize,
        path: &[Seg],
        dim: &Dim,
        what: &str,
    ) -> Option<f64> {
        match dim {
            Dim::Number(n) => Some(*n),
            Dim::Reference(text) => {
                let params = &self.graph.sources[source].params;
                let name = text.strip_prefix('$').unwrap_or(text);
                match params.get(name) {
                    Some(ParamValue::Number(n)) => Some(*n),
                    Some(other) => {
                        self.error(
                            source,
                            path,
                            format!(
                                "parameter \"${name}\" used as {what} is {other:?}, not a number"
                            ),
                        );
                        None
                    }
                    None => {
                        let names: Vec<&str> = params.keys().map(String::as_str).collect();
                        let hint = crate::diagnostic::nearest(name, names)
                            .map(|n| format!("did you mean \"${n}\"?"))
                            .or(Some("declare it in the file's `params`".into()));
                        self.error(source, path, format!("unknown parameter \"{text}\""))
                            .hint = hint;
                        None
                    }
                }
            }
        }
    }

    /// A size's two scale factors, each in (0, 16].
    pub(super) fn scale_pair(
        &mut self,
        source: usize,
        path: &[Seg],
        x: &Dim,
        y: &Dim,
    ) -> (f64, f64) {
        let sx = self.dim(source, path, x, "a scale").unwrap_or(1.0);
        let sy = self.dim(source, path, y, "a scale").unwrap_or(1.0);
        if !(sx > 0.0 && sy > 0.0 && sx <= 16.0 && sy <= 16.0) {
            self.error(
                source,
                path,
                format!("scale ({sx}, {sy}) must be in (0, 16]"),
            );
            return (1.0, 1.0);
        }
        (sx, sy)
    }

    pub(super) fn count(
        &mut self,
        source: usize,
        path: &[Seg],
        dim: &Dim,
        what: &str,
        max: u32,
    ) -> u32 {
        match self.dim(source, path, dim, what) {
            Some(n) if n >= 1.0 && n.fract() == 0.0 && n <= max as f64 => n as u32,
            Some(n) => {
                self.error(
                    source,
                    path,
                    format!("{what} must be a whole number from 1 to {max}, found {n}"),
                );
                1
            }
            None => 1,
        }
    }
}

/// The work-group count per dimension every Vulkan device supports
/// (`maxComputeWorkGroupCount`'s required minimum).
pub const MAX_WORKGROUP_COUNT: u32 = 65_535;

/// Bytes of one indirect dispatch's record (`VkDispatchIndirectCommand`:
/// three u32 group counts).
pub const INDIRECT_RECORD_BYTES: u32 = 12;

/// The most samples per pixel a progressive graph may add in one frame: more
/// would make a single frame run for seconds even on a fast GPU.
pub const MAX_SAMPLES_PER_FRAME: u32 = 4096;

/// The most dispatches per frame a compute pass may `repeat` (as many as a
/// progressive graph may add samples per frame).
pub const MAX_REPEAT: u32 = MAX_SAMPLES_PER_FRAME;

pub use crate::plan::MAX_IMAGE_DIMENSION;

/// The error for an image side over [`MAX_IMAGE_DIMENSION`].
pub(crate) fn oversized_image(name: &str, size: Extent, output: Extent) -> String {
    format!(
        "\"{name}\" would be {}x{} at output size {}x{}, over the {MAX_IMAGE_DIMENSION} pixels an image side may have",
        size.width, size.height, output.width, output.height
    )
}

/// An image's size for a given output size; `None` for a `Like` cycle or a buffer.
pub fn image_extent(ir: &Ir, resource: IrResourceId, output: Extent) -> Option<Extent> {
    let scale = |v: u32, s: f64| ((v as f64 * s).floor() as u32).max(1);
    let mut current = resource;
    let (mut fx, mut fy) = (1.0, 1.0);
    for _ in 0..=ir.resources.len() {
        let IrKind::Image { size, .. } = ir.resources.get(current)?.kind else {
            return None;
        };
        match size {
            SizeSpec::Output => {
                return Some(Extent {
                    width: scale(output.width, fx),
                    height: scale(output.height, fy),
                })
            }
            SizeSpec::Scale(sx, sy) => {
                return Some(Extent {
                    width: scale(output.width, sx * fx),
                    height: scale(output.height, sy * fy),
                })
            }
            SizeSpec::Absolute(w, h) => {
                return Some(Extent {
                    width: scale(w, fx),
                    height: scale(h, fy),
                })
            }
            SizeSpec::Like(other, sx, sy) => {
                fx *= sx;
                fy *= sy;
                current = other;
            }
        }
    }
    None
}

/// Each scene value the graph declares, as a size expression's variable,
/// with `measured`'s value or 0.
pub fn scene_value_vars(
    graph: &crate::load::LoadedGraph,
    measured: impl Fn(&str) -> Option<f64>,
) -> std::collections::BTreeMap<String, f64> {
    graph
        .scene_values
        .iter()
        .map(|(_, name)| (name.clone(), measured(name).unwrap_or(0.0)))
        .collect()
}

/// The most bytes a buffer may have: above any device's `maxBufferSize`,
/// and far enough below `u64::MAX` that placing buffers cannot overflow.
pub const MAX_BUFFER_BYTES: u64 = 1 << 48;

/// Variables available to buffer size expressions: the output size, the
/// declaring file's numeric parameters and the scene values the graph
/// declares (`scene`: each with the value the renderer measured, or 0 in a
/// compile without a scene). Nothing else about scenes or techniques.
pub fn expression_vars(
    params: &BTreeMap<String, ParamValue>,
    output: Extent,
    scene: &BTreeMap<String, f64>,
) -> BTreeMap<String, f64> {
    let mut vars: BTreeMap<String, f64> = params
        .iter()
        .filter_map(|(k, v)| match v {
            ParamValue::Number(n) => Some((k.clone(), *n)),
            _ => None,
        })
        .collect();
    vars.insert("width".into(), output.width as f64);
    vars.insert("height".into(), output.height as f64);
    vars.insert("pixels".into(), output.width as f64 * output.height as f64);
    vars.extend(scene.iter().map(|(k, v)| (k.clone(), *v)));
    vars
}
