//! What the script's functions act on, shared between the engine's callbacks.

use super::*;

/// What the script's functions act on.
pub(super) struct State {
    /// The scene file (or the script, for `.rhai` scenes): blocks resolve against it.
    pub(super) scene: PathBuf,
    /// Objects the load adds (positions relative to `desc.origin`).
    pub(super) desc: SceneDesc,
    /// Lights the scene had before the script's, so a light's index counts every light.
    pub(super) lights_before: usize,
    /// The scene's placements before the script's (file, transform), for bounds
    /// and so a placement's index counts every placement.
    pub(super) models_before: Vec<(PathBuf, Mat4)>,
    /// Problems the `.scene` reader reported for added objects.
    pub(super) diag: Diagnostics,
    pub(super) rng: Rng,
    /// How model files are loaded for `scene_bounds`.
    pub(super) options: LoadOptions,
    /// Model files `scene_bounds` loaded, by canonical path, for the scene to reuse.
    pub(super) models: HashMap<PathBuf, Model>,
    /// Each model file's bounds, by canonical path.
    pub(super) model_bounds: HashMap<PathBuf, Aabb>,
    /// After the load: the loaded scene's bounds (relative to the origin).
    pub(super) scene_bounds: Aabb,
    /// Per frame: the scene's lights as the script leaves them, which are
    /// on, and which it has changed (the others keep their `.scene` motions).
    pub(super) lights: Vec<Light>,
    pub(super) on: Vec<bool>,
    pub(super) touched: Vec<bool>,
    /// Per frame: each placement's model-to-world transform (relative to the
    /// origin) and its colour override.
    pub(super) transforms: Vec<Mat4>,
    pub(super) colors: Vec<Option<Vec3>>,
    /// Per frame: the scene's cameras, and which the script has set.
    pub(super) cameras: Vec<Camera>,
    pub(super) camera_set: Vec<bool>,
    /// Whether objects may be added (the load) or lights changed (init, update).
    pub(super) loading: bool,
    /// Objects the load has added, and how many it may ([`Limits::objects`]).
    pub(super) objects_added: usize,
    pub(super) object_limit: usize,
    /// When the call running now must end, and what the script is told
    /// then: the earliest of the call's, the frame's and the render's limits
    /// ([`Limits::call_seconds`], [`Limits::frame_seconds`],
    /// [`Limits::render_seconds`]).
    pub(super) deadline: Option<Deadline>,
}

impl State {
    /// The state for loading `scene_file`'s script, with nothing per frame yet.
    pub(super) fn loading(
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
    pub(super) fn placed_bounds(&mut self) -> Result<Aabb, SceneError> {
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

pub(super) type Shared = Arc<Mutex<State>>;

/// A mutex's value (the script's state, or a resolver's records), also
/// after a panic elsewhere poisoned it.
pub(super) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

pub(super) fn fail(ctx: &NativeCallContext, message: impl Into<String>) -> Box<EvalAltResult> {
    EvalAltResult::ErrorRuntime(message.into().into(), ctx.call_position()).into()
}
