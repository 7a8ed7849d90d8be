//! The resolved graph: names replaced by indices, parameters by numbers.

use crate::id::{IdVec, IrPassId, IrResourceId};
use crate::plan::ShaderFiles;
use crate::schema::{
    Blend, Draw, LoadDecl, ParamValue, PassKind, ProviderDecl, RasterState, StoreDecl,
};
use crate::vk::FormatInfo;
use std::collections::BTreeMap;

/// A graph with names resolved to indices.
#[derive(Debug, Clone)]
pub struct Ir {
    pub resources: IdVec<IrResourceId, IrResource>,
    pub passes: IdVec<IrPassId, IrPass>,
    pub output: Option<IrResourceId>,
    /// Samples per pixel each frame adds, for a progressive graph.
    pub samples_per_frame: Option<u32>,
    /// Summarised views ([`crate::schema::GraphFile::views`]).
    pub views: Vec<IrView>,
}

/// A resolved summarised view.
#[derive(Debug, Clone)]
pub struct IrView {
    pub name: String,
    pub image: IrResourceId,
    pub threshold: f64,
    pub enabled_if: Vec<String>,
}

/// A resolved resource.
#[derive(Debug, Clone)]
pub struct IrResource {
    pub name: String,
    pub source: usize,
    pub index: usize,
    pub kind: IrKind,
    pub history: bool,
    /// Kept across frames, written before it is read ([`crate::schema::ImageDecl::persistent`]).
    pub persistent: bool,
}

impl IrResource {
    /// Whether the contents outlive the frame (history or persistent).
    pub fn kept_across_frames(&self) -> bool {
        self.history || self.persistent
    }
}

/// Image or buffer specifics.
#[derive(Debug, Clone)]
pub enum IrKind {
    Image {
        format: &'static FormatInfo,
        size: SizeSpec,
        mips: u32,
        layers: u32,
        samples: u32,
    },
    Buffer {
        size: BufferSize,
    },
    /// The scene's acceleration structures: no memory of the graph's own.
    AccelerationStructure,
    /// A fragment's input when the fragment is checked on its own, or an image
    /// whose format is unknown: names resolve, but nothing more is checked.
    External,
}

/// An image size with parameters resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SizeSpec {
    Output,
    Scale(f64, f64),
    Absolute(u32, u32),
    Like(IrResourceId, f64, f64),
}

/// A buffer size: fixed, or an expression evaluated per compile.
#[derive(Debug, Clone, PartialEq)]
pub enum BufferSize {
    Bytes(u64),
    Expression(String),
}

/// A resolved pass.
#[derive(Debug, Clone)]
pub struct IrPass {
    pub name: String,
    pub source: usize,
    pub index: usize,
    pub kind: PassKind,
    pub shaders: ShaderFiles,
    pub draw: Option<Draw>,
    pub dispatch: Option<IrDispatch>,
    /// Dispatches per frame of a compute pass (1 unless it declares `repeat`).
    pub repeat: u32,
    pub params: BTreeMap<String, ParamValue>,
    pub accesses: Vec<IrAccess>,
    pub after: Vec<IrPassId>,
    pub enabled_if: Vec<String>,
    /// Fixed-function state of a raster pass.
    pub raster: RasterState,
    /// Provider uses with their arguments resolved.
    pub derive: Vec<ProviderDecl>,
    /// Shader defines with the features each needs.
    pub defines: Vec<crate::schema::DefineDecl>,
}

/// How many compute work groups, resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum IrDispatch {
    Output(u32, u32),
    Image(IrResourceId, u32, u32),
    Groups(u32, u32, u32),
    /// A buffer and the bytes between the records of successive dispatches.
    Indirect(IrResourceId, u32),
}

impl IrPass {
    /// How many features decide the pass's shader defines (its conditional
    /// reads' `HAS_<NAME>` and its declared defines' `enabled_if`): its
    /// shaders come in at most 2^this variants, one per combination.
    pub fn variant_bits(&self) -> u32 {
        let mut features: Vec<&str> = self
            .accesses
            .iter()
            .flat_map(|a| a.conditions.iter())
            .chain(self.defines.iter().flat_map(|d| d.enabled_if.iter()))
            .flat_map(|c| crate::condition::names(c))
            .collect();
        features.sort_unstable();
        features.dedup();
        features.len() as u32
    }
}

/// Most shader variants a pass may have: 2^16 = 65,536 define sets. The
/// shipped forward pass and the path tracer's trace pass are decided by 16
/// features (forward: 11 scene features, shadow casters, ray-traced shadows,
/// the overshading view, TAA's motion output and ray queries, whose read of
/// the acceleration structure selects the hardware walk). Variants are
/// compiled on demand, only for the feature sets a scene selects, so the cap
/// bounds the key space of a pass, not the work done.
pub const MAX_VARIANT_BITS: u32 = 16;

/// 2^`bits`, the variants `bits` features can select, saturating past 2^63.
pub fn variant_count(bits: u32) -> u64 {
    1u64.checked_shl(bits).unwrap_or(u64::MAX)
}

/// One use of a resource by a pass.
#[derive(Debug, Clone)]
pub struct IrAccess {
    pub resource: IrResourceId,
    pub usage: Usage,
    /// Features that must hold for this access to happen.
    pub conditions: Vec<String>,
    /// The field and index in the pass declaration, for diagnostics.
    pub field: &'static str,
    pub item: Option<usize>,
}

/// How a pass uses a resource.
#[derive(Debug, Clone, PartialEq)]
pub enum Usage {
    Sampled,
    StorageRead,
    StorageWrite,
    Color {
        load: LoadDecl,
        store: StoreDecl,
        blend: Option<Blend>,
        /// The single-sample image the colour attachment before it
        /// resolves into (`resolve:`), not an attachment shaders write.
        resolve_target: bool,
    },
    Depth {
        load: LoadDecl,
        store: StoreDecl,
        read_only: bool,
    },
    TransferSrc,
    TransferDst,
    /// Work-group counts an indirect dispatch reads.
    IndirectRead,
}

impl Usage {
    /// Whether this is the single-sample image a colour attachment resolves
    /// into (the access just after that attachment's).
    pub fn is_resolve_target(&self) -> bool {
        matches!(
            self,
            Usage::Color {
                resolve_target: true,
                ..
            }
        )
    }

    /// Whether this is a colour attachment shaders write (not a resolve target).
    pub fn is_color_output(&self) -> bool {
        matches!(
            self,
            Usage::Color {
                resolve_target: false,
                ..
            }
        )
    }

    /// Whether the access needs what earlier passes left in the resource.
    pub fn reads_previous(&self) -> bool {
        match self {
            Usage::Sampled | Usage::StorageRead | Usage::TransferSrc | Usage::IndirectRead => true,
            Usage::Color { load, .. } => *load == LoadDecl::Load,
            Usage::Depth {
                load, read_only, ..
            } => *load == LoadDecl::Load || *read_only,
            Usage::StorageWrite | Usage::TransferDst => false,
        }
    }

    /// Whether the access changes the resource.
    pub fn writes(&self) -> bool {
        match self {
            Usage::Sampled | Usage::StorageRead | Usage::TransferSrc | Usage::IndirectRead => false,
            Usage::Depth { read_only, .. } => !read_only,
            Usage::Color { .. } | Usage::StorageWrite | Usage::TransferDst => true,
        }
    }

    /// Whether the access overwrites every texel without reading, so older contents may be discarded.
    pub fn discards(&self) -> bool {
        match self {
            Usage::Color { load, .. } => *load != LoadDecl::Load,
            Usage::Depth {
                load, read_only, ..
            } => *load != LoadDecl::Load && !read_only,
            Usage::TransferDst => true,
            _ => false,
        }
    }
}
