//! A loaded model file: meshes, materials, and the lights and cameras a glTF file brings.

use crate::bounds::Aabb;
use crate::camera::Camera;
use crate::light::Light;
use crate::material::Material;
use crate::mesh::Mesh;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// The contents of one OBJ or glTF file, in the file's own space.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Model {
    /// The file it came from.
    pub path: PathBuf,
    /// Its meshes (glTF node transforms already applied).
    pub meshes: Vec<Mesh>,
    /// Its materials; meshes index into this list.
    pub materials: Vec<Material>,
    /// Lights it defines (glTF KHR_lights_punctual), in model space.
    pub lights: Vec<Light>,
    /// Cameras it defines (glTF), in model space.
    pub cameras: Vec<Camera>,
    /// The box around all meshes.
    pub bounds: Aabb,
    /// Every file the import looked at, the model file first (material libraries, buffers,
    /// textures, including ones that were missing): the cache checks them for changes.
    pub sources: Vec<PathBuf>,
}

impl Model {
    /// The number of triangles in all meshes.
    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(Mesh::triangle_count).sum()
    }

    /// Recomputes `bounds` from the meshes' bounds.
    pub(crate) fn update_bounds(&mut self) {
        self.bounds = self
            .meshes
            .iter()
            .fold(Aabb::EMPTY, |b, m| b.union(&m.bounds));
    }
}
