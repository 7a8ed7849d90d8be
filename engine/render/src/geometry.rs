//! The scene flattened for drawing: every model's meshes in one vertex and one
//! index array (plus the light-volume meshes), one draw record per placed mesh
//! (transform and material), and draws sorted by material so a pass rebinds
//! textures as rarely as possible.

use crate::gpu_types::{GpuDraw, GpuVertex};
use crate::materials;
use crate::volumes::{self, VolumeMesh};
use glam::{Mat4, UVec4, Vec2, Vec3, Vec4};
use weft_graph::schema::MaterialFilter;
use weft_scene::{Aabb, Material, Scene};

/// The scene vertex's attributes: location, float count and what it holds.
pub const VERTEX_ATTRIBUTES: [(u32, u32, &str); 3] =
    [(0, 3, "position"), (1, 3, "normal"), (2, 2, "UV")];

/// Bytes per vertex: position (3 floats), normal (3), uv (2).
pub const VERTEX_BYTES: u32 = std::mem::size_of::<GpuVertex>() as u32;

/// Where a mesh lies in the shared arrays.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MeshRange {
    /// First index in the shared index buffer.
    pub first_index: u32,
    /// Number of indices (three per triangle).
    pub index_count: u32,
    /// Added to every index: where the mesh's vertices start.
    pub vertex_offset: i32,
}

/// One placed mesh: what to draw, its record in the draw buffer (the draw's
/// `firstInstance`), and its material (index into the scene's material list).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrawItem {
    /// The mesh's indices and vertices.
    pub range: MeshRange,
    /// Index of its draw record, passed as `firstInstance`.
    pub draw_id: u32,
    /// Index into [`SceneGeometry::materials`].
    pub material: u32,
    /// Whether the instance's transform mirrors (negative determinant), which
    /// turns its triangles' winding around.
    pub mirrored: bool,
    /// World-space box around the mesh as placed, for view-frustum culling.
    pub bounds: Aabb,
}

/// The scene's triangles as the ray tracer reads them, one entry per triangle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct TraceMesh {
    /// World-space corners.
    pub corners: Vec<[Vec3; 3]>,
    /// Unit world-space normals at the corners.
    pub normals: Vec<[Vec3; 3]>,
    /// Texture coordinates at the corners.
    pub uvs: Vec<[Vec2; 3]>,
    /// Index into [`SceneGeometry::materials`].
    pub materials: Vec<u32>,
    /// World-space unit tangents at the corners, w the bitangent's sign
    /// (mirrored instances flip it); zero where the mesh has none.
    pub tangents: Vec<[Vec4; 3]>,
}

/// The flattened scene, ready to upload.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneGeometry {
    /// Every vertex.
    pub vertices: Vec<GpuVertex>,
    /// Each vertex's MikkTSpace tangent (w the handedness), zero where its
    /// mesh has none. Only the ray tracer reads them (normal maps).
    pub tangents: Vec<Vec4>,
    /// Triangle corners of every mesh, each range relative to its vertex offset.
    pub indices: Vec<u32>,
    /// Draw records (model matrix, normal matrix, material).
    pub draw_records: Vec<GpuDraw>,
    /// Draws sorted by material.
    pub draws: Vec<DrawItem>,
    /// Every material, index 0 being the default for meshes without one.
    pub materials: Vec<Material>,
    /// The point-light volume (see [`crate::volumes::sphere`]).
    pub sphere: MeshRange,
    /// The spot-light volume (see [`crate::volumes::cone`]).
    pub cone: MeshRange,
    /// Meshes left out because their arrays disagree, as `model file: mesh name`.
    pub skipped: Vec<String>,
}

impl SceneGeometry {
    /// Flattens `scene`.
    pub fn new(scene: &Scene) -> Self {
        let mut g = SceneGeometry {
            materials: vec![Material::default()],
            ..Self::default()
        };
        let mut ranges = Vec::with_capacity(scene.models.len());
        let mut material_base = Vec::with_capacity(scene.models.len());
        for model in &scene.models {
            material_base.push(g.materials.len() as u32);
            g.materials.extend(model.materials.iter().cloned());
            let mut model_ranges = Vec::with_capacity(model.meshes.len());
            for mesh in &model.meshes {
                if !mesh.is_consistent() || mesh.indices.is_empty() {
                    g.skipped
                        .push(format!("{}: {}", model.path.display(), mesh.name));
                    model_ranges.push(None);
                    continue;
                }
                let range = g.append(&mesh.positions, &mesh.normals, &mesh.uvs, &mesh.indices);
                g.tangents.extend(
                    (0..mesh.positions.len())
                        .map(|i| mesh.tangents.get(i).copied().unwrap_or(Vec4::ZERO)),
                );
                let material = mesh
                    .material
                    .filter(|&i| i < model.materials.len())
                    .map_or(0, |i| material_base[material_base.len() - 1] + i as u32);
                let bounds = Aabb::from_points(&mesh.positions);
                model_ranges.push(Some((range, material, bounds)));
            }
            ranges.push(model_ranges);
        }
        for instance in &scene.instances {
            let Some(model_ranges) = ranges.get(instance.model) else {
                continue;
            };
            let normal = instance.transform.inverse().transpose();
            let mirrored = instance.transform.determinant() < 0.0;
            for &(range, material, bounds) in model_ranges.iter().flatten() {
                let draw_id = g.draws.len() as u32;
                g.draw_records.push(GpuDraw {
                    model: instance.transform,
                    normal,
                    material: UVec4::new(material, 0, 0, 0),
                });
                g.draws.push(DrawItem {
                    range,
                    draw_id,
                    material,
                    mirrored,
                    bounds: bounds.transformed(&instance.transform),
                });
            }
        }
        g.draws.sort_by_key(|d| (d.material, d.draw_id));
        g.sphere = g.append_volume(&volumes::sphere());
        g.cone = g.append_volume(&volumes::cone());
        g
    }

    fn append(
        &mut self,
        positions: &[Vec3],
        normals: &[Vec3],
        uvs: &[Vec2],
        indices: &[u32],
    ) -> MeshRange {
        let range = MeshRange {
            first_index: self.indices.len() as u32,
            index_count: indices.len() as u32,
            vertex_offset: self.vertices.len() as i32,
        };
        for (i, p) in positions.iter().enumerate() {
            let n = normals.get(i).copied().unwrap_or(Vec3::Y);
            let uv = uvs.get(i).copied().unwrap_or(Vec2::ZERO);
            self.vertices.push(GpuVertex {
                position: p.to_array(),
                normal: n.to_array(),
                uv: uv.to_array(),
            });
        }
        self.indices.extend_from_slice(indices);
        range
    }

    fn append_volume(&mut self, mesh: &VolumeMesh) -> MeshRange {
        let normals: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|p| p.try_normalize().unwrap_or(Vec3::Y))
            .collect();
        let range = self.append(&mesh.positions, &normals, &[], &mesh.indices);
        self.tangents.resize(self.vertices.len(), Vec4::ZERO);
        range
    }

    /// The draws a pass with `filter` makes, in material order.
    pub fn filtered(&self, filter: MaterialFilter) -> impl Iterator<Item = &DrawItem> + '_ {
        self.draws.iter().filter(move |d| {
            self.materials
                .get(d.material as usize)
                .is_some_and(|m| materials::matches(filter, m))
        })
    }

    /// Every placed mesh's triangles in world space, draw by draw, with their
    /// corners' world normals and UVs and their material: what the ray tracer
    /// traces (light-volume meshes are not drawn, so not included).
    pub fn trace_mesh(&self) -> TraceMesh {
        let mut out = TraceMesh::default();
        for d in &self.draws {
            let Some(record) = self.draw_records.get(d.draw_id as usize) else {
                continue;
            };
            let first = d.range.first_index as usize;
            let indices = &self.indices[first..first + d.range.index_count as usize];
            let vertex = |i: u32| &self.vertices[(d.range.vertex_offset + i as i32) as usize];
            let tangent = |i: u32| {
                self.tangents
                    .get((d.range.vertex_offset + i as i32) as usize)
                    .copied()
                    .unwrap_or(Vec4::ZERO)
            };
            let handedness = if record.model.determinant() < 0.0 {
                -1.0
            } else {
                1.0
            };
            for t in indices.chunks_exact(3) {
                out.tangents.push([t[0], t[1], t[2]].map(|i| {
                    let v = tangent(i);
                    record
                        .model
                        .transform_vector3(v.truncate())
                        .normalize_or_zero()
                        .extend(v.w * handedness)
                }));
                let corners = [vertex(t[0]), vertex(t[1]), vertex(t[2])];
                out.corners
                    .push(corners.map(|v| record.model.transform_point3(Vec3::from(v.position))));
                out.normals.push(corners.map(|v| {
                    record
                        .normal
                        .transform_vector3(Vec3::from(v.normal))
                        .normalize_or_zero()
                }));
                out.uvs.push(corners.map(|v| Vec2::from(v.uv)));
                out.materials.push(d.material);
            }
        }
        out
    }

    /// The model matrix of a draw record (transparent meshes sort by its origin).
    pub fn model_matrix(&self, draw_id: u32) -> Option<Mat4> {
        self.draw_records.get(draw_id as usize).map(|d| d.model)
    }
}
