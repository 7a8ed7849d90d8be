//! The CPU mirror of tiled light culling (`shaders/light_cull.comp`): the
//! frustum slab of one screen tile between its nearest and farthest reverse-Z
//! depths, the box and 2.5D depth mask of its surface points (the graph's
//! `tile_box` and `tile_depth_mask` features), whether a light's bounding
//! sphere reaches them, and the spot bounds. Tests compare the GPU's per-tile
//! counts with this; keep the two in step.

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

/// Slices of a tile's range of eye distances in the 2.5D depth mask.
pub const DEPTH_SLICES: u32 = 32;

/// A tile's surface points as the tighter culling tests see them: their
/// world-space box and, per slice of their range of distances from the eye,
/// whether a point lies in it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TileSurface {
    /// Corners of the box around the points.
    pub min: Vec3,
    /// See `min`.
    pub max: Vec3,
    /// Nearest and farthest eye distance of a point.
    pub distances: (f32, f32),
    eye: Vec3,
    points: usize,
}

impl TileSurface {
    /// The box and distance range of `points` seen from `eye`; `None` when
    /// there are none (a background tile, which lists no light).
    pub fn new(points: &[Vec3], eye: Vec3) -> Option<Self> {
        let first = *points.first()?;
        let (mut min, mut max) = (first, first);
        let (mut near, mut far) = (f32::INFINITY, 0.0f32);
        for p in points {
            min = min.min(*p);
            max = max.max(*p);
            let d = p.distance(eye);
            near = near.min(d);
            far = far.max(d);
        }
        Some(Self {
            min,
            max,
            distances: (near, far),
            eye,
            points: points.len(),
        })
    }

    /// How far the sphere is from the box, minus its radius: at most zero, the
    /// box test lists it.
    pub fn box_margin(&self, centre: Vec3, radius: f32) -> f32 {
        let gap = (self.min - centre).max(centre - self.max).max(Vec3::ZERO);
        gap.length() - radius
    }

    /// Slices per unit of eye distance (one slice for a flat tile).
    fn slices_per_unit(&self) -> f32 {
        DEPTH_SLICES as f32 / (self.distances.1 - self.distances.0).max(1e-30)
    }

    /// The slice (fractional) of eye distance `d`, before rounding down.
    fn slice(&self, d: f32) -> f32 {
        (d - self.distances.0) * self.slices_per_unit()
    }

    /// The depth mask of `points` (the same points `new` was given), with every
    /// point's slice moved by `slack` slices towards (negative) or away from
    /// (positive) the slice boundaries: a positive slack marks every slice a
    /// point may fall in given rounding, a negative one only those it surely does.
    pub fn depth_mask(&self, points: &[Vec3], slack: f32) -> u32 {
        debug_assert_eq!(points.len(), self.points);
        let last = (DEPTH_SLICES - 1) as f32;
        let mut mask = 0u32;
        for p in points {
            let s = self.slice(p.distance(self.eye));
            let (lo, hi) = ((s - slack).clamp(0.0, last), (s + slack).clamp(0.0, last));
            let (lo, hi) = (lo.floor() as u32, hi.floor() as u32);
            if slack >= 0.0 || lo == hi {
                for k in lo.min(hi)..=hi.max(lo) {
                    mask |= 1 << k;
                }
            }
        }
        mask
    }

    /// The slices a sphere's range of eye distances covers, widened (positive
    /// `slack`) or narrowed (negative) by `slack` slices at each end; zero when
    /// the range misses every slice.
    pub fn sphere_slices(&self, centre: Vec3, radius: f32, slack: f32) -> u32 {
        let d = centre.distance(self.eye);
        let first = (self.slice(d - radius) - slack).floor();
        let last = (self.slice(d + radius) + slack).floor();
        let top = (DEPTH_SLICES - 1) as f32;
        if last < 0.0 || first > top || first > last {
            return 0;
        }
        let (first, last) = (first.clamp(0.0, top) as u32, last.clamp(0.0, top) as u32);
        (u32::MAX >> (31 - last)) & (u32::MAX << first)
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
    use weft_scene::reverse_z_projection;

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
    fn a_surface_box_lists_spheres_that_reach_the_points_box() {
        let points = [Vec3::new(0.0, 0.0, -10.0), Vec3::new(2.0, 0.0, -12.0)];
        let surface = TileSurface::new(&points, Vec3::ZERO).unwrap();
        assert_eq!(
            (surface.min, surface.max),
            (points[1].with_x(0.0), points[0].with_x(2.0))
        );
        // Above the flat box by 1 unit: radius 1 is on it.
        assert!((surface.box_margin(Vec3::new(1.0, 1.0, -11.0), 0.9) - 0.1).abs() < 1e-6);
        assert!(surface.box_margin(Vec3::new(1.0, 1.0, -11.0), 1.1) < 0.0);
        // Off a corner: distance sqrt(2).
        let m = surface.box_margin(Vec3::new(3.0, 1.0, -10.0 + 0.0), 0.0);
        assert!((m - 2f32.sqrt()).abs() < 1e-6, "{m}");
        assert!(TileSurface::new(&[], Vec3::ZERO).is_none());
    }

    #[test]
    fn the_depth_mask_marks_occupied_slices_and_spheres_meet_them() {
        // Points at eye distances 10, 10.5 and 18 of a range 10..18: slices 0, 2 and 31.
        let points = [
            Vec3::new(0.0, 0.0, -10.0),
            Vec3::new(0.0, 0.0, -10.5),
            Vec3::new(0.0, 0.0, -18.0),
        ];
        let surface = TileSurface::new(&points, Vec3::ZERO).unwrap();
        assert_eq!(surface.distances, (10.0, 18.0));
        let mask = surface.depth_mask(&points, 0.0);
        assert_eq!(mask, 1 | 1 << 2 | 1 << 31);
        // A sphere between the near points and the far one (distances 12..16)
        // covers slices 8..=24: empty, so a slab or box test would list it but
        // the mask does not.
        let between = surface.sphere_slices(Vec3::new(0.0, 0.0, -14.0), 2.0, 0.0);
        assert_eq!(between, (u32::MAX >> 7) & (u32::MAX << 8));
        assert_eq!(between & mask, 0);
        // Reaching the far point.
        assert_ne!(
            surface.sphere_slices(Vec3::new(0.0, 0.0, -19.0), 1.5, 0.0) & mask,
            0
        );
        // Wholly beyond or before the range.
        assert_eq!(
            surface.sphere_slices(Vec3::new(0.0, 0.0, -25.0), 1.0, 0.0),
            0
        );
        assert_eq!(
            surface.sphere_slices(Vec3::new(0.0, 0.0, -5.0), 1.0, 0.0),
            0
        );
        // A point on a slice boundary (10.25 is exactly slice 1) is marked
        // either side with slack and in neither surely.
        let edge = [points[0], Vec3::new(0.0, 0.0, -10.25), points[2]];
        let surface = TileSurface::new(&edge, Vec3::ZERO).unwrap();
        assert_eq!(surface.depth_mask(&edge, 0.05) & 0b11, 0b11);
        assert_eq!(surface.depth_mask(&edge, -0.05) & 0b10, 0);
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
