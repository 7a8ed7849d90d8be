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
    /// The scripts it imported while loading, so they are watched too.
    pub imports: Vec<PathBuf>,
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

/// `import` for scripts under one folder only; records what it read.
struct FolderResolver {
    root: PathBuf,
    files: FileModuleResolver,
    read: Arc<Mutex<Vec<PathBuf>>>,
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
        if inside {
            let mut read = self.read.lock().unwrap_or_else(|p| p.into_inner());
            if !read.contains(&file) {
                read.push(file.clone());
            }
        } else {
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
        Ok::<Array, Box<EvalAltResult>>(vec![world.x.into(), world.y.into(), world.z.into()])
    });
    let st = state.clone();
    engine.register_fn(
        "set_light_position",
        move |ctx: NativeCallContext, i: INT, x: Dynamic, y: Dynamic, z: Dynamic| {
            let p = (vec3(&ctx, &x, &y, &z)? - origin).as_vec3();
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
        move |ctx: NativeCallContext, i: INT, x: Dynamic, y: Dynamic, z: Dynamic| {
            let d = vec3(&ctx, &x, &y, &z)?.as_vec3();
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
        move |ctx: NativeCallContext, i: INT, r: Dynamic, g: Dynamic, b: Dynamic| {
            let c = vec3(&ctx, &r, &g, &b)?.as_vec3();
            if c.min_element() < 0.0 {
                return Err(fail(&ctx, format!("colour {c} is negative")));
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
    engine.set_module_resolver(FolderResolver {
        files: FileModuleResolver::new_with_path(&root),
        root,
        read: imports.clone(),
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
    script_ref: &mut ScriptRef,
    scene_file: &Path,
    desc: &mut SceneDesc,
    diag: &mut Diagnostics,
    limits: &Limits,
) -> Result<(), SceneError> {
    let path = script_ref.path.clone();
    let script = path.as_path();
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
    let imports = Arc::new(Mutex::new(Vec::new()));
    let engine = engine_for(script, &state, desc.origin, limits, &imports);
    let ast = compile(&engine, script)?;
    engine
        .run_ast_with_scope(&mut Scope::new(), &ast)
        .map_err(|e| located(script, &e))?;
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
        let engine = engine_for(script, &state, origin, limits, &Arc::default());
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
            imports: Vec::new(),
        }
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
            limits,
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
        let desc = load(&dir, &Limits::default()).unwrap();
        let runtime = || {
            ScriptRuntime::new(
                &script_ref(&path),
                &path,
                &desc.lights,
                DVec3::ZERO,
                &Limits::default(),
            )
            .unwrap()
        };
        let mut a = runtime();
        assert!(a.animates());
        // 0.5 s = 30 steps of 1/60 s: x = 30 / 60, y = t of the last step, z = steps.
        let at_half = a.lights_at(0.5).unwrap();
        let p = point(&at_half[0]);
        assert!(
            (p.position - Vec3::new(0.5, 0.5, 30.0)).abs().max_element() < 1e-5,
            "{p:?}"
        );
        assert_eq!(p.color, Vec3::ONE, "step 30 is even: on");
        // Reached through other frame times, or again after going back: the same.
        let mut b = runtime();
        for t in [0.1, 0.25, 0.4999, 0.5] {
            b.lights_at(t).unwrap();
        }
        assert_eq!(b.lights_at(0.5).unwrap(), at_half);
        a.lights_at(3.0).unwrap();
        assert_eq!(a.lights_at(0.5).unwrap(), at_half, "going back starts over");
        // Step 31 is odd: off, with zero colour.
        assert_eq!(
            point(&a.lights_at(31.0 / 60.0 + 1e-9).unwrap()[0]).color,
            Vec3::ZERO
        );
        assert_eq!(point(&a.lights_at(0.0).unwrap()[0]).position, Vec3::ZERO);
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
        let mut runtime =
            ScriptRuntime::new(&script_ref(&path), &path, &[], DVec3::ZERO, &limits).unwrap();
        let error = runtime.lights_at(1.0).expect_err("refused").to_string();
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
    fn scripts_have_no_file_access_and_no_clock() {
        for (name, body) in [
            ("open", "open_file(\"/etc/passwd\");"),
            ("clock", "let t = timestamp();"),
        ] {
            let error = load_error(name, body, &Limits::default());
            assert!(error.contains("Function not found"), "{name}: {error}");
        }
    }
}
