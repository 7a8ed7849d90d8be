//! The CPU mirror of tiled light culling (`shaders/light_cull.comp`): the
//! frustum slab of one screen tile between its nearest and farthest reverse-Z
//! depths, whether a light's bounding sphere reaches it, and the spot bounds.
//! Tests compare the GPU's per-tile counts with this; keep the two in step.

use glam::{Mat4, Vec2, Vec3, Vec4};

/// Pixels per tile side (`TILE_SIZE` in `shaders/include/tiles.glsl`).
pub const TILE_SIZE: u32 = 16;

/// Tiles across and down a `width` x `height` image (partial tiles count).
pub fn tile_grid(width: u32, height: u32) -> (u32, u32) {
    (width.div_ceil(TILE_SIZE), height.div_ceil(TILE_SIZE))
}

/// The world position at `pixel` (pixel coordinates, not centres) with
/// reverse-Z depth `depth`, as `position_from_depth` in `include/gbuffer.glsl`.
pub fn unproject(inv_view_proj: Mat4, viewport: Vec2, pixel: Vec2, depth: f32) -> Vec3 {
    let ndc = pixel / viewport * 2.0 - Vec2::ONE;
    let p = inv_view_proj * Vec4::new(ndc.x, ndc.y, depth, 1.0);
    p.truncate() / p.w
}

/// The plane through `a`, `b`, `c` with its normal pointing away from `inside`.
fn plane(a: Vec3, b: Vec3, c: Vec3, inside: Vec3) -> Vec4 {
    let n = (b - a).cross(c - a).normalize();
    let p = n.extend(-n.dot(a));
    if p.truncate().dot(inside) + p.w > 0.0 {
        -p
    } else {
        p
    }
}

/// The six planes bounding one tile's geometry, normals pointing out.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TileSlab {
    /// Left, right, top, bottom (through the eye), near, far.
    pub planes: [Vec4; 6],
}

impl TileSlab {
    /// The slab of tile (`tx`, `ty`) of a `viewport`-sized image seen from `eye`,
    /// between reverse-Z depths `nearest` (largest) and `farthest` (smallest).
    pub fn new(
        inv_view_proj: Mat4,
        eye: Vec3,
        viewport: Vec2,
        tile: (u32, u32),
        nearest: f32,
        farthest: f32,
    ) -> Self {
        let lo = Vec2::new(tile.0 as f32, tile.1 as f32) * TILE_SIZE as f32;
        let hi = (lo + Vec2::splat(TILE_SIZE as f32)).min(viewport);
        let at = |x: f32, y: f32, d: f32| unproject(inv_view_proj, viewport, Vec2::new(x, y), d);
        let n00 = at(lo.x, lo.y, nearest);
        let n10 = at(hi.x, lo.y, nearest);
        let n01 = at(lo.x, hi.y, nearest);
        let n11 = at(hi.x, hi.y, nearest);
        let f00 = at(lo.x, lo.y, farthest);
        let f10 = at(hi.x, lo.y, farthest);
        let f01 = at(lo.x, hi.y, farthest);
        let f11 = at(hi.x, hi.y, farthest);
        let centre = (n00 + n11 + f00 + f11) * 0.25;
        let facing = |p: Vec4, towards_eye: bool| {
            let eye_side = p.truncate().dot(eye) + p.w > 0.0;
            if eye_side == towards_eye {
                p
            } else {
                -p
            }
        };
        Self {
            planes: [
                plane(eye, n00, n01, centre),
                plane(eye, n10, n11, centre),
                plane(eye, n00, n10, centre),
                plane(eye, n01, n11, centre),
                facing(plane(n00, n10, n01, centre), true),
                facing(plane(f00, f10, f01, centre), false),
            ],
        }
    }

    /// How far the sphere is outside the slab: the largest signed distance of
    /// its centre from a plane minus its radius. At most zero: the light is listed.
    pub fn margin(&self, centre: Vec3, radius: f32) -> f32 {
        self.planes
            .iter()
            .map(|p| p.truncate().dot(centre) + p.w - radius)
            .fold(f32::NEG_INFINITY, f32::max)
    }

    /// Whether a light at `centre` with cutoff `radius` is listed for the tile.
    pub fn touches(&self, centre: Vec3, radius: f32) -> bool {
        self.margin(centre, radius) <= 0.0
    }
}

/// A sphere (centre, radius) holding everything a spot lights: the part of
/// the ball of radius `range` around `apex` inside the cone about unit `axis`
/// with half-angle cosine `cos_half`. Up to 45 degrees the sphere through the
/// apex and the rim circle (radius `range / (2 cos)`), up to 90 the sphere
/// around the rim circle (radius `range sin`); wider spots keep the ball.
/// Mirrors `light_bounds` in `shaders/include/tiles.glsl`.
pub fn spot_bounds(apex: Vec3, axis: Vec3, cos_half: f32, range: f32) -> (Vec3, f32) {
    if cos_half <= 0.0 {
        return (apex, range);
    }
    if cos_half >= std::f32::consts::FRAC_1_SQRT_2 {
        let r = range / (2.0 * cos_half);
        return (apex + axis * r, r);
    }
    (
        apex + axis * (range * cos_half),
        range * (1.0 - cos_half * cos_half).sqrt(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_render::camera::reverse_z_projection;

    /// A camera at the origin looking down -Z, 90 degrees vertical field of view,
    /// square 64x64 image (4x4 tiles), and its reverse-Z depth of view distance `z`.
    fn setup() -> (Mat4, Vec2) {
        let proj = reverse_z_projection(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 100.0);
        (proj.inverse(), Vec2::splat(64.0))
    }

    fn depth_at(distance: f32) -> f32 {
        let proj = reverse_z_projection(std::f32::consts::FRAC_PI_2, 1.0, 0.1, 100.0);
        let c = proj * Vec4::new(0.0, 0.0, -distance, 1.0);
        c.z / c.w
    }

    #[test]
    fn grids_count_partial_tiles() {
        assert_eq!(tile_grid(1280, 720), (80, 45));
        assert_eq!(tile_grid(1920, 1080), (120, 68));
        assert_eq!(tile_grid(1, 1), (1, 1));
    }

    #[test]
    fn unprojecting_the_centre_at_a_depth_gives_that_distance_along_the_view() {
        let (inv, vp) = setup();
        let p = unproject(inv, vp, Vec2::splat(32.0), depth_at(10.0));
        assert!((p - Vec3::new(0.0, 0.0, -10.0)).length() < 1e-3, "{p}");
    }

    #[test]
    fn spheres_inside_beside_and_beyond_a_tile_slab() {
        let (inv, vp) = setup();
        // Tile (2, 2) covers pixels 32..48 in x and y: x from 0 to half the
        // half-width at each distance; slab from 10 to 12 units away.
        let slab = TileSlab::new(inv, Vec3::ZERO, vp, (2, 2), depth_at(10.0), depth_at(12.0));
        // Inside: x = 2.5, y = -2.5 at z = -11 (the image's y runs down, world y up).
        assert!(slab.touches(Vec3::new(2.5, -2.5, -11.0), 0.1));
        // Beyond the far face by 1 unit: radius 0.9 misses, 1.1 reaches.
        assert!(!slab.touches(Vec3::new(2.5, -2.5, -13.0), 0.9));
        assert!(slab.touches(Vec3::new(2.5, -2.5, -13.0), 1.1));
        // In front of the near face.
        assert!(!slab.touches(Vec3::new(2.5, -2.5, -8.0), 1.5));
        // Left of the tile's left plane (x = 0) by 1 unit.
        assert!(!slab.touches(Vec3::new(-1.0, -2.5, -11.0), 0.9));
        assert!(slab.touches(Vec3::new(-1.0, -2.5, -11.0), 1.1));
        // Above it (world y > 0 is the tile row above).
        assert!(!slab.touches(Vec3::new(2.5, 1.0, -11.0), 0.9));
    }

    #[test]
    fn a_flat_slab_lists_spheres_that_cross_its_depth() {
        let (inv, vp) = setup();
        let d = depth_at(10.0);
        let slab = TileSlab::new(inv, Vec3::ZERO, vp, (2, 2), d, d);
        assert!(slab.touches(Vec3::new(2.5, -2.5, -10.5), 0.6));
        assert!(!slab.touches(Vec3::new(2.5, -2.5, -10.5), 0.4));
        assert!(!slab.touches(Vec3::new(2.5, -2.5, -9.5), 0.4));
        let m = slab.margin(Vec3::new(2.5, -2.5, -10.5), 0.4);
        assert!((m - 0.1).abs() < 1e-3, "{m}");
    }

    #[test]
    fn spot_bounds_hold_the_lit_sector_and_are_tighter_than_the_range_ball() {
        let apex = Vec3::new(1.0, 2.0, 3.0);
        let axis = Vec3::new(0.3, -1.0, 0.2).normalize();
        let helper = axis.cross(Vec3::X).normalize();
        let other = axis.cross(helper);
        let range = 5.0;
        for degrees in [
            1.0f32, 10.0, 30.0, 44.9, 45.0, 45.1, 60.0, 89.0, 90.0, 120.0, 180.0,
        ] {
            let cos_half = degrees.to_radians().cos();
            let (centre, radius) = spot_bounds(apex, axis, cos_half, range);
            assert!(radius <= range * 1.0001, "{degrees}: {radius}");
            // Points of the lit sector: distances 0..range, angles 0..half, all around.
            for i in 0..=16 {
                for j in 0..=16 {
                    for k in 0..8 {
                        let d = range * i as f32 / 16.0;
                        let angle = degrees.min(180.0).to_radians() * j as f32 / 16.0;
                        let around = std::f32::consts::TAU * k as f32 / 8.0;
                        let side = helper * around.cos() + other * around.sin();
                        let p = apex + (axis * angle.cos() + side * angle.sin()) * d;
                        let outside = p.distance(centre) - radius;
                        assert!(
                            outside <= 1e-4 * range,
                            "{degrees} deg: {p} is {outside} outside"
                        );
                    }
                }
            }
        }
        // A 10-degree spot's sphere has about half the range ball's radius (an eighth of its volume).
        let (_, narrow) = spot_bounds(apex, axis, 10f32.to_radians().cos(), range);
        assert!((narrow / range - 1.0 / (2.0 * 10f32.to_radians().cos())).abs() < 1e-6);
        assert!(narrow < 0.51 * range);
    }
}
