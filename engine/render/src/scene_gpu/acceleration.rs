//! The scene as hardware acceleration structures, for passes compiled for
//! ray queries ([`crate::providers::trace_backend`]): a bottom level per
//! mesh in its own space (placements of one mesh share it) and a top level
//! placing them with each draw's transform. A placement's instance carries
//! its first triangle in the ray tracer's triangle order
//! ([`SceneGeometry::trace_mesh`]) as its custom index, so a ray query names
//! the same triangle the software walk does. Moved placements refit the top
//! level in place; the bottom levels never change.

use crate::geometry::{MeshRange, SceneGeometry};
use std::collections::HashMap;
use std::time::Duration;
use weft_gpu::acceleration::{self, BottomLevels, Mesh, Placement, TopLevel};
use weft_gpu::{Gpu, GpuError};

/// The scene's acceleration structures on the device.
pub(super) struct SceneStructures<'g> {
    bottom: BottomLevels<'g>,
    pub(super) top: TopLevel<'g>,
}

/// A mesh's place in the shared index and vertex buffers: placements of
/// one mesh share its bottom level.
type MeshKey = (u32, u32, i32);

fn key(range: &MeshRange) -> MeshKey {
    (range.first_index, range.index_count, range.vertex_offset)
}

impl<'g> SceneStructures<'g> {
    /// Builds the bottom levels over `geometry`'s meshes and the top level
    /// placing them as its draw records do now.
    pub(super) fn build(gpu: &'g Gpu, geometry: &SceneGeometry) -> Result<Self, GpuError> {
        let (meshes, levels) = distinct_meshes(geometry);
        let inputs: Vec<(Vec<[f32; 3]>, Vec<u32>)> =
            meshes.iter().map(|m| mesh_input(geometry, m)).collect();
        let views: Vec<Mesh<'_>> = inputs
            .iter()
            .map(|(positions, indices)| Mesh { positions, indices })
            .collect();
        let bottom = acceleration::build_bottom_levels(gpu, &views)?;
        let top = TopLevel::build(gpu, &bottom, &placements(geometry, &levels)?)?;
        Ok(Self { bottom, top })
    }

    /// Refits the top level to the draw records' transforms as they are now.
    pub(super) fn refit(&mut self, geometry: &SceneGeometry) -> Result<(), GpuError> {
        let (_, levels) = distinct_meshes(geometry);
        self.top
            .refit(&self.bottom, &placements(geometry, &levels)?)
    }

    /// How long the bottom levels took to build, and the top level's last
    /// build or refit.
    pub(super) fn build_times(&self) -> (Duration, Duration) {
        (self.bottom.build_time, self.top.last_time)
    }

    /// Bytes of device memory the structures hold (bottom levels, then the
    /// top level with its instances and scratch).
    pub(super) fn bytes(&self) -> (u64, u64) {
        let bottom = self.bottom.levels.iter().map(|l| l.bytes()).sum();
        (bottom, self.top.bytes())
    }
}

/// The distinct meshes the ray tracer's draws place, in first-placed order,
/// and the index of each key among them.
fn distinct_meshes(geometry: &SceneGeometry) -> (Vec<MeshRange>, HashMap<MeshKey, usize>) {
    let mut meshes = Vec::new();
    let mut levels = HashMap::new();
    for draw in traced_draws(geometry) {
        levels.entry(key(&draw.range)).or_insert_with(|| {
            meshes.push(draw.range);
            meshes.len() - 1
        });
    }
    (meshes, levels)
}

/// The draws [`SceneGeometry::trace_mesh`] turns into triangles, in its order.
fn traced_draws(geometry: &SceneGeometry) -> impl Iterator<Item = &crate::geometry::DrawItem> {
    geometry
        .draws
        .iter()
        .filter(|d| geometry.draw_records.get(d.draw_id as usize).is_some())
}

/// A mesh's positions (those its indices reach) and its triangles' indices.
fn mesh_input(geometry: &SceneGeometry, mesh: &MeshRange) -> (Vec<[f32; 3]>, Vec<u32>) {
    let first = mesh.first_index as usize;
    let indices = geometry.indices[first..first + mesh.index_count as usize].to_vec();
    let reach = indices.iter().max().map_or(0, |&i| i as usize + 1);
    let base = mesh.vertex_offset as usize;
    let positions = geometry.vertices[base..base + reach]
        .iter()
        .map(|v| v.position)
        .collect();
    (positions, indices)
}

/// Each traced draw as a placement: its record's transform, its mesh's
/// level and its first triangle.
fn placements(
    geometry: &SceneGeometry,
    levels: &HashMap<MeshKey, usize>,
) -> Result<Vec<Placement>, GpuError> {
    let mut first_triangle = 0u32;
    let mut placements = Vec::new();
    for draw in traced_draws(geometry) {
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
        let model = geometry.draw_records[draw.draw_id as usize].model;
        let rows = model.transpose().to_cols_array_2d();
        placements.push(Placement {
            transform: [rows[0], rows[1], rows[2]],
            level: levels[&key(&draw.range)],
            custom_index: first_triangle,
        });
        first_triangle += draw.range.index_count / 3;
    }
    Ok(placements)
}

/// What the acceleration structures cost, for `weft bench bvh`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StructureReport {
    /// The bottom levels' build, inputs' upload included.
    pub bottom_build: Duration,
    /// The top level's last build or refit.
    pub top_build: Duration,
    /// Bytes the bottom levels hold.
    pub bottom_bytes: u64,
    /// Bytes the top level holds with its instances and scratch.
    pub top_bytes: u64,
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

    /// Builds the acceleration structures when tracing passes use ray
    /// queries and they are not built yet.
    pub(super) fn ensure_structures(&mut self) -> Result<(), GpuError> {
        if self.hardware && self.structures.is_none() {
            self.structures = Some(SceneStructures::build(self.gpu, &self.geometry)?);
        }
        Ok(())
    }

    /// Refits the top level to the placements as they are now, when there is
    /// one: what each frame that moves a placement pays (`weft bench bvh`
    /// times it with [`Self::structure_report`]).
    pub fn refit_structures(&mut self) -> Result<(), GpuError> {
        match &mut self.structures {
            Some(structures) => structures.refit(&self.geometry),
            None => Ok(()),
        }
    }

    /// The acceleration structures' build times and memory, once built.
    pub fn structure_report(&self) -> Option<StructureReport> {
        let structures = self.structures.as_ref()?;
        let (bottom_build, top_build) = structures.build_times();
        let (bottom_bytes, top_bytes) = structures.bytes();
        Some(StructureReport {
            bottom_build,
            top_build,
            bottom_bytes,
            top_bytes,
        })
    }
}
