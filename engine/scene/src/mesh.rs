//! Triangle meshes in the layout a renderer uploads: separate attribute arrays and u32 indices.

use crate::bounds::Aabb;
use glam::{Vec2, Vec3, Vec4};
use serde::{Deserialize, Serialize};

/// One triangle list with one material.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Mesh {
    /// The object or group name from the source file.
    pub name: String,
    /// Vertex positions in model space.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals, one per position (computed when the source has none).
    pub normals: Vec<Vec3>,
    /// Texture coordinates (top-left origin, as glTF and Vulkan use), one per position, or
    /// empty when the source has none.
    pub uvs: Vec<Vec2>,
    /// A second UV set (glTF `TEXCOORD_1`, for textures whose `tex_coord` is 1), or empty.
    pub uvs1: Vec<Vec2>,
    /// Vertex colours (glTF `COLOR_0`, OBJ `v x y z r g b`) as linear RGBA, or empty.
    pub colors: Vec<Vec4>,
    /// MikkTSpace tangents (xyz, w = handedness), one per position, or empty when the
    /// material has no normal map.
    pub tangents: Vec<Vec4>,
    /// Triangle corners, three per triangle.
    pub indices: Vec<u32>,
    /// Index into the model's materials, or `None` for the default material.
    pub material: Option<usize>,
    /// The box around the positions.
    pub bounds: Aabb,
}

impl Mesh {
    /// The number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Whether the arrays agree: whole triangles, indices in range, and every attribute array
    /// either empty (where allowed) or one entry per position.
    pub fn is_consistent(&self) -> bool {
        let n = self.positions.len();
        let per_vertex = |len: usize| len == 0 || len == n;
        self.indices.len().is_multiple_of(3)
            && self.indices.iter().all(|&i| (i as usize) < n)
            && self.normals.len() == n
            && per_vertex(self.uvs.len())
            && per_vertex(self.uvs1.len())
            && per_vertex(self.colors.len())
            && per_vertex(self.tangents.len())
    }
}

/// Area-weighted vertex normals for an indexed triangle list; degenerate vertices get +Y.
pub(crate) fn compute_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for tri in indices.chunks_exact(3) {
        let [a, b, c] = [tri[0] as usize, tri[1] as usize, tri[2] as usize];
        let (Some(&pa), Some(&pb), Some(&pc)) =
            (positions.get(a), positions.get(b), positions.get(c))
        else {
            continue;
        };
        let n = (pb - pa).cross(pc - pa);
        normals[a] += n;
        normals[b] += n;
        normals[c] += n;
    }
    normals
        .into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}

/// Smooth vertex normals for a mesh whose vertices may be split per face
/// (an OBJ with flat `vn`s, `s off`): each vertex gets the area-weighted
/// normal of every triangle that touches its position, wherever that
/// position is repeated, so a faceted sphere shades round. A `model`
/// block's `smooth_normals 1` asks for it.
pub(crate) fn smooth_normals(positions: &[Vec3], indices: &[u32]) -> Vec<Vec3> {
    let key = |p: Vec3| p.to_array().map(f32::to_bits);
    let mut at: std::collections::HashMap<[u32; 3], Vec3> = std::collections::HashMap::new();
    for tri in indices.chunks_exact(3) {
        let (Some(&a), Some(&b), Some(&c)) = (
            positions.get(tri[0] as usize),
            positions.get(tri[1] as usize),
            positions.get(tri[2] as usize),
        ) else {
            continue;
        };
        let n = (b - a).cross(c - a);
        for p in [a, b, c] {
            *at.entry(key(p)).or_insert(Vec3::ZERO) += n;
        }
    }
    positions
        .iter()
        .map(|&p| {
            at.get(&key(p))
                .and_then(|n| n.try_normalize())
                .unwrap_or(Vec3::Y)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_of_a_quad_face_up() {
        let p = [
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::ONE,
        ];
        let n = compute_normals(&p, &[0, 1, 2, 0, 2, 3]);
        assert_eq!(n, vec![Vec3::Y, Vec3::Y, Vec3::Y, Vec3::Y, Vec3::Y]);
    }

    /// Two triangles of a roof meeting at a ridge, each with its own copy
    /// of the ridge's vertices (flat normals, as an OBJ with `s off` has):
    /// smoothed, both copies of a ridge vertex point straight up, and the
    /// eaves keep their own face's normal.
    #[test]
    fn split_vertices_share_their_smoothed_normal() {
        let p = [
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, -1.0),
            Vec3::new(0.0, 1.0, 1.0),
        ];
        let n = smooth_normals(&p, &[0, 1, 2, 3, 4, 5]);
        let left = Vec3::new(-1.0, 1.0, 0.0).normalize();
        let right = Vec3::new(1.0, 1.0, 0.0).normalize();
        for (got, want) in n
            .iter()
            .zip([left, Vec3::Y, Vec3::Y, right, Vec3::Y, Vec3::Y])
        {
            assert!((*got - want).length() < 1e-6, "{got} against {want}");
        }
    }
}
