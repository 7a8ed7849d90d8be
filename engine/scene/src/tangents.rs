//! MikkTSpace tangents for meshes whose material has a normal or bump map,
//! in glTF's convention: the bitangent is `cross(normal, tangent.xyz) *
//! tangent.w` and points the way a normal map's green channel does, up in
//! the image. MikkTSpace runs on weft's UVs, whose origin is the image's top
//! left (OBJ's v is flipped on import), so its bitangent points down the
//! image; the sign it reports is negated to match glTF's (whose exporters
//! compute tangents before flipping v).

use crate::mesh::Mesh;
use crate::model::Model;
use glam::Vec4;

/// Adapts an indexed mesh to the mikktspace face/vertex interface.
struct Geometry<'a> {
    mesh: &'a Mesh,
    tangents: Vec<Vec4>,
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
        let i = self.index(face, vert);
        // Vertices shared between faces get the last face's tangent; MikkTSpace gives shared
        // vertices the same frame unless the UV layout splits them.
        self.tangents[i] = Vec4::new(tangent[0], tangent[1], tangent[2], -tangent[3]);
    }
}

/// Computes tangents for one mesh; false when it has no UVs or mikktspace fails.
pub fn generate_mesh_tangents(mesh: &mut Mesh) -> bool {
    if mesh.uvs.len() != mesh.positions.len() || mesh.normals.len() != mesh.positions.len() {
        return false;
    }
    let mut g = Geometry {
        mesh,
        tangents: vec![Vec4::new(1.0, 0.0, 0.0, 1.0); mesh.positions.len()],
    };
    if !mikktspace::generate_tangents(&mut g) {
        return false;
    }
    let tangents = g.tangents;
    mesh.tangents = tangents;
    true
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
    }
}
