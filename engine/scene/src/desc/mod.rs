//! Gives meaning to parsed `.scene` blocks: models to load, lights, cameras, bounds,
//! includes and light generators, with the 15-462 quirks accepted and reported.

use crate::bounds::Aabb;
use crate::camera::{look_at_rotation, Camera, CameraKey, CameraOrigin, DEFAULT_FOV_Y};
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::Light;
use crate::material::MaterialOverride;
use crate::props::Props;
use crate::source::{read_text, MAX_SCENE_BYTES};
use crate::syntax::{parse, Block, Item, Prop, Value};
use glam::{DVec3, EulerRot, Mat4, Quat, Vec3};
use std::path::{Path, PathBuf};

mod lights;

use lights::{arealight, environment, generate, pointlight, spotlight, sunlight};

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
    /// `absorption r g b`: the Beer–Lambert coefficient σ (per world unit)
    /// inside the model's dielectric (glass) materials.
    pub absorption: Option<Vec3>,
    /// `ior n`: the index of refraction of the model's dielectric (glass)
    /// materials, replacing the file's.
    pub ior: Option<f32>,
    /// `thin 1`: the model's glass is a thin shell (light goes straight
    /// through); `thin 0`: solid.
    pub thin: Option<bool>,
    /// `color`, `emission`, `roughness`, `metallic`: factors replaced for
    /// this placement's materials.
    pub material: MaterialOverride,
    /// `smooth_normals 1`: the model's vertex normals recomputed smooth
    /// across the faces around each position (for a faceted OBJ).
    pub smooth_normals: bool,
}

/// A scene's script: the file, where the scene named it, and the index of
/// the first light the script adds (lights before it come from the `.scene`).
#[derive(Debug, Clone, PartialEq)]
pub struct ScriptRef {
    /// The `.rhai` file.
    pub path: PathBuf,
    /// The `script` line, or the script itself for `.rhai` scenes.
    pub at: Location,
    /// Lights the scene declared before the script's.
    pub first_light: usize,
    /// Model placements the scene declared before the script's.
    pub first_model: usize,
    /// The scripts it imported while loading, so they are watched too.
    pub imports: Vec<PathBuf>,
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
    /// The world point every position above is relative to ([`origin_of`]).
    pub origin: DVec3,
    /// The scene's script (`script "file.rhai"`, or the `.rhai` scene itself).
    pub script: Option<ScriptRef>,
    /// The `environment` block (the last one, when several are given).
    pub environment: Option<crate::environment::EnvironmentDesc>,
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

/// The grid the origin snaps to: a scene within half of it from zero is
/// stored as written.
pub const ORIGIN_GRID: f64 = 1024.0;

/// The world point a scene's positions are stored relative to, from the
/// top-level file's `items`: the first camera's `position` (or its first
/// `key`'s), else the first `position` of any block, else zero; rounded to the nearest
/// multiple of [`ORIGIN_GRID`], so scenes within 512 units of zero keep
/// their coordinates. Positions are read in f64 and the origin subtracted
/// before they become f32, so a scene placed far from zero keeps near its
/// camera the precision it has near zero (docs/stability.md, "Far from the
/// origin").
pub(crate) fn origin_of(items: &[Item]) -> DVec3 {
    let point = |values: &[Value]| match values {
        [Value::Num(x), Value::Num(y), Value::Num(z), ..] => Some(DVec3::new(*x, *y, *z)),
        _ => None,
    };
    let position = |block: &Block| {
        block.props.iter().find_map(|p| match p.name.as_str() {
            "position" => point(&p.values),
            "key" => point(p.values.get(1..).unwrap_or(&[])),
            _ => None,
        })
    };
    let blocks: Vec<&Block> = items
        .iter()
        .filter_map(|item| match item {
            Item::Block(b) => Some(b),
            Item::Include { .. } | Item::Script { .. } => None,
        })
        .collect();
    blocks
        .iter()
        .filter(|b| b.kind == "camera")
        .find_map(|b| position(b))
        .or_else(|| blocks.iter().find_map(|b| position(b)))
        .map_or(DVec3::ZERO, |p| (p / ORIGIN_GRID).round() * ORIGIN_GRID)
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
    // An include outside the top-level scene's folder tree, or a system file,
    // may be anything (`/proc/self/environ`, `/etc/passwd`): its errors and
    // warnings name its file and line, never its text.
    let private = match stack.first().and_then(|root| root.parent()) {
        Some(root) => !weft_io::paths::is_within(path, root) || weft_io::paths::is_system(path),
        None => weft_io::paths::is_system(path),
    };
    stack.push(key);
    let result = if private {
        interpret_private(&text, path, desc, stack, diag)
    } else {
        interpret(&text, path, desc, stack, diag)
    };
    stack.pop();
    result
}

/// What an error or warning about a private file says in place of its own
/// text.
const PRIVATE: &str = "the file is outside the scene's folder, so its content is not shown";

/// [`interpret`] for a file whose content must not be echoed: its text is
/// dropped from what error printers show, and a message located in `path`
/// itself is replaced by its kind and [`PRIVATE`].
fn interpret_private(
    text: &str,
    path: &Path,
    desc: &mut SceneDesc,
    stack: &mut Vec<PathBuf>,
    diag: &mut Diagnostics,
) -> Result<(), SceneError> {
    weft_io::sources::forget(path);
    let mut own = Diagnostics::default();
    let result = interpret(text, path, desc, stack, &mut own);
    for mut warning in own.warnings {
        if warning.at.file == path {
            warning.message = format!("a warning ({PRIVATE})");
        }
        diag.warnings.push(warning);
    }
    // Any error located in the file itself: even a missing include's name
    // is text from it.
    result.map_err(|error| match error {
        SceneError::Syntax { at, .. } if at.file == path => SceneError::Syntax {
            at,
            message: format!("not a .scene file, or a syntax error ({PRIVATE})"),
        },
        other if other.location().file == path => SceneError::Syntax {
            at: other.location().clone(),
            message: format!("an error ({PRIVATE})"),
        },
        other => other,
    })
}

/// Interprets the text of one file; the top-level one (the only file on
/// `stack`) also sets the scene's origin before any position is read.
fn interpret(
    text: &str,
    path: &Path,
    desc: &mut SceneDesc,
    stack: &mut Vec<PathBuf>,
    diag: &mut Diagnostics,
) -> Result<(), SceneError> {
    let items = parse(text, path, diag)?;
    if stack.len() == 1 {
        desc.origin = origin_of(&items);
    }
    for item in items {
        match item {
            Item::Include { path: name, line } => {
                let target = resolve(path, &name);
                read_into(&target, &Location::line(path, line), desc, stack, diag)?;
            }
            Item::Block(block) => block_into(&block, path, desc, diag)?,
            Item::Script { path: name, line } => {
                let at = Location::line(path, line);
                if let Some(first) = &desc.script {
                    return Err(SceneError::Syntax {
                        at,
                        message: format!(
                            "a scene has one script, and {} is already named",
                            first.path.display()
                        ),
                    });
                }
                desc.script = Some(ScriptRef {
                    path: resolve(path, &name),
                    at,
                    first_light: 0,
                    first_model: 0,
                    imports: Vec::new(),
                });
            }
        }
    }
    Ok(())
}

/// Adds the object blocks of `text` (no includes or scripts) to `desc`, with
/// positions relative to `desc.origin`: how a script's calls become objects.
pub(crate) fn blocks_into(
    text: &str,
    file: &Path,
    desc: &mut SceneDesc,
    diag: &mut Diagnostics,
) -> Result<(), SceneError> {
    for item in parse(text, file, diag)? {
        match item {
            Item::Block(block) => block_into(&block, file, desc, diag)?,
            Item::Include { line, .. } | Item::Script { line, .. } => {
                return Err(SceneError::syntax(
                    file,
                    line,
                    "only objects may be added here",
                ))
            }
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
    let mut props = Props::new(block, file, desc.origin);
    let first_warning = diag.warnings.len();
    match block.kind.as_str() {
        "model" => {
            if let Some(p) = model(&mut props, diag)? {
                desc.models.push(p);
            }
        }
        "sunlight" => desc.lights.push(Light::Sun(sunlight(&mut props, diag)?)),
        "spotlight" => desc.lights.push(Light::Spot(spotlight(&mut props, diag)?)),
        "pointlight" => desc
            .lights
            .push(Light::Point(pointlight(&mut props, diag)?)),
        "arealight" => desc.lights.push(Light::Area(arealight(&mut props, diag)?)),
        "pointlights" => desc
            .lights
            .extend(generate(&mut props)?.into_iter().map(Light::Point)),
        "camera" => {
            let index = desc.cameras.len();
            desc.cameras
                .push(camera(&mut props, block.label.clone(), index)?);
        }
        "environment" => desc.environment = Some(environment(&mut props)?),
        "boundingbox" => {
            let min = props.point_or("min", DVec3::ZERO)?;
            let max = props.point_or("max", DVec3::ZERO)?;
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
    rotation_from(&prop.name, &props.numbers(prop)?).map_err(|m| props.error(prop, m))
}

/// [`rotation`] from the values of a property called `name`.
pub(crate) fn rotation_from(name: &str, v: &[f32]) -> Result<Quat, String> {
    match v {
        [pitch, yaw, roll] => Ok(Quat::from_euler(
            EulerRot::YXZ,
            yaw.to_radians(),
            pitch.to_radians(),
            roll.to_radians(),
        )),
        [angle, x, y, z] => {
            let axis = Vec3::new(*x, *y, *z)
                .try_normalize()
                .ok_or_else(|| format!("'{name}' has a zero rotation axis"))?;
            Ok(Quat::from_axis_angle(axis, *angle))
        }
        _ => Err(format!(
            "'{name}' expects 3 numbers (pitch yaw roll, degrees) or 4 (angle in radians, axis x y z), found {}",
            v.len()
        )),
    }
}

/// A `model` block's `scale`: one uniform factor or x y z.
pub(crate) fn scale_from(v: &[f32]) -> Result<Vec3, String> {
    match v {
        [s] => Ok(Vec3::splat(*s)),
        [x, y, z] => Ok(Vec3::new(*x, *y, *z)),
        other => Err(format!(
            "'scale' expects 1 or 3 numbers, found {}",
            other.len()
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
    let position = props.point_or("position", DVec3::ZERO)?;
    let rot = match props.last("orientation") {
        Some(p) => {
            warn_angle_axis(props, p, diag);
            rotation(props, p)?
        }
        None => Quat::IDENTITY,
    };
    let scale = match props.last("scale") {
        Some(p) => scale_from(&props.numbers(p)?).map_err(|m| props.error(p, m))?,
        None => Vec3::ONE,
    };
    let absorption = match props.last("absorption") {
        Some(p) => match props.numbers(p)?.as_slice() {
            [s] if s.is_finite() && *s >= 0.0 => Some(Vec3::splat(*s)),
            [r, g, b] if [r, g, b].iter().all(|v| v.is_finite() && **v >= 0.0) => {
                Some(Vec3::new(*r, *g, *b))
            }
            _ => {
                return Err(props.error(
                    p,
                    "'absorption' expects 1 or 3 finite numbers of at least 0 (per world unit)",
                ))
            }
        },
        None => None,
    };
    let ior = props.f32_where(
        "ior",
        |n| n.is_finite() && n >= 1.0,
        "a finite index of refraction of at least 1",
    )?;
    let thin = props
        .f32_where("thin", |v| v == 0.0 || v == 1.0, "0 or 1")?
        .map(|v| v == 1.0);
    let smooth_normals =
        props.f32_where("smooth_normals", |v| v == 0.0 || v == 1.0, "0 or 1")? == Some(1.0);
    let material = material_override(props)?;
    let Some((name, line)) = file else {
        diag.warn(props.block_at(), "model without a 'file'; skipped");
        return Ok(None);
    };
    Ok(Some(Placement {
        file: resolve(props.file(), &name),
        at: Location::line(props.file(), line),
        transform: Mat4::from_scale_rotation_translation(scale, rot, position),
        absorption,
        ior,
        thin,
        material,
        smooth_normals,
    }))
}

/// A `model` block's material overrides: colours of three numbers of at
/// least 0, roughness and metallic in [0, 1].
fn material_override(props: &mut Props<'_>) -> Result<MaterialOverride, SceneError> {
    let color = props.colour("color")?;
    let emission = props.colour("emission")?;
    let unit = |v: f32| (0.0..=1.0).contains(&v);
    Ok(MaterialOverride {
        color,
        emission,
        roughness: props.f32_where("roughness", unit, "in [0, 1]")?,
        metallic: props.f32_where("metallic", unit, "in [0, 1]")?,
    })
}

/// A `camera` block; `index` names unlabelled cameras `camera0`, `camera1`, ...
fn camera(
    props: &mut Props<'_>,
    label: Option<String>,
    index: usize,
) -> Result<Camera, SceneError> {
    let position = props.point_or("position", DVec3::ZERO)?;
    let target = props.point("target")?;
    let orientation = match (props.last("orientation"), target) {
        (Some(p), None) => rotation(props, p)?,
        (None, Some(t)) => {
            if let Some(p) = props.last("target") {
                no_view_direction(props, p, position, t)?;
            }
            look_at_rotation(position, t)
        }
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
        let key_position = props.point_at(p, 1)?;
        let key_target = props.point_at(p, 4)?;
        no_view_direction(props, p, key_position, key_target)?;
        path.push(CameraKey {
            time: v[0],
            position: key_position,
            orientation: look_at_rotation(key_position, key_target),
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

/// Refuses a camera `target` that is its position: there is no direction to
/// look in (the image would be black).
fn no_view_direction(
    props: &Props<'_>,
    at: &Prop,
    position: Vec3,
    target: Vec3,
) -> Result<(), SceneError> {
    if (target - position).try_normalize().is_some() {
        return Ok(());
    }
    Err(props.error(
        at,
        format!(
            "the camera's target is its position ({} {} {}): there is no direction to look in",
            position.x, position.y, position.z
        ),
    ))
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
