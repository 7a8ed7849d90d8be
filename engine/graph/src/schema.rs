//! The RON schema users write, as serde types. These mirror the file one to one;
//! resolution (includes, parameters, names) happens in `load` and `validate`.

use serde::de::{self, Deserializer, EnumAccess, VariantAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// A graph file: a whole configuration or a fragment meant to be included.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename = "Graph")]
pub struct GraphFile {
    /// Human-readable name shown in plans and the viewer.
    #[serde(default)]
    pub name: Option<String>,
    /// Marks a file meant to be included: it has no output, and can be checked on its own.
    #[serde(default)]
    pub fragment: bool,
    /// Resources a fragment uses that the including graph must declare.
    #[serde(default)]
    pub inputs: Vec<String>,
    /// Fragments merged into this graph, in order.
    #[serde(default)]
    pub include: Vec<Include>,
    /// User toggles that are on unless turned off (`--features !bloom`).
    #[serde(default)]
    pub features: Vec<String>,
    /// Parameters with defaults; passes and sizes refer to them as `"$name"`.
    #[serde(default)]
    pub params: BTreeMap<String, ParamValue>,
    /// What values parameters accept beyond their default's type
    /// (`"max_depth": (integer: true, min: 1)`): a `--param` or include-site
    /// value outside it is an error.
    #[serde(default)]
    pub param_ranges: BTreeMap<String, ParamRange>,
    /// Images and buffers.
    #[serde(default)]
    pub resources: Vec<ResourceDecl>,
    /// Passes, in any order; execution order comes from data dependencies.
    #[serde(default)]
    pub passes: Vec<PassDecl>,
    /// The image presented or saved. Fragments leave it out.
    #[serde(default)]
    pub output: Option<String>,
    /// Images besides the output that tools read back, first the linear
    /// image an `.exr` output is written from (`weft render --out F.exr`);
    /// `--readback` replaces the list. An entry may hold only under features:
    /// `(name: "bloom", enabled_if: ["bloom"])`. A graph that includes a whole
    /// graph (not a fragment) reads back its images too.
    #[serde(default)]
    pub readback: Vec<ReadDecl>,
    /// Marks a graph whose output converges over frames (a path tracer): each
    /// frame adds `samples_per_frame` samples per pixel to its history images,
    /// so tools can render to a sample count and the viewer can show it.
    #[serde(default)]
    pub progressive: Option<Progressive>,
    /// Per-pixel counts or measures that tools summarise (`weft render
    /// --json` prints a `views` object: mean, median, p95, max, histogram,
    /// share above a threshold). Fragments may declare them; each is read
    /// back when its features hold.
    #[serde(default)]
    pub views: Vec<ViewDecl>,
    /// Where the graph's picture differs from the path-traced reference by
    /// design, not by error (bloom the reference does not model, filtered
    /// shadow maps, lights that cast no shadows): `weft compare` lists those
    /// whose features hold beside each configuration's error, so technique
    /// error can be told from modelling gaps. Fragments may declare them.
    #[serde(default)]
    pub caveats: Vec<CaveatDecl>,
}

/// One known difference from the reference (see [`GraphFile::caveats`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaveatDecl {
    /// What differs and why, in a sentence a user reads beside the error.
    pub note: String,
    /// Features that must hold for the caveat to apply (`["bloom"]`,
    /// `["area_lights"]`); empty: always.
    #[serde(default)]
    pub enabled_if: Vec<String>,
}

/// A debug view's summarised image (see [`GraphFile::views`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewDecl {
    /// The key in the `views` summary (the feature that turns the view on, by convention).
    pub name: String,
    /// A single-channel image (`R32_UINT` counts or `R32_SFLOAT` measures).
    pub image: String,
    /// `share_above` is the share of covered pixels whose value exceeds this.
    pub threshold: f64,
    /// Features that must hold for the view to be summarised.
    #[serde(default)]
    pub enabled_if: Vec<String>,
}

/// How a progressive graph accumulates (see [`GraphFile::progressive`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Progressive {
    /// Samples per pixel each frame adds: a whole number or a `"$param"`.
    pub samples_per_frame: Dim,
}

/// An included fragment and the parameter values it is given.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Include {
    /// Path relative to the including file.
    pub file: String,
    /// Overrides for the fragment's declared parameters.
    #[serde(default)]
    pub params: BTreeMap<String, ParamValue>,
}

/// The values a numeric parameter accepts; every bound is optional.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamRange {
    /// The smallest value (inclusive).
    #[serde(default)]
    pub min: Option<f64>,
    /// The largest value (inclusive).
    #[serde(default)]
    pub max: Option<f64>,
    /// Whether the value must be a whole number.
    #[serde(default)]
    pub integer: bool,
    /// The only values accepted (a mode switch), when not empty.
    #[serde(default)]
    pub one_of: Vec<f64>,
}

impl ParamRange {
    /// Why `value` is outside the range, when it is.
    pub fn refuses(&self, value: f64) -> Option<String> {
        let list = |values: &[f64]| {
            values
                .iter()
                .map(|v| format!("{v}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        if !self.one_of.is_empty() && !self.one_of.contains(&value) {
            return Some(format!("must be one of {}", list(&self.one_of)));
        }
        if self.integer && value.fract() != 0.0 {
            return Some("must be a whole number".into());
        }
        if let Some(min) = self.min.filter(|&min| value < min) {
            return Some(format!("must be at least {min}"));
        }
        if let Some(max) = self.max.filter(|&max| value > max) {
            return Some(format!("must be at most {max}"));
        }
        None
    }
}

/// A parameter value: a number, a vector, a boolean, or a reference `"$name"`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum ParamValue {
    Bool(bool),
    Number(f64),
    Vector(Vec<f64>),
    Reference(String),
}

/// A dimension that is either a number or a `"$param"` reference.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Dim {
    Number(f64),
    Reference(String),
}

/// A declared resource.
#[derive(Debug, Clone, Deserialize)]
pub enum ResourceDecl {
    /// A 2D image (optionally layered, mipmapped, multisampled).
    Image(ImageDecl),
    /// A buffer.
    Buffer(BufferDecl),
}

/// An image declaration.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImageDecl {
    pub name: String,
    /// Vulkan format name, e.g. `R16G16B16A16_SFLOAT`.
    pub format: FormatName,
    #[serde(default)]
    pub size: SizeDecl,
    #[serde(default = "one_dim")]
    pub mips: Dim,
    #[serde(default = "one_dim")]
    pub layers: Dim,
    #[serde(default = "one_dim")]
    pub samples: Dim,
    /// Persists from the previous frame: reads before this frame's writer see last frame's contents.
    #[serde(default)]
    pub history: bool,
    /// Kept across frames in memory of its own, but written and read in the
    /// usual order within a frame: a pass that loads it sees what the
    /// previous frame left (shadow-map tiles that did not change).
    #[serde(default)]
    pub persistent: bool,
}

fn one_dim() -> Dim {
    Dim::Number(1.0)
}

/// How big an image is.
#[derive(Debug, Clone, Default, Deserialize)]
pub enum SizeDecl {
    /// The output size.
    #[default]
    Output,
    /// The output size times a factor per axis.
    Scale(Dim, Dim),
    /// A fixed size in pixels.
    Absolute(Dim, Dim),
    /// Another image's size times a factor per axis.
    Like(String, Dim, Dim),
}

/// A buffer declaration.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BufferDecl {
    pub name: String,
    /// Bytes: a number, or an expression over `width`, `height`, `pixels`, `lights` and parameters,
    /// e.g. `"lights * 32 + 16"`.
    pub size: Expr,
    #[serde(default)]
    pub history: bool,
}

/// A byte count or an arithmetic expression in a string.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum Expr {
    Number(f64),
    Text(String),
}

/// A format name given as a bare identifier (`D32_SFLOAT`) or a string, checked by validation
/// so that every misspelling is reported with a hint, not just the first.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FormatName(pub String);

impl<'de> Deserialize<'de> for FormatName {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct FormatVisitor;
        impl<'de> Visitor<'de> for FormatVisitor {
            type Value = FormatName;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a Vulkan format name such as R16G16B16A16_SFLOAT")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<FormatName, E> {
                Ok(FormatName(v.to_string()))
            }
            fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<FormatName, A::Error> {
                let (name, variant): (Identifier, _) = data.variant()?;
                variant.unit_variant()?;
                Ok(FormatName(name.0))
            }
        }
        deserializer.deserialize_enum("Format", &[], FormatVisitor)
    }
}

/// A bare identifier, read through `deserialize_identifier` as RON requires for enum variants.
struct Identifier(String);

impl<'de> Deserialize<'de> for Identifier {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct IdentifierVisitor;
        impl Visitor<'_> for IdentifierVisitor {
            type Value = Identifier;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an identifier")
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Identifier, E> {
                Ok(Identifier(v.to_string()))
            }
        }
        deserializer.deserialize_identifier(IdentifierVisitor)
    }
}

/// What a pass is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum PassKind {
    /// Draws geometry into colour/depth attachments.
    Raster,
    /// Draws one fullscreen triangle.
    Fullscreen,
    /// Dispatches a compute shader.
    Compute,
    /// Copies one image or buffer to another of the same size.
    Copy,
    /// Blits (scaled, filtered copy) one image to another.
    Blit,
}

/// A pass declaration.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename = "Pass")]
pub struct PassDecl {
    pub name: String,
    pub kind: PassKind,
    /// Shader files relative to the graph file.
    #[serde(default)]
    pub shaders: Shaders,
    #[serde(default)]
    pub color: Vec<AttachmentDecl>,
    #[serde(default)]
    pub depth: Option<AttachmentDecl>,
    /// Images and buffers read through samplers or uniform buffers.
    #[serde(default)]
    pub sampled: Vec<ReadDecl>,
    /// Storage images/buffers read.
    #[serde(default)]
    pub storage_read: Vec<ReadDecl>,
    /// Storage images/buffers written (read-modify-write when also in `storage_read`).
    #[serde(default)]
    pub storage_write: Vec<ReadDecl>,
    /// Source of a copy or blit.
    #[serde(default)]
    pub src: Option<String>,
    /// Destination of a copy or blit.
    #[serde(default)]
    pub dst: Option<String>,
    /// What a raster pass draws.
    #[serde(default)]
    pub draw: Option<Draw>,
    /// How a compute pass is dispatched.
    #[serde(default)]
    pub dispatch: Option<Dispatch>,
    /// Values handed to the shaders.
    #[serde(default)]
    pub params: BTreeMap<String, ParamValue>,
    /// Features that must all hold (`"name"`) or not hold (`"!name"`) for the pass to run.
    #[serde(default)]
    pub enabled_if: Vec<String>,
    /// Passes this one must run after, beyond what its data implies.
    #[serde(default)]
    pub after: Vec<String>,
    /// Fixed-function state a raster pass bakes into its pipeline.
    #[serde(default)]
    pub raster: Option<RasterDecl>,
    /// Values the engine derives for this pass, each from a provider the
    /// renderer registers: `derive: [Gaussian(sigma: "$sigma", radius: 21)]`.
    #[serde(default)]
    pub derive: Vec<ProviderDecl>,
    /// Preprocessor defines for the pass's shaders, each under the features
    /// it needs: `defines: [(name: "SCENE_MIRRORS", enabled_if: ["mirrors"])]`
    /// compiles mirror code only for scenes with mirrors.
    #[serde(default)]
    pub defines: Vec<DefineDecl>,
}

/// A shader define a pass sets when its features hold.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DefineDecl {
    /// A preprocessor name: capitals, digits and underscores, not `HAS_...`
    /// (conditional reads define those).
    pub name: String,
    /// Features that must all hold (`"name"`) or not hold (`"!name"`).
    #[serde(default)]
    pub enabled_if: Vec<String>,
    /// Set only for the pass's mesh draws whose material uses this shading
    /// model: the pass's draws are grouped by model, one shader variant each.
    #[serde(default)]
    pub draws: Option<ShadingModel>,
}

/// A material's shading model, as mesh draws are grouped by it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Deserialize, Serialize)]
pub enum ShadingModel {
    /// MTL materials: diffuse, specular and shininess (mirrors and coats too).
    BlinnPhong,
    /// glTF materials: base colour, metallic and roughness.
    MetallicRoughness,
}

/// A use of a named value provider: its name and arguments (numbers, vectors,
/// booleans or `"$param"` references). The graph crate knows no provider; the
/// renderer's registry (`weft_graph::provider::ProviderSpec`) says which names
/// and arguments exist, and `check_providers` holds a graph to it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProviderDecl {
    pub name: String,
    pub args: BTreeMap<String, ParamValue>,
}

impl<'de> Deserialize<'de> for ProviderDecl {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct ArgsVisitor;
        impl<'de> Visitor<'de> for ArgsVisitor {
            type Value = BTreeMap<String, ParamValue>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("named arguments such as `(sigma: 9.0, radius: \"$radius\")`")
            }
            fn visit_map<M: de::MapAccess<'de>>(self, mut map: M) -> Result<Self::Value, M::Error> {
                let mut args = BTreeMap::new();
                while let Some((key, value)) = map.next_entry::<Identifier, ParamValue>()? {
                    if args.insert(key.0.clone(), value).is_some() {
                        return Err(de::Error::custom(format!(
                            "argument `{}` is given twice",
                            key.0
                        )));
                    }
                }
                Ok(args)
            }
        }
        struct ProviderVisitor;
        impl<'de> Visitor<'de> for ProviderVisitor {
            type Value = ProviderDecl;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a provider such as `Gaussian(sigma: 9.0, radius: 21)`")
            }
            fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<ProviderDecl, A::Error> {
                let (name, variant): (Identifier, _) = data.variant()?;
                let args = variant.struct_variant(&[], ArgsVisitor)?;
                Ok(ProviderDecl { name: name.0, args })
            }
        }
        deserializer.deserialize_enum("Provider", &[], ProviderVisitor)
    }
}

/// Fixed-function state of a raster pass: how depth is compared and biased,
/// which faces are culled. Blending is declared per colour attachment, depth
/// writes by the depth attachment's `read_only`.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RasterDecl {
    /// How a fragment's depth is compared with the attachment's; without it
    /// `GreaterOrEqual`, the reverse-Z test of camera passes.
    #[serde(default)]
    pub depth_compare: Option<CompareOp>,
    /// Constant and slope-scaled depth bias (numbers or `"$param"`s), in units
    /// of the depth format's resolution and of the primitive's depth slope.
    #[serde(default)]
    pub depth_bias: Option<(Dim, Dim)>,
    /// Which faces are culled; without it `None`.
    #[serde(default)]
    pub cull: Option<CullMode>,
    /// Clamp fragment depth to the depth range instead of clipping triangles
    /// at the near and far planes (`depthClampEnable`): a light volume that
    /// reaches past the far plane still covers every surface it lights, and
    /// its depth stays exact up to the clamp. Without it `false`.
    #[serde(default)]
    pub depth_clamp: Option<bool>,
}

/// A depth comparison (`VkCompareOp`): the fragment passes when
/// `fragment OP stored` holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum CompareOp {
    Never,
    Less,
    Equal,
    LessOrEqual,
    Greater,
    NotEqual,
    GreaterOrEqual,
    Always,
}

/// Which triangle faces are culled (`VkCullModeFlags`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum CullMode {
    #[default]
    None,
    Front,
    Back,
}

/// A raster pass's fixed-function state with parameters resolved.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct RasterState {
    /// The declared depth comparison, if any.
    pub depth_compare: Option<CompareOp>,
    /// Constant and slope-scaled depth bias.
    pub depth_bias: Option<(f64, f64)>,
    /// Culled faces.
    pub cull: CullMode,
    /// Whether fragment depth is clamped instead of triangles clipped at near and far.
    pub depth_clamp: bool,
}

/// Shader stages of a pass.
#[derive(Debug, Clone, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(deny_unknown_fields)]
pub struct Shaders {
    #[serde(default)]
    pub vertex: Option<String>,
    #[serde(default)]
    pub fragment: Option<String>,
    #[serde(default)]
    pub compute: Option<String>,
}

/// A colour or depth attachment.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AttachmentDecl {
    pub image: String,
    #[serde(default)]
    pub load: LoadDecl,
    #[serde(default)]
    pub store: StoreDecl,
    /// Colour blending.
    #[serde(default)]
    pub blend: Option<Blend>,
    /// Depth attachment used for testing only (no depth writes), so it can be sampled too.
    #[serde(default)]
    pub read_only: bool,
    /// Features that must all hold for a colour attachment to be attached
    /// (the shaders then see `HAS_<IMAGE>`); conditional attachments come
    /// after every unconditional one, so fragment output locations stay put.
    #[serde(default)]
    pub enabled_if: Vec<String>,
}

/// What happens to an attachment's contents when a pass begins.
#[derive(Debug, Clone, Default, PartialEq, Deserialize, Serialize)]
pub enum LoadDecl {
    /// Keep what earlier passes wrote.
    Load,
    /// Clear to a value: one number for depth, four for colour.
    Clear(Vec<f64>),
    /// Contents are undefined; the pass overwrites every pixel.
    #[default]
    DontCare,
}

/// Whether an attachment's contents are kept after the pass. The compiler
/// downgrades `Store` to `DONT_CARE` where nothing reads the result later.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, Serialize)]
pub enum StoreDecl {
    #[default]
    Store,
    DontCare,
}

/// Colour blend modes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Deserialize, Serialize)]
pub enum Blend {
    /// dst + src (light accumulation).
    Additive,
    /// Source-over with source alpha.
    Alpha,
}

/// A sampled or storage read, optionally only under some features.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
pub enum ReadDecl {
    Name(String),
    Conditional(ConditionalRead),
}

/// A read that only happens when its features hold; the shader sees `HAS_<NAME>`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConditionalRead {
    pub name: String,
    pub enabled_if: Vec<String>,
}

impl ReadDecl {
    /// The resource read.
    pub fn name(&self) -> &str {
        match self {
            ReadDecl::Name(n) => n,
            ReadDecl::Conditional(c) => &c.name,
        }
    }

    /// The features this read depends on.
    pub fn conditions(&self) -> &[String] {
        match self {
            ReadDecl::Name(_) => &[],
            ReadDecl::Conditional(c) => &c.enabled_if,
        }
    }
}

/// What a raster pass draws.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub enum Draw {
    /// Scene meshes whose material matches the filter.
    Meshes(MaterialFilter),
    /// One proxy volume per light of a kind.
    LightVolumes(LightKind),
    /// One triangle covering the target.
    FullscreenTriangle,
}

/// Which scene meshes a raster pass draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
pub enum MaterialFilter {
    All,
    Opaque,
    Transparent,
    Emissive,
    ShadowCasters,
}

/// Light kinds that get proxy volumes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
pub enum LightKind {
    Point,
    Spot,
    /// Area lights' own outlines (their panels: a rectangle or a disc), so a
    /// pass can draw what camera rays see of them.
    Area,
}

/// How a compute pass is dispatched.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub enum Dispatch {
    /// One invocation per output pixel, in groups of the given size.
    Output(u32, u32),
    /// One invocation per pixel of the named image, in groups of the given size.
    Image(String, u32, u32),
    /// A fixed number of work groups.
    Groups(u32, u32, u32),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_provider_is_a_name_with_named_arguments() {
        let decl: Vec<ProviderDecl> = ron::from_str(
            r#"[Gaussian(sigma: 9.0, radius: "$radius", linear_taps: false), ShadowAtlas()]"#,
        )
        .expect("parses");
        assert_eq!(decl[0].name, "Gaussian");
        assert_eq!(decl[0].args["sigma"], ParamValue::Number(9.0));
        assert_eq!(
            decl[0].args["radius"],
            ParamValue::Reference("$radius".into())
        );
        assert_eq!(decl[0].args["linear_taps"], ParamValue::Bool(false));
        assert_eq!(decl[1].name, "ShadowAtlas");
        assert!(decl[1].args.is_empty());
        let twice = ron::from_str::<ProviderDecl>("Gaussian(sigma: 1.0, sigma: 2.0)");
        assert!(twice
            .expect_err("duplicate")
            .to_string()
            .contains("`sigma` is given twice"));
    }
}
