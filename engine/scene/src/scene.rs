//! The loaded scene a renderer consumes: unique models, their placements, world-space lights,
//! cameras (always at least one) and bounds.

use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::error::Warning;
use crate::light::Light;
use crate::material::MaterialOverride;
use crate::model::Model;
use glam::Mat4;
use std::path::PathBuf;

/// One placement of a model in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Instance {
    /// Index into [`Scene::models`].
    pub model: usize,
    /// Model-to-world transform.
    pub transform: Mat4,
    /// World-space box around the placed model.
    pub bounds: Aabb,
    /// Factors that replace the model's for this placement only.
    pub material: MaterialOverride,
}

/// A loaded scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// The file it was loaded from.
    pub path: PathBuf,
    /// Each model file once, however often it is placed.
    pub models: Vec<Model>,
    /// Placements of the models.
    pub instances: Vec<Instance>,
    /// Lights in world space at time 0 (see [`crate::animation::lights_at`]).
    pub lights: Vec<Light>,
    /// Cameras by name; the first is the one to start with. Never empty: without any camera
    /// the default framing camera is added.
    pub cameras: Vec<Camera>,
    /// World-space box around every instance.
    pub bounds: Aabb,
    /// The `boundingbox` block, when the scene declares one.
    pub declared_bounds: Option<Aabb>,
    /// The world point every position here is relative to (near the first
    /// camera, see `desc::origin_of`; zero for scenes near zero): world =
    /// origin + stored position.
    /// Renderers never need it; reports that print world coordinates do.
    pub origin: glam::DVec3,
    /// The Rhai script that added to the scene and animates it per frame
    /// ([`crate::script`]), if any.
    pub script: Option<crate::desc::ScriptRef>,
    /// The environment map rays that leave the scene see, if any.
    pub environment: Option<crate::environment::Environment>,
    /// What the loader accepted but reported.
    pub warnings: Vec<Warning>,
}

impl Scene {
    /// The camera called `name`.
    pub fn camera(&self, name: &str) -> Option<&Camera> {
        self.cameras.iter().find(|c| c.name == name)
    }

    /// The bounds used for framing and light extents: declared ones when given.
    pub fn effective_bounds(&self) -> Aabb {
        self.declared_bounds.unwrap_or(self.bounds)
    }

    /// Triangles drawn, counting every instance.
    pub fn triangle_count(&self) -> usize {
        self.instances
            .iter()
            .filter_map(|i| self.models.get(i.model))
            .map(Model::triangle_count)
            .sum()
    }
}
