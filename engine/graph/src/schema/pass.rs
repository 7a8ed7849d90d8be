//! What a pass declares: its kind, shaders, attachments, reads and writes,
//! what it draws or how it dispatches, fixed-function state, defines and the
//! values providers derive for it.

use super::*;

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
    /// Builds or refits the scene's acceleration structures (the one it
    /// names in `storage_write`) for passes that trace with ray queries.
    BuildAccelerationStructures,
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
    /// How many times in a row a compute pass is dispatched each frame (a
    /// number or `"$param"`), each dispatch seeing the previous one's storage
    /// writes and its index in the `repeat_index` push constant. Splitting
    /// long work (a progressive pass's samples) into dispatches bounds what
    /// one shader invocation runs: lavapipe silently ends every loop of an
    /// invocation after 65,535 iterations in all.
    #[serde(default)]
    pub repeat: Option<Dim>,
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
    /// The graph's define sets whose defines the pass's shaders get, in
    /// order, before its own `defines`.
    #[serde(default)]
    pub define_sets: Vec<String>,
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
    /// model (a name from the renderer's [`crate::vocabulary::SceneVocabulary`]):
    /// the pass's draws are grouped by model, one shader variant each.
    #[serde(default)]
    pub draws: Option<SceneTerm>,
    /// A whole-number value, given or a graph parameter's (`"$light_choice"`):
    /// `NAME=VALUE`, so code a parameter switches off is not compiled (on
    /// lavapipe, which runs both sides of every branch, it would still run).
    /// Resolved to the number when the graph is resolved.
    #[serde(default)]
    pub value: Option<ParamValue>,
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
    /// For a multisampled colour attachment: the single-sample image of its
    /// size and format its samples are averaged into at the end of the pass
    /// (a render pass's resolve attachment), for later passes to sample.
    #[serde(default)]
    pub resolve: Option<String>,
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

/// What a raster pass draws. The names inside are the scene vocabulary's:
/// the graph crate knows none of them, the renderer registers them
/// ([`crate::vocabulary::SceneVocabulary`]) and `check_vocabulary` holds a
/// graph to it.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
pub enum Draw {
    /// Scene meshes whose material matches the named filter (`Meshes(Opaque)`).
    Meshes(SceneTerm),
    /// One proxy volume per light of the named kind (`LightVolumes(Point)`).
    LightVolumes(SceneTerm),
    /// One triangle covering the target.
    FullscreenTriangle,
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
    /// Work-group counts the GPU reads from the named buffer when the
    /// dispatch runs (`vkCmdDispatchIndirect`): three u32 at byte
    /// `repeat_index × stride`, so each dispatch of a repeating pass reads its
    /// own record, one that earlier passes or dispatches wrote (a queue's
    /// length that only the GPU knows).
    Indirect(String, u32),
}
