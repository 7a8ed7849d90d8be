//! The scene flattened for drawing: every model's meshes in one vertex and one
//! index array (plus the light-volume meshes), one draw record per placed mesh
//! (transform and material), and draws sorted by material so a pass rebinds
//! textures as rarely as possible.

use crate::gpu_types::{GpuDraw, GpuVertex};
use crate::materials;
use crate::vocabulary::MeshFilter;
use crate::volumes::{self, VolumeMesh};
use glam::{Mat4, UVec4, Vec2, Vec3, Vec4};
use std::collections::HashMap;
use weft_gpu::scene::{VertexAttribute, VertexFormat};
use weft_scene::tangent_frame::{self, TangentFrame};
use weft_scene::{Aabb, Material, Mesh, Scene};

/// The scene vertex's attributes: location, float count and what it holds.
pub const VERTEX_ATTRIBUTES: [VertexAttribute; 3] = [
    VertexAttribute {
        location: 0,
        offset: 0,
        format: VertexFormat::Float3,
        what: "position",
    },
    VertexAttribute {
        location: 1,
        offset: 12,
        format: VertexFormat::Uint,
        what: "packed tangent frame",
    },
    VertexAttribute {
        location: 2,
        offset: 16,
        format: VertexFormat::Unorm16x2,
        what: "UV",
    },
];

/// Bytes per vertex: position (3 floats), tangent frame (32 bits), UV (2 × 16 bits).
pub const VERTEX_BYTES: u32 = std::mem::size_of::<GpuVertex>() as u32;

/// The box around `uvs` as (smallest, size), the mapping [`quantize_uv`]
/// stores UVs against; zero for a mesh without UVs. Non-finite UVs are left out.
pub fn uv_box(uvs: &[Vec2]) -> (Vec2, Vec2) {
    let finite = || uvs.iter().filter(|uv| uv.is_finite());
    let lo = finite().fold(Vec2::splat(f32::INFINITY), |a, b| a.min(*b));
    let hi = finite().fold(Vec2::splat(f32::NEG_INFINITY), |a, b| a.max(*b));
    if lo.x > hi.x {
        return (Vec2::ZERO, Vec2::ZERO);
    }
    (lo, hi - lo)
}

/// `uv` as 16-bit fractions of the box `(lo, size)`: the error is at most half
/// of `size / 65535` per component (a non-finite UV becomes the box's corner).
pub fn quantize_uv(uv: Vec2, (lo, size): (Vec2, Vec2)) -> [u16; 2] {
    let fraction = |x: f32, lo: f32, size: f32| {
        if size > 0.0 && x.is_finite() {
            (((x - lo) / size).clamp(0.0, 1.0) * 65535.0).round() as u16
        } else {
            0
        }
    };
    [fraction(uv.x, lo.x, size.x), fraction(uv.y, lo.y, size.y)]
}

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
    /// The draw record the triangle was placed by (its `previous` says where
    /// it was at the frame before).
    pub draws: Vec<u32>,
    /// World-space unit tangents at the corners, w the bitangent's sign
    /// (mirrored instances flip it); zero where the mesh has none.
    pub tangents: Vec<[Vec4; 3]>,
}

/// Widens `changed` to cover `ids` as well: the one range of draw records to
/// write.
fn widen(changed: &mut Option<std::ops::Range<u32>>, ids: std::ops::Range<u32>) {
    *changed = Some(match changed.take() {
        Some(c) => c.start.min(ids.start)..c.end.max(ids.end),
        None => ids,
    });
}

/// The flattened scene, ready to upload.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneGeometry {
    /// Every vertex, packed for the GPU.
    pub vertices: Vec<GpuVertex>,
    /// Each vertex's unit normal, as imported (the ray tracer reads these).
    pub normals: Vec<Vec3>,
    /// Each vertex's UV, as imported (the ray tracer reads these).
    pub uvs: Vec<Vec2>,
    /// Each vertex's MikkTSpace tangent (w the handedness), zero where its
    /// mesh has none, as imported (the ray tracer reads these).
    pub tangents: Vec<Vec4>,
    /// Triangle corners of every mesh, each range relative to its vertex offset.
    pub indices: Vec<u32>,
    /// Draw records (model matrix, normal matrix, material).
    pub draw_records: Vec<GpuDraw>,
    /// Draws sorted by material.
    pub draws: Vec<DrawItem>,
    /// Per scene instance, its draw records (ids), so a moved instance
    /// rewrites only those ([`SceneGeometry::place_instances`]).
    pub instance_draws: Vec<std::ops::Range<u32>>,
    /// Per draw id, the mesh's model-space box and where the draw sits in `draws`.
    draw_places: Vec<(Aabb, usize)>,
    /// Per scene instance, with [`SceneGeometry::with_own_materials`]: its
    /// own material copies, each with the model material it copies (so a
    /// script can recolour one instance).
    pub instance_materials: Vec<Vec<(u32, u32)>>,
    /// Every material, index 0 being the default for meshes without one.
    pub materials: Vec<Material>,
    /// The point-light volume (see [`crate::volumes::sphere`]).
    pub sphere: MeshRange,
    /// The spot-light volume (see [`crate::volumes::cone`]).
    pub cone: MeshRange,
    /// The area-light panel (see [`crate::volumes::panel`]).
    pub panel: MeshRange,
    /// Meshes left out because their arrays disagree, as `model file: mesh name`.
    pub skipped: Vec<String>,
    /// Triangles left out because a corner's position is not finite, as
    /// `model file: mesh name: count` (`sanitize`: a NaN or infinite vertex
    /// would otherwise reach the rasterizer).
    pub non_finite: Vec<String>,
}

impl SceneGeometry {
    /// Flattens `scene`.
    pub fn new(scene: &Scene) -> Self {
        Self::flatten(scene, false)
    }

    /// Flattens `scene` with every instance drawing its own copies of its
    /// materials (listed in `instance_materials`), so each can be recoloured
    /// alone; the geometry is shared as before.
    pub fn with_own_materials(scene: &Scene) -> Self {
        Self::flatten(scene, true)
    }

    fn flatten(scene: &Scene, own_materials: bool) -> Self {
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
                let uv_box = uv_box(&mesh.uvs);
                let (range, dropped) = g.append(mesh, uv_box);
                if dropped > 0 {
                    g.non_finite.push(format!(
                        "{}: {}: {dropped}",
                        model.path.display(),
                        mesh.name
                    ));
                }
                let material = mesh
                    .material
                    .filter(|&i| i < model.materials.len())
                    .map_or(0, |i| material_base[material_base.len() - 1] + i as u32);
                let finite: Vec<Vec3> = mesh
                    .positions
                    .iter()
                    .copied()
                    .filter(|p| p.is_finite())
                    .collect();
                let bounds = Aabb::from_points(&finite);
                let uv_box = Vec4::new(uv_box.0.x, uv_box.0.y, uv_box.1.x, uv_box.1.y);
                model_ranges.push(Some((range, material, bounds, uv_box)));
            }
            ranges.push(model_ranges);
        }
        // Overridden materials are copies appended once per (material,
        // override), or per (material, instance) with own materials.
        let mut overridden: HashMap<(u32, [u32; 8], usize), u32> = HashMap::new();
        let mut local_bounds = Vec::new();
        for (index, instance) in scene.instances.iter().enumerate() {
            let first = g.draw_records.len() as u32;
            let owner = if own_materials { index } else { usize::MAX };
            g.instance_materials.push(Vec::new());
            let Some(model_ranges) = ranges.get(instance.model) else {
                g.instance_draws.push(first..first);
                continue;
            };
            let normal = instance.transform.inverse().transpose();
            let mirrored = instance.transform.determinant() < 0.0;
            for &(range, material, bounds, uv_box) in model_ranges.iter().flatten() {
                let material = if instance.material.is_empty() && !own_materials {
                    material
                } else {
                    *overridden
                        .entry((material, instance.material.key(), owner))
                        .or_insert_with(|| {
                            let copy = instance.material.apply(&g.materials[material as usize]);
                            g.materials.push(copy);
                            let copy = g.materials.len() as u32 - 1;
                            if own_materials {
                                g.instance_materials[index].push((copy, material));
                            }
                            copy
                        })
                };
                let draw_id = g.draws.len() as u32;
                g.draw_records.push(GpuDraw {
                    model: instance.transform,
                    normal,
                    material: UVec4::new(
                        material,
                        range.first_index,
                        range.vertex_offset as u32,
                        0,
                    ),
                    uv_box,
                    previous: Mat4::IDENTITY,
                });
                g.draws.push(DrawItem {
                    range,
                    draw_id,
                    material,
                    mirrored,
                    bounds: bounds.transformed(&instance.transform),
                });
                local_bounds.push(bounds);
            }
            g.instance_draws.push(first..g.draw_records.len() as u32);
        }
        g.draws.sort_by_key(|d| (d.material, d.draw_id));
        g.draw_places = local_bounds.into_iter().map(|b| (b, 0)).collect();
        for (slot, d) in g.draws.iter().enumerate() {
            g.draw_places[d.draw_id as usize].1 = slot;
        }
        g.sphere = g.append_volume(&volumes::sphere());
        g.cone = g.append_volume(&volumes::cone());
        g.panel = g.append_volume(&volumes::panel());
        g
    }

    /// Moves every scene instance whose transform in `transforms` differs
    /// from the one in `placed` (which is updated to match): its draw records
    /// (with where it was, `previous`) and their world boxes; an instance
    /// still again after moving has its records' `previous` reset, and moves
    /// no box. Pushes the moved draws' world boxes, before and
    /// after, onto `moved`, and returns the draw ids rewritten as one range
    /// (`None` when nothing moved), the span of the draw buffer to write.
    pub fn place_instances(
        &mut self,
        transforms: &[Mat4],
        placed: &mut [Mat4],
        moved: &mut Vec<Aabb>,
    ) -> Option<std::ops::Range<u32>> {
        let mut changed: Option<std::ops::Range<u32>> = None;
        for (instance, (new, old)) in transforms.iter().zip(placed.iter_mut()).enumerate() {
            let Some(ids) = self.instance_draws.get(instance).cloned() else {
                *old = *new;
                continue;
            };
            if new == old {
                // Still now: a placement that moved at the frame before is
                // where it was then, so its records say so again.
                let was_moving = ids
                    .clone()
                    .any(|id| self.draw_records[id as usize].previous != Mat4::IDENTITY);
                if was_moving {
                    for id in ids.clone() {
                        self.draw_records[id as usize].previous = Mat4::IDENTITY;
                    }
                    widen(&mut changed, ids);
                }
                continue;
            }
            let previous = *old * new.inverse();
            *old = *new;
            moved.extend(self.boxes(ids.clone()));
            let normal = new.inverse().transpose();
            let mirrored = new.determinant() < 0.0;
            for id in ids.clone() {
                let record = &mut self.draw_records[id as usize];
                record.model = *new;
                record.normal = normal;
                record.previous = previous;
                let (local, slot) = self.draw_places[id as usize];
                let draw = &mut self.draws[slot];
                draw.bounds = local.transformed(new);
                draw.mirrored = mirrored;
            }
            moved.extend(self.boxes(ids.clone()));
            if !ids.is_empty() {
                widen(&mut changed, ids);
            }
        }
        changed
    }

    /// The world boxes of the draws `ids` as placed now.
    fn boxes(&self, ids: std::ops::Range<u32>) -> impl Iterator<Item = Aabb> + '_ {
        ids.map(|id| self.draws[self.draw_places[id as usize].1].bounds)
    }

    /// The world-space corners of each triangle `draw` draws, as placed now
    /// and wound as drawn (a mirroring placement's triangles turned back, so
    /// they stay counter-clockwise about their front).
    pub fn world_triangles<'a>(
        &'a self,
        draw: &'a DrawItem,
    ) -> impl Iterator<Item = [Vec3; 3]> + 'a {
        let model = self
            .draw_records
            .get(draw.draw_id as usize)
            .map_or(Mat4::IDENTITY, |r| r.model);
        let first = (draw.range.first_index as usize).min(self.indices.len());
        let end = (first + draw.range.index_count as usize).min(self.indices.len());
        let offset = draw.range.vertex_offset;
        self.indices[first..end].chunks_exact(3).map(move |t| {
            let corner = |i: u32| {
                let v = (offset + i as i32) as usize;
                self.vertices.get(v).map_or(Vec3::NAN, |v| {
                    model.transform_point3(Vec3::from(v.position))
                })
            };
            let [a, b, c] = [corner(t[0]), corner(t[1]), corner(t[2])];
            if draw.mirrored {
                [a, c, b]
            } else {
                [a, b, c]
            }
        })
    }

    /// The UVs of `draw`'s triangles, in the order [`Self::world_triangles`]
    /// gives them (unmirrored).
    pub fn triangle_uvs<'a>(&'a self, draw: &'a DrawItem) -> impl Iterator<Item = [Vec2; 3]> + 'a {
        let first = (draw.range.first_index as usize).min(self.indices.len());
        let end = (first + draw.range.index_count as usize).min(self.indices.len());
        let offset = draw.range.vertex_offset;
        let uv = move |i: u32| {
            self.uvs
                .get((offset + i as i32) as usize)
                .copied()
                .unwrap_or(Vec2::ZERO)
        };
        self.indices[first..end]
            .chunks_exact(3)
            .map(move |t| [uv(t[0]), uv(t[1]), uv(t[2])])
    }

    /// The box around every draw as placed now.
    pub fn placed_bounds(&self) -> Aabb {
        self.draws
            .iter()
            .fold(Aabb::EMPTY, |b, d| b.union(&d.bounds))
    }

    /// Appends a mesh's vertices (frames packed, UVs against `uv_box`) and its
    /// triangles whose corners all have finite positions; returns the range
    /// and how many triangles were left out.
    fn append(&mut self, mesh: &Mesh, uv_box: (Vec2, Vec2)) -> (MeshRange, usize) {
        let tangents: Vec<Vec4> = (0..mesh.positions.len())
            .map(|i| mesh.tangents.get(i).copied().unwrap_or(Vec4::ZERO))
            .collect();
        let finite = |i: &u32| {
            mesh.positions
                .get(*i as usize)
                .is_some_and(|p| p.is_finite())
        };
        let indices: Vec<u32> = mesh
            .indices
            .chunks_exact(3)
            .filter(|t| t.iter().all(finite))
            .flatten()
            .copied()
            .collect();
        let dropped = (mesh.indices.len() - indices.len()) / 3;
        let range = self.append_arrays(
            &mesh.positions,
            &mesh.normals,
            &mesh.uvs,
            &tangents,
            &indices,
            uv_box,
        );
        (range, dropped)
    }

    fn append_arrays(
        &mut self,
        positions: &[Vec3],
        normals: &[Vec3],
        uvs: &[Vec2],
        tangents: &[Vec4],
        indices: &[u32],
        uv_box: (Vec2, Vec2),
    ) -> MeshRange {
        let range = MeshRange {
            first_index: self.indices.len() as u32,
            index_count: indices.len() as u32,
            vertex_offset: self.vertices.len() as i32,
        };
        for (i, p) in positions.iter().enumerate() {
            let n = normals.get(i).copied().unwrap_or(Vec3::Y);
            let uv = uvs.get(i).copied().unwrap_or(Vec2::ZERO);
            let t = tangents.get(i).copied().filter(|t| *t != Vec4::ZERO);
            let frame = TangentFrame::new(n, t);
            self.vertices.push(GpuVertex {
                position: p.to_array(),
                frame: tangent_frame::pack(&frame),
                uv: quantize_uv(uv, uv_box),
            });
            self.normals.push(n);
            self.uvs.push(uv);
            self.tangents.push(t.unwrap_or(Vec4::ZERO));
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
        self.append_arrays(
            &mesh.positions,
            &normals,
            &[],
            &[],
            &mesh.indices,
            (Vec2::ZERO, Vec2::ZERO),
        )
    }

    /// The draws a pass with `filter` makes, in material order.
    pub fn filtered(&self, filter: MeshFilter) -> impl Iterator<Item = &DrawItem> + '_ {
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
            let vertex = |i: u32| (d.range.vertex_offset + i as i32) as usize;
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
                out.corners.push(corners.map(|v| {
                    record
                        .model
                        .transform_point3(Vec3::from(self.vertices[v].position))
                }));
                out.normals.push(corners.map(|v| {
                    record
                        .normal
                        .transform_vector3(self.normals[v])
                        .normalize_or_zero()
                }));
                out.uvs.push(corners.map(|v| self.uvs[v]));
                out.materials.push(d.material);
                out.draws.push(d.draw_id);
            }
        }
        out
    }

    /// The model matrix of a draw record (transparent meshes sort by its origin).
    pub fn model_matrix(&self, draw_id: u32) -> Option<Mat4> {
        self.draw_records.get(draw_id as usize).map(|d| d.model)
    }
}
