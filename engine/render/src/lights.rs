//! Light records for the GPU: suns, then point lights, then spots, each with the
//! cutoff range both forward and deferred shading apply, so the light volumes
//! and the per-pixel loop cut light off at the same distance; area lights last.

use crate::gpu_types::GpuLight;
use crate::sanitize;
use glam::{Vec3, Vec4};
use std::f32::consts::PI;
use weft_scene::light::{derive_radius, DEFAULT_LUMINANCE_THRESHOLD};
use weft_scene::{Aabb, AreaLight, AreaShape, Attenuation, Light};

/// Bytes of one light record (`struct Light` in `shaders/include/scene.glsl`).
pub const LIGHT_BYTES: usize = std::mem::size_of::<GpuLight>();
/// Type code of a sun.
pub const SUN: f32 = 0.0;
/// Type code of a point light.
pub const POINT: f32 = 1.0;
/// Type code of a spot drawn with a cone volume.
pub const SPOT_CONE: f32 = 2.0;
/// Type code of a spot too wide for a cone, drawn with a sphere volume.
pub const SPOT_SPHERE: f32 = 3.0;
/// Type code of a rectangular area light.
pub const AREA_RECT: f32 = 4.0;
/// Type code of a disc area light.
pub const AREA_DISC: f32 = 5.0;
/// Type code of an emissive polygon (`crate::emitter_lights`), after every other record.
pub const AREA_POLYGON: f32 = 6.0;
/// Widest half-angle (degrees) drawn as a cone; wider cones would be huge or inverted.
pub const CONE_MAX_ANGLE: f32 = 70.0;

/// Whether a spot of half-angle `angle` (degrees) is drawn with a cone volume,
/// and so gets a shadow view; wider spots use a sphere and cast no shadow.
pub fn is_cone(angle: f32) -> bool {
    angle <= CONE_MAX_ANGLE
}

/// The scene's lights packed for the shaders.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct LightSet {
    /// Records in order: suns, points, spot cones, spot spheres, areas.
    pub records: Vec<GpuLight>,
    /// Number of suns.
    pub suns: u32,
    /// Number of point lights.
    pub points: u32,
    /// Number of spots drawn with cone volumes.
    pub spot_cones: u32,
    /// Number of spots too wide for a cone, drawn with sphere volumes.
    pub spot_spheres: u32,
    /// Number of area lights.
    pub areas: u32,
    /// Number of emissive polygons, the last records: raster passes shade
    /// them, the path tracer samples the emissive triangles instead.
    pub emitter_polygons: u32,
    /// Sum of the suns' ambient terms.
    pub ambient: Vec3,
    /// Direction of the first sun, for its shadow map.
    pub sun_direction: Option<Vec3>,
}

impl LightSet {
    /// Number of records but the emissive polygons (`frame.counts.w`).
    pub fn len(&self) -> u32 {
        self.suns + self.points + self.spot_cones + self.spot_spheres + self.areas
    }

    /// Whether there is no light at all.
    pub fn is_empty(&self) -> bool {
        self.records.is_empty()
    }

    /// Appends the emissive polygons' records (one each) after every other light.
    pub fn add_emitter_polygons(&mut self, polygons: &[GpuLight]) {
        self.records.extend_from_slice(polygons);
        self.emitter_polygons += polygons.len() as u32;
    }

    /// Index of the first point light record.
    pub fn first_point(&self) -> u32 {
        self.suns
    }

    /// Index of the first spot record drawn as a cone.
    pub fn first_spot_cone(&self) -> u32 {
        self.suns + self.points
    }

    /// Index of the first spot record drawn as a sphere.
    pub fn first_spot_sphere(&self) -> u32 {
        self.suns + self.points + self.spot_cones
    }

    /// Index of the first area light record.
    pub fn first_area(&self) -> u32 {
        self.first_spot_sphere() + self.spot_spheres
    }
}

/// Distance beyond which a light with this colour and falloff is dimmer than
/// one 8-bit step, or `fallback` when it never falls that low.
pub fn cutoff_range(color: Vec3, attenuation: &Attenuation, fallback: f32) -> f32 {
    derive_radius(color, attenuation, DEFAULT_LUMINANCE_THRESHOLD)
        .filter(|r| r.is_finite() && *r > 0.0)
        .unwrap_or(fallback)
}

/// One light as the shaders see it.
struct Record {
    position: Vec3,
    range: f32,
    direction: Vec3,
    kind: f32,
    color: Vec3,
    exponent: f32,
    attenuation: Attenuation,
    cos_cutoff: f32,
}

impl Record {
    /// Appends the record, its colour and falloff made finite and bounded
    /// (`sanitize`); a light whose position, direction or range is not finite
    /// lights nothing and is left out (false).
    fn pack(&self, records: &mut Vec<GpuLight>) -> bool {
        if !(self.position.is_finite() && self.direction.is_finite() && self.range.is_finite()) {
            return false;
        }
        let a = &self.attenuation;
        let falloff = |x: f32| sanitize::bounded(x, sanitize::RADIANCE_MAX);
        records.push(GpuLight {
            position_range: self.position.extend(self.range),
            direction_type: self.direction.extend(self.kind),
            color_exponent: sanitize::radiance(self.color)
                .extend(sanitize::bounded(self.exponent, sanitize::RADIANCE_MAX)),
            attenuation_cos: Vec4::new(
                falloff(a.constant),
                falloff(a.linear),
                falloff(a.quadratic),
                self.cos_cutoff,
            ),
        });
        true
    }
}

/// Packs `lights` (already animated to the frame's time); `bounds` gives the range of
/// lights that never fade out.
pub fn pack_lights(lights: &[Light], bounds: &Aabb) -> LightSet {
    let fallback = if bounds.is_empty() {
        100.0
    } else {
        (bounds.diagonal() * 2.0).max(1.0)
    };
    let mut set = LightSet::default();
    for light in lights {
        if let Light::Sun(s) = light {
            let dir = s.direction.try_normalize().unwrap_or(Vec3::NEG_Y);
            Record {
                position: Vec3::ZERO,
                range: 0.0,
                direction: dir,
                kind: SUN,
                color: s.color,
                exponent: 0.0,
                attenuation: Attenuation::NONE,
                cos_cutoff: -1.0,
            }
            .pack(&mut set.records)
            .then(|| set.suns += 1);
            set.ambient += sanitize::radiance(s.ambient);
            set.sun_direction.get_or_insert(dir);
        }
    }
    for light in lights {
        if let Light::Point(p) = light {
            let range = if p.radius.is_finite() && p.radius > 0.0 {
                p.radius
            } else {
                cutoff_range(p.color, &p.attenuation, fallback)
            };
            Record {
                position: p.position,
                range,
                direction: Vec3::ZERO,
                kind: POINT,
                color: p.color,
                exponent: 0.0,
                attenuation: p.attenuation,
                cos_cutoff: -1.0,
            }
            .pack(&mut set.records)
            .then(|| set.points += 1);
        }
    }
    for wide in [false, true] {
        for light in lights {
            let Light::Spot(s) = light else { continue };
            if is_cone(s.angle) == wide {
                continue;
            }
            let range = s
                .length
                .filter(|l| l.is_finite() && *l > 0.0)
                .unwrap_or_else(|| cutoff_range(s.color, &s.attenuation, fallback));
            let dir = s.direction.try_normalize().unwrap_or(Vec3::NEG_Y);
            let kind = if wide { SPOT_SPHERE } else { SPOT_CONE };
            // A NaN angle lights nothing rather than everything.
            let cos_cutoff = if s.angle.is_nan() {
                1.0
            } else {
                s.angle.clamp(0.0, 180.0).to_radians().cos()
            };
            Record {
                position: s.position,
                range,
                direction: dir,
                kind,
                color: s.color,
                exponent: s.exponent,
                attenuation: s.attenuation,
                cos_cutoff,
            }
            .pack(&mut set.records)
            .then(|| {
                if wide {
                    set.spot_spheres += 1;
                } else {
                    set.spot_cones += 1;
                }
            });
        }
    }
    for light in lights {
        if let Light::Area(a) = light {
            if pack_area(a, &mut set.records) {
                set.areas += 1;
            }
        }
    }
    set
}

/// An area light as the shaders see it: centre, half-extent axes (local X and
/// Y scaled by the half size, or by the radius for a disc), facing `-(x × y)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AreaGeometry {
    /// World centre.
    pub centre: Vec3,
    /// Local X times the half width (or the radius).
    pub x: Vec3,
    /// Local Y times the half height (or the radius).
    pub y: Vec3,
    /// A disc inscribed in the rectangle rather than the rectangle.
    pub disc: bool,
    /// Whether both faces emit.
    pub two_sided: bool,
}

impl AreaGeometry {
    /// The unit direction the light faces.
    pub fn facing(&self) -> Vec3 {
        -self.x.cross(self.y).normalize()
    }

    /// The emitting area.
    pub fn area(&self) -> f32 {
        (if self.disc { PI } else { 4.0 }) * self.x.length() * self.y.length()
    }
}

/// An area light as the shaders see it (centre, half-extent axes: local X and Y
/// scaled by the half size or the radius), or `None` when it has no area or its
/// placement is not finite (its emission is bounded when packed, `sanitize`).
pub fn area_shape(a: &AreaLight) -> Option<AreaGeometry> {
    let (disc, half_x, half_y) = match a.shape {
        AreaShape::Rect { width, height } => (false, width * 0.5, height * 0.5),
        AreaShape::Disc { radius } => (true, radius, radius),
    };
    let rotation = a.orientation.normalize();
    let shape = AreaGeometry {
        centre: a.position,
        x: rotation * Vec3::X * half_x,
        y: rotation * Vec3::Y * half_y,
        disc,
        two_sided: a.two_sided,
    };
    let finite = [shape.centre, shape.x, shape.y]
        .iter()
        .all(|v| v.is_finite());
    (half_x > 0.0 && half_y > 0.0 && finite).then_some(shape)
}

/// Appends an area light's record (layout in `scene.glsl`); lights without a
/// usable shape are left out: false.
fn pack_area(a: &AreaLight, records: &mut Vec<GpuLight>) -> bool {
    let Some(shape) = area_shape(a) else {
        return false;
    };
    records.push(GpuLight {
        position_range: shape.centre.extend(0.0),
        direction_type: shape
            .x
            .extend(if shape.disc { AREA_DISC } else { AREA_RECT }),
        color_exponent: sanitize::radiance(a.emission).extend(if shape.two_sided {
            1.0
        } else {
            0.0
        }),
        attenuation_cos: shape.y.extend(0.0),
    });
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use weft_scene::light::{RadiusSource, SpotLight, SunLight};
    use weft_scene::PointLight;

    fn spot(angle: f32, length: Option<f32>) -> Light {
        Light::Spot(SpotLight {
            position: Vec3::Y,
            direction: Vec3::new(0.0, -2.0, 0.0),
            color: Vec3::ONE,
            exponent: 2.0,
            angle,
            inner_angle: None,
            length,
            attenuation: Attenuation {
                constant: 1.0,
                linear: 1.0,
                quadratic: 0.0,
            },
            swivel: None,
        })
    }

    #[test]
    fn orders_suns_points_cones_spheres_with_ranges() {
        let lights = vec![
            spot(80.0, Some(5.0)),
            Light::Point(PointLight {
                position: Vec3::X,
                color: Vec3::ONE,
                velocity: 0.0,
                amplitude: 0.0,
                attenuation: Attenuation::NONE,
                radius: 3.0,
                radius_source: RadiusSource::Given,
            }),
            spot(30.0, None),
            Light::Sun(SunLight {
                direction: Vec3::new(0.0, -3.0, 0.0),
                color: Vec3::ONE,
                ambient: Vec3::splat(0.1),
                motion: None,
            }),
        ];
        let set = pack_lights(&lights, &Aabb::EMPTY);
        assert_eq!(
            (set.suns, set.points, set.spot_cones, set.spot_spheres),
            (1, 1, 1, 1)
        );
        assert_eq!(set.records.len(), 4);
        let floats: &[f32] = bytemuck::cast_slice(&set.records);
        let word = |record: usize, i: usize| floats[record * 16 + i];
        assert_eq!(word(0, 5), -1.0, "sun direction normalised");
        assert_eq!(word(1, 3), 3.0, "point range is its radius");
        assert_eq!(word(1, 7), POINT);
        // luminance 1 / (1 + d) = 1/256 at d = 255
        assert!((word(2, 3) - 255.0).abs() < 1e-2, "{}", word(2, 3));
        assert_eq!(word(2, 7), SPOT_CONE);
        assert!((word(2, 15) - 30f32.to_radians().cos()).abs() < 1e-6);
        assert_eq!(word(3, 3), 5.0, "spot length");
        assert_eq!(word(3, 7), SPOT_SPHERE);
        assert_eq!(set.ambient, Vec3::splat(0.1));
    }

    #[test]
    fn area_lights_come_last_with_their_half_axes() {
        let panel = |shape, width: f32| {
            Light::Area(AreaLight {
                shape,
                position: Vec3::new(0.0, 2.0, 0.0),
                // Facing down: local -Z turned onto -Y.
                orientation: glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
                emission: Vec3::new(17.0, 12.0, width),
                two_sided: width > 0.0,
            })
        };
        let lights = vec![
            panel(
                AreaShape::Rect {
                    width: 0.5,
                    height: 0.25,
                },
                0.5,
            ),
            panel(AreaShape::Disc { radius: 0.3 }, 0.0),
            panel(
                AreaShape::Rect {
                    width: 0.0,
                    height: 1.0,
                },
                0.0,
            ),
            spot(30.0, None),
        ];
        let set = pack_lights(&lights, &Aabb::EMPTY);
        assert_eq!(
            (set.spot_cones, set.areas, set.len()),
            (1, 2, 3),
            "the empty rectangle is left out"
        );
        assert_eq!(set.first_area(), 1);
        let floats: &[f32] = bytemuck::cast_slice(&set.records);
        let record = |r: usize| -> Vec<f32> { floats[r * 16..(r + 1) * 16].to_vec() };
        let close = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-6);
        let rect = record(1);
        assert!(
            close(
                &rect,
                &[
                    0.0, 2.0, 0.0, 0.0, 0.25, 0.0, 0.0, AREA_RECT, 17.0, 12.0, 0.5, 1.0, 0.0, 0.0,
                    -0.125, 0.0
                ]
            ),
            "{rect:?}"
        );
        let disc = record(2);
        assert!(
            close(
                &disc,
                &[
                    0.0, 2.0, 0.0, 0.0, 0.3, 0.0, 0.0, AREA_DISC, 17.0, 12.0, 0.0, 0.0, 0.0, 0.0,
                    -0.3, 0.0
                ]
            ),
            "{disc:?}"
        );
        // The shaders' facing direction -normalize(cross(x, y)) is the light's normal.
        let x = Vec3::new(rect[4], rect[5], rect[6]);
        let y = Vec3::new(rect[12], rect[13], rect[14]);
        assert!((-x.cross(y).normalize() - Vec3::NEG_Y).length() < 1e-6);
    }
}
