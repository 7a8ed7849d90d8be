//! The scene as hardware acceleration structures, for passes compiled for
//! ray queries ([`crate::providers::trace_backend`]): a bottom level per
//! mesh in its own space (placements of one mesh share it) and a top level
//! placing them with each draw's transform. A placement's instance carries
//! its first triangle in the ray tracer's triangle order
//! ([`SceneGeometry::trace_mesh`]) as its custom index, so a ray query names
//! the same triangle the software walk does. Moved placements refit the top
//! level in place; the bottom levels never change. Builds and refits are
//! recorded by the graph's `BuildAccelerationStructures` pass
//! ([`super::GpuScene::record_structures`]), which the compiler orders and
//! synchronizes with the passes that trace, in the scratch buffer the graph
//! declares: transient memory, sized by [`structure_scratch_bytes`] before
//! the plan is compiled.

use crate::geometry::{MeshRange, SceneGeometry, VERTEX_BYTES};
use std::collections::{HashMap, HashSet};
use std::time::{Duration, Instant};
use weft_gpu::acceleration::{
    self, scratch_for, scratch_needed, BottomLevels, Mesh, Placement, Scratch, ScratchSpan,
    TopLevel,
};
use weft_gpu::buffer::Buffer;
use weft_gpu::{Gpu, GpuError};
use weft_scene::Scene;

/// The scene's acceleration structures on the device.
pub(super) struct SceneStructures<'g> {
    bottom: BottomLevels<'g>,
    pub(super) top: TopLevel<'g>,
    /// Per traced draw, in the ray tracer's order, the bottom level it places.
    levels: Vec<usize>,
    /// Bytes of scratch the builds need ([`scratch_for`]).
    scratch_bytes: u64,
}

impl<'g> SceneStructures<'g> {
    /// Creates the bottom levels over `geometry`'s meshes, read in place
    /// from the scene's vertex and index buffers (made with
    /// [`acceleration::INPUT_USAGE`]), the top level placing them as its
    /// draw records do now; nothing is built until [`Self::record`].
    pub(super) fn new(
        gpu: &'g Gpu,
        geometry: &SceneGeometry,
        (vertices, indices): (&Buffer<'g>, &Buffer<'g>),
    ) -> Result<Self, GpuError> {
        let (meshes, levels) = distinct_meshes(geometry);
        let (vertex_base, index_base) = (vertices.address(), indices.address());
        let inputs: Vec<Mesh> = meshes
            .iter()
            .map(|mesh| {
                let first = mesh.first_index as usize;
                let used = &geometry.indices[first..first + mesh.index_count as usize];
                Mesh {
                    vertices: vertex_base + mesh.vertex_offset as u64 * VERTEX_BYTES as u64,
                    stride: VERTEX_BYTES as u64,
                    max_vertex: used.iter().copied().max().unwrap_or(0),
                    indices: index_base + u64::from(mesh.first_index) * 4,
                    triangles: mesh.index_count / 3,
                }
            })
            .collect();
        let bottom = BottomLevels::new(gpu, &inputs)?;
        let placed = placements(geometry, &levels)?;
        let top = TopLevel::new(gpu, &bottom, &placed)?;
        Ok(Self {
            scratch_bytes: scratch_for(gpu, &bottom, &top),
            bottom,
            top,
            levels,
        })
    }

    /// Moves the top level's placements to the draw records' transforms as
    /// they are now: the next [`Self::record`] refits it.
    pub(super) fn place(&mut self, geometry: &SceneGeometry) -> Result<(), GpuError> {
        self.top
            .place(&self.bottom, &placements(geometry, &self.levels)?)
    }

    /// Records what the structures need before this frame's ray queries
    /// into `scratch`: the bottom levels' build the first time (then a
    /// barrier, as the top level reads them and reuses the scratch), the
    /// top level's build or refit when it is not current, or nothing.
    pub(super) fn record(
        &mut self,
        gpu: &'g Gpu,
        cmd: ash::vk::CommandBuffer,
        scratch: ScratchSpan,
    ) -> Result<(), GpuError> {
        self.bottom.record(gpu, cmd, scratch)?;
        self.top.record(gpu, cmd, scratch)
    }

    /// What was recorded has been submitted: it counts.
    pub(super) fn submitted(&mut self) {
        self.bottom.submitted();
        self.top.submitted();
    }

    /// What was recorded was never submitted (its frame failed first): the
    /// next [`Self::record`] records it again.
    pub(super) fn forget_unsubmitted(&mut self) {
        self.bottom.forget_unsubmitted();
        self.top.forget_unsubmitted();
    }

    /// Bytes of device memory the structures hold: the bottom levels, then
    /// the top level with its instances. Their scratch is the graph's.
    pub(super) fn bytes(&self) -> (u64, u64) {
        (self.bottom.bytes(), self.top.bytes())
    }
}

/// The distinct meshes the ray tracer's draws place, in first-placed order
/// (placements of one mesh, the same range of the shared buffers, share its
/// bottom level), and per traced draw the index of its mesh among them.
fn distinct_meshes(geometry: &SceneGeometry) -> (Vec<MeshRange>, Vec<usize>) {
    let mut meshes = Vec::new();
    let mut seen = HashMap::new();
    let levels = traced_draws(geometry)
        .map(|draw| {
            let range = draw.range;
            let key = (range.first_index, range.index_count, range.vertex_offset);
            *seen.entry(key).or_insert_with(|| {
                meshes.push(range);
                meshes.len() - 1
            })
        })
        .collect();
    (meshes, levels)
}

/// The draws [`SceneGeometry::trace_mesh`] turns into triangles, in its order.
fn traced_draws(geometry: &SceneGeometry) -> impl Iterator<Item = &crate::geometry::DrawItem> {
    geometry
        .draws
        .iter()
        .filter(|d| geometry.draw_records.get(d.draw_id as usize).is_some())
}

/// Bytes of scratch the builds of `scene`'s structures need, from the scene
/// alone: the value of the scene value `structure_scratch_bytes`, measured
/// before the scene's geometry is on the device and before the plan whose
/// scratch buffer it sizes is compiled. It counts every placed mesh as
/// [`SceneGeometry`] flattens them (consistent, with triangles: one bottom
/// level each, shared by its placements) with its triangles and highest
/// index as read, and a placement per placed mesh. Flattening only drops
/// triangles (non-finite ones), so this is never less than what
/// [`SceneStructures`] needs.
pub fn structure_scratch_bytes(gpu: &Gpu, scene: &Scene) -> Result<u64, GpuError> {
    let built = |mesh: &&weft_scene::Mesh| mesh.is_consistent() && !mesh.indices.is_empty();
    let placed: HashSet<usize> = scene.instances.iter().map(|i| i.model).collect();
    let meshes: Vec<Mesh> = scene
        .models
        .iter()
        .enumerate()
        .filter(|(m, _)| placed.contains(m))
        .flat_map(|(_, model)| model.meshes.iter().filter(built))
        .map(|mesh| Mesh {
            vertices: 0,
            stride: VERTEX_BYTES as u64,
            max_vertex: mesh.indices.iter().copied().max().unwrap_or(0),
            indices: 0,
            triangles: (mesh.indices.len() / 3) as u32,
        })
        .collect();
    let placements: usize = scene
        .instances
        .iter()
        .filter_map(|i| scene.models.get(i.model))
        .map(|model| model.meshes.iter().filter(built).count())
        .sum();
    scratch_needed(gpu, &meshes, placements as u32)
}

/// Each traced draw as a placement: its record's transform, its mesh's
/// level (`levels`, per traced draw) and its first triangle.
fn placements(geometry: &SceneGeometry, levels: &[usize]) -> Result<Vec<Placement>, GpuError> {
    let mut first_triangle = 0u32;
    let mut placements = Vec::new();
    for (draw, &level) in traced_draws(geometry).zip(levels) {
        if first_triangle > acceleration::MAX_CUSTOM_INDEX {
            return Err(GpuError::Allocation {
                what: "the top-level acceleration structure".into(),
                message: format!(
                    "a placement starts at triangle {first_triangle}, past the {} an instance's \
                     24-bit custom index can name",
                    acceleration::MAX_CUSTOM_INDEX
                ),
            });
        }
        // The transpose's columns are the model matrix's rows.
        let rows = geometry.draw_records[draw.draw_id as usize]
            .model
            .transpose()
            .to_cols_array();
        placements.push(Placement {
            transform: std::array::from_fn(|i| rows[i]),
            level,
            custom_index: first_triangle,
        });
        first_triangle += draw.range.index_count / 3;
    }
    Ok(placements)
}

/// What the acceleration structures cost, for `weft bench bvh`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StructureReport {
    /// The bottom levels' build, when it was recorded by
    /// [`super::GpuScene::build_structures_now`] (zero when it is not built
    /// yet, or was built by a frame).
    pub bottom_build: Duration,
    /// The top level's build or refit by the last
    /// [`super::GpuScene::build_structures_now`].
    pub top_build: Duration,
    /// Bytes the bottom levels hold.
    pub bottom_bytes: u64,
    /// Bytes the top level holds with its instances.
    pub top_bytes: u64,
    /// Bytes of scratch the builds need: transient memory in a frame.
    pub scratch_bytes: u64,
}

impl super::GpuScene<'_> {
    /// Makes tracing passes trace through ray queries (`hardware`, as the
    /// plan was compiled: [`crate::providers::trace_backend::in_hardware`])
    /// or the software BVH: what the ray tracer's buffers are built with,
    /// and when they exist already, what is built and bound now. Call it
    /// between frames.
    pub fn trace_in_hardware(&mut self, hardware: bool) -> Result<(), GpuError> {
        if hardware == self.hardware {
            return Ok(());
        }
        let Some(trace) = &self.trace else {
            self.hardware = hardware;
            return Ok(());
        };
        let rebuild_tables = !hardware && !trace.has_bvh();
        self.hardware = hardware;
        if rebuild_tables {
            // Built for ray queries alone: the walk needs its BVH.
            self.trace = None;
        }
        if let Err(error) = self.ensure_trace_buffers() {
            // The bound set still holds what the other backend reads.
            self.hardware = !hardware;
            return Err(error);
        }
        if let Some(set) = self.traced_set {
            self.write_scene_set(set, true);
        }
        Ok(())
    }

    /// Creates the acceleration structures when tracing passes use ray
    /// queries and they do not exist yet; the graph's build pass builds
    /// them.
    pub(super) fn ensure_structures(&mut self) -> Result<(), GpuError> {
        if self.hardware && self.structures.is_none() {
            let buffers = (&self.vertices, &self.indices);
            self.structures = Some(SceneStructures::new(self.gpu, &self.geometry, buffers)?);
        }
        Ok(())
    }

    /// Moves the top level's placements to the draw records as they are
    /// now, when there is one: the next build pass refits it, what each
    /// frame that moves a placement pays.
    pub fn refit_structures(&mut self) -> Result<(), GpuError> {
        match &mut self.structures {
            Some(structures) => structures.place(&self.geometry),
            None => Ok(()),
        }
    }

    /// Records into `cmd` what the acceleration structures need before the
    /// frame's ray queries (their first build, a refit, or nothing), after
    /// creating them and the ray tracer's tables if this is the first frame:
    /// the work of a `BuildAccelerationStructures` pass, whose barriers
    /// order it, building in `scratch`, the pass's scratch buffer. `pass`
    /// names the pass in errors.
    pub fn record_structures(
        &mut self,
        pass: &str,
        cmd: ash::vk::CommandBuffer,
        scratch: ScratchSpan,
    ) -> Result<(), GpuError> {
        if !self.hardware {
            return Err(GpuError::Pass {
                pass: pass.to_string(),
                message: "builds acceleration structures, but the scene traces with the software \
                          BVH: the plan was not compiled for ray queries"
                    .into(),
            });
        }
        self.ensure_trace_buffers()?;
        let structures = self.structures.as_mut().ok_or_else(|| GpuError::Pass {
            pass: pass.to_string(),
            message: "the scene has no acceleration structures".into(),
        })?;
        structures.record(self.gpu, cmd, scratch)
    }

    /// The frame whose command buffer [`Self::record_structures`] recorded
    /// into was submitted: its builds count. The executor says so through
    /// the draw recorder after each submission.
    pub fn structures_submitted(&mut self) {
        if let Some(structures) = &mut self.structures {
            structures.submitted();
        }
    }

    /// Builds recorded but never submitted (a frame that failed after its
    /// build pass) are recorded again by the next build pass: what a draw
    /// recorder calls as each frame begins.
    pub fn forget_unsubmitted_structures(&mut self) {
        if let Some(structures) = &mut self.structures {
            structures.forget_unsubmitted();
        }
    }

    /// Builds (or refits) the acceleration structures now, each level in a
    /// command buffer of its own waited for, and times both: what `weft
    /// bench bvh` measures. A frame's build pass records the same commands.
    pub fn build_structures_now(&mut self) -> Result<StructureReport, GpuError> {
        self.ensure_trace_buffers()?;
        let gpu = self.gpu;
        let Some(structures) = self.structures.as_mut() else {
            return Err(GpuError::Plan(
                "the scene traces with the software BVH: no acceleration structures".into(),
            ));
        };
        let scratch = Scratch::new(gpu, structures.scratch_bytes)?;
        let mut bottom_build = Duration::ZERO;
        if !structures.bottom.settled() {
            let start = Instant::now();
            gpu.one_shot(|cmd| structures.bottom.record(gpu, cmd, scratch.span()))?;
            structures.bottom.submitted();
            bottom_build = start.elapsed();
        }
        let start = Instant::now();
        gpu.one_shot(|cmd| {
            // After the last submission's build, whose scratch this reuses.
            acceleration::between_builds(gpu, cmd);
            structures.top.record(gpu, cmd, scratch.span())
        })?;
        structures.top.submitted();
        let top_build = start.elapsed();
        let (bottom_bytes, top_bytes) = structures.bytes();
        Ok(StructureReport {
            bottom_build,
            top_build,
            bottom_bytes,
            top_bytes,
            scratch_bytes: structures.scratch_bytes,
        })
    }
}
