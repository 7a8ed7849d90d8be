//! The compiled plan: plain, serialisable data that says exactly what the GPU
//! executor creates, in what order passes run, and every barrier and layout
//! transition between them. Nothing here needs Vulkan.

use crate::diagnostic::Diagnostic;
use crate::id::{IdVec, PassId, ResourceId};
use crate::schema::{Blend, Draw, ParamValue, PassKind, ProviderDecl, RasterState};
use crate::vk::{Access, Aspect, BufferUsage, ImageUsage, Layout, Stage};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Width and height in pixels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Extent {
    pub width: u32,
    pub height: u32,
}

/// The largest image side weft creates: `maxImageDimension2D` on the devices
/// it targets, and the limit of `Absolute` sizes.
pub const MAX_IMAGE_DIMENSION: u32 = 16_384;

impl std::str::FromStr for Extent {
    type Err = String;

    /// Parses `WIDTHxHEIGHT` (`1280x720`), each side 1..=[`MAX_IMAGE_DIMENSION`],
    /// as command lines take sizes.
    fn from_str(text: &str) -> Result<Self, String> {
        let (w, h) = text
            .split_once(['x', 'X'])
            .ok_or_else(|| format!("expected WIDTHxHEIGHT such as 1280x720, found \"{text}\""))?;
        let max = MAX_IMAGE_DIMENSION;
        let side = |v: &str| match v.trim().parse::<u32>() {
            Ok(n) if (1..=max).contains(&n) => Ok(n),
            _ => Err(format!(
                "each side of a size must be 1..={max}, found \"{v}\""
            )),
        };
        Ok(Extent {
            width: side(w)?,
            height: side(h)?,
        })
    }
}

/// A summarised view in a plan (see [`crate::schema::GraphFile::views`]).
#[derive(Debug, Clone, Serialize)]
pub struct PlanView {
    /// The summary's key.
    pub name: String,
    /// The image summarised; also in [`Plan::readback`].
    pub image: ResourceId,
    /// `share_above` counts pixels above this value.
    pub threshold: f64,
}

/// A compiled graph, ready to execute for one output size and feature set.
#[derive(Debug, Clone, Serialize)]
pub struct Plan {
    pub name: String,
    /// The root graph file.
    pub file: PathBuf,
    /// Every file the graph was built from (root first), for hot reload.
    pub files: Vec<PathBuf>,
    pub extent: Extent,
    /// Features that were on while compiling.
    pub features: Vec<String>,
    /// The scene values the graph declares, as its buffers were sized: what
    /// the renderer measured, or 0 where the compile had no scene.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub scene_values: BTreeMap<String, f64>,
    pub resources: IdVec<ResourceId, PlanResource>,
    /// Passes in execution order.
    pub passes: IdVec<PassId, PlanPass>,
    /// Passes left out, and why.
    pub culled: Vec<CulledPass>,
    /// The output image.
    pub output: ResourceId,
    /// Further images left readable after the frame (`CompileOptions::readback`).
    pub readback: Vec<ResourceId>,
    /// For a progressive graph (`progressive` in the file), the samples per
    /// pixel each frame adds to its history.
    pub samples_per_frame: Option<u32>,
    /// The views whose features hold: images read back and summarised per pixel.
    pub views: Vec<PlanView>,
    /// The graph's known differences from the reference whose features hold
    /// (`caveats` in the file), for `weft compare`.
    pub caveats: Vec<String>,
    /// Whether the camera's projection moves by a sub-pixel offset each
    /// frame (`jitter` in the file, its features holding).
    pub camera_jitter: bool,
    /// Where transient images and buffers live.
    pub memory: MemoryPlan,
    /// Barriers after the last pass: the output to `TRANSFER_SRC_OPTIMAL` for presenting or
    /// saving, history resources back to the state the next frame starts from.
    pub epilogue: Vec<Barrier>,
    pub warnings: Vec<Diagnostic>,
}

/// A resource the executor creates.
#[derive(Debug, Clone, Serialize)]
pub struct PlanResource {
    pub name: String,
    pub desc: ResourceDesc,
    pub residency: Residency,
    /// First and last pass that use it.
    pub lifetime: (PassId, PassId),
    /// Where a transient image or buffer lives inside the shared memory blocks.
    pub placement: Option<Placement>,
    /// For persistent resources: the layout it must be in when a frame starts
    /// (the executor puts it there when it creates it).
    pub frame_start_layout: Layout,
}

/// Image or buffer creation parameters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum ResourceDesc {
    Image(ImageDesc),
    Buffer(BufferDesc),
    /// The scene's acceleration structures: the scene creates and owns them,
    /// so the executor creates nothing and synchronizes them with memory
    /// barriers.
    AccelerationStructure,
}

/// Image creation parameters.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
pub struct ImageDesc {
    /// Vulkan format name.
    pub format: String,
    /// `VkFormat` value.
    pub format_raw: i32,
    pub aspect: Aspect,
    pub extent: Extent,
    pub mips: u32,
    pub layers: u32,
    pub samples: u32,
    pub usage: ImageUsage,
    /// Bytes per texel, for memory estimates.
    pub texel_bytes: u32,
}

/// Buffer creation parameters.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct BufferDesc {
    pub size: u64,
    pub usage: BufferUsage,
}

/// How long a resource lives.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Residency {
    /// Only within a frame; images and buffers may share memory with others.
    Transient,
    /// Persists from one frame to the next.
    History,
    /// The image presented or saved.
    Output,
}

/// A transient image's or buffer's place in memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Placement {
    pub block: usize,
    pub offset: u64,
    pub size: u64,
}

/// Memory blocks shared by transient images and buffers, and what aliasing saved.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct MemoryPlan {
    pub blocks: Vec<MemoryBlock>,
    /// Bytes of all blocks.
    pub transient_bytes: u64,
    /// Bytes if every transient image and buffer had its own memory.
    pub transient_bytes_unaliased: u64,
}

/// One block of device memory that transient images and buffers are bound into.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct MemoryBlock {
    pub size: u64,
    pub alignment: u64,
}

/// Where something was declared, so errors found later (shader checks, hot reload)
/// can name the file, line and column.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize)]
pub struct Location {
    pub file: PathBuf,
    pub pos: crate::spans::Pos,
}

/// A pass that will run.
#[derive(Debug, Clone, Serialize)]
pub struct PlanPass {
    pub name: String,
    /// The pass's `name` in its graph file.
    pub declared_at: Location,
    pub kind: PassKind,
    /// Shader files, resolved relative to the graph file that declared the pass.
    pub shaders: ShaderFiles,
    pub draw: Option<Draw>,
    /// Work groups for compute passes dispatched with counts known now.
    pub dispatch: Option<[u32; 3]>,
    /// Where a compute pass dispatched indirectly reads its group counts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub indirect: Option<IndirectDispatch>,
    /// Dispatches in a row each frame (1 unless the pass declares `repeat`).
    #[serde(skip_serializing_if = "once")]
    pub repeat: u32,
    /// Barriers recorded between a repeating pass's dispatches.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub repeat_barriers: Vec<Barrier>,
    /// Parameter values for the shaders, with `$references` resolved.
    pub params: BTreeMap<String, ParamValue>,
    /// Preprocessor defines selecting the shader variant (`HAS_SHADOW_MAP`, ...).
    pub defines: Vec<String>,
    /// Defines set only for the mesh draws of one shading model (declared with
    /// `draws:`, the model named as the scene vocabulary names it); when
    /// there are any, the pass draws its meshes grouped by model, each group
    /// with `defines` plus its own.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub model_defines: Vec<(String, String)>,
    /// How many define sets the pass's features can give its shaders (the
    /// variant this plan compiles is one of them), at most
    /// 2^[`crate::resolve::MAX_VARIANT_BITS`].
    pub variants: u64,
    /// Barriers recorded before the pass, batched into one `vkCmdPipelineBarrier2`.
    pub barriers: Vec<Barrier>,
    /// The render pass for raster and fullscreen passes.
    pub render_pass: Option<RenderPassDesc>,
    /// Sampled and storage bindings in declaration order.
    pub bindings: Vec<Binding>,
    /// Source and destination of copy and blit passes.
    pub transfer: Option<(ResourceId, ResourceId)>,
    /// Declared fixed-function state of a raster pass.
    pub raster: RasterState,
    /// Values the renderer's providers derive for this pass, with arguments
    /// resolved (checked against the registry by `check_providers`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub derive: Vec<ProviderDecl>,
    /// The acceleration structure the pass builds (a
    /// `BuildAccelerationStructures` pass) or its ray queries read (a
    /// `storage_read` of an `AccelerationStructure`), if any: it has no
    /// binding of its own, and the renderer lets a pass trace in hardware
    /// only against a structure the plan builds and orders it after.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub structure: Option<ResourceId>,
    /// The buffer a `BuildAccelerationStructures` pass builds in (its
    /// scratch, the one buffer in its `storage_write`), transient memory the
    /// aliasing step shares with what other passes use at other times.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub scratch: Option<ResourceId>,
}

/// An indirect dispatch's source: the `k`-th dispatch of the pass reads the
/// three u32 group counts at byte `k × stride` of `buffer`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct IndirectDispatch {
    pub buffer: ResourceId,
    pub stride: u32,
}

/// Whether a pass runs once per frame (serialized plans leave `repeat: 1` out).
fn once(repeat: &u32) -> bool {
    *repeat == 1
}

impl PlanPass {
    /// Whether the pass draws its meshes grouped by shading model.
    pub fn groups_by_model(&self) -> bool {
        !self.model_defines.is_empty()
    }

    /// The defines of the variant that draws meshes of `model` (sorted): the
    /// pass's defines plus those declared for that model.
    pub fn defines_for(&self, model: &str) -> Vec<String> {
        let mut defines = self.defines.clone();
        defines.extend(
            self.model_defines
                .iter()
                .filter(|(m, _)| m == model)
                .map(|(_, d)| d.clone()),
        );
        defines.sort();
        defines.dedup();
        defines
    }
}

/// Shader file paths.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct ShaderFiles {
    pub vertex: Option<PathBuf>,
    pub fragment: Option<PathBuf>,
    pub compute: Option<PathBuf>,
}

/// A resource bound to a pass's shaders.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Binding {
    pub resource: ResourceId,
    pub kind: BindingKind,
}

/// How a bound resource is accessed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum BindingKind {
    /// A combined image sampler, or a uniform buffer.
    Sampled,
    StorageRead,
    StorageWrite,
    StorageReadWrite,
}

/// A pass left out of the plan.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CulledPass {
    pub name: String,
    pub reason: String,
}

/// A synchronization2 barrier.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Barrier {
    pub resource: ResourceId,
    pub src_stage: Stage,
    pub src_access: Access,
    pub dst_stage: Stage,
    pub dst_access: Access,
    /// Image layouts; `None` for buffers.
    pub layouts: Option<(Layout, Layout)>,
}

/// A render pass built from the graph: attachments with their load/store ops and layouts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RenderPassDesc {
    pub extent: Extent,
    pub attachments: Vec<AttachmentDesc>,
    /// Indices into `attachments`.
    pub color: Vec<usize>,
    /// Per colour attachment, the index of the attachment it resolves into
    /// at the end of the pass (`resolve:` in the file), if any.
    pub resolve: Vec<Option<usize>>,
    pub depth: Option<usize>,
}

/// `VkAttachmentLoadOp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum LoadOp {
    Load,
    Clear,
    DontCare,
}

/// `VkAttachmentStoreOp`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum StoreOp {
    Store,
    DontCare,
    /// Nothing is written back (read-only attachments).
    None,
}

/// One attachment of a render pass.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AttachmentDesc {
    pub resource: ResourceId,
    pub format_raw: i32,
    pub samples: u32,
    pub load: LoadOp,
    pub store: StoreOp,
    /// One value for depth, four for colour.
    pub clear: Vec<f64>,
    pub initial_layout: Layout,
    /// The layout during the subpass.
    pub layout: Layout,
    pub final_layout: Layout,
    pub blend: Option<Blend>,
    pub read_only: bool,
}

/// Counts that summarise a plan, printed by `weft graph plan --json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanStats {
    pub passes: usize,
    pub culled: usize,
    pub barriers: usize,
    pub transient_bytes: u64,
    pub transient_bytes_unaliased: u64,
    pub compile_us: f64,
}

impl Plan {
    /// The summary counts; `compile_us` is measured by the caller.
    pub fn stats(&self, compile_us: f64) -> PlanStats {
        PlanStats {
            passes: self.passes.len(),
            culled: self.culled.len(),
            barriers: self.passes.iter().map(|p| p.barriers.len()).sum::<usize>()
                + self.epilogue.len(),
            transient_bytes: self.memory.transient_bytes,
            transient_bytes_unaliased: self.memory.transient_bytes_unaliased,
            compile_us,
        }
    }

    /// Looks up a resource by name.
    pub fn resource(&self, name: &str) -> Option<ResourceId> {
        self.resources.position(|r| r.name == name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_as_command_lines_write_them() {
        assert_eq!(
            "1280x720".parse::<Extent>(),
            Ok(Extent {
                width: 1280,
                height: 720
            })
        );
        assert_eq!(
            "wide".parse::<Extent>(),
            Err("expected WIDTHxHEIGHT such as 1280x720, found \"wide\"".to_string())
        );
        assert_eq!(
            "0x10".parse::<Extent>(),
            Err("each side of a size must be 1..=16384, found \"0\"".to_string())
        );
        assert!("16385X2".parse::<Extent>().is_err());
    }
}
