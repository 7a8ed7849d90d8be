//! A loaded scene's script running per frame: `init`, then `update` in fixed steps.

use super::*;

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
pub(super) struct Loaded {
    /// The random sequence where the load left it, so every restart draws
    /// the same numbers.
    pub(super) rng: Rng,
    pub(super) lights: Vec<Light>,
    pub(super) transforms: Vec<Mat4>,
    pub(super) colors: Vec<Option<Vec3>>,
    pub(super) cameras: Vec<Camera>,
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
    /// The limits each call, frame and the whole run are held to.
    limits: Limits,
    /// Wall-clock seconds the `update` steps have run in all
    /// ([`Limits::render_seconds`]).
    spent: f64,
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
        start_call(&state, limits.call_seconds, None);
        run_top_level(&engine, &ast, script)?;
        {
            let mut s = lock(&state);
            s.loading = false;
            loaded.rng = s.rng.clone();
        }
        let has = |name: &str, params: usize| {
            let arities: Vec<usize> = ast
                .iter_functions()
                .filter(|f| f.name == name)
                .map(|f| f.params.len())
                .collect();
            match arities.as_slice() {
                [] => Ok(false),
                found if found.contains(&params) => Ok(true),
                [found, ..] => Err(SceneError::Syntax {
                    at: first_mention(script, &format!("fn {name}")),
                    message: wrong_arity(name, *found),
                }),
            }
        };
        let mut runtime = Self {
            script: script.to_path_buf(),
            has_init: has("init", 0)?,
            has_update: has("update", 2)?,
            engine,
            ast,
            state,
            loaded,
            this: Dynamic::UNIT,
            steps: 0,
            limits: *limits,
            spent: 0.0,
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
        start_call(&self.state, self.limits.call_seconds, None);
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

    /// When the steps of a frame started at `started` (reaching `time`, step
    /// `target`) must end: the earlier of [`Limits::frame_seconds`] from
    /// `started` and what is left of [`Limits::render_seconds`], with what
    /// the script is told then.
    fn frame_end(&self, started: std::time::Instant, time: f64, target: u64) -> Option<Deadline> {
        let steps = target.saturating_sub(self.steps);
        let frame = after(started, self.limits.frame_seconds).map(|at| {
            (
                at,
                format!(
                    "the script's update steps for one frame ran past the frame's limit of {} s ({steps} steps of 1/60 s to reach t = {time} s)",
                    self.limits.frame_seconds
                ),
            )
        });
        let render = after(started, (self.limits.render_seconds - self.spent).max(0.0)).map(|at| {
            (
                at,
                format!(
                    "the script's update steps ran past their limit of {} s in all for this render (at t = {time} s)",
                    self.limits.render_seconds
                ),
            )
        });
        earlier(frame, render)
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
        let frame_started = std::time::Instant::now();
        let frame_end = self.frame_end(frame_started, time, target);
        while self.has_update && self.steps < target {
            // Checked between steps too: Rhai counts a call's operations
            // from zero, so steps too short to reach its progress check
            // would never meet the frame's or the render's limit.
            if let Some((_, reason)) = frame_end
                .as_ref()
                .filter(|(end, _)| std::time::Instant::now() > *end)
            {
                self.spent += frame_started.elapsed().as_secs_f64();
                self.steps = u64::MAX;
                return Err(SceneError::Syntax {
                    at: first_mention(&self.script, "fn update"),
                    message: reason.clone(),
                });
            }
            self.steps += 1;
            let t = self.steps as f64 * STEP;
            start_call(&self.state, self.limits.call_seconds, frame_end.clone());
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
                self.spent += frame_started.elapsed().as_secs_f64();
                self.steps = u64::MAX;
                return Err(e);
            }
        }
        self.spent += frame_started.elapsed().as_secs_f64();
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

/// Why a function named `name` with `found` parameters is never called.
fn wrong_arity(name: &str, found: usize) -> String {
    let (wanted, count) = match name {
        "init" => ("fn init()", 0),
        _ => ("fn update(t, dt)", 2),
    };
    format!(
        "`fn {name}` takes {found} parameter{}; weft calls {wanted} with {count}, so it would never run",
        if found == 1 { "" } else { "s" }
    )
}

/// `light` giving no light.
pub(super) fn switched_off(light: &Light) -> Light {
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
