//! Point-light shadows: six 90° perspective views per shadowed point light
//! (a cube), in the atlas after the area lights. Which lights get them: the
//! `point_lights` budget of the `ShadowAtlas` provider, the lights whose
//! reach lies nearest the camera (brightest first among equals), kept in
//! light order so a light keeps its tiles while the choice holds.

use crate::emitters::luminance;
use crate::gpu_types::GpuLight;
use crate::lights::LightSet;
use glam::Vec3;

/// Most point lights given cube shadows.
pub const MAX_POINT_SHADOWS: u32 = 4;
/// The cube's faces, in the order the shader numbers them: +x, −x, +y, −y,
/// +z, −z (`point_visibility` in shaders/include/shadows.glsl).
pub const CUBE_FACES: [Vec3; 6] = [
    Vec3::X,
    Vec3::NEG_X,
    Vec3::Y,
    Vec3::NEG_Y,
    Vec3::Z,
    Vec3::NEG_Z,
];

/// The light indices (into `lights.records`) of the point lights given
/// shadows: at most `budget`, those whose sphere of reach lies nearest
/// `eye` (inside it counts as 0), the brighter first among equals, in
/// ascending index.
pub fn shadowed_points(lights: &LightSet, eye: Vec3, budget: u32) -> Vec<u32> {
    let first = lights.suns;
    let distance = |r: &GpuLight| {
        let gap = (r.position_range.truncate() - eye).length() - r.position_range.w;
        gap.max(0.0)
    };
    let mut points: Vec<(u32, &GpuLight)> = (first..first + lights.points)
        .filter_map(|i| Some((i, lights.records.get(i as usize)?)))
        .filter(|(_, r)| luminance(r.color_exponent.truncate()) > 0.0)
        .collect();
    points.sort_by(|(ia, a), (ib, b)| {
        distance(a)
            .total_cmp(&distance(b))
            .then(
                luminance(b.color_exponent.truncate())
                    .total_cmp(&luminance(a.color_exponent.truncate())),
            )
            .then(ia.cmp(ib))
    });
    let mut chosen: Vec<u32> = points
        .into_iter()
        .take(budget.min(MAX_POINT_SHADOWS) as usize)
        .map(|(i, _)| i)
        .collect();
    chosen.sort_unstable();
    chosen
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    fn point(at: Vec3, range: f32, colour: f32) -> GpuLight {
        GpuLight {
            position_range: at.extend(range),
            color_exponent: Vec4::splat(colour),
            ..bytemuck::Zeroable::zeroed()
        }
    }

    #[test]
    fn the_nearest_reaches_are_chosen_and_kept_in_light_order() {
        let lights = LightSet {
            records: vec![
                bytemuck::Zeroable::zeroed(), // a sun
                point(Vec3::new(10.0, 0.0, 0.0), 1.0, 1.0),
                point(Vec3::new(2.0, 0.0, 0.0), 1.0, 1.0),
                point(Vec3::new(0.0, 0.0, 30.0), 29.5, 1.0),
                point(Vec3::new(3.0, 0.0, 0.0), 5.0, 0.0),
                point(Vec3::new(0.0, 5.0, 0.0), 1.0, 2.0),
            ],
            suns: 1,
            points: 5,
            ..LightSet::default()
        };
        // Gaps: 9, 1, 0.5, (black), 4.
        assert_eq!(shadowed_points(&lights, Vec3::ZERO, 2), vec![2, 3]);
        assert_eq!(shadowed_points(&lights, Vec3::ZERO, 3), vec![2, 3, 5]);
        assert_eq!(shadowed_points(&lights, Vec3::ZERO, 0), Vec::<u32>::new());
        assert_eq!(shadowed_points(&lights, Vec3::ZERO, 99), vec![1, 2, 3, 5]);
    }
}
