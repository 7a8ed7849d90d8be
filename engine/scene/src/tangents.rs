//! MikkTSpace tangents for meshes whose material has a normal or bump map,
//! in glTF's convention: the bitangent is `cross(normal, tangent.xyz) *
//! tangent.w` and points the way a normal map's green channel does, up in
//! the image. MikkTSpace runs on weft's UVs, whose origin is the image's top
//! left (OBJ's v is flipped on import), so its bitangent points down the
//! image; the sign it reports is negated to match glTF's (whose exporters
//! compute tangents before flipping v).
//!
//! MikkTSpace gives each triangle corner its own tangent. Where the corners
//! of one vertex disagree (a UV seam, mirrored UVs meeting), the vertex is
//! split, one copy per distinct tangent, so no corner gets another's frame.

use crate::mesh::Mesh;
use crate::model::Model;
use glam::Vec4;
use std::collections::HashMap;

/// Adapts an indexed mesh to the mikktspace face/vertex interface.
struct Geometry<'a> {
    mesh: &'a Mesh,
    /// One tangent per triangle corner.
    corner_tangents: Vec<Vec4>,
}

impl Geometry<'_> {
    /// The vertex index of a face corner.
    fn index(&self, face: usize, vert: usize) -> usize {
        self.mesh.indices[face * 3 + vert] as usize
    }
}

impl mikktspace::Geometry for Geometry<'_> {
    fn num_faces(&self) -> usize {
        self.mesh.indices.len() / 3
    }

    fn num_vertices_of_face(&self, _face: usize) -> usize {
        3
    }

    fn position(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.positions[self.index(face, vert)].to_array()
    }

    fn normal(&self, face: usize, vert: usize) -> [f32; 3] {
        self.mesh.normals[self.index(face, vert)].to_array()
    }

    fn tex_coord(&self, face: usize, vert: usize) -> [f32; 2] {
        self.mesh.uvs[self.index(face, vert)].to_array()
    }

    fn set_tangent_encoded(&mut self, tangent: [f32; 4], face: usize, vert: usize) {
        self.corner_tangents[face * 3 + vert] =
            Vec4::new(tangent[0], tangent[1], tangent[2], -tangent[3]);
    }
}

/// Computes tangents for one mesh, splitting vertices whose corners got
/// different tangents; false when it has no UVs or mikktspace fails. Returns
/// through `mesh` only on success.
pub fn generate_mesh_tangents(mesh: &mut Mesh) -> bool {
    if mesh.uvs.len() != mesh.positions.len() || mesh.normals.len() != mesh.positions.len() {
        return false;
    }
    let mut g = Geometry {
        mesh,
        corner_tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); mesh.indices.len()],
    };
    if !mikktspace::generate_tangents(&mut g) {
        return false;
    }
    let corners = g.corner_tangents;
    assign_corner_tangents(mesh, &corners);
    true
}

/// Gives each vertex its corners' tangent, splitting a vertex into one copy
/// per distinct tangent among its corners (the copies repeat every other
/// attribute) and re-pointing those corners' indices.
fn assign_corner_tangents(mesh: &mut Mesh, corners: &[Vec4]) {
    let key = |t: Vec4| t.to_array().map(f32::to_bits);
    let mut tangents: Vec<Option<Vec4>> = vec![None; mesh.positions.len()];
    let mut copies: HashMap<(u32, [u32; 4]), u32> = HashMap::new();
    for (corner, &t) in corners.iter().enumerate() {
        let v = mesh.indices[corner];
        match tangents[v as usize] {
            None => tangents[v as usize] = Some(t),
            Some(existing) if key(existing) == key(t) => {}
            Some(_) => {
                let copy = *copies.entry((v, key(t))).or_insert_with(|| {
                    let i = v as usize;
                    mesh.positions.push(mesh.positions[i]);
                    mesh.normals.push(mesh.normals[i]);
                    mesh.uvs.push(mesh.uvs[i]);
                    if !mesh.uvs1.is_empty() {
                        mesh.uvs1.push(mesh.uvs1[i]);
                    }
                    if !mesh.colors.is_empty() {
                        mesh.colors.push(mesh.colors[i]);
                    }
                    tangents.push(Some(t));
                    (mesh.positions.len() - 1) as u32
                });
                mesh.indices[corner] = copy;
            }
        }
    }
    mesh.tangents = tangents
        .into_iter()
        .map(|t| t.unwrap_or(Vec4::new(1.0, 0.0, 0.0, 1.0)))
        .collect();
}

/// Computes tangents for every mesh of `model` whose material needs them and that has none.
/// Returns how many meshes needed tangents but had no UVs.
pub fn generate_model_tangents(model: &mut Model) -> usize {
    let mut without_uvs = 0;
    for mesh in &mut model.meshes {
        let needs = mesh
            .material
            .and_then(|i| model.materials.get(i))
            .is_some_and(|m| m.textures.needs_tangents());
        if needs && mesh.tangents.is_empty() && !generate_mesh_tangents(mesh) {
            without_uvs += 1;
        }
    }
    without_uvs
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bounds::Aabb;
    use glam::{Vec2, Vec3};

    #[test]
    fn quad_in_xy_plane_gets_plus_x_tangents() {
        let mut mesh = Mesh {
            name: "quad".into(),
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
            normals: vec![Vec3::Z; 4],
            uvs: vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
            ],
            uvs1: Vec::new(),
            colors: Vec::new(),
            tangents: Vec::new(),
            indices: vec![0, 1, 2, 0, 2, 3],
            material: None,
            bounds: Aabb::EMPTY,
        };
        assert!(generate_mesh_tangents(&mut mesh));
        for t in &mesh.tangents {
            assert!(t.truncate().distance(Vec3::X) < 1e-5, "{t}");
            // v = 0 is the image's top, at y = 1: the bitangent cross(N, T) * w
            // must point up the image, +Y, as glTF's does.
            assert_eq!(t.w, 1.0, "{t}");
        }
        assert_eq!(mesh.positions.len(), 4, "one frame per vertex: no split");
    }

    #[test]
    fn a_vertex_on_a_mirrored_uv_seam_is_split_per_tangent() {
        // Two quads sharing the edge x = 1; the right one's u runs backwards
        // (mirrored UVs), so the shared vertices need both handednesses.
        let mut mesh = Mesh {
            name: "mirrored".into(),
            positions: vec![
                Vec3::ZERO,
                Vec3::X,
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::Y,
                Vec3::new(2.0, 0.0, 0.0),
                Vec3::new(2.0, 1.0, 0.0),
            ],
            normals: vec![Vec3::Z; 6],
            uvs: vec![
                Vec2::new(0.0, 1.0),
                Vec2::new(1.0, 1.0),
                Vec2::new(1.0, 0.0),
                Vec2::new(0.0, 0.0),
                Vec2::new(0.0, 1.0),
                Vec2::new(0.0, 0.0),
            ],
            uvs1: Vec::new(),
            colors: Vec::new(),
            tangents: Vec::new(),
            indices: vec![0, 1, 2, 0, 2, 3, 1, 4, 5, 1, 5, 2],
            material: None,
            bounds: Aabb::EMPTY,
        };
        assert!(generate_mesh_tangents(&mut mesh));
        assert_eq!(mesh.positions.len(), 8, "the two seam vertices are split");
        assert_eq!(mesh.tangents.len(), 8);
        assert_eq!(mesh.uvs.len(), 8);
        for tri in mesh.indices.chunks(3) {
            let right = tri.iter().any(|&i| mesh.positions[i as usize].x > 1.5);
            for &i in tri {
                let t = mesh.tangents[i as usize];
                // Mirrored: the tangent turns round and the handedness flips,
                // so the bitangent still points up the image.
                let (expected, w) = if right {
                    (-Vec3::X, -1.0)
                } else {
                    (Vec3::X, 1.0)
                };
                assert!(t.truncate().distance(expected) < 1e-5, "{t} in {tri:?}");
                assert_eq!(t.w, w, "{t}");
            }
        }
    }
}
