//! The RON schema users write, as serde types. These mirror the file one to one;
//! resolution (includes, parameters, names) happens in `load` and `validate`.

use serde::de::{self, Deserializer, EnumAccess, VariantAccess, Visitor};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

mod pass;

pub use pass::*;

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
    /// Numbers the renderer measures from each scene, by name
    /// (`scene_values: ["structure_scratch_bytes"]`), for buffer size
    /// expressions: declared so a misspelt variable is an error, and checked
    /// against the renderer's scene vocabulary. A compile without a scene
    /// (`weft graph check`, `weft graph plan`) takes each as 0. Fragments may
    /// declare them.
    #[serde(default)]
    pub scene_values: Vec<String>,
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
    /// Named lists of shader defines, declared once and used by passes
    /// (`define_sets: ["scene_models"]`); fragments may declare them. A
    /// define's `draws` applies where the pass draws meshes.
    #[serde(default)]
    pub define_sets: BTreeMap<String, Vec<DefineDecl>>,
    /// Moves the camera's projection by a different sub-pixel offset each
    /// frame (Halton 2, 3) while its features hold, for passes that
    /// accumulate pixels over frames (`graphs/taa.ron`): `view_proj` in the
    /// Frame uniform is jittered, the unjittered one kept for motion.
    /// Fragments may declare it; it holds when any declaration's features do.
    #[serde(default)]
    pub jitter: Vec<JitterDecl>,
}

/// When the camera is jittered (see [`GraphFile::jitter`]).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JitterDecl {
    /// Features that must hold (`["taa"]`); empty: always.
    #[serde(default)]
    pub enabled_if: Vec<String>,
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
    /// The scene's acceleration structures for ray queries (a bottom level
    /// per mesh, a top level placing them): the scene owns their memory, a
    /// `BuildAccelerationStructures` pass writes them each frame, and passes
    /// that trace list them in `storage_read`, so the compiler orders the
    /// build before the traces and synchronizes both ways.
    AccelerationStructure(AccelerationStructureDecl),
}

/// An acceleration-structure declaration (see
/// [`ResourceDecl::AccelerationStructure`]): a name, nothing to size.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AccelerationStructureDecl {
    pub name: String,
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
    /// Bytes: a number, or an expression over `width`, `height`, `pixels`,
    /// the graph's scene values and parameters, e.g. `"pixels * 16 + 16"`.
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

/// A name from the scene vocabulary (a mesh filter, a light kind, a shading
/// model), given as a bare identifier (`Opaque`): the renderer
/// registers which exist, so a misspelling is a located error with a hint
/// (`check_vocabulary`), not a parse failure that stops at the first.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(transparent)]
pub struct SceneTerm(pub String);

impl<'de> Deserialize<'de> for SceneTerm {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct TermVisitor;
        impl<'de> Visitor<'de> for TermVisitor {
            type Value = SceneTerm;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a name such as Opaque, Point or MetallicRoughness")
            }
            fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<SceneTerm, A::Error> {
                let (name, variant): (Identifier, _) = data.variant()?;
                variant.unit_variant()?;
                Ok(SceneTerm(name.0))
            }
        }
        deserializer.deserialize_enum("SceneTerm", &[], TermVisitor)
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
