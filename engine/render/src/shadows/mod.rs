//! Shadow views, pure math: the sun's cascades fitted each frame to slices of
//! the camera's view volume (orthographic, forward Z), one perspective view per
//! shadow-casting spot cone and per area light (`perspective`), their tiles in
//! the shadow-map atlas (`atlas`), and the record the shaders read (`Shadows`
//! in `shaders/include/shadows.glsl`).
//!
//! Atlas: the graph's `shadow_map` (`resolution` squared) is cut into a
//! `grid` x `grid` array of square tiles, `grid = ceil(sqrt(views))`; views are
//! the cascades, then the spots, then the area lights, then six cube faces per
//! shadowed point light (`points`). One cascade and nothing else uses the
//! whole map.

mod atlas;
mod perspective;
mod points;

pub use atlas::Atlas;
pub use perspective::{area_clip, area_emitter, spot_clip};
pub use points::{shadowed_points, CUBE_FACES, MAX_POINT_SHADOWS};

use crate::gpu_types::{bytes_of, GpuShadowView, GpuShadowsHeader};
use crate::lights::LightSet;
use glam::{Mat4, Vec3, Vec4};
use weft_scene::Aabb;

/// Most sun cascades (`ShadowAtlas` rejects more).
pub const MAX_CASCADES: u32 = 4;
/// Most spot cones given a shadow view; later spots are unshadowed.
pub const MAX_SPOT_SHADOWS: u32 = 8;
/// Area lights (rectangles, discs, emissive polygons) given a shadow view:
/// the first ones in record order.
pub const MAX_AREA_SHADOWS: u32 = 4;
/// Half-angle of an area light's view: its hemisphere but the 10° above its
/// plane, where it sends little light (cos 80° = 0.17 of its head-on
/// radiance per unit area).
pub const AREA_HALF_ANGLE_DEGREES: f32 = 80.0;
/// Largest manual PCF radius (a 15x15 kernel of 2x2 filtered taps; `ShadowAtlas` rejects more).
pub const MAX_PCF_RADIUS: u32 = 7;
/// Bytes before the first view record: counts, splits, camera forward + normal bias.
pub const HEADER_BYTES: usize = std::mem::size_of::<GpuShadowsHeader>();
/// Bytes of one view record: clip matrix, lookup matrix, tile bounds, texel size.
pub const VIEW_BYTES: usize = std::mem::size_of::<GpuShadowView>();
/// Bytes of the whole record with room for every view.
pub const SHADOWS_BYTES: usize = HEADER_BYTES
    + VIEW_BYTES
        * (MAX_CASCADES + MAX_SPOT_SHADOWS + MAX_AREA_SHADOWS + 6 * MAX_POINT_SHADOWS) as usize;

/// A shadow pass's settings: the `ShadowAtlas` provider's arguments
/// (`providers.rs` declares their ranges and defaults).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowSettings {
    /// Sun cascades, 1..=[`MAX_CASCADES`].
    pub cascades: u32,
    /// Manual PCF kernel radius r: (2r+1)^2 taps, each a hardware 2x2 compare.
    pub pcf_radius: u32,
    /// Lookup offset along the surface normal, in shadow texels per kernel ring
    /// (the offset is `normal_bias * (pcf_radius + 1)` texels).
    pub normal_bias: f32,
    /// Split blend: 0 uniform, 1 logarithmic (practical split scheme).
    pub split_lambda: f32,
    /// Area lights given soft shadows, 0..=[`MAX_AREA_SHADOWS`]: the first
    /// ones in record order; 0 turns area shadows off.
    pub area_lights: u32,
    /// Point lights given cube shadows, 0..=[`MAX_POINT_SHADOWS`]
    /// ([`shadowed_points`] picks them).
    pub point_lights: u32,
}

impl Default for ShadowSettings {
    fn default() -> Self {
        Self {
            cascades: 1,
            pcf_radius: 1,
            normal_bias: 1.0,
            split_lambda: 0.75,
            area_lights: MAX_AREA_SHADOWS,
            point_lights: MAX_POINT_SHADOWS,
        }
    }
}

impl ShadowSettings {
    /// Texels kept free at a tile's edge so a kernel never reads a neighbour tile.
    fn margin(&self) -> f32 {
        self.pcf_radius as f32 + 2.0
    }
}

/// The camera's view volume at this frame, what the sun's cascades are fitted to.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewVolume {
    /// Camera position.
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit right and up vectors.
    pub right: Vec3,
    /// Unit up vector.
    pub up: Vec3,
    /// tan(fov_y / 2).
    pub tan_half_y: f32,
    /// Width / height.
    pub aspect: f32,
    /// Near and far clip distances.
    pub near: f32,
    /// Far clip distance.
    pub far: f32,
}

impl ViewVolume {
    /// The volume of a camera posed at `eye` with `rotation` (looking down -Z).
    pub fn new(
        eye: Vec3,
        rotation: glam::Quat,
        fov_y: f32,
        aspect: f32,
        near: f32,
        far: f32,
    ) -> Self {
        Self {
            eye,
            forward: rotation * Vec3::NEG_Z,
            right: rotation * Vec3::X,
            up: rotation * Vec3::Y,
            tan_half_y: (fov_y * 0.5).tan(),
            aspect,
            near,
            far,
        }
    }

    /// The eight corners of the slice between view depths `near` and `far`.
    pub fn corners(&self, near: f32, far: f32) -> [Vec3; 8] {
        let mut out = [Vec3::ZERO; 8];
        for (i, c) in out.iter_mut().enumerate() {
            let d = if i & 4 == 0 { near } else { far };
            let y = d * self.tan_half_y * if i & 2 == 0 { -1.0 } else { 1.0 };
            let x = d * self.tan_half_y * self.aspect * if i & 1 == 0 { -1.0 } else { 1.0 };
            *c = self.eye + self.forward * d + self.right * x + self.up * y;
        }
        out
    }

    /// The far distance worth covering: the camera's far plane, or the farthest
    /// corner of `bounds` along the view direction if nearer.
    pub fn shadow_far(&self, bounds: &Aabb) -> f32 {
        if bounds.is_empty() {
            return self.far;
        }
        let deepest = aabb_corners(bounds)
            .iter()
            .map(|c| (*c - self.eye).dot(self.forward))
            .fold(f32::MIN, f32::max);
        deepest.min(self.far).max(self.near * 2.0)
    }
}

fn aabb_corners(b: &Aabb) -> [Vec3; 8] {
    std::array::from_fn(|i| {
        Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        )
    })
}

/// Far view depth of each of `count` cascades between `near` and `far`: the
/// practical split scheme, `lambda` of the logarithmic split plus `1 - lambda`
/// of the uniform one, so near cascades stay small without starving far ones.
pub fn cascade_splits(near: f32, far: f32, count: u32, lambda: f32) -> Vec<f32> {
    let near = near.max(1e-4);
    let far = far.max(near * 1.0001);
    (1..=count.max(1))
        .map(|i| {
            let f = i as f32 / count.max(1) as f32;
            let log = near * (far / near).powf(f);
            let uniform = near + (far - near) * f;
            lambda * log + (1.0 - lambda) * uniform
        })
        .collect()
}

/// One rendered shadow view.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowView {
    /// World to clip space, for drawing casters into the tile (forward Z, Y flipped).
    pub clip: Mat4,
    /// World to atlas coordinates for `textureProj` (xy / w texture coordinates, z / w depth).
    pub lookup: Mat4,
    /// Tile corner and side in texels.
    pub viewport: [u32; 3],
    /// Texture-coordinate bounds inside which a kernel stays in the tile.
    pub rect: Vec4,
    /// World size of one texel: constant for the sun, per unit distance for spots.
    pub texel: f32,
    /// Whether `texel` scales with distance from the light (spots).
    pub perspective: bool,
    /// For an area light's view, the light's size (the side of a square of
    /// its area) and the view's near and far depth, which soft shadows
    /// need; `None` for suns and spots.
    pub area: Option<[f32; 3]>,
}

/// An orthographic world-to-clip matrix for the sun travelling along `direction`:
/// x/y cover the part of `slice` (points of a view-volume slice) that lies inside
/// `bounds`, squared, widened by `margin` texels and snapped to whole texels of a
/// `tile`-texel map (so moving the camera does not make edges shimmer); z covers
/// all of `bounds`, so casters outside the view still cast. Returns the matrix and
/// the world size of one texel.
pub fn fit_sun(
    direction: Vec3,
    slice: &[Vec3; 8],
    bounds: &Aabb,
    tile: u32,
    margin: f32,
) -> (Mat4, f32) {
    let (dir, up) = view_axes(direction);
    let (center, radius) = if bounds.is_empty() {
        (Vec3::ZERO, 1.0)
    } else {
        (bounds.center(), (bounds.diagonal() * 0.5).max(1e-3))
    };
    // A fixed light-space origin (the scene's centre), so snapping to texels in
    // light space is stable from frame to frame.
    let view = Mat4::look_at_rh(center - dir * radius * 2.0, center, up);
    let to_light = |p: &Vec3| view.transform_point3(*p);
    let scene_pts: Vec<Vec3> = if bounds.is_empty() {
        aabb_corners(&Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        })
        .iter()
        .map(to_light)
        .collect()
    } else {
        aabb_corners(bounds).iter().map(to_light).collect()
    };
    let lo = |pts: &[Vec3]| pts.iter().fold(Vec3::splat(f32::MAX), |a, p| a.min(*p));
    let hi = |pts: &[Vec3]| pts.iter().fold(Vec3::splat(f32::MIN), |a, p| a.max(*p));
    let (s_lo, s_hi) = (lo(&scene_pts), hi(&scene_pts));
    let view_pts: Vec<Vec3> = slice.iter().map(to_light).collect();
    let (v_lo, v_hi) = (lo(&view_pts), hi(&view_pts));
    let (mut min, mut max) = (v_lo.max(s_lo), v_hi.min(s_hi));
    if min.x >= max.x || min.y >= max.y {
        (min, max) = (s_lo, s_hi);
    }
    let scene_side = (s_hi.x - s_lo.x).max(s_hi.y - s_lo.y).max(1e-4);
    let wanted = (max.x - min.x).max(max.y - min.y).max(scene_side * 1e-3);
    // Quarter-octave steps of the scene's extent: the texel size changes only when
    // the view's footprint crosses a step, not every frame.
    let steps = ((wanted / scene_side).log2() * 4.0).ceil() / 4.0;
    let tile = tile.max(1) as f32;
    let usable = (tile - 2.0 * margin).max(1.0);
    let side = scene_side * steps.exp2() * tile / usable;
    let texel = side / tile;
    let half = side * 0.5;
    let snap = |v: f32| (v / texel).round() * texel;
    let cx = snap((min.x + max.x) * 0.5);
    let cy = snap((min.y + max.y) * 0.5);
    // Light-space z is negative in front of the light; pad by 1% so bounds-hugging
    // casters are not clipped.
    let pad = (s_hi.z - s_lo.z).abs() * 0.01 + 1e-4;
    let (near, far) = (-s_hi.z - pad, -s_lo.z + pad);
    let mut proj = Mat4::orthographic_rh(cx - half, cx + half, cy - half, cy + half, near, far);
    proj.y_axis.y = -proj.y_axis.y;
    (proj * view, texel)
}

/// Everything about this frame's shadows: the views and the record shaders read.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowFrame {
    /// Cascades first, then spots.
    pub views: Vec<ShadowView>,
    /// Cascades rendered (0 without a sun).
    pub cascades: u32,
    /// Spot views rendered.
    pub spots: u32,
    /// Light index of the first spot cone (spot view k belongs to light `first_spot + k`).
    pub first_spot: u32,
    /// Area-light views rendered, after the spots'.
    pub areas: u32,
    /// Light index of the first area light (area view k belongs to light
    /// `first_area + k`: rectangles and discs, then emissive polygons).
    pub first_area: u32,
    /// The point lights with cube views (six each, after the area views).
    pub points: Vec<u32>,
    /// Far view depth of each cascade.
    pub splits: [f32; 4],
    /// The camera's view direction, for picking a cascade by view depth.
    pub forward: Vec3,
}

/// A light view's unit forward axis for `direction` (straight down if it has
/// no length), and an up vector not parallel to it, for `look_at`.
fn view_axes(direction: Vec3) -> (Vec3, Vec3) {
    let dir = direction.try_normalize().unwrap_or(Vec3::NEG_Y);
    let up = if dir.cross(Vec3::Y).length_squared() < 1e-6 {
        Vec3::Z
    } else {
        Vec3::Y
    };
    (dir, up)
}

/// Lays out and fits this frame's views for a `atlas_size` squared shadow map.
pub fn shadow_frame(
    settings: &ShadowSettings,
    atlas_size: u32,
    volume: &ViewVolume,
    lights: &LightSet,
    bounds: &Aabb,
) -> ShadowFrame {
    let cascades = if lights.sun_direction.is_some() {
        settings.cascades.clamp(1, MAX_CASCADES)
    } else {
        0
    };
    let spots = lights.spot_cones.min(MAX_SPOT_SHADOWS);
    let first_area = lights.first_area();
    let emitters: Vec<(Vec3, Vec3, f32)> = lights
        .records
        .iter()
        .skip(first_area as usize)
        .map_while(area_emitter)
        .take(settings.area_lights.min(MAX_AREA_SHADOWS) as usize)
        .collect();
    let areas = emitters.len() as u32;
    let points = shadowed_points(lights, volume.eye, settings.point_lights);
    let atlas = Atlas::new(
        atlas_size,
        cascades + spots + areas + 6 * points.len() as u32,
    );
    let margin = settings.margin();
    let far = volume.shadow_far(bounds);
    let near = volume.near.min(far * 0.5);
    let ends = cascade_splits(near, far, cascades.max(1), settings.split_lambda);
    let mut splits = [0.0; 4];
    let mut views = Vec::new();
    let mut start = near;
    for (i, &end) in ends.iter().enumerate().take(cascades as usize) {
        let dir = lights.sun_direction.unwrap_or(Vec3::NEG_Y);
        let (clip, texel) = fit_sun(dir, &volume.corners(start, end), bounds, atlas.tile, margin);
        views.push(view(&atlas, i as u32, clip, texel, false, margin));
        splits[i] = end;
        start = end;
    }
    let first_spot = lights.first_spot_cone();
    let spot_records = lights.records.iter().skip(first_spot as usize);
    for (k, spot) in (0..spots).zip(spot_records) {
        let (clip, texel) = spot_clip(
            spot.position_range.truncate(),
            spot.direction_type.truncate(),
            spot.attenuation_cos.w,
            spot.position_range.w,
            atlas.tile,
            margin,
        );
        views.push(view(&atlas, cascades + k, clip, texel, true, margin));
    }
    let corners = aabb_corners(bounds);
    for (k, (centre, facing, size)) in emitters.into_iter().enumerate() {
        let reach = corners
            .iter()
            .map(|c| (*c - centre).dot(facing))
            .fold(0.0f32, f32::max);
        let (clip, texel, near) = area_clip(centre, facing, reach * 1.01, atlas.tile, margin);
        let mut v = view(
            &atlas,
            cascades + spots + k as u32,
            clip,
            texel,
            true,
            margin,
        );
        v.area = Some([size, near, reach.max(1e-3) * 1.01]);
        views.push(v);
    }
    for &light in &points {
        let record = &lights.records[light as usize];
        for face in CUBE_FACES {
            let at = views.len() as u32;
            let (position, range) = (record.position_range.truncate(), record.position_range.w);
            let (clip, texel) = spot_clip(
                position,
                face,
                std::f32::consts::FRAC_1_SQRT_2,
                range,
                atlas.tile,
                margin,
            );
            views.push(view(&atlas, at, clip, texel, true, margin));
        }
    }
    ShadowFrame {
        views,
        cascades,
        spots,
        first_spot,
        areas,
        first_area,
        points,
        splits,
        forward: volume.forward,
    }
}

fn view(
    atlas: &Atlas,
    i: u32,
    clip: Mat4,
    texel: f32,
    perspective: bool,
    margin: f32,
) -> ShadowView {
    ShadowView {
        clip,
        lookup: atlas.clip_to_uv(i) * clip,
        viewport: atlas.viewport(i),
        rect: atlas.inner_rect(i, margin - 1.0),
        texel,
        perspective,
        area: None,
    }
}

impl ShadowFrame {
    /// The bytes of the `Shadows` record: counts (cascades, spot views, first
    /// spot light, PCF radius), cascade splits, camera forward and normal bias,
    /// then the views.
    pub fn pack(&self, settings: &ShadowSettings) -> Vec<u8> {
        let header = GpuShadowsHeader {
            counts: glam::UVec4::new(
                self.cascades,
                self.spots,
                self.first_spot,
                settings.pcf_radius,
            ),
            splits: Vec4::from_array(self.splits),
            forward: self
                .forward
                .extend(settings.normal_bias * (settings.pcf_radius as f32 + 1.0)),
            areas: glam::UVec4::new(
                self.cascades + self.spots,
                self.first_area,
                self.areas,
                self.points.len() as u32,
            ),
            point_lights: std::array::from_fn(|k| self.points.get(k).copied().unwrap_or(u32::MAX))
                .into(),
        };
        let views: Vec<GpuShadowView> = self
            .views
            .iter()
            .map(|v| GpuShadowView {
                clip: v.clip,
                lookup: v.lookup,
                rect: v.rect,
                texel: Vec4::new(v.texel, if v.perspective { 1.0 } else { 0.0 }, 0.0, 0.0),
                light: v.area.map_or(Vec4::ZERO, |[size, near, far]| {
                    Vec4::new(size, near, far, 0.0)
                }),
            })
            .collect();
        let mut bytes = bytes_of(&[header]).to_vec();
        bytes.extend_from_slice(bytes_of(&views));
        bytes
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4Swizzles;

    fn cube(h: f32) -> Aabb {
        Aabb {
            min: Vec3::splat(-h),
            max: Vec3::splat(h),
        }
    }

    fn volume() -> ViewVolume {
        let rot = glam::Quat::from_rotation_y(0.3);
        ViewVolume::new(Vec3::new(0.0, 1.0, 8.0), rot, 1.0, 16.0 / 9.0, 0.1, 100.0)
    }

    #[test]
    fn splits_blend_logarithmic_and_uniform() {
        let s = cascade_splits(1.0, 100.0, 2, 1.0);
        assert!(
            (s[0] - 10.0).abs() < 1e-4 && (s[1] - 100.0).abs() < 1e-3,
            "{s:?}"
        );
        let u = cascade_splits(1.0, 101.0, 4, 0.0);
        assert_eq!(
            u.iter().map(|v| v.round() as i32).collect::<Vec<_>>(),
            [26, 51, 76, 101]
        );
        let p = cascade_splits(1.0, 100.0, 2, 0.5);
        assert!((p[0] - 0.5 * (10.0 + 50.5)).abs() < 1e-3, "{p:?}");
    }

    #[test]
    fn the_sun_view_holds_the_visible_slice_and_every_caster_in_depth() {
        let v = volume();
        let bounds = cube(3.0);
        let slice = v.corners(0.1, 12.0);
        let (m, texel) = fit_sun(Vec3::new(-0.3, -1.0, -0.2), &slice, &bounds, 1024, 3.0);
        // Every point of the slice inside the bounds projects inside x/y.
        for i in 0..=20 {
            for j in 0..=20 {
                let p =
                    slice[0].lerp(slice[7], i as f32 / 20.0) + Vec3::Y * (j as f32 / 10.0 - 1.0);
                if (p.abs().max_element()) > 3.0 {
                    continue;
                }
                let c = m * p.extend(1.0);
                assert!(c.xy().abs().max_element() <= 1.0, "{p} -> {c}");
            }
        }
        // Every corner of the bounds lies within the depth range.
        for c in aabb_corners(&bounds) {
            let z = (m * c.extend(1.0)).z;
            assert!((0.0..=1.0).contains(&z), "{c}: {z}");
        }
        // Texel world size matches the ortho width over the tile.
        let width = 2.0 / m.row(0).xyz().length();
        assert!((width / 1024.0 - texel).abs() < 1e-5 * width);
    }

    #[test]
    fn moving_the_camera_moves_the_sun_view_by_whole_texels() {
        let bounds = cube(50.0);
        let dir = Vec3::new(-0.3, -1.0, -0.2);
        let a = volume();
        let mut b = a;
        b.eye += Vec3::new(0.0137, 0.0, -0.0071);
        let (ma, ta) = fit_sun(dir, &a.corners(0.1, 10.0), &bounds, 1024, 3.0);
        let (mb, tb) = fit_sun(dir, &b.corners(0.1, 10.0), &bounds, 1024, 3.0);
        assert_eq!(ta, tb, "same footprint step, same texel size");
        // A fixed world point shifts by a whole number of texels (2 / tile in clip units).
        let p = Vec3::new(1.0, 0.5, -2.0).extend(1.0);
        let shift = ((mb * p).xy() - (ma * p).xy()) * 1024.0 / 2.0;
        assert!(
            (shift - shift.round()).abs().max_element() < 1e-2,
            "{shift}"
        );
    }

    #[test]
    fn area_lights_get_views_after_the_spots_up_to_the_setting() {
        let area = |x: f32| {
            weft_scene::Light::Area(weft_scene::AreaLight {
                shape: weft_scene::AreaShape::Rect {
                    width: 1.0,
                    height: 0.5,
                },
                position: Vec3::new(x, 4.0, 0.0),
                orientation: glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
                emission: Vec3::ONE,
                two_sided: false,
            })
        };
        let bounds = cube(5.0);
        let lights = crate::lights::pack_lights(&[area(-1.0), area(1.0)], &bounds);
        let frame = |area_lights| {
            let settings = ShadowSettings {
                area_lights,
                ..ShadowSettings::default()
            };
            shadow_frame(&settings, 2048, &volume(), &lights, &bounds)
        };
        let both = frame(4);
        assert_eq!((both.cascades, both.spots, both.areas), (0, 0, 2));
        assert_eq!(both.first_area, lights.first_area());
        // Each view looks down from its light, the size of a 1 x 0.5 light.
        for v in &both.views {
            let [size, near, far] = v.area.expect("an area view");
            assert!((size - 0.5f32.sqrt()).abs() < 1e-6 && near > 0.0 && far > 4.0);
        }
        assert_eq!(frame(1).areas, 1);
        let none = frame(0);
        assert_eq!((none.areas, none.views.len()), (0, 0));
    }
}
