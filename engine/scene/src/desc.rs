//! Gives meaning to parsed `.scene` blocks: models to load, lights, cameras, bounds,
//! includes and light generators, with the 15-462 quirks accepted and reported.

use crate::bounds::Aabb;
use crate::camera::{look_at_rotation, Camera, CameraKey, CameraOrigin, DEFAULT_FOV_Y};
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::{
    derive_radius, AreaLight, AreaShape, Attenuation, Light, PointLight, RadiusSource, SpotLight,
    SunLight, SunMotion, Swivel, DEFAULT_LUMINANCE_THRESHOLD,
};
use crate::props::Props;
use crate::rng::Rng;
use crate::source::{read_text, MAX_SCENE_BYTES};
use crate::syntax::{parse, Block, Item, Prop};
use glam::{EulerRot, Mat4, Quat, Vec3};
use std::path::{Path, PathBuf};

/// How deep `include` may nest.
pub const MAX_INCLUDE_DEPTH: usize = 16;
/// The most lights one generator block may make.
pub const MAX_GENERATED_LIGHTS: u32 = 1_000_000;
/// The default period of a spotlight swivel, in seconds.
pub const DEFAULT_SWIVEL_PERIOD: f32 = 4.0;

/// A model file placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Placement {
    /// The model file, resolved against the scene file.
    pub file: PathBuf,
    /// The `file` line that names it.
    pub at: Location,
    /// Model-to-world transform (translate · rotate · scale).
    pub transform: Mat4,
}

/// Everything a `.scene` file (with its includes) declares, before models are loaded.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SceneDesc {
    /// Model placements in file order.
    pub models: Vec<Placement>,
    /// Lights in file order (generated ones where their block is).
    pub lights: Vec<Light>,
    /// Cameras in file order.
    pub cameras: Vec<Camera>,
    /// A `boundingbox` block, when present.
    pub bounding_box: Option<Aabb>,
}

/// Reads a `.scene` file and its includes.
pub fn read_scene_desc(path: &Path, diag: &mut Diagnostics) -> Result<SceneDesc, SceneError> {
    let mut desc = SceneDesc::default();
    let mut stack = Vec::new();
    read_into(path, &Location::file(path), &mut desc, &mut stack, diag)?;
    Ok(desc)
}

/// Parses `text` as if it were the file `path` (includes resolve against `path`'s folder).
pub fn scene_desc_from_str(
    text: &str,
    path: &Path,
    diag: &mut Diagnostics,
) -> Result<SceneDesc, SceneError> {
    let mut desc = SceneDesc::default();
    let mut stack = vec![path.to_path_buf()];
    interpret(text, path, &mut desc, &mut stack, diag)?;
    Ok(desc)
}

/// Reads one file into `desc`; `stack` holds the files being included, to stop cycles.
fn read_into(
    path: &Path,
    asked_at: &Location,
    desc: &mut SceneDesc,
    stack: &mut Vec<PathBuf>,
    diag: &mut Diagnostics,
) -> Result<(), SceneError> {
    let text = read_text(path, asked_at, MAX_SCENE_BYTES)?;
    let key = path.canonicalize().unwrap_or_else(|_| path.to_path_buf());
    if stack.contains(&key) {
        return Err(SceneError::Syntax {
            at: asked_at.clone(),
            message: format!("include cycle: {} includes itself", path.display()),
        });
    }
    if stack.len() >= MAX_INCLUDE_DEPTH {
        return Err(SceneError::Syntax {
            at: asked_at.clone(),
            message: format!("includes nest deeper than {MAX_INCLUDE_DEPTH}"),
        });
    }
    stack.push(key);
    let result = interpret(&text, path, desc, stack, diag);
    stack.pop();
    result
}

/// Interprets the text of one file.
fn interpret(
    text: &str,
    path: &Path,
    desc: &mut SceneDesc,
    stack: &mut Vec<PathBuf>,
    diag: &mut Diagnostics,
) -> Result<(), SceneError> {
    for item in parse(text, path, diag)? {
        match item {
            Item::Include { path: name, line } => {
                let target = resolve(path, &name);
                read_into(&target, &Location::line(path, line), desc, stack, diag)?;
            }
            Item::Block(block) => block_into(&block, path, desc, diag)?,
        }
    }
    Ok(())
}

/// A path from a scene file, relative to the scene's folder; backslashes are separators.
pub(crate) fn resolve(scene: &Path, name: &str) -> PathBuf {
    let cleaned = name.replace('\\', "/");
    let base = scene.parent().unwrap_or(Path::new(""));
    base.join(cleaned)
}

/// Adds one block to `desc`.
fn block_into(
    block: &Block,
    file: &Path,
    desc: &mut SceneDesc,
    diag: &mut Diagnostics,
) -> Result<(), SceneError> {
    let mut props = Props::new(block, file);
    let first_warning = diag.warnings.len();
    match block.kind.as_str() {
        "model" => {
            if let Some(p) = model(&mut props, diag)? {
                desc.models.push(p);
            }
        }
        "sunlight" => desc.lights.push(Light::Sun(sunlight(&mut props, diag)?)),
        "spotlight" => desc.lights.push(Light::Spot(spotlight(&mut props, diag)?)),
        "pointlight" => desc.lights.push(Light::Point(pointlight(&mut props)?)),
        "arealight" => desc.lights.push(Light::Area(arealight(&mut props)?)),
        "pointlights" => desc
            .lights
            .extend(generate(&mut props)?.into_iter().map(Light::Point)),
        "camera" => {
            let index = desc.cameras.len();
            desc.cameras
                .push(camera(&mut props, block.label.clone(), index)?);
        }
        "boundingbox" => {
            let min = props.vec3("min")?.unwrap_or(Vec3::ZERO);
            let max = props.vec3("max")?.unwrap_or(Vec3::ZERO);
            desc.bounding_box = Some(Aabb::from_points(&[min, max]));
        }
        other => {
            diag.warn(
                Location::line(file, block.line),
                format!("unknown object '{other}'; skipped"),
            );
            return Ok(());
        }
    }
    props.finish(diag);
    diag.warnings[first_warning..].sort_by_key(|w| w.at.line);
    Ok(())
}

/// A rotation from 3 values (pitch, yaw, roll in degrees, applied roll then pitch then yaw)
/// or 4 values (angle in radians, then axis: the 15-462 reference loader's reading).
fn rotation(props: &Props<'_>, prop: &Prop) -> Result<Quat, SceneError> {
    let v = props.numbers(prop)?;
    match v.as_slice() {
        [pitch, yaw, roll] => Ok(Quat::from_euler(
            EulerRot::YXZ,
            yaw.to_radians(),
            pitch.to_radians(),
            roll.to_radians(),
        )),
        [angle, x, y, z] => {
            let axis = Vec3::new(*x, *y, *z)
                .try_normalize()
                .ok_or_else(|| props.error(prop, format!("'{}' has a zero rotation axis", prop.name)))?;
            Ok(Quat::from_axis_angle(axis, *angle))
        }
        _ => Err(props.error(
            prop,
            format!(
                "'{}' expects 3 numbers (pitch yaw roll, degrees) or 4 (angle in radians, axis x y z), found {}",
                prop.name,
                v.len()
            ),
        )),
    }
}

/// Warns that a 4-value orientation was read as angle-axis.
fn warn_angle_axis(props: &Props<'_>, prop: &Prop, diag: &mut Diagnostics) {
    if prop.values.len() == 4 {
        diag.warn(
            Location::line(props.file(), prop.line),
            format!(
                "'{}' has 4 values; read as angle (radians) and axis, as the 15-462 reference loader does",
                prop.name
            ),
        );
    }
}

/// A `model` block; `None` (with a warning) when it names no file.
fn model(props: &mut Props<'_>, diag: &mut Diagnostics) -> Result<Option<Placement>, SceneError> {
    let file = props.text("file")?;
    let position = props.vec3("position")?.unwrap_or(Vec3::ZERO);
    let rot = match props.last("orientation") {
        Some(p) => {
            warn_angle_axis(props, p, diag);
            rotation(props, p)?
        }
        None => Quat::IDENTITY,
    };
    let scale = match props.last("scale") {
        Some(p) => match props.numbers(p)?.as_slice() {
            [s] => Vec3::splat(*s),
            [x, y, z] => Vec3::new(*x, *y, *z),
            other => {
                return Err(props.error(
                    p,
                    format!("'scale' expects 1 or 3 numbers, found {}", other.len()),
                ))
            }
        },
        None => Vec3::ONE,
    };
    let Some((name, line)) = file else {
        diag.warn(props.block_at(), "model without a 'file'; skipped");
        return Ok(None);
    };
    Ok(Some(Placement {
        file: resolve(props.file(), &name),
        at: Location::line(props.file(), line),
        transform: Mat4::from_scale_rotation_translation(scale, rot, position),
    }))
}

/// A `sunlight` block.
fn sunlight(props: &mut Props<'_>, diag: &mut Diagnostics) -> Result<SunLight, SceneError> {
    let direction = props.direction("direction")?.unwrap_or(Vec3::NEG_Y);
    let color = props.vec3("color")?.unwrap_or(Vec3::ONE);
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
fn spotlight(props: &mut Props<'_>, diag: &mut Diagnostics) -> Result<SpotLight, SceneError> {
    let position = props.vec3("position")?.unwrap_or(Vec3::ZERO);
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
    Ok(SpotLight {
        position,
        direction,
        color: props.vec3("color")?.unwrap_or(Vec3::ONE),
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
fn pointlight(props: &mut Props<'_>) -> Result<PointLight, SceneError> {
    let color = props.vec3("color")?.unwrap_or(Vec3::ONE);
    let att = attenuation(props)?.unwrap_or(Attenuation::NONE);
    let threshold = positive(props, "threshold")?.unwrap_or(DEFAULT_LUMINANCE_THRESHOLD);
    let (radius, radius_source) = radius(positive(props, "radius")?, color, &att, threshold);
    Ok(PointLight {
        position: props.vec3("position")?.unwrap_or(Vec3::ZERO),
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
fn arealight(props: &mut Props<'_>) -> Result<AreaLight, SceneError> {
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
    let position = props.vec3("position")?.unwrap_or(Vec3::ZERO);
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
    Ok(AreaLight {
        shape,
        position,
        orientation,
        emission: props.vec3("emission")?.unwrap_or(Vec3::ONE),
        two_sided,
    })
}

/// A `pointlights` generator: `count` lights at seeded random places in the `min`..`max` box.
fn generate(props: &mut Props<'_>) -> Result<Vec<PointLight>, SceneError> {
    let count = props
        .f32_where(
            "count",
            |c| c >= 0.0 && c.fract() == 0.0 && c <= MAX_GENERATED_LIGHTS as f32,
            &format!("a whole number from 0 to {MAX_GENERATED_LIGHTS}"),
        )?
        .unwrap_or(0.0);
    let seed = props.f32("seed")?.unwrap_or(0.0);
    let min = props.vec3("min")?.unwrap_or(Vec3::splat(-1.0));
    let max = props.vec3("max")?.unwrap_or(Vec3::splat(1.0));
    let color_min = props.vec3("color_min")?.unwrap_or(Vec3::ONE);
    let color_max = props.vec3("color_max")?.unwrap_or(color_min);
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

/// A `camera` block; `index` names unlabelled cameras `camera0`, `camera1`, ...
fn camera(
    props: &mut Props<'_>,
    label: Option<String>,
    index: usize,
) -> Result<Camera, SceneError> {
    let position = props.vec3("position")?.unwrap_or(Vec3::ZERO);
    let target = props.vec3("target")?;
    let orientation = match (props.last("orientation"), target) {
        (Some(p), None) => rotation(props, p)?,
        (None, Some(t)) => look_at_rotation(position, t),
        (None, None) => Quat::IDENTITY,
        (Some(p), Some(_)) => {
            return Err(props.error(p, "give 'orientation' or 'target', not both"))
        }
    };
    let fov_y = match (
        props.last("fov"),
        props.f32_where("fov_deg", |d| d > 0.0 && d < 180.0, "in (0, 180)")?,
    ) {
        (Some(p), None) => {
            let f = props.exactly(p, 1)?[0];
            if !(f > 0.0 && f < std::f32::consts::PI) {
                return Err(props.error(p, format!("'fov' is in radians and must be in (0, pi), found {f}; use 'fov_deg' for degrees")));
            }
            f
        }
        (None, Some(d)) => d.to_radians(),
        (None, None) => DEFAULT_FOV_Y,
        (Some(p), Some(_)) => return Err(props.error(p, "give 'fov' or 'fov_deg', not both")),
    };
    let near = clip(props, "near", "near_clip")?.unwrap_or(0.01);
    let far = clip(props, "far", "far_clip")?.unwrap_or(1000.0);
    if near <= 0.0 || far <= near {
        return Err(SceneError::Syntax {
            at: props.block_at(),
            message: format!(
                "camera clip distances must satisfy 0 < near < far, found near {near} far {far}"
            ),
        });
    }
    let mut path = Vec::new();
    for p in props.all("key") {
        let v = props.exactly(p, 7)?;
        let key_position = Vec3::new(v[1], v[2], v[3]);
        path.push(CameraKey {
            time: v[0],
            position: key_position,
            orientation: look_at_rotation(key_position, Vec3::new(v[4], v[5], v[6])),
        });
        if path.len() > 1 && path[path.len() - 2].time >= v[0] {
            return Err(props.error(p, "camera 'key' times must increase"));
        }
    }
    Ok(Camera {
        name: label.unwrap_or_else(|| format!("camera{index}")),
        position,
        orientation,
        fov_y,
        near,
        far,
        path,
        origin: CameraOrigin::Scene,
    })
}

/// A clip distance under its new or its 15-462 name (the last one given wins).
fn clip(props: &mut Props<'_>, name: &str, legacy: &str) -> Result<Option<f32>, SceneError> {
    let a = props.last(name).map(|p| (p.line, name));
    let b = props.last(legacy).map(|p| (p.line, legacy));
    match a.max(b) {
        Some((_, chosen)) => props.f32(chosen),
        None => Ok(None),
    }
}
