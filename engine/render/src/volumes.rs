//! Proxy meshes for deferred light volumes: a sphere for point lights and a cone
//! for spots, both slightly larger than the shapes they stand for (every face lies
//! outside the true surface), so no lit pixel is missed; shading cuts off exactly.

use glam::Vec3;

/// Segments around the cone's base circle.
const CONE_SEGMENTS: u32 = 24;

/// A triangle list with outward-facing, counter-clockwise triangles.
#[derive(Debug, Clone, PartialEq)]
pub struct VolumeMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Three indices per triangle.
    pub indices: Vec<u32>,
}

/// A sphere around the origin containing the unit sphere: an icosahedron
/// subdivided twice, scaled so its faces' planes lie at distance >= 1.
pub fn sphere() -> VolumeMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..2 {
        let mut next = Vec::with_capacity(faces.len() * 4);
        let mut midpoints = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| -> u32 {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(p);
                positions.len() as u32 - 1
            })
        };
        for [a, b, c] in faces {
            let ab = mid(a, b, &mut positions);
            let bc = mid(b, c, &mut positions);
            let ca = mid(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let inradius = faces
        .iter()
        .map(|&[a, b, c]| {
            let [pa, pb, pc] = [a, b, c].map(|i| positions[i as usize]);
            (pb - pa).cross(pc - pa).normalize().dot(pa)
        })
        .fold(f32::MAX, f32::min);
    let scale = 1.0 / inradius;
    VolumeMesh {
        positions: positions.into_iter().map(|p| p * scale).collect(),
        indices: faces.into_iter().flatten().collect(),
    }
}

/// A cone with its apex at the origin opening along -Z to a base at z = -1 that
/// contains the unit circle (the polygon circumscribes it), with a base cap.
pub fn cone() -> VolumeMesh {
    let n = CONE_SEGMENTS;
    let r = 1.0 / (std::f32::consts::PI / n as f32).cos();
    let mut positions = vec![Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0)];
    for i in 0..n {
        let a = std::f32::consts::TAU * i as f32 / n as f32;
        positions.push(Vec3::new(r * a.cos(), r * a.sin(), -1.0));
    }
    let mut indices = Vec::new();
    for i in 0..n {
        let (a, b) = (2 + i, 2 + (i + 1) % n);
        indices.extend([0, a, b]);
        indices.extend([1, b, a]);
    }
    VolumeMesh { positions, indices }
}

/// Segments around the area-light panel (a multiple of 8, so its outline
/// passes through the square's corners and edge midpoints).
const PANEL_SEGMENTS: u32 = 32;

/// An area light's panel: a fan over the unit circle in z = 0, counter-clockwise
/// about +Z. `shaders/area_panel.vert` keeps it for a disc and pushes each
/// outline point out to the square |x|, |y| <= 1 for a rectangle: every
/// corner and edge midpoint of the square is a vertex, so the square is exact.
pub fn panel() -> VolumeMesh {
    let n = PANEL_SEGMENTS;
    let mut positions = vec![Vec3::ZERO];
    for i in 0..n {
        let a = std::f32::consts::TAU * i as f32 / n as f32;
        positions.push(Vec3::new(a.cos(), a.sin(), 0.0));
    }
    let indices = (0..n).flat_map(|i| [0, 1 + i, 1 + (i + 1) % n]).collect();
    VolumeMesh { positions, indices }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outward(mesh: &VolumeMesh, inside: Vec3) -> bool {
        mesh.indices.chunks_exact(3).all(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| mesh.positions[i as usize]);
            (b - a).cross(c - a).dot(a - inside) > 0.0
        })
    }

    #[test]
    fn the_panel_covers_the_unit_disc_and_has_the_squares_corners() {
        let p = panel();
        assert!(p.indices.chunks_exact(3).all(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| p.positions[i as usize]);
            (b - a).cross(c - a).z > 0.0
        }));
        let area: f32 = p
            .indices
            .chunks_exact(3)
            .map(|t| {
                let [a, b, c] = [t[0], t[1], t[2]].map(|i| p.positions[i as usize]);
                0.5 * (b - a).cross(c - a).z
            })
            .sum();
        // The inscribed 32-gon: 16 sin(2 pi / 32), within 0.7% of pi.
        assert!((area - 16.0 * (std::f32::consts::TAU / 32.0).sin()).abs() < 1e-5);
        for corner in [(1.0f32, 1.0f32), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0)] {
            let direction = Vec3::new(corner.0, corner.1, 0.0).normalize();
            assert!(p.positions.iter().any(|q| q.distance(direction) < 1e-6));
        }
    }

    #[test]
    fn sphere_contains_the_unit_sphere_and_faces_out() {
        let s = sphere();
        assert_eq!(s.indices.len(), 320 * 3);
        assert!(outward(&s, Vec3::ZERO));
        for t in s.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| s.positions[i as usize]);
            let d = (b - a).cross(c - a).normalize().dot(a);
            assert!(d >= 1.0 - 1e-5, "face plane at {d}");
        }
    }

    #[test]
    fn cone_contains_the_unit_base_circle_and_faces_out() {
        let c = cone();
        assert_eq!(c.indices.len(), 2 * 24 * 3);
        assert!(outward(&c, Vec3::new(0.0, 0.0, -0.5)));
        let edge = (c.positions[2] + c.positions[3]) * 0.5;
        assert!((edge.truncate().length() - 1.0).abs() < 1e-5);
    }
}
