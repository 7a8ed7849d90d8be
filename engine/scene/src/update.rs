//! The scene at a time: what changes from frame to frame (lights, the
//! placements and colours a script moves, the cameras it sets), computed on
//! the CPU for a renderer to upload. The `.scene` motions are evaluated here,
//! and the scene's script, when it animates, runs here: simulation stays out
//! of the renderer's upload code.

use crate::animation::lights_at_with;
use crate::camera::Camera;
use crate::error::SceneError;
use crate::light::Light;
use crate::scene::Scene;
use crate::script::{Limits, ScriptFrame, ScriptRuntime};
use glam::{Mat4, Vec3};

/// What a scene is at one time.
#[derive(Debug, Clone, Copy)]
pub struct SceneAt<'u> {
    /// Every light, moved by its motion or set by the script.
    pub lights: &'u [Light],
    /// Every placement's model-to-world transform, when a script moves them
    /// (`None`: the placements stay as loaded).
    pub transforms: Option<&'u [Mat4]>,
    /// Every placement's colour override, when a script may change them.
    pub colors: Option<&'u [Option<Vec3>]>,
    /// The cameras the script has set, which stand in for the scene's own of
    /// the same name.
    pub cameras: &'u [Camera],
}

impl<'u> SceneAt<'u> {
    /// The camera to look through for `camera`: the script's of that name,
    /// or `camera` itself.
    pub fn camera<'c>(&self, camera: &'c Camera) -> &'c Camera
    where
        'u: 'c,
    {
        self.cameras
            .iter()
            .find(|c| c.name == camera.name)
            .unwrap_or(camera)
    }
}

/// Moves a loaded scene through time: its lights' motions, and its script's
/// `update` when it has one.
pub struct SceneUpdater {
    source_lights: Vec<Light>,
    script: Option<ScriptRuntime>,
    /// What the script left for the last time it reached.
    frame: ScriptFrame,
    /// The script's last error; the frames keep the last good frame's state.
    error: Option<SceneError>,
    /// The lights at the last time asked for.
    lights: Vec<Light>,
}

impl SceneUpdater {
    /// An updater for `scene` in a render of bounded length, with its
    /// script's runtime (the script loads again and runs `init`) under the
    /// default [`Limits`]: its `update` steps may run 10 s a frame and 120 s
    /// in all.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        Self::with_limits(scene, &Limits::default())
    }

    /// An updater for a live view or `--watch`, which runs until it is
    /// closed: each frame's steps keep their limit, the whole run has none.
    pub fn live(scene: &Scene) -> Result<Self, SceneError> {
        Self::with_limits(
            scene,
            &Limits {
                render_seconds: f64::INFINITY,
                ..Limits::default()
            },
        )
    }

    /// An updater whose script runs under `limits`.
    pub fn with_limits(scene: &Scene, limits: &Limits) -> Result<Self, SceneError> {
        let script = match &scene.script {
            Some(script) => Some(ScriptRuntime::new(script, scene, limits)?),
            None => None,
        };
        Ok(Self {
            source_lights: scene.lights.clone(),
            script,
            frame: ScriptFrame {
                lights: scene.lights.clone(),
                touched: vec![false; scene.lights.len()],
                transforms: scene.instances.iter().map(|i| i.transform).collect(),
                colors: scene.instances.iter().map(|i| i.material.color).collect(),
                cameras: Vec::new(),
            },
            error: None,
            lights: scene.lights.clone(),
        })
    }

    /// Whether the scene's script animates (has `fn update`): placements
    /// and colours may then change every frame.
    pub fn animates(&self) -> bool {
        self.script.as_ref().is_some_and(ScriptRuntime::animates)
    }

    /// The scene at `time`. The script, when it animates, runs up to `time`;
    /// on an error the last good frame's state stands, and the error waits
    /// for [`SceneUpdater::take_error`].
    pub fn at(&mut self, time: f64) -> SceneAt<'_> {
        let animates = self.animates();
        if let Some(script) = self.script.as_mut().filter(|s| s.animates()) {
            match script.frame_at(time) {
                Ok(frame) => self.frame = frame,
                Err(e) => self.error = Some(e),
            }
        }
        let frame = &self.frame;
        self.lights = lights_at_with(&self.source_lights, time, 0, |i| {
            (animates && frame.touched.get(i) == Some(&true))
                .then(|| frame.lights.get(i))
                .flatten()
        });
        SceneAt {
            lights: &self.lights,
            transforms: animates.then_some(self.frame.transforms.as_slice()),
            colors: animates.then_some(self.frame.colors.as_slice()),
            cameras: &self.frame.cameras,
        }
    }

    /// The script's error since the last call, if one failed.
    pub fn take_error(&mut self) -> Option<SceneError> {
        self.error.take()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::animation::lights_at;
    use std::path::PathBuf;

    /// A folder with a one-triangle model and `scene.rhai`.
    fn folder(name: &str, script: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("weft-update-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("dir");
        std::fs::write(dir.join("tri.obj"), "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").expect("obj");
        std::fs::write(dir.join("scene.rhai"), script).expect("script");
        dir
    }

    #[test]
    fn without_update_lights_follow_their_motion_and_placements_stay() {
        let scene = crate::load_scene(std::path::Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenes/animation.scene"
        )))
        .expect("loads");
        let mut updater = SceneUpdater::new(&scene).expect("updater");
        assert!(!updater.animates());
        for time in [0.0, 1.5, 7.25] {
            let at = updater.at(time);
            assert_eq!(at.lights, lights_at(&scene.lights, time, 0).as_slice());
            assert_eq!((at.transforms, at.colors), (None, None));
            assert!(at.cameras.is_empty());
        }
        assert!(updater.take_error().is_none());
    }

    #[test]
    fn a_script_with_update_moves_recolours_and_keeps_the_last_good_step() {
        let dir = folder(
            "script",
            r#"
            model("tri.obj", #{ position: [0, 0, 0] });
            point_light(#{ position: [0, 2, 0], color: [1, 1, 1], radius: 4 });
            fn update(t, dt) {
                set_model_transform(0, #{ position: [t, 0, 0] });
                set_model_color(0, 0.5, 0.25, 1.0);
                if t > 1.0 { throw "past one second"; }
            }
            "#,
        );
        let scene = crate::load_scene(&dir.join("scene.rhai")).expect("loads");
        let mut updater = SceneUpdater::new(&scene).expect("updater");
        assert!(updater.animates());
        let at = updater.at(0.5);
        let moved = at.transforms.expect("moved placements")[0].w_axis.x;
        assert!((moved - 0.5).abs() < 0.02, "{moved}");
        assert_eq!(at.colors, Some(&[Some(Vec3::new(0.5, 0.25, 1.0))][..]));
        assert_eq!(at.lights.len(), 1);
        assert!(updater.take_error().is_none());
        let at = updater.at(2.0);
        let kept = at.transforms.expect("moved placements")[0].w_axis.x;
        assert_eq!(kept, moved, "the last good frame's placements stand");
        let error = updater
            .take_error()
            .expect("the script's error")
            .to_string();
        assert!(error.contains("past one second"), "{error}");
        assert!(updater.take_error().is_none(), "taken once");
        std::fs::remove_dir_all(&dir).expect("clean up");
    }
}
