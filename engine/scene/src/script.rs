//! Scene scripts in Rhai (scenes/SCRIPTING.md): a `.rhai` file that is a
//! scene, or one a `.scene` names with `script "file.rhai"`.
//!
//! At load the script's top level runs once and adds objects through
//! functions that take the `.scene` format's properties as a map
//! (`point_light(#{ position: [0, 2, 0], color: [1, 1, 1] })`): each call
//! becomes an object block read by the `.scene` reader itself, so a script
//! and a file mean the same thing and are validated the same way.
//!
//! Per frame, `fn update(t, dt)` moves, recolours and switches lights. Time
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

use crate::desc::{blocks_into, SceneDesc};
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::Light;
use crate::rng::Rng;
use glam::{DVec3, Vec3};
use rhai::module_resolvers::FileModuleResolver;
use rhai::{
    Array, CallFnOptions, Dynamic, Engine, EvalAltResult, Map, Module, ModuleResolver,
    NativeCallContext, Position, Scope, Shared as RhaiShared, AST, FLOAT, INT,
};
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
}

/// Seconds per update step.
pub const STEP: f64 = 1.0 / 60.0;

/// Most update steps one request for a time may run (ten minutes of scene
/// time); further times are refused rather than frozen on.
pub const MAX_STEPS_AT_ONCE: u64 = 36_000;

/// The sandbox's limits, per call into the script (the load, `init`, each `update`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
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
    /// Problems the `.scene` reader reported for added objects.
    diag: Diagnostics,
    rng: Rng,
    /// Per frame: the scene's lights as the script leaves them, and which are on.
    lights: Vec<Light>,
    on: Vec<bool>,
    /// Whether objects may be added (the load) or lights changed (init, update).
    loading: bool,
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
fn located(script: &Path, error: &EvalAltResult) -> SceneError {
    let at = position_at(script, error.position());
    let message = match error {
        EvalAltResult::ErrorRuntime(value, _) => value.to_string(),
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

/// `import` for scripts under one folder only.
struct FolderResolver {
    root: PathBuf,
    files: FileModuleResolver,
}

impl ModuleResolver for FolderResolver {
    fn resolve(
        &self,
        engine: &Engine,
        source: Option<&str>,
        path: &str,
        position: Position,
    ) -> Result<RhaiShared<Module>, Box<EvalAltResult>> {
        let file = self.root.join(format!("{path}.rhai"));
        let inside = file.canonicalize().is_ok_and(|f| f.starts_with(&self.root));
        if !inside {
            return Err(EvalAltResult::ErrorRuntime(
                format!(
                    "import \"{path}\": scripts may import only scripts under {}",
                    self.root.display()
                )
                .into(),
                position,
            )
            .into());
        }
        self.files.resolve(engine, source, path, position)
    }
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

/// Adds one object through the `.scene` reader; returns the new light's index
/// over every light of the scene, for lights.
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
    let text = block_text(kind, label, props).map_err(|m| fail(ctx, m))?;
    let scene = s.scene.clone();
    let State { desc, diag, .. } = &mut *s;
    blocks_into(&text, &scene, desc, diag)
        .map_err(|e| fail(ctx, format!("{kind}: {}", e.message())))?;
    Ok((s.lights_before + s.desc.lights.len()) as INT - 1)
}

/// The light `index` refers to, for the per-frame functions.
fn light_index(
    ctx: &NativeCallContext,
    s: &State,
    index: INT,
) -> Result<usize, Box<EvalAltResult>> {
    if s.loading {
        return Err(fail(
            ctx,
            "lights are changed in init or update, after the scene has loaded",
        ));
    }
    usize::try_from(index)
        .ok()
        .filter(|&i| i < s.lights.len())
        .ok_or_else(|| {
            fail(
                ctx,
                format!("no light {index}: the scene has {}", s.lights.len()),
            )
        })
}

fn vec3(
    ctx: &NativeCallContext,
    x: FLOAT,
    y: FLOAT,
    z: FLOAT,
) -> Result<DVec3, Box<EvalAltResult>> {
    let v = DVec3::new(x, y, z);
    if v.is_finite() {
        Ok(v)
    } else {
        Err(fail(ctx, format!("({x}, {y}, {z}) is not finite")))
    }
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
            add_object(&ctx, &st, "model", None, &props).map(|_| ())
        },
    );
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
    engine.register_fn("rand_range", move |lo: FLOAT, hi: FLOAT| {
        lo + (hi - lo) * FLOAT::from(lock(&st).rng.next_f32())
    });
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
        let p = match &s.lights[i] {
            Light::Point(l) => l.position,
            Light::Spot(l) => l.position,
            Light::Area(l) => l.position,
            Light::Sun(l) => l.direction,
        };
        let world = origin + p.as_dvec3();
        Ok::<Array, Box<EvalAltResult>>(vec![world.x.into(), world.y.into(), world.z.into()])
    });
    let st = state.clone();
    engine.register_fn(
        "set_light_position",
        move |ctx: NativeCallContext, i: INT, x: FLOAT, y: FLOAT, z: FLOAT| {
            let p = (vec3(&ctx, x, y, z)? - origin).as_vec3();
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
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
        move |ctx: NativeCallContext, i: INT, x: FLOAT, y: FLOAT, z: FLOAT| {
            let d = vec3(&ctx, x, y, z)?.as_vec3();
            let Some(d) = d.try_normalize() else {
                return Err(fail(&ctx, "a light's direction must not be zero"));
            };
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
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
        move |ctx: NativeCallContext, i: INT, r: FLOAT, g: FLOAT, b: FLOAT| {
            let c = vec3(&ctx, r, g, b)?.as_vec3();
            if c.min_element() < 0.0 {
                return Err(fail(&ctx, format!("colour ({r}, {g}, {b}) is negative")));
            }
            let mut s = lock(&st);
            let i = light_index(&ctx, &s, i)?;
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
            s.on[i] = on;
            Ok::<(), Box<EvalAltResult>>(())
        },
    );
}

fn engine_for(script: &Path, state: &Shared, origin: DVec3, limits: &Limits) -> Engine {
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
    engine.set_module_resolver(FolderResolver {
        files: FileModuleResolver::new_with_path(&root),
        root,
    });
    engine.on_print(|_| {});
    engine.on_debug(|_, _, _| {});
    register(&mut engine, state, origin);
    engine
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
/// already there); records the script as the scene's.
pub fn run_load(
    script: &ScriptRef,
    scene_file: &Path,
    desc: &mut SceneDesc,
    diag: &mut Diagnostics,
    limits: &Limits,
) -> Result<(), SceneError> {
    let script_ref = script;
    let script = script_ref.path.as_path();
    let state: Shared = Arc::new(Mutex::new(State {
        scene: scene_file.to_path_buf(),
        desc: SceneDesc {
            origin: desc.origin,
            ..SceneDesc::default()
        },
        lights_before: script_ref.first_light,
        diag: Diagnostics::default(),
        rng: Rng::new(0),
        lights: Vec::new(),
        on: Vec::new(),
        loading: true,
    }));
    let engine = engine_for(script, &state, desc.origin, limits);
    let ast = compile(&engine, script)?;
    engine
        .run_ast_with_scope(&mut Scope::new(), &ast)
        .map_err(|e| located(script, &e))?;
    let mut s = lock(&state);
    let added = std::mem::take(&mut s.desc);
    desc.models.extend(added.models);
    desc.lights.extend(added.lights);
    desc.cameras.extend(added.cameras);
    if added.bounding_box.is_some() {
        desc.bounding_box = added.bounding_box;
    }
    diag.warnings.append(&mut s.diag.warnings);
    Ok(())
}

/// A loaded scene's script, running per frame: the lights at a time.
pub struct ScriptRuntime {
    script: PathBuf,
    engine: Engine,
    ast: AST,
    state: Shared,
    /// The scene's lights as loaded, to start over from.
    loaded: Vec<Light>,
    has_init: bool,
    has_update: bool,
    /// `init`'s value, seen by `update` as `this`.
    this: Dynamic,
    /// Update steps run since time 0.
    steps: u64,
}

impl ScriptRuntime {
    /// The runtime for `scene`'s script, with the scene's lights as loaded
    /// (the script's own included): runs the load again for the script's
    /// random state, then `init`.
    pub fn new(
        script_ref: &ScriptRef,
        scene_file: &Path,
        lights: &[Light],
        origin: DVec3,
        limits: &Limits,
    ) -> Result<Self, SceneError> {
        let script = script_ref.path.as_path();
        let state: Shared = Arc::new(Mutex::new(State {
            scene: scene_file.to_path_buf(),
            desc: SceneDesc {
                origin,
                ..SceneDesc::default()
            },
            lights_before: script_ref.first_light,
            diag: Diagnostics::default(),
            rng: Rng::new(0),
            lights: lights.to_vec(),
            on: vec![true; lights.len()],
            loading: true,
        }));
        let engine = engine_for(script, &state, origin, limits);
        let ast = compile(&engine, script)?;
        engine
            .run_ast_with_scope(&mut Scope::new(), &ast)
            .map_err(|e| located(script, &e))?;
        lock(&state).loading = false;
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
            loaded: lights.to_vec(),
            this: Dynamic::UNIT,
            steps: 0,
        };
        runtime.restart()?;
        Ok(runtime)
    }

    /// Back to time 0: the loaded lights, all on, and `init` run again.
    fn restart(&mut self) -> Result<(), SceneError> {
        {
            let mut s = lock(&self.state);
            s.lights = self.loaded.clone();
            s.on = vec![true; self.loaded.len()];
        }
        self.steps = 0;
        self.this = if self.has_init {
            self.engine
                .call_fn_with_options::<Dynamic>(
                    CallFnOptions::new().eval_ast(false),
                    &mut Scope::new(),
                    &self.ast,
                    "init",
                    (),
                )
                .map_err(|e| located(&self.script, &e))?
        } else {
            Dynamic::UNIT
        };
        Ok(())
    }

    /// Whether the script animates anything (has `fn update(t, dt)`).
    pub fn animates(&self) -> bool {
        self.has_update
    }

    /// The lights at `time`: `update` run in steps of [`STEP`] from 0 up to
    /// `time` (from the last step taken when time only moved forward). Lights
    /// switched off come back with zero colour. On an error the runtime
    /// starts over at the next call.
    pub fn lights_at(&mut self, time: f64) -> Result<Vec<Light>, SceneError> {
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
            let result = self.engine.call_fn_with_options::<Dynamic>(
                CallFnOptions::new()
                    .eval_ast(false)
                    .bind_this_ptr(&mut self.this),
                &mut Scope::new(),
                &self.ast,
                "update",
                (t, STEP),
            );
            if let Err(e) = result {
                self.steps = u64::MAX;
                return Err(located(&self.script, &e));
            }
        }
        let s = lock(&self.state);
        Ok(s.lights
            .iter()
            .zip(&s.on)
            .map(|(light, &on)| {
                if on {
                    light.clone()
                } else {
                    switched_off(light)
                }
            })
            .collect())
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
