//! Light blocks of a `.scene`: `sunlight`, `spotlight`, `pointlight`,
//! `arealight`, seeded `generate` blocks of point lights, and the
//! `environment` map.

use super::{rotation, DEFAULT_SWIVEL_PERIOD, MAX_GENERATED_LIGHTS};
use crate::camera::look_at_rotation;
use crate::environment::EnvironmentDesc;
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::{
    derive_radius, AreaLight, AreaShape, Attenuation, PointLight, RadiusSource, SpotLight,
    SunLight, SunMotion, Swivel, DEFAULT_LUMINANCE_THRESHOLD,
};
use crate::props::Props;
use crate::rng::Rng;
use crate::syntax::Prop;
use glam::{DVec3, Quat, Vec3};

/// The largest value an RGBA16F HDR image holds.
const HALF_MAX: f32 = 65504.0;

/// Warns at `name`'s line when a colour or emission channel is beyond the
/// half-float range HDR images hold (the renderer clamps what each pass
/// writes, docs/stability.md).
fn warn_if_beyond_half(props: &mut Props<'_>, name: &str, value: Vec3, diag: &mut Diagnostics) {
    if let Some(p) = props.last(name) {
        if value.max_element() > HALF_MAX {
            diag.warn(
                Location::line(props.file(), p.line),
                format!(
                    "'{name}' {} is beyond the half-float range (65504) of HDR images: the lit surfaces saturate; each pass clamps what it writes at 8192",
                    value.max_element()
                ),
            );
        }
    }
}

/// An `environment` block: `file` (required), `intensity` (at least 0,
/// default 1), `rotation_deg` (about +y, default 0).
pub(super) fn environment(props: &mut Props<'_>) -> Result<EnvironmentDesc, SceneError> {
    let Some((name, line)) = props.text("file")? else {
        return Err(SceneError::Syntax {
            at: props.block_at(),
            message: "'environment' needs a 'file': an equirectangular OpenEXR or Radiance HDR map"
                .into(),
        });
    };
    let intensity = props
        .f32_where(
            "intensity",
            |v| v.is_finite() && v >= 0.0,
            "a finite number of at least 0",
        )?
        .unwrap_or(1.0);
    let rotation_deg = props
        .f32_where("rotation_deg", f32::is_finite, "a finite angle in degrees")?
        .unwrap_or(0.0);
    Ok(EnvironmentDesc {
        file: super::resolve(props.file(), &name),
        at: Location::line(props.file(), line),
        intensity,
        rotation_deg,
    })
}

/// A `sunlight` block.
pub(super) fn sunlight(
    props: &mut Props<'_>,
    diag: &mut Diagnostics,
) -> Result<SunLight, SceneError> {
    let direction = props.direction("direction")?.unwrap_or(Vec3::NEG_Y);
    let color = props.colour("color")?.unwrap_or(Vec3::ONE);
    warn_if_beyond_half(props, "color", color, diag);
    let ambient = match props.last("ambient") {
        Some(p) => match props.numbers(p)?.as_slice() {
            [a] => color * *a,
            [r, g, b] => {
                diag.warn(
                    Location::line(props.file(), p.line),
                    "'ambient' has 3 values; read as an RGB ambient colour (the format has one intensity)",
                );
                Vec3::new(*r, *g, *b)
            }
            other => {
                return Err(props.error(
                    p,
                    format!("'ambient' expects 1 number, found {}", other.len()),
                ))
            }
        },
        None => Vec3::ZERO,
    };
    if let Some(p) = props
        .last("ambient")
        .filter(|_| ambient.min_element() < 0.0)
    {
        return Err(props.error(
            p,
            format!("'ambient' must not be negative, found {ambient}"),
        ));
    }
    let motion = match props.last("motion") {
        Some(p) => {
            let v = props.exactly(p, 4)?;
            let axis = Vec3::new(v[0], v[1], v[2])
                .try_normalize()
                .ok_or_else(|| props.error(p, "'motion' has a zero axis"))?;
            Some(SunMotion {
                axis,
                degrees_per_second: v[3],
            })
        }
        None => None,
    };
    Ok(SunLight {
        direction,
        color,
        ambient,
        motion,
    })
}

/// The direction a 15-462 spotlight `orientation` gives: the local +Z axis rotated.
fn spot_axis(q: Quat) -> Vec3 {
    (q * Vec3::Z).normalize()
}

/// A `spotlight` block, with the legacy `orientation`, `slerp` and `correction` properties.
pub(super) fn spotlight(
    props: &mut Props<'_>,
    diag: &mut Diagnostics,
) -> Result<SpotLight, SceneError> {
    let position = props.point_or("position", DVec3::ZERO)?;
    let given = props.direction("direction")?;
    let oriented = match props.last("orientation") {
        Some(p) => {
            let q = rotation(props, p)?;
            let at = Location::line(props.file(), p.line);
            if given.is_some() {
                diag.warn(
                    at,
                    "spotlight has both 'direction' and 'orientation'; 'direction' is used",
                );
            } else {
                diag.warn(
                    at,
                    "spotlight 'orientation' is not in the format; read as a rotation of the +Z axis",
                );
            }
            Some(spot_axis(q))
        }
        None => None,
    };
    let direction = given.or(oriented).unwrap_or(Vec3::NEG_Y);
    let mut swivel = None;
    let period = props.f32("swivel_period")?.unwrap_or(DEFAULT_SWIVEL_PERIOD);
    if let Some(p) = props.last("slerp") {
        let v = props.exactly(p, 8)?;
        let from = angle_axis(props, p, v[0], Vec3::new(v[1], v[2], v[3]))?;
        let to = angle_axis(props, p, v[4], Vec3::new(v[5], v[6], v[7]))?;
        diag.warn(
            Location::line(props.file(), p.line),
            format!(
                "spotlight 'slerp' is not in the format; read as a swivel between two angle-axis rotations of +Z, period {period} s"
            ),
        );
        swivel = Some(Swivel {
            from: spot_axis(from),
            to: spot_axis(to),
            period,
        });
    }
    if let Some(p) = props.last("swivel") {
        let v = props.numbers(p)?;
        if v.len() != 6 && v.len() != 7 {
            return Err(props.error(
                p,
                format!(
                    "'swivel' expects 6 numbers (two directions) and an optional period, found {}",
                    v.len()
                ),
            ));
        }
        let from = crate::props::normalize_wide(Vec3::new(v[0], v[1], v[2]));
        let to = crate::props::normalize_wide(Vec3::new(v[3], v[4], v[5]));
        let (Some(from), Some(to)) = (from, to) else {
            return Err(props.error(p, "'swivel' directions must not be zero vectors"));
        };
        let period = v.get(6).copied().unwrap_or(period);
        if period <= 0.0 {
            return Err(props.error(p, "'swivel' period must be > 0"));
        }
        swivel = Some(Swivel { from, to, period });
    }
    for p in props.all("correction") {
        diag.warn(
            Location::line(props.file(), p.line),
            "spotlight 'correction' has no documented meaning; ignored",
        );
    }
    // A swivelling light points at its first direction at time 0.
    let direction = swivel.map_or(direction, |sw| sw.from);
    let angle = props
        .f32_where(
            "angle",
            |a| (0.0..=180.0).contains(&a),
            "within 0..180 degrees",
        )?
        .unwrap_or(45.0);
    let color = props.colour("color")?.unwrap_or(Vec3::ONE);
    warn_if_beyond_half(props, "color", color, diag);
    Ok(SpotLight {
        position,
        direction,
        color,
        exponent: props.f32("exponent")?.unwrap_or(1.0),
        angle,
        inner_angle: props.f32("inner_angle")?,
        length: props.f32("length")?,
        attenuation: attenuation(props)?.unwrap_or(Attenuation::NONE),
        swivel,
    })
}

/// A normalised angle-axis rotation from a property's fields.
fn angle_axis(props: &Props<'_>, prop: &Prop, angle: f32, axis: Vec3) -> Result<Quat, SceneError> {
    let axis = axis
        .try_normalize()
        .ok_or_else(|| props.error(prop, format!("'{}' has a zero rotation axis", prop.name)))?;
    Ok(Quat::from_axis_angle(axis, angle))
}

/// The `attenuation` property, rejecting negative terms and an all-zero falloff.
fn attenuation(props: &mut Props<'_>) -> Result<Option<Attenuation>, SceneError> {
    let Some(p) = props.last("attenuation") else {
        return Ok(None);
    };
    let v = props.exactly(p, 3)?;
    if v.iter().any(|&x| x < 0.0) || v.iter().all(|&x| x == 0.0) {
        return Err(props.error(p, "'attenuation' terms must be >= 0 and not all 0"));
    }
    Ok(Some(Attenuation {
        constant: v[0],
        linear: v[1],
        quadratic: v[2],
    }))
}

/// The cutoff radius: given, or derived from attenuation and the luminance threshold
/// (infinite when the light never falls off; the loader bounds it by the scene).
fn radius(
    given: Option<f32>,
    color: Vec3,
    att: &Attenuation,
    threshold: f32,
) -> (f32, RadiusSource) {
    match given {
        Some(r) => (r, RadiusSource::Given),
        None => (
            derive_radius(color, att, threshold).unwrap_or(f32::INFINITY),
            RadiusSource::Derived,
        ),
    }
}

/// A `pointlight` block.
pub(super) fn pointlight(
    props: &mut Props<'_>,
    diag: &mut Diagnostics,
) -> Result<PointLight, SceneError> {
    let color = props.colour("color")?.unwrap_or(Vec3::ONE);
    warn_if_beyond_half(props, "color", color, diag);
    let att = attenuation(props)?.unwrap_or(Attenuation::NONE);
    let threshold = positive(props, "threshold")?.unwrap_or(DEFAULT_LUMINANCE_THRESHOLD);
    let (radius, radius_source) = radius(positive(props, "radius")?, color, &att, threshold);
    Ok(PointLight {
        position: props.point_or("position", DVec3::ZERO)?,
        color,
        velocity: props.f32("velocity")?.unwrap_or(0.0),
        amplitude: props.f32("amplitude")?.unwrap_or(1.0),
        attenuation: att,
        radius,
        radius_source,
    })
}

/// A number property that must be > 0.
fn positive(props: &mut Props<'_>, name: &str) -> Result<Option<f32>, SceneError> {
    props.f32_where(name, |v| v > 0.0, "> 0")
}

/// An `arealight` block: `shape rect` with `size W H`, or `shape disc` with `radius R`.
pub(super) fn arealight(
    props: &mut Props<'_>,
    diag: &mut Diagnostics,
) -> Result<AreaLight, SceneError> {
    let (shape_name, shape_line) = props
        .text("shape")?
        .unwrap_or_else(|| ("rect".to_string(), props.block_at().line.unwrap_or(1)));
    let shape = match shape_name.as_str() {
        "rect" => {
            let (width, height) = positive_pair(props, "size", Order::Any)?.unwrap_or((1.0, 1.0));
            AreaShape::Rect { width, height }
        }
        "disc" => AreaShape::Disc {
            radius: positive(props, "radius")?.unwrap_or(0.5),
        },
        other => {
            return Err(SceneError::syntax(
                props.file(),
                shape_line,
                format!("arealight 'shape' must be rect or disc, found '{other}'"),
            ));
        }
    };
    let position = props.point_or("position", DVec3::ZERO)?;
    let orientation = match (props.last("orientation"), props.direction("direction")?) {
        (Some(p), None) => rotation(props, p)?,
        (None, Some(d)) => look_at_rotation(Vec3::ZERO, d),
        (None, None) => look_at_rotation(Vec3::ZERO, Vec3::NEG_Y),
        (Some(p), Some(_)) => {
            return Err(props.error(p, "give 'orientation' or 'direction', not both"))
        }
    };
    let two_sided = match props.f32("two_sided")? {
        Some(v) => v != 0.0,
        None => false,
    };
    let emission = props.colour("emission")?.unwrap_or(Vec3::ONE);
    warn_if_beyond_half(props, "emission", emission, diag);
    Ok(AreaLight {
        shape,
        position,
        orientation,
        emission,
        two_sided,
    })
}

/// A `pointlights` generator: `count` lights at seeded random places in the `min`..`max` box.
pub(super) fn generate(props: &mut Props<'_>) -> Result<Vec<PointLight>, SceneError> {
    let count = props
        .f32_where(
            "count",
            |c| c >= 0.0 && c.fract() == 0.0 && c <= MAX_GENERATED_LIGHTS as f32,
            &format!("a whole number from 0 to {MAX_GENERATED_LIGHTS}"),
        )?
        .unwrap_or(0.0);
    let seed = props.f32("seed")?.unwrap_or(0.0);
    let min = props.point_or("min", DVec3::splat(-1.0))?;
    let max = props.point_or("max", DVec3::ONE)?;
    let color_min = props.colour("color_min")?.unwrap_or(Vec3::ONE);
    let color_max = props.colour("color_max")?.unwrap_or(color_min);
    let radius_range = positive_pair(props, "radius", Order::Increasing)?;
    let velocity_range = pair(props, "velocity")?.unwrap_or((0.0, 0.0));
    let amplitude = props.f32("amplitude")?.unwrap_or(1.0);
    let att = attenuation(props)?.unwrap_or(Attenuation::INVERSE_SQUARE);
    let threshold = positive(props, "threshold")?.unwrap_or(DEFAULT_LUMINANCE_THRESHOLD);
    let mut rng = Rng::new(seed.to_bits() as u64);
    let mut lights = Vec::with_capacity(count as usize);
    for _ in 0..count as u32 {
        let position = Vec3::new(
            rng.range(min.x, max.x),
            rng.range(min.y, max.y),
            rng.range(min.z, max.z),
        );
        let color = Vec3::new(
            rng.range(color_min.x, color_max.x),
            rng.range(color_min.y, color_max.y),
            rng.range(color_min.z, color_max.z),
        );
        let given = radius_range.map(|(lo, hi)| rng.range(lo, hi));
        let (radius, radius_source) = radius(given, color, &att, threshold);
        lights.push(PointLight {
            position,
            color,
            velocity: rng.range(velocity_range.0, velocity_range.1),
            amplitude,
            attenuation: att,
            radius,
            radius_source,
        });
    }
    Ok(lights)
}

/// A `NAME lo hi` range property.
fn pair(props: &mut Props<'_>, name: &str) -> Result<Option<(f32, f32)>, SceneError> {
    match props.last(name) {
        Some(p) => {
            let v = props.exactly(p, 2)?;
            Ok(Some((v[0], v[1])))
        }
        None => Ok(None),
    }
}

/// Whether the two numbers of a pair must be in increasing order (a range).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Order {
    Any,
    Increasing,
}

/// A `NAME a b` property whose numbers must both be > 0 (and, for a range,
/// satisfy a <= b).
fn positive_pair(
    props: &mut Props<'_>,
    name: &str,
    order: Order,
) -> Result<Option<(f32, f32)>, SceneError> {
    let Some(p) = props.last(name) else {
        return Ok(None);
    };
    let v = props.exactly(p, 2)?;
    let ordered = order == Order::Any || v[0] <= v[1];
    if v[0] > 0.0 && v[1] > 0.0 && ordered {
        return Ok(Some((v[0], v[1])));
    }
    let expected = match order {
        Order::Any => "two numbers > 0",
        Order::Increasing => "a range lo hi with 0 < lo <= hi",
    };
    Err(props.error(
        p,
        format!("'{name}' must be {expected}, found {} {}", v[0], v[1]),
    ))
}
