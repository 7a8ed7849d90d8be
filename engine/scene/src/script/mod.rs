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
use crate::desc::ScriptRef;
use crate::desc::{blocks_into, SceneDesc};
use crate::error::{Diagnostics, Location, SceneError};
use crate::light::Light;
use crate::model::Model;
use crate::model_file::{load_model, LoadOptions};
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

mod api;
mod imports;
mod limits;
mod runtime;
mod state;
#[cfg(test)]
mod tests;

use api::*;
use imports::*;
use limits::*;
use state::*;

pub use imports::MAX_IMPORT_DEPTH;
pub use limits::Limits;
pub use runtime::{ScriptFrame, ScriptRuntime};

/// Seconds per update step.
pub const STEP: f64 = 1.0 / 60.0;

/// Most update steps one request for a time may run (ten minutes of scene
/// time); further times are refused rather than frozen on.
pub const MAX_STEPS_AT_ONCE: u64 = 36_000;

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
    let watched = state.clone();
    engine.on_progress(move |operations| {
        if operations % 1024 != 0 {
            return None;
        }
        let s = lock(&watched);
        let (deadline, reason) = s.deadline.as_ref()?;
        (std::time::Instant::now() > *deadline).then(|| Dynamic::from(reason.clone()))
    });
    {
        let mut s = lock(state);
        s.object_limit = limits.objects;
    }
    register(&mut engine, state, origin);
    engine
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

fn compile(engine: &Engine, script: &Path) -> Result<AST, SceneError> {
    let at = Location::file(script);
    let text = crate::source::read_text(script, &at, crate::source::MAX_SCENE_BYTES)?;
    // A system file (named with `--allow-outside`) may be anything
    // (`/proc/self/environ`): its errors give its position, never its text.
    let system = weft_io::paths::is_system(script);
    if system {
        weft_io::sources::forget(script);
    }
    engine.compile(&text).map_err(|e| SceneError::Syntax {
        at: position_at(script, e.position()),
        message: if system {
            "not a Rhai script (a system file, so its content is not shown)".to_string()
        } else {
            e.err_type().to_string()
        },
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
    start_call(&state, limits.call_seconds, None);
    run_top_level(&engine, &ast, script)?;
    script_ref.imports = std::mem::take(&mut *lock(&imports));
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
