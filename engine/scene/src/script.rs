//! Scene scripts in Rhai (scenes/SCRIPTING.md): a `.rhai` file that is a
//! scene, or one a `.scene` names with `script "file.rhai"`.
//!
//! At load the script's top level runs once and adds objects through
//! functions that take the `.scene` format's properties as a map
//! (`point_light(#{ position: [0, 2, 0], color: [1, 1, 1] })`): each call
//! becomes an object block read by the `.scene` reader itself, so a script
//! and a file mean the same thing and are validated the same way.
//!
//! At load a script may also read the bounds of the models placed so far
//! (`scene_bounds()`, which loads them; the scene reuses what it loaded).
//!
//! Per frame, `fn update(t, dt)` moves, recolours and switches lights, moves
//! model placements and cameras ([`ScriptFrame`]). Time
//! advances in fixed steps of [`STEP`] from 0, so the lights at time `t` are
//! the same on every run and every machine, however the frames fell: `weft
//! render --time T` is deterministic and golden-testable. `fn init()`, when
//! present, returns the value update sees as `this` (a map of the script's
//! own state, for flocking and the like). Wall-clock time is not available.
//!
//! The sandbox: Rhai has no file, network or process access; `import` reads
//! only scripts under the scene's folder; every call is limited in operations,
//! call depth, expression depth and string, array and map sizes
//! ([`Limits`]). A script that breaks a limit, loops forever or fails gets a
//! located error (file:line:column).

use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::desc::{blocks_into, SceneDesc};
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::Light;
use crate::load::{load_model, LoadOptions};
use crate::model::Model;
use crate::rng::Rng;
use crate::scene::Scene;
use glam::{DVec3, Mat4, Vec3};
use rhai::{
    Array, CallFnOptions, Dynamic, Engine, EvalAltResult, Map, Module, ModuleResolver,
    NativeCallContext, Position, Scope, Shared as RhaiShared, AST, FLOAT, INT,
};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};

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

/// Seconds per update step.
pub const STEP: f64 = 1.0 / 60.0;

/// Most update steps one request for a time may run (ten minutes of scene
/// time); further times are refused rather than frozen on.
pub const MAX_STEPS_AT_ONCE: u64 = 36_000;

/// The sandbox's limits, per call into the script (the load, `init`, each `update`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Rhai operations (roughly one per expression node evaluated).
    pub operations: u64,
    /// Nested function calls.
    pub call_depth: usize,
    /// Nested expressions, at global level and in functions.
    pub expression_depth: usize,
    /// Bytes in one string.
    pub string_bytes: usize,
    /// Elements in one array.
    pub array_len: usize,
    /// Entries in one map.
    pub map_len: usize,
    /// Objects (lights, models, cameras) the load may add: each is read by
    /// the `.scene` reader, about 0.1 ms apiece.
    pub objects: usize,
    /// Wall-clock seconds one call may run: the load, `init` or one `update`
    /// step. It bounds what the operation count cannot: Rhai re-measures an
    /// array after every push, so growing one is quadratic in its length.
    pub call_seconds: f64,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            operations: 50_000_000,
            call_depth: 64,
            expression_depth: 64,
            string_bytes: 1 << 20,
            array_len: 1 << 20,
            map_len: 1 << 16,
            objects: 100_000,
            call_seconds: 30.0,
        }
    }
}

/// What the script's functions act on.
struct State {
    /// The scene file (or the script, for `.rhai` scenes): blocks resolve against it.
    scene: PathBuf,
    /// Objects the load adds (positions relative to `desc.origin`).
    desc: SceneDesc,
    /// Lights the scene had before the script's, so a light's index counts every light.
    lights_before: usize,
    /// The scene's placements before the script's (file, transform), for bounds
    /// and so a placement's index counts every placement.
    models_before: Vec<(PathBuf, Mat4)>,
    /// Problems the `.scene` reader reported for added objects.
    diag: Diagnostics,
    rng: Rng,
    /// How model files are loaded for `scene_bounds`.
    options: LoadOptions,
    /// Model files `scene_bounds` loaded, by canonical path, for the scene to reuse.
    models: HashMap<PathBuf, Model>,
    /// Each model file's bounds, by canonical path.
    model_bounds: HashMap<PathBuf, Aabb>,
    /// After the load: the loaded scene's bounds (relative to the origin).
    scene_bounds: Aabb,
    /// Per frame: the scene's lights as the script leaves them, which are
    /// on, and which it has changed (the others keep their `.scene` motions).
    lights: Vec<Light>,
    on: Vec<bool>,
    touched: Vec<bool>,
    /// Per frame: each placement's model-to-world transform (relative to the
    /// origin) and its colour override.
    transforms: Vec<Mat4>,
    colors: Vec<Option<Vec3>>,
    /// Per frame: the scene's cameras, and which the script has set.
    cameras: Vec<Camera>,
    camera_set: Vec<bool>,
    /// Whether objects may be added (the load) or lights changed (init, update).
    loading: bool,
    /// Objects the load has added, and how many it may ([`Limits::objects`]).
    objects_added: usize,
    object_limit: usize,
    /// When the call running now must end ([`Limits::call_seconds`]).
    deadline: Option<std::time::Instant>,
}

impl State {
    /// The state for loading `scene_file`'s script, with nothing per frame yet.
    fn loading(
        script_ref: &ScriptRef,
        scene_file: &Path,
        origin: DVec3,
        options: &LoadOptions,
    ) -> Self {
        Self {
            scene: scene_file.to_path_buf(),
            desc: SceneDesc {
                origin,
                ..SceneDesc::default()
            },
            lights_before: script_ref.first_light,
            models_before: Vec::new(),
            diag: Diagnostics::default(),
            rng: Rng::new(0),
            options: options.clone(),
            models: HashMap::new(),
            model_bounds: HashMap::new(),
            scene_bounds: Aabb::EMPTY,
            lights: Vec::new(),
            on: Vec::new(),
            touched: Vec::new(),
            transforms: Vec::new(),
            colors: Vec::new(),
            cameras: Vec::new(),
            camera_set: Vec::new(),
            loading: true,
            objects_added: 0,
            object_limit: 0,
            deadline: None,
        }
    }

    /// The bounds (relative to the origin) of every model placed so far,
    /// loading model files not yet read.
    fn placed_bounds(&mut self) -> Result<Aabb, SceneError> {
        let placed: Vec<(PathBuf, Mat4, Location)> = self
            .models_before
            .iter()
            .map(|(file, m)| (file.clone(), *m, Location::file(file)))
            .chain(
                self.desc
                    .models
                    .iter()
                    .map(|p| (p.file.clone(), p.transform, p.at.clone())),
            )
            .collect();
        let mut bounds = Aabb::EMPTY;
        for (file, transform, at) in placed {
            let key = file.canonicalize().unwrap_or_else(|_| file.clone());
            let local = match self.model_bounds.get(&key) {
                Some(b) => *b,
                None => {
                    let model = load_model(&file, &at, &self.options, &mut self.diag)?;
                    let b = model.bounds;
                    self.model_bounds.insert(key.clone(), b);
                    self.models.insert(key, model);
                    b
                }
            };
            bounds = bounds.union(&local.transformed(&transform));
        }
        Ok(bounds)
    }
}

type Shared = Arc<Mutex<State>>;

fn lock(state: &Shared) -> MutexGuard<'_, State> {
    state
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn fail(ctx: &NativeCallContext, message: impl Into<String>) -> Box<EvalAltResult> {
    EvalAltResult::ErrorRuntime(message.into().into(), ctx.call_position()).into()
}

/// The script error as a scene error at the script's file, line and column.
/// [`located`] for an error raised inside function `name` (`init`,
/// `update`): one Rhai reports without a position (a time limit, say) is
/// located at the function's definition.
fn located_in(script: &Path, error: &EvalAltResult, name: &str) -> SceneError {
    let mut located = located(script, error);
    if let SceneError::Syntax { at, .. } = &mut located {
        if at.line.is_none() {
            *at = first_mention(script, &format!("fn {name}"));
        }
    }
    located
}

fn located(script: &Path, error: &EvalAltResult) -> SceneError {
    let at = position_at(script, error.position());
    let message = match error {
        EvalAltResult::ErrorRuntime(value, _) | EvalAltResult::ErrorTerminated(value, _) => {
            value.to_string()
        }
        other => other.to_string(),
    };
    let message = message
        .split(" (line ")
        .next()
        .unwrap_or_default()
        .to_string();
    SceneError::Syntax { at, message }
}

fn position_at(script: &Path, position: Position) -> Location {
    match (position.line(), position.position()) {
        (Some(line), Some(column)) => Location::column(script, line, column),
        (Some(line), None) => Location::line(script, line),
        _ => Location::file(script),
    }
}

/// How deeply imports may nest (a script importing one that imports another…).
pub const MAX_IMPORT_DEPTH: usize = 16;

/// `import` for scripts under one folder only, read through weft's one
/// reader; records what it read, and refuses an import cycle (which would
/// otherwise recurse until the stack overflows) naming the chain.
struct FolderResolver {
    root: PathBuf,
    read: Arc<Mutex<Vec<PathBuf>>>,
    /// The scripts being evaluated, outermost (the scene's script) first.
    resolving: Mutex<Vec<PathBuf>>,
    /// Modules already evaluated, by file, so a script imported by several
    /// (or inside `update`) is read and run once.
    modules: Mutex<HashMap<PathBuf, RhaiShared<Module>>>,
}

impl FolderResolver {
    fn new(root: PathBuf, script: &Path, read: Arc<Mutex<Vec<PathBuf>>>) -> Self {
        let script = script
            .canonicalize()
            .unwrap_or_else(|_| script.to_path_buf());
        Self {
            root,
            read,
            resolving: Mutex::new(vec![script]),
            modules: Mutex::new(HashMap::new()),
        }
    }

    /// Reads, compiles and runs one imported file.
    fn evaluate(
        &self,
        engine: &Engine,
        file: &Path,
        path: &str,
        position: Position,
    ) -> Result<RhaiShared<Module>, Box<EvalAltResult>> {
        let text =
            crate::source::read_text(file, &Location::file(file), crate::source::MAX_SCENE_BYTES)
                .map_err(|e| {
                EvalAltResult::ErrorRuntime(format!("import \"{path}\": {e}").into(), position)
            })?;
        let in_module = |e: Box<EvalAltResult>| {
            Box::new(EvalAltResult::ErrorInModule(path.to_string(), e, position))
        };
        let mut ast = engine.compile(&text).map_err(|e| in_module(e.into()))?;
        ast.set_source(file.to_string_lossy().as_ref());
        let module = Module::eval_ast_as_new(Scope::new(), &ast, engine).map_err(in_module)?;
        Ok(module.into())
    }
}

impl ModuleResolver for FolderResolver {
    fn resolve(
        &self,
        engine: &Engine,
        _source: Option<&str>,
        path: &str,
        position: Position,
    ) -> Result<RhaiShared<Module>, Box<EvalAltResult>> {
        let refuse =
            |message: String| Err(EvalAltResult::ErrorRuntime(message.into(), position).into());
        let file = self.root.join(format!("{path}.rhai"));
        let Some(canonical) = file
            .canonicalize()
            .ok()
            .filter(|f| f.starts_with(&self.root))
        else {
            return refuse(format!(
                "import \"{path}\": scripts may import only scripts under {}",
                self.root.display()
            ));
        };
        {
            let mut read = self.read.lock().unwrap_or_else(|p| p.into_inner());
            if !read.contains(&file) {
                read.push(file.clone());
            }
        }
        if let Some(module) = lock_any(&self.modules).get(&canonical) {
            return Ok(module.clone());
        }
        {
            let mut resolving = lock_any(&self.resolving);
            if let Some(first) = resolving.iter().position(|f| *f == canonical) {
                let chain: Vec<String> = resolving[first..]
                    .iter()
                    .chain(std::iter::once(&canonical))
                    .map(|f| {
                        f.file_name()
                            .unwrap_or_default()
                            .to_string_lossy()
                            .into_owned()
                    })
                    .collect();
                return refuse(format!(
                    "import \"{path}\" is a cycle: {}",
                    chain.join(" -> ")
                ));
            }
            if resolving.len() > MAX_IMPORT_DEPTH {
                return refuse(format!(
                    "import \"{path}\": imports nest deeper than {MAX_IMPORT_DEPTH} scripts"
                ));
            }
            resolving.push(canonical.clone());
        }
        let module = self.evaluate(engine, &file, path, position);
        lock_any(&self.resolving).pop();
        let module = module?;
        lock_any(&self.modules).insert(canonical, module.clone());
        Ok(module)
    }
}

/// A mutex's value, also after a panic elsewhere poisoned it.
fn lock_any<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|p| p.into_inner())
}

/// A number from a script value (integers and floats alike).
fn number(value: &Dynamic) -> Option<f64> {
    value
        .as_float()
        .ok()
        .or_else(|| value.as_int().ok().map(|i| i as FLOAT))
}

/// One property line of an object block, from a script map entry.
fn property(name: &str, value: &Dynamic) -> Result<String, String> {
    if let Some(n) = number(value) {
        return Ok(format!("\t{name} {n:?}\n"));
    }
    if let Some(array) = value.read_lock::<Array>() {
        let numbers: Option<Vec<String>> = array
            .iter()
            .map(|v| number(v).map(|n| format!("{n:?}")))
            .collect();
        return numbers
            .map(|n| format!("\t{name} {}\n", n.join(" ")))
            .ok_or_else(|| format!("property '{name}' must be a number or an array of numbers"));
    }
    if let Ok(text) = value.clone().into_immutable_string() {
        if text.contains('"') || text.contains('\n') {
            return Err(format!(
                "property '{name}' may not contain quotes or line breaks"
            ));
        }
        return Ok(format!("\t{name} \"{text}\"\n"));
    }
    if let Ok(flag) = value.as_bool() {
        return Ok(format!("\t{name} {}\n", u8::from(flag)));
    }
    Err(format!(
        "property '{name}' is a {}; expected a number, an array of numbers or a string",
        value.type_name()
    ))
}

/// The object block for `kind` (with an optional label) from a script map.
fn block_text(kind: &str, label: Option<&str>, props: &Map) -> Result<String, String> {
    let mut text = match label {
        Some(l) if l.contains('"') => return Err("a name may not contain quotes".into()),
        Some(l) => format!("{kind} \"{l}\"\n{{\n"),
        None => format!("{kind}\n{{\n"),
    };
    for (name, value) in props {
        text.push_str(&property(name, value)?);
    }
    text.push_str("}\n");
    Ok(text)
}

/// Adds one object through the `.scene` reader; returns the new object's
/// index over every object of its kind in the scene, for lights and models.
fn add_object(
    ctx: &NativeCallContext,
    state: &Shared,
    kind: &str,
    label: Option<&str>,
    props: &Map,
) -> Result<INT, Box<EvalAltResult>> {
    let mut s = lock(state);
    if !s.loading {
        return Err(fail(
            ctx,
            format!("{kind} objects are added while the scene loads, not in init or update"),
        ));
    }
    if s.objects_added >= s.object_limit {
        return Err(fail(
            ctx,
            format!(
                "{kind}: a script may add at most {} objects (lights, models and cameras) while the scene loads",
                s.object_limit
            ),
        ));
    }
    s.objects_added += 1;
    let text = block_text(kind, label, props).map_err(|m| fail(ctx, m))?;
    let scene = s.scene.clone();
    let State { desc, diag, .. } = &mut *s;
    blocks_into(&text, &scene, desc, diag)
        .map_err(|e| fail(ctx, format!("{kind}: {}", e.message())))?;
    let count = match kind {
        "model" => s.models_before.len() + s.desc.models.len(),
        _ => s.lights_before + s.desc.lights.len(),
    };
    Ok(count as INT - 1)
}

/// The object of `kind` that `props` describe, read by the `.scene` reader
/// (so a per-frame pose means what the same block in a file means), from
/// the properties in `allowed` only.
fn read_object(
    ctx: &NativeCallContext,
    s: &State,
    function: &str,
    (kind, label): (&str, Option<&str>),
    props: &Map,
    allowed: &[&str],
) -> Result<SceneDesc, Box<EvalAltResult>> {
    if let Some(key) = props.keys().find(|k| !allowed.contains(&k.as_str())) {
        return Err(fail(
            ctx,
            format!("{function} takes {}; not '{key}'", allowed.join(", ")),
        ));
    }
    let text = block_text(kind, label, props).map_err(|m| fail(ctx, m))?;
    let mut desc = SceneDesc {
        origin: s.desc.origin,
        ..SceneDesc::default()
    };
    blocks_into(&text, &s.scene, &mut desc, &mut Diagnostics::default())
        .map_err(|e| fail(ctx, format!("{function}: {}", e.message())))?;
    Ok(desc)
}

/// A script value's numbers (one number, or an array of numbers), for the
/// property `name`.
fn numbers_of(name: &str, value: &Dynamic) -> Result<Vec<f32>, String> {
    let wrong = || format!("'{name}' must be a number or an array of numbers");
    if let Some(n) = number(value) {
        return Ok(vec![n as f32]);
    }
    let array = value.read_lock::<Array>().ok_or_else(wrong)?;
    array
        .iter()
        .map(|v| number(v).map(|n| n as f32).ok_or_else(wrong))
        .collect()
}

/// The model-to-world transform (relative to `origin`) of a `model` block
/// with these `position`, `orientation` and `scale`, built as the `.scene`
/// reader builds it (the same rotation and scale rules) without going
/// through its text: `set_model_transform` runs per placement per step.
fn placement_transform(props: &Map, origin: DVec3) -> Result<Mat4, String> {
    let mut position = -origin;
    let mut rotation = glam::Quat::IDENTITY;
    let mut scale = Vec3::ONE;
    for (name, value) in props {
        match name.as_str() {
            "position" => {
                let p: Vec<f64> = match value.read_lock::<Array>() {
                    Some(a) => a.iter().filter_map(number).collect(),
                    None => Vec::new(),
                };
                let [x, y, z] = p[..] else {
                    return Err(format!(
                        "'position' expects an array of 3 numbers, found {value}"
                    ));
                };
                position = DVec3::new(x, y, z) - origin;
            }
            "orientation" => {
                rotation = crate::desc::rotation_from("orientation", &numbers_of(name, value)?)?
            }
            "scale" => scale = crate::desc::scale_from(&numbers_of(name, value)?)?,
            other => {
                return Err(format!(
                    "'{other}' is not a transform property (position, orientation, scale)"
                ))
            }
        }
    }
    Ok(Mat4::from_scale_rotation_translation(
        scale,
        rotation,
        position.as_vec3(),
    ))
}

/// The index of the `what` that `index` refers to (of `count`), for the
/// per-frame functions.
fn frame_index(
    ctx: &NativeCallContext,
    s: &State,
    (what, count): (&str, usize),
    index: INT,
) -> Result<usize, Box<EvalAltResult>> {
    if s.loading {
        return Err(fail(
            ctx,
            format!("{what}s are changed in init or update, after the scene has loaded"),
        ));
    }
    usize::try_from(index)
        .ok()
        .filter(|&i| i < count)
        .ok_or_else(|| fail(ctx, format!("no {what} {index}: the scene has {count}")))
}

/// The light `index` refers to, for the per-frame functions.
fn light_index(
    ctx: &NativeCallContext,
    s: &State,
    index: INT,
) -> Result<usize, Box<EvalAltResult>> {
    frame_index(ctx, s, ("light", s.lights.len()), index)
}

/// `v` as a script array of three floats.
fn array3(v: DVec3) -> Array {
    vec![v.x.into(), v.y.into(), v.z.into()]
}

/// Three numbers (integers or floats) as a finite vector.
fn vec3(
    ctx: &NativeCallContext,
    x: &Dynamic,
    y: &Dynamic,
    z: &Dynamic,
) -> Result<DVec3, Box<EvalAltResult>> {
    let (Some(x), Some(y), Some(z)) = (number(x), number(y), number(z)) else {
        return Err(fail(ctx, "expected three numbers"));
    };
    let v = DVec3::new(x, y, z);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(fail(ctx, format!("({x}, {y}, {z}) is not finite")))
    }
}

/// Three numbers as a colour: finite and not negative.
fn colour(
    ctx: &NativeCallContext,
    r: &Dynamic,
    g: &Dynamic,
    b: &Dynamic,
) -> Result<Vec3, Box<EvalAltResult>> {
    let c = vec3(ctx, r, g, b)?.as_vec3();
    if c.min_element() < 0.0 {
        return Err(fail(ctx, format!("colour {c} is negative")));
    }
    Ok(c)
}

/// Registers every function scripts may call.
fn register(engine: &mut Engine, state: &Shared, origin: DVec3) {
    for (name, kind) in [
        ("point_light", "pointlight"),
        ("spot_light", "spotlight"),
        ("sun_light", "sunlight"),
        ("area_light", "arealight"),
    ] {
        let st = state.clone();
        engine.register_fn(name, move |ctx: NativeCallContext, props: Map| {
            add_object(&ctx, &st, kind, None, &props)
        });
    }
    let st = state.clone();
    engine.register_fn(
        "model",
        move |ctx: NativeCallContext, file: &str, props: Map| {
            let mut props = props;
            props.insert("file".into(), file.into());
            add_object(&ctx, &st, "model", None, &props)
        },
    );
    register_models(engine, state, origin);
    register_model_colors(engine, state);
    register_cameras(engine, state);
    let st = state.clone();
    engine.register_fn(
        "camera",
        move |ctx: NativeCallContext, name: &str, props: Map| {
            add_object(&ctx, &st, "camera", Some(name), &props).map(|_| ())
        },
    );
    let st = state.clone();
    engine.register_fn("rand", move || FLOAT::from(lock(&st).rng.next_f32()));
    let st = state.clone();
    engine.register_fn(
        "rand_range",
        move |ctx: NativeCallContext, lo: Dynamic, hi: Dynamic| {
            let (Some(lo), Some(hi)) = (number(&lo), number(&hi)) else {
                return Err(fail(&ctx, "rand_range expects two numbers"));
            };
            Ok::<FLOAT, Box<EvalAltResult>>(lo + (hi - lo) * FLOAT::from(lock(&st).rng.next_f32()))
        },
    );
    let st = state.clone();
    engine.register_fn("light_count", move || {
        let s = lock(&st);
        (if s.loading {
            s.lights_before + s.desc.lights.len()
        } else {
            s.lights.len()
        }) as INT
    });
    let st = state.clone();
    engine.register_fn("light_position", move |ctx: NativeCallContext, i: INT| {
        let s = lock(&st);
        let i = light_index(&ctx, &s, i)?;
        // Positions are stored relative to the scene's origin; a sun's direction is not a point.
        let world = match &s.lights[i] {
            Light::Point(l) => origin + l.position.as_dvec3(),
            Light::Spot(l) => origin + l.position.as_dvec3(),
            Light::Area(l) => origin + l.position.as_dvec3(),
            Light::Sun(l) => l.direction.as_dvec3(),
        };
        Ok::<Array, Box<EvalAltResult>>(array3(world))
    });
    let st = state.clone();
    engine.register_fn(
        "set_light_position",
        move |ctx: NativeCallContext, i: INT, x: Dynamic, y: Dynamic, z: Dynamic| {
            let p = (vec3(&ctx, &x, &y, &z)? - origin).as_vec3();
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            match &mut s.lights[i] {
                Light::Point(l) => l.position = p,
                Light::Spot(l) => l.position = p,
                Light::Area(l) => l.position = p,
                Light::Sun(_) => {
                    return Err(fail(
                        &ctx,
                        format!("light {i} is a sun: it has a direction, not a position"),
                    ))
                }
            }
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
    let st = state.clone();
    engine.register_fn(
        "set_light_direction",
        move |ctx: NativeCallContext, i: INT, x: Dynamic, y: Dynamic, z: Dynamic| {
            let d = vec3(&ctx, &x, &y, &z)?.as_vec3();
            let Some(d) = d.try_normalize() else {
                return Err(fail(&ctx, "a light's direction must not be zero"));
            };
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            match &mut s.lights[i] {
                Light::Sun(l) => l.direction = d,
                Light::Spot(l) => l.direction = d,
                _ => {
                    return Err(fail(
                        &ctx,
                        format!("light {i} has no direction (suns and spots do)"),
                    ))
                }
            }
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
    let st = state.clone();
    engine.register_fn(
        "set_light_color",
        move |ctx: NativeCallContext, i: INT, r: Dynamic, g: Dynamic, b: Dynamic| {
            let c = colour(&ctx, &r, &g, &b)?;
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            match &mut s.lights[i] {
                Light::Sun(l) => l.color = c,
                Light::Spot(l) => l.color = c,
                Light::Point(l) => l.color = c,
                Light::Area(l) => l.emission = c,
            }
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
    let st = state.clone();
    engine.register_fn(
        "set_light_on",
        move |ctx: NativeCallContext, i: INT, on: bool| {
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
            s.touched[i] = true;
            s.on[i] = on;
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

/// The functions on model placements: their count and bounds, and per frame
/// their transforms.
fn register_models(engine: &mut Engine, state: &Shared, origin: DVec3) {
    let st = state.clone();
    engine.register_fn("model_count", move || {
        let s = lock(&st);
        (if s.loading {
            s.models_before.len() + s.desc.models.len()
        } else {
            s.transforms.len()
        }) as INT
    });
    let st = state.clone();
    engine.register_fn("scene_bounds", move |ctx: NativeCallContext| {
        let mut s = lock(&st);
        let bounds = if s.loading {
            s.placed_bounds()
                .map_err(|e| fail(&ctx, format!("scene_bounds: {e}")))?
        } else {
            s.scene_bounds
        };
        if bounds.is_empty() {
            return Err(fail(&ctx, "scene_bounds: no model is placed yet"));
        }
        let mut map = Map::new();
        map.insert("min".into(), array3(origin + bounds.min.as_dvec3()).into());
        map.insert("max".into(), array3(origin + bounds.max.as_dvec3()).into());
        Ok::<Map, Box<EvalAltResult>>(map)
    });
    let st = state.clone();
    engine.register_fn("model_position", move |ctx: NativeCallContext, i: INT| {
        let s = lock(&st);
        let i = frame_index(&ctx, &s, ("model", s.transforms.len()), i)?;
        let p = s.transforms[i].w_axis.truncate().as_dvec3();
        Ok::<Array, Box<EvalAltResult>>(array3(origin + p))
    });
    let st = state.clone();
    engine.register_fn(
        "set_model_transform",
        move |ctx: NativeCallContext, i: INT, props: Map| {
            let mut s = lock(&st);
            let i = frame_index(&ctx, &s, ("model", s.transforms.len()), i)?;
            let transform = placement_transform(&props, origin)
                .map_err(|m| fail(&ctx, format!("set_model_transform: {m}")))?;
            if !transform.is_finite() {
                return Err(fail(
                    &ctx,
                    "set_model_transform: the transform is not finite",
                ));
            }
            s.transforms[i] = transform;
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

/// `set_model_color`: a placement's colour override per frame.
fn register_model_colors(engine: &mut Engine, state: &Shared) {
    let st = state.clone();
    engine.register_fn(
        "set_model_color",
        move |ctx: NativeCallContext, i: INT, r: Dynamic, g: Dynamic, b: Dynamic| {
            let c = colour(&ctx, &r, &g, &b)?;
            let mut s = lock(&st);
            let i = frame_index(&ctx, &s, ("model", s.colors.len()), i)?;
            s.colors[i] = Some(c);
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

/// `set_camera`: a camera's pose (and field of view) per frame.
fn register_cameras(engine: &mut Engine, state: &Shared) {
    let st = state.clone();
    engine.register_fn(
        "set_camera",
        move |ctx: NativeCallContext, name: &str, props: Map| {
            let mut s = lock(&st);
            if s.loading {
                return Err(fail(
                    &ctx,
                    "cameras are moved in init or update; at load, add them with camera(name, #{...})",
                ));
            }
            let Some(i) = s.cameras.iter().position(|c| c.name == name) else {
                let names: Vec<&str> = s.cameras.iter().map(|c| c.name.as_str()).collect();
                return Err(fail(
                    &ctx,
                    format!("no camera '{name}': the scene has {}", names.join(", ")),
                ));
            };
            if !props.contains_key("position") {
                return Err(fail(&ctx, "set_camera needs a 'position'"));
            }
            let desc = read_object(
                &ctx,
                &s,
                "set_camera",
                ("camera", Some(name)),
                &props,
                &["position", "target", "orientation", "fov", "fov_deg"],
            )?;
            let set = &desc.cameras[0];
            let camera = &mut s.cameras[i];
            camera.position = set.position;
            camera.orientation = set.orientation;
            if props.contains_key("fov") || props.contains_key("fov_deg") {
                camera.fov_y = set.fov_y;
            }
            camera.path.clear();
            s.camera_set[i] = true;
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

fn engine_for(
    script: &Path,
    state: &Shared,
    origin: DVec3,
    limits: &Limits,
    imports: &Arc<Mutex<Vec<PathBuf>>>,
) -> Engine {
    let mut engine = Engine::new();
    engine
        .set_max_operations(limits.operations)
        .set_max_call_levels(limits.call_depth)
        .set_max_expr_depths(limits.expression_depth, limits.expression_depth)
        .set_max_string_size(limits.string_bytes)
        .set_max_array_size(limits.array_len)
        .set_max_map_size(limits.map_len);
    let root = script
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let root = root.canonicalize().unwrap_or_else(|_| root.to_path_buf());
    engine.set_module_resolver(FolderResolver::new(root, script, imports.clone()));
    engine.on_print(|_| {});
    engine.on_debug(|_, _, _| {});
    let (watched, seconds) = (state.clone(), limits.call_seconds);
    engine.on_progress(move |operations| {
        let deadline = (operations % 1024 == 0).then(|| lock(&watched).deadline)??;
        (std::time::Instant::now() > deadline).then(|| {
            Dynamic::from(format!(
                "the script ran past its limit of {seconds} s for one call (the load, init or one update step)"
            ))
        })
    });
    {
        let mut s = lock(state);
        s.object_limit = limits.objects;
    }
    register(&mut engine, state, origin);
    engine
}

/// Starts the clock of one call ([`Limits::call_seconds`]).
fn start_call(state: &Shared, limits_seconds: f64) {
    lock(state).deadline = std::time::Instant::now().checked_add(
        std::time::Duration::from_secs_f64(limits_seconds.clamp(0.0, 1e9)),
    );
}

/// Runs the script's top level, then checks the variables it leaves against
/// the size limits. Rhai 1.27 checks a map's size when `m.k = v` adds a key
/// but not when `m[k] = v` does, so a map can outgrow its limit by indexing.
fn run_top_level(engine: &Engine, ast: &AST, script: &Path) -> Result<(), SceneError> {
    let mut scope = Scope::new();
    engine
        .run_ast_with_scope(&mut scope, ast)
        .map_err(|e| located(script, &e))?;
    for (name, _, value) in scope.iter_raw() {
        within_limits(
            engine,
            script,
            value,
            (&format!("variable `{name}`"), &format!("let {name}")),
        )?;
    }
    Ok(())
}

/// `value` checked against the string, array and map size limits. The
/// state kept between `update` calls is checked after each call, so indexing
/// cannot grow it past a limit frame by frame.
fn within_limits(
    engine: &Engine,
    script: &Path,
    value: &Dynamic,
    (what, declared_by): (&str, &str),
) -> Result<(), SceneError> {
    engine
        .ensure_data_size_within_limits(value)
        .map_err(|e| SceneError::Syntax {
            at: first_mention(script, declared_by),
            message: format!("{what}: {e}"),
        })
}

/// Where `words` (`fn update`, `let x`) first appear in the script as weft
/// read it: a value that outgrew a limit is located where it was declared.
fn first_mention(script: &Path, words: &str) -> Location {
    let text = weft_io::sources::text_of(script);
    let found = text.as_deref().and_then(|text| {
        text.lines().enumerate().find_map(|(i, line)| {
            let column = line.find(words)?;
            let end = line[column + words.len()..].chars().next();
            end.is_none_or(|c| !(c.is_alphanumeric() || c == '_'))
                .then(|| Location::column(script, i + 1, line[..column].chars().count() + 1))
        })
    });
    found.unwrap_or_else(|| Location::file(script))
}

fn compile(engine: &Engine, script: &Path) -> Result<AST, SceneError> {
    let at = Location::file(script);
    let text = crate::source::read_text(script, &at, crate::source::MAX_SCENE_BYTES)?;
    engine.compile(&text).map_err(|e| SceneError::Syntax {
        at: position_at(script, e.position()),
        message: e.err_type().to_string(),
    })
}

/// Runs `script`'s top level, adding its objects to `desc` (after those
/// already there); records the script as the scene's. Returns the model
/// files `scene_bounds` loaded, by canonical path, for the scene to reuse.
pub fn run_load(
    script_ref: &mut ScriptRef,
    scene_file: &Path,
    desc: &mut SceneDesc,
    diag: &mut Diagnostics,
    (options, limits): (&LoadOptions, &Limits),
) -> Result<HashMap<PathBuf, Model>, SceneError> {
    let path = script_ref.path.clone();
    let script = path.as_path();
    script_ref.first_model = desc.models.len();
    let mut loading = State::loading(script_ref, scene_file, desc.origin, options);
    loading.models_before = desc
        .models
        .iter()
        .map(|p| (p.file.clone(), p.transform))
        .collect();
    let state: Shared = Arc::new(Mutex::new(loading));
    let imports = Arc::new(Mutex::new(Vec::new()));
    let engine = engine_for(script, &state, desc.origin, limits, &imports);
    let ast = compile(&engine, script)?;
    start_call(&state, limits.call_seconds);
    run_top_level(&engine, &ast, script)?;
    script_ref.imports = std::mem::take(&mut *imports.lock().unwrap_or_else(|p| p.into_inner()));
    let mut s = lock(&state);
    let added = std::mem::take(&mut s.desc);
    desc.models.extend(added.models);
    desc.lights.extend(added.lights);
    desc.cameras.extend(added.cameras);
    if added.bounding_box.is_some() {
        desc.bounding_box = added.bounding_box;
    }
    diag.warnings.append(&mut s.diag.warnings);
    Ok(std::mem::take(&mut s.models))
}

/// What a script's `update` leaves for a frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ScriptFrame {
    /// Every light of the scene (those switched off with zero colour).
    pub lights: Vec<Light>,
    /// Per light, whether the script has changed it since time 0; a light
    /// it has not changed keeps its `.scene` motion (`velocity`, `swivel`,
    /// `motion`), which the renderer evaluates.
    pub touched: Vec<bool>,
    /// Every placement's model-to-world transform, relative to the origin.
    pub transforms: Vec<Mat4>,
    /// Every placement's colour override (`color`), as loaded or as the
    /// script set it.
    pub colors: Vec<Option<Vec3>>,
    /// The cameras the script has set since time 0, with their paths cleared.
    pub cameras: Vec<Camera>,
}

/// The per-frame objects as the scene loaded them, to start over from.
struct Loaded {
    /// The random sequence where the load left it, so every restart draws
    /// the same numbers.
    rng: Rng,
    lights: Vec<Light>,
    transforms: Vec<Mat4>,
    colors: Vec<Option<Vec3>>,
    cameras: Vec<Camera>,
}

/// A loaded scene's script, running per frame: the lights, placements and
/// cameras at a time.
pub struct ScriptRuntime {
    script: PathBuf,
    engine: Engine,
    ast: AST,
    state: Shared,
    loaded: Loaded,
    has_init: bool,
    has_update: bool,
    /// `init`'s value, seen by `update` as `this`.
    this: Dynamic,
    /// Update steps run since time 0.
    steps: u64,
    /// [`Limits::call_seconds`].
    call_seconds: f64,
}

impl ScriptRuntime {
    /// The runtime for `scene`'s script, with the scene's objects as loaded
    /// (the script's own included): runs the load again for the script's
    /// random state (reading bounds from the loaded models), then `init`.
    pub fn new(script_ref: &ScriptRef, scene: &Scene, limits: &Limits) -> Result<Self, SceneError> {
        let script = script_ref.path.as_path();
        let origin = scene.origin;
        let canonical = |p: &Path| p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
        let mut loading = State::loading(script_ref, &scene.path, origin, &LoadOptions::default());
        loading.models_before = scene
            .instances
            .iter()
            .take(script_ref.first_model)
            .filter_map(|i| Some((scene.models.get(i.model)?.path.clone(), i.transform)))
            .collect();
        loading.model_bounds = scene
            .models
            .iter()
            .map(|m| (canonical(&m.path), m.bounds))
            .collect();
        loading.scene_bounds = scene.bounds;
        let mut loaded = Loaded {
            rng: Rng::new(0),
            lights: scene.lights.clone(),
            transforms: scene.instances.iter().map(|i| i.transform).collect(),
            colors: scene.instances.iter().map(|i| i.material.color).collect(),
            cameras: scene.cameras.clone(),
        };
        let state: Shared = Arc::new(Mutex::new(loading));
        let engine = engine_for(script, &state, origin, limits, &Arc::default());
        let ast = compile(&engine, script)?;
        start_call(&state, limits.call_seconds);
        run_top_level(&engine, &ast, script)?;
        {
            let mut s = lock(&state);
            s.loading = false;
            loaded.rng = s.rng.clone();
        }
        let has = |name: &str, params: usize| {
            ast.iter_functions()
                .any(|f| f.name == name && f.params.len() == params)
        };
        let mut runtime = Self {
            script: script.to_path_buf(),
            has_init: has("init", 0),
            has_update: has("update", 2),
            engine,
            ast,
            state,
            loaded,
            this: Dynamic::UNIT,
            steps: 0,
            call_seconds: limits.call_seconds,
        };
        runtime.restart()?;
        if runtime.has_update {
            // One step now, so an `update` that fails is refused at load, as
            // the same located error in `weft render`, `--watch` and `weft
            // view`, whatever time they start at; then back to time 0.
            runtime.frame_at(STEP)?;
            runtime.restart()?;
        }
        Ok(runtime)
    }

    /// Back to time 0: the loaded objects, lights all on, and `init` run again.
    fn restart(&mut self) -> Result<(), SceneError> {
        {
            let mut s = lock(&self.state);
            s.rng = self.loaded.rng.clone();
            s.lights = self.loaded.lights.clone();
            s.on = vec![true; self.loaded.lights.len()];
            s.touched = vec![false; self.loaded.lights.len()];
            s.transforms = self.loaded.transforms.clone();
            s.colors = self.loaded.colors.clone();
            s.cameras = self.loaded.cameras.clone();
            s.camera_set = vec![false; self.loaded.cameras.len()];
        }
        self.steps = 0;
        start_call(&self.state, self.call_seconds);
        self.this = if self.has_init {
            self.engine
                .call_fn_with_options::<Dynamic>(
                    CallFnOptions::new().eval_ast(false),
                    &mut Scope::new(),
                    &self.ast,
                    "init",
                    (),
                )
                .map_err(|e| located_in(&self.script, &e, "init"))?
        } else {
            Dynamic::UNIT
        };
        within_limits(
            &self.engine,
            &self.script,
            &self.this,
            ("the state `init` returned", "fn init"),
        )
    }

    /// Whether the script animates anything (has `fn update(t, dt)`).
    pub fn animates(&self) -> bool {
        self.has_update
    }

    /// The scene at `time`: `update` run in steps of [`STEP`] from 0 up to
    /// `time` (from the last step taken when time only moved forward). Lights
    /// switched off come back with zero colour. On an error the runtime
    /// starts over at the next call.
    pub fn frame_at(&mut self, time: f64) -> Result<ScriptFrame, SceneError> {
        let target = if time.is_finite() && time > 0.0 {
            (time / STEP).floor() as u64
        } else {
            0
        };
        if target < self.steps {
            self.restart()?;
        }
        if self.has_update && target - self.steps > MAX_STEPS_AT_ONCE {
            return Err(SceneError::Syntax {
                at: Location::file(&self.script),
                message: format!(
                    "time {time} s needs {} update steps of 1/60 s; at most {MAX_STEPS_AT_ONCE} run at once",
                    target - self.steps
                ),
            });
        }
        while self.has_update && self.steps < target {
            self.steps += 1;
            let t = self.steps as f64 * STEP;
            start_call(&self.state, self.call_seconds);
            let result = self.engine.call_fn_with_options::<Dynamic>(
                CallFnOptions::new()
                    .eval_ast(false)
                    .bind_this_ptr(&mut self.this),
                &mut Scope::new(),
                &self.ast,
                "update",
                (t, STEP),
            );
            let checked = result
                .map_err(|e| located_in(&self.script, &e, "update"))
                .and_then(|_| {
                    within_limits(
                        &self.engine,
                        &self.script,
                        &self.this,
                        (
                            &format!("the state (`this`) after update at t = {t:.3} s"),
                            "fn update",
                        ),
                    )
                });
            if let Err(e) = checked {
                self.steps = u64::MAX;
                return Err(e);
            }
        }
        let s = lock(&self.state);
        Ok(ScriptFrame {
            lights: s
                .lights
                .iter()
                .zip(&s.on)
                .map(|(light, &on)| {
                    if on {
                        light.clone()
                    } else {
                        switched_off(light)
                    }
                })
                .collect(),
            touched: s.touched.clone(),
            transforms: s.transforms.clone(),
            colors: s.colors.clone(),
            cameras: s
                .cameras
                .iter()
                .zip(&s.camera_set)
                .filter(|(_, &set)| set)
                .map(|(c, _)| c.clone())
                .collect(),
        })
    }
}

/// `light` giving no light.
fn switched_off(light: &Light) -> Light {
    let mut off = light.clone();
    match &mut off {
        Light::Sun(l) => {
            l.color = Vec3::ZERO;
            l.ambient = Vec3::ZERO;
        }
        Light::Spot(l) => l.color = Vec3::ZERO,
        Light::Point(l) => l.color = Vec3::ZERO,
        Light::Area(l) => l.emission = Vec3::ZERO,
    }
    off
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::PointLight;

    /// A folder of its own under the temp folder, with `files` written in it.
    fn folder(name: &str, files: &[(&str, &str)]) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("weft-script-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for (file, text) in files {
            let path = dir.join(file);
            std::fs::create_dir_all(path.parent().unwrap()).unwrap();
            std::fs::write(path, text).unwrap();
        }
        dir
    }

    fn script_ref(path: &Path) -> ScriptRef {
        ScriptRef {
            path: path.to_path_buf(),
            at: Location::file(path),
            first_light: 0,
            first_model: 0,
            imports: Vec::new(),
        }
    }

    /// The runtime of the `.rhai` scene at `path`, loaded as a scene.
    fn runtime(path: &Path) -> ScriptRuntime {
        try_runtime(path).unwrap()
    }

    /// The runtime of the `.rhai` scene at `path`, or why it is refused (an
    /// `update` that fails at its first step is refused at load).
    fn try_runtime(path: &Path) -> Result<ScriptRuntime, SceneError> {
        let scene = crate::load_scene(path).unwrap();
        ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &Limits::default())
    }

    /// Runs a `.rhai` scene's load with `limits`.
    fn load(dir: &Path, limits: &Limits) -> Result<SceneDesc, SceneError> {
        let path = dir.join("scene.rhai");
        let mut desc = SceneDesc::default();
        let mut script = script_ref(&path);
        run_load(
            &mut script,
            &path,
            &mut desc,
            &mut Diagnostics::default(),
            (&LoadOptions::default(), limits),
        )?;
        desc.script = Some(script);
        Ok(desc)
    }

    fn point(light: &Light) -> &PointLight {
        match light {
            Light::Point(p) => p,
            other => panic!("not a point light: {other:?}"),
        }
    }

    #[test]
    fn objects_a_script_adds_are_the_scene_files_objects() {
        let dir = folder(
            "objects",
            &[(
                "scene.rhai",
                r#"
                point_light(#{ position: [1, 2, 3], color: [0.5, 0.25, 1], radius: 4 });
                spot_light(#{ position: [0, 5, 0], direction: [0, -1, 0], angle: 30 });
                sun_light(#{ direction: [0, -1, 0], ambient: 0.1 });
                area_light(#{ position: [0, 4, 0], size: [1, 2] });
                model("box.obj", #{ position: [1, 0, 0], scale: 2 });
                camera("top", #{ position: [0, 9, 0.1], target: [0, 0, 0] });
                "#,
            )],
        );
        let from_script = load(&dir, &Limits::default()).unwrap();
        let text = "pointlight\n{\n\tposition 1 2 3\n\tcolor 0.5 0.25 1\n\tradius 4\n}\n\
            spotlight\n{\n\tposition 0 5 0\n\tdirection 0 -1 0\n\tangle 30\n}\n\
            sunlight\n{\n\tdirection 0 -1 0\n\tambient 0.1\n}\n\
            arealight\n{\n\tposition 0 4 0\n\tsize 1 2\n}\n\
            model\n{\n\tfile \"box.obj\"\n\tposition 1 0 0\n\tscale 2\n}\n\
            camera \"top\"\n{\n\tposition 0 9 0.1\n\ttarget 0 0 0\n}\n";
        let from_file =
            crate::scene_desc_from_str(text, &dir.join("scene.rhai"), &mut Diagnostics::default())
                .unwrap();
        assert_eq!(from_script.lights, from_file.lights);
        assert_eq!(from_script.cameras, from_file.cameras);
        assert_eq!(from_script.models.len(), 1);
        assert_eq!(from_script.models[0].file, dir.join("box.obj"));
        assert_eq!(
            from_script.models[0].transform,
            from_file.models[0].transform
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn updates_are_fixed_steps_so_a_time_gives_the_same_lights_however_it_is_reached() {
        let dir = folder(
            "steps",
            &[(
                "scene.rhai",
                r#"
                point_light(#{ position: [0, 0, 0], color: [1, 1, 1] });
                fn init() { #{ steps: 0 } }
                fn update(t, dt) {
                    this.steps += 1;
                    let p = light_position(0);
                    set_light_position(0, p[0] + dt, t, this.steps);
                    set_light_on(0, this.steps % 2 == 0);
                }
                "#,
            )],
        );
        let path = dir.join("scene.rhai");
        let runtime = || runtime(&path);
        let mut a = runtime();
        assert!(a.animates());
        // 0.5 s = 30 steps of 1/60 s: x = 30 / 60, y = t of the last step, z = steps.
        let at_half = a.frame_at(0.5).unwrap().lights;
        let p = point(&at_half[0]);
        assert!(
            (p.position - Vec3::new(0.5, 0.5, 30.0)).abs().max_element() < 1e-5,
            "{p:?}"
        );
        assert_eq!(p.color, Vec3::ONE, "step 30 is even: on");
        // Reached through other frame times, or again after going back: the same.
        let mut b = runtime();
        for t in [0.1, 0.25, 0.4999, 0.5] {
            b.frame_at(t).unwrap();
        }
        assert_eq!(b.frame_at(0.5).unwrap().lights, at_half);
        a.frame_at(3.0).unwrap();
        assert_eq!(
            a.frame_at(0.5).unwrap().lights,
            at_half,
            "going back starts over"
        );
        // Step 31 is odd: off, with zero colour.
        assert_eq!(
            point(&a.frame_at(31.0 / 60.0 + 1e-9).unwrap().lights[0]).color,
            Vec3::ZERO
        );
        assert_eq!(
            point(&a.frame_at(0.0).unwrap().lights[0]).position,
            Vec3::ZERO
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// The error a script body gets under `limits`, with its location.
    fn load_error(name: &str, body: &str, limits: &Limits) -> String {
        let dir = folder(name, &[("scene.rhai", body)]);
        let error = load(&dir, limits)
            .map(|_| ())
            .expect_err(&format!("{name} refused"))
            .to_string();
        std::fs::remove_dir_all(&dir).unwrap();
        error.replace(&dir.join("scene.rhai").display().to_string(), "scene.rhai")
    }

    #[test]
    fn each_limit_stops_a_script_with_a_located_error() {
        let small = Limits {
            operations: 10_000,
            call_depth: 8,
            expression_depth: 16,
            string_bytes: 64,
            array_len: 16,
            map_len: 4,
            ..Limits::default()
        };
        let cases = [
            (
                "loop",
                "let x = 0;\nloop { x += 1; }",
                "scene.rhai:2:",
                "Too many operations",
            ),
            (
                "depth",
                "fn f(n) { f(n + 1) }\nf(0);",
                "scene.rhai:2:",
                "Stack overflow",
            ),
            (
                "string",
                "let s = \"\";\nfor i in 0..100 { s += \"x\"; }",
                "scene.rhai:2:",
                "Length of string",
            ),
            (
                "array",
                "let a = [];\nfor i in 0..100 { a.push(i); }",
                "scene.rhai:2:",
                "Size of array",
            ),
            (
                "map",
                "let m = #{ a: 1, b: 2, c: 3 };\nm.mixin(#{ d: 4, e: 5, f: 6 });",
                "scene.rhai:2:",
                "Size of object map",
            ),
            (
                "expression",
                &format!("let x = {}1{};", "(".repeat(40), ")".repeat(40)),
                "scene.rhai:1:",
                "Expression exceeds maximum complexity",
            ),
        ];
        for (name, body, at, message) in cases {
            let error = load_error(name, body, &small);
            assert!(error.starts_with(at), "{name}: {error}");
            assert!(error.contains(message), "{name}: {error}");
        }
    }

    #[test]
    fn the_load_adds_at_most_the_object_limit_and_each_call_has_a_time_limit() {
        let few = Limits {
            objects: 3,
            ..Limits::default()
        };
        let error = load_error(
            "objects",
            "for i in 0..2000000 {\n    point_light(#{ position: [0, 1, 0], color: [1, 1, 1] });\n}",
            &few,
        );
        assert_eq!(
            error,
            "scene.rhai:2:5: pointlight: a script may add at most 3 objects (lights, models and cameras) while the scene loads"
        );
        // Growing an array costs Rhai time quadratic in its length; the call's
        // clock stops it, located where it was.
        let quick = Limits {
            call_seconds: 0.2,
            ..Limits::default()
        };
        let started = std::time::Instant::now();
        let error = load_error("slow", "let a = [];\nloop {\n    a.push(1);\n}", &quick);
        assert!(
            started.elapsed() < std::time::Duration::from_secs(5),
            "{:?}",
            started.elapsed()
        );
        assert!(
            error.starts_with("scene.rhai:3:")
                && error.ends_with("the script ran past its limit of 0.2 s for one call (the load, init or one update step)"),
            "{error}"
        );
        let dir = folder(
            "slow-update",
            &[(
                "scene.rhai",
                "fn update(t, dt) {\n    let a = [];\n    loop { a.push(t); }\n}\n",
            )],
        );
        let path = dir.join("scene.rhai");
        let scene = crate::load_scene(&path).unwrap();
        let error = ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &quick)
            .err()
            .expect("stopped at load, in the first update step")
            .to_string();
        assert!(
            error.starts_with(&format!("{}:1:1: ", path.display()))
                && error.contains("ran past its limit of 0.2 s"),
            "{error}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn maps_grown_by_indexing_are_held_to_the_size_limit() {
        let small = Limits {
            map_len: 4,
            ..Limits::default()
        };
        let error = load_error(
            "map-index",
            "let m = #{};\nfor i in 0..10 { m[\"k\" + i] = i; }",
            &small,
        );
        assert_eq!(
            error,
            "scene.rhai:1:1: variable `m`: Size of object map too large"
        );
        let dir = folder(
            "map-state",
            &[(
                "scene.rhai",
                "fn init() { #{ m: #{} } }\nfn update(t, dt) { this.m[\"k\" + t] = t; }\n",
            )],
        );
        let path = dir.join("scene.rhai");
        let scene = crate::load_scene(&path).unwrap();
        let mut runtime =
            ScriptRuntime::new(scene.script.as_ref().unwrap(), &scene, &small).unwrap();
        // Rhai counts nested maps' entries together: `m` and three keys are four.
        runtime
            .frame_at(3.5 * STEP)
            .expect("four entries are within the limit");
        let error = runtime
            .frame_at(4.5 * STEP)
            .expect_err("a fifth entry")
            .to_string();
        assert_eq!(
            error,
            format!(
                "{}:2:1: the state (`this`) after update at t = 0.067 s: Size of object map too large",
                path.display()
            )
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn runtime_errors_and_misuse_are_located_at_file_line_and_column() {
        let limits = Limits::default();
        let error = load_error(
            "missing",
            "let x = 1;\n  point_light(#{ position: [1, 2] });",
            &limits,
        );
        assert!(
            error.starts_with("scene.rhai:2:3: pointlight: "),
            "the .scene reader's own message, at the call: {error}"
        );
        assert!(error.contains("position"), "{error}");
        let error = load_error("update-only", "set_light_on(0, false);", &limits);
        assert_eq!(
            error,
            "scene.rhai:1:1: lights are changed in init or update, after the scene has loaded"
        );
        let error = load_error("syntax", "let x = ;", &limits);
        assert!(error.starts_with("scene.rhai:1:9: "), "{error}");
        let dir = folder(
            "adds-late",
            &[(
                "scene.rhai",
                "fn update(t, dt) {\n    point_light(#{});\n}\n",
            )],
        );
        let path = dir.join("scene.rhai");
        let error = try_runtime(&path)
            .err()
            .expect("refused at load, by the first update step")
            .to_string();
        assert_eq!(
            error,
            format!(
                "{}:2:5: pointlight objects are added while the scene loads, not in init or update",
                path.display()
            )
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn imports_reach_only_scripts_under_the_scenes_folder() {
        let dir = folder(
            "imports",
            &[
                (
                    "scene.rhai",
                    "import \"lib/colours\" as c;\npoint_light(#{ color: c::warm() });",
                ),
                ("lib/colours.rhai", "fn warm() { [1.0, 0.5, 0.25] }"),
            ],
        );
        let desc = load(&dir, &Limits::default()).unwrap();
        assert_eq!(point(&desc.lights[0]).color, Vec3::new(1.0, 0.5, 0.25));
        assert_eq!(
            desc.script.unwrap().imports,
            [dir.canonicalize().unwrap().join("lib/colours.rhai")],
            "imports are recorded, to be watched"
        );
        std::fs::write(dir.join("scene.rhai"), "import \"../outside\" as o;").unwrap();
        std::fs::write(dir.join("../outside.rhai"), "fn f() { 1 }").unwrap();
        let error = load(&dir, &Limits::default())
            .expect_err("refused")
            .to_string();
        assert!(
            error.contains("import \"../outside\": scripts may import only scripts under"),
            "{error}"
        );
        std::fs::remove_file(dir.join("../outside.rhai")).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn import_cycles_are_located_errors_naming_the_chain() {
        let dir = folder(
            "import-cycle",
            &[
                ("scene.rhai", "import \"self\" as s;"),
                ("self.rhai", "import \"self\" as p;\nfn f() { 1 }"),
            ],
        );
        let error = load(&dir, &Limits::default())
            .expect_err("a file importing itself")
            .to_string();
        assert!(
            error.contains("import \"self\" is a cycle: self.rhai -> self.rhai"),
            "{error}"
        );
        assert!(
            error.contains("scene.rhai:1:8: "),
            "located at the scene script's import: {error}"
        );
        std::fs::write(dir.join("scene.rhai"), "import \"a\" as a;").unwrap();
        std::fs::write(dir.join("a.rhai"), "import \"b\" as b;").unwrap();
        std::fs::write(dir.join("b.rhai"), "import \"a\" as a;").unwrap();
        let error = load(&dir, &Limits::default())
            .expect_err("two files importing each other")
            .to_string();
        assert!(
            error.contains("is a cycle: a.rhai -> b.rhai -> a.rhai"),
            "{error}"
        );
        std::fs::write(dir.join("scene.rhai"), "import \"scene\" as s;").unwrap();
        let error = load(&dir, &Limits::default())
            .expect_err("the scene's script importing itself")
            .to_string();
        assert!(
            error.contains("is a cycle: scene.rhai -> scene.rhai"),
            "{error}"
        );
        // The same module imported twice, not in a cycle, is fine.
        std::fs::write(dir.join("scene.rhai"), "import \"c\" as c1;\nimport \"c\" as c2;\npoint_light(#{ color: [c1::v(), c2::v(), 1.0] });").unwrap();
        std::fs::write(dir.join("c.rhai"), "fn v() { 0.5 }").unwrap();
        let desc = load(&dir, &Limits::default()).expect("no cycle");
        assert_eq!(point(&desc.lights[0]).color, Vec3::new(0.5, 0.5, 1.0));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn an_import_of_a_fifo_is_refused_without_waiting() {
        let dir = folder("import-fifo", &[("scene.rhai", "import \"pipe\" as p;")]);
        let made = std::process::Command::new("mkfifo")
            .arg(dir.join("pipe.rhai"))
            .status()
            .unwrap();
        assert!(made.success());
        let error = load(&dir, &Limits::default())
            .expect_err("a FIFO is no script")
            .to_string();
        assert!(error.contains("is a FIFO, not a regular file"), "{error}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn scripts_have_no_file_access_and_no_clock() {
        for (name, body) in [
            ("open", "open_file(\"/etc/passwd\");"),
            ("clock", "let t = timestamp();"),
        ] {
            let error = load_error(name, body, &Limits::default());
            assert!(error.contains("Function not found"), "{name}: {error}");
        }
    }

    /// A one-triangle OBJ spanning (0, 0, 0)..(1, 1, 0).
    const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

    #[test]
    fn scene_bounds_at_load_are_those_of_the_models_placed_so_far() {
        let dir = folder(
            "bounds",
            &[
                ("tri.obj", TRIANGLE),
                (
                    "scene.rhai",
                    r#"
                    let i = model("tri.obj", #{ position: [10, 0, 0], scale: 2 });
                    let b = scene_bounds();
                    point_light(#{ position: b.max, radius: 1 });
                    point_light(#{ position: b.min, radius: 1 });
                    let j = model("tri.obj", #{ position: [-4, 0, 0] });
                    point_light(#{ position: scene_bounds().min, radius: i + j });
                    "#,
                ),
            ],
        );
        let scene = crate::load_scene(&dir.join("scene.rhai")).unwrap();
        let positions: Vec<Vec3> = scene.lights.iter().map(|l| point(l).position).collect();
        assert_eq!(
            positions,
            [
                Vec3::new(12.0, 2.0, 0.0),
                Vec3::new(10.0, 0.0, 0.0),
                Vec3::new(-4.0, 0.0, 0.0)
            ]
        );
        assert_eq!(
            point(&scene.lights[2]).radius,
            1.0,
            "model() gives indices 0 and 1"
        );
        assert_eq!(scene.models.len(), 1, "the file is loaded once");
        std::fs::write(dir.join("scene.rhai"), "let b = scene_bounds();").unwrap();
        let error = crate::load_scene(&dir.join("scene.rhai"))
            .expect_err("refused")
            .to_string();
        assert!(
            error.ends_with("scene.rhai:1:9: scene_bounds: no model is placed yet"),
            "{error}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn update_moves_placements_and_cameras_as_the_same_blocks_in_a_file_would_place_them() {
        let dir = folder(
            "placements",
            &[
                ("tri.obj", TRIANGLE),
                (
                    "scene.rhai",
                    r#"
                    model("tri.obj", #{ color: [1, 0, 0], roughness: 0.25 });
                    model("tri.obj", #{});
                    camera("top", #{ position: [0, 9, 0.1], target: [0, 0, 0], fov_deg: 30 });
                    fn update(t, dt) {
                        set_model_transform(1, #{ position: [t, 2, 0], orientation: [0, 90, 0], scale: [1, 2, 3] });
                        let p = model_position(1);
                        set_camera("top", #{ position: [p[0], 5, 5], target: p });
                        set_model_color(1, 0, 1, 0.5);
                    }
                    "#,
                ),
            ],
        );
        let path = dir.join("scene.rhai");
        let scene = crate::load_scene(&path).unwrap();
        assert_eq!(
            scene.instances[0].material,
            crate::material::MaterialOverride {
                color: Some(Vec3::new(1.0, 0.0, 0.0)),
                roughness: Some(0.25),
                ..Default::default()
            }
        );
        assert!(scene.instances[1].material.is_empty());
        let frame = runtime(&path).frame_at(0.5).unwrap();
        let file = "model\n{\n\tfile \"tri.obj\"\n\tposition 0.5 2 0\n\torientation 0 90 0\n\tscale 1 2 3\n}\n\
            camera \"top\"\n{\n\tposition 0.5 5 5\n\ttarget 0.5 2 0\n\tfov_deg 30\n}\n";
        let desc = crate::scene_desc_from_str(file, &path, &mut Diagnostics::default()).unwrap();
        assert_eq!(
            frame.transforms[0], scene.instances[0].transform,
            "not moved"
        );
        assert_eq!(
            frame.colors,
            [
                Some(Vec3::new(1.0, 0.0, 0.0)),
                Some(Vec3::new(0.0, 1.0, 0.5))
            ],
            "the load's override, and the colour set per frame"
        );
        assert_eq!(frame.transforms[1], desc.models[0].transform);
        assert_eq!(frame.cameras.len(), 1, "the camera the script set");
        let (set, file) = (&frame.cameras[0], &desc.cameras[0]);
        assert_eq!(
            (set.position, set.orientation, set.fov_y),
            (file.position, file.orientation, file.fov_y),
            "the field of view kept"
        );
        let error = |body: &str| {
            std::fs::write(&path, format!("camera(\"top\", #{{}});\nmodel(\"tri.obj\", #{{}});\nfn update(t, dt) {{\n    {body}\n}}\n")).unwrap();
            try_runtime(&path)
                .err()
                .expect("refused at load, by the first update step")
                .to_string()
                .replace(&path.display().to_string(), "scene.rhai")
        };
        assert_eq!(
            error("set_model_transform(0, #{ color: [1, 0, 0] });"),
            "scene.rhai:4:5: set_model_transform: 'color' is not a transform property (position, orientation, scale)"
        );
        assert_eq!(
            error("set_model_transform(1, #{});"),
            "scene.rhai:4:5: no model 1: the scene has 1"
        );
        assert_eq!(
            error("set_model_color(0, 1, -1, 0);"),
            "scene.rhai:4:5: colour [1, -1, 0] is negative"
        );
        assert_eq!(
            error("set_camera(\"side\", #{ position: [0, 0, 0] });"),
            "scene.rhai:4:5: no camera 'side': the scene has top"
        );
        assert!(
            error("set_model_transform(0, #{ scale: [1, 2] });")
                .starts_with("scene.rhai:4:5: set_model_transform: "),
            "the .scene reader's message"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
