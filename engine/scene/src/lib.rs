//! Scenes for weft: `.scene` files, OBJ/MTL and glTF models, lights and animation.
//!
//! A renderer calls [`load_scene`] (or [`load_scene_with`] for the model cache) and gets a
//! [`Scene`]: each model file once ([`Model`]: [`Mesh`]es with positions, normals, UVs,
//! tangents and `u32` indices, and [`Material`]s), the [`Instance`]s that place them, world-space
//! [`Light`]s, named [`Camera`]s (never empty) and bounds. [`animation::lights_at`] gives the
//! lights at a time. `weft scene check` uses [`check_report`]. The format is documented in
//! `scenes/FORMAT.md`.
//!
//! ```no_run
//! let scene = weft_scene::load_scene("scenes/demo.scene".as_ref())?;
//! for instance in &scene.instances {
//!     let model = &scene.models[instance.model];
//!     for mesh in &model.meshes {
//!         let _material = mesh.material.map(|i| &model.materials[i]);
//!         // upload mesh.positions, mesh.normals, mesh.uvs, mesh.tangents, mesh.indices;
//!         // draw with instance.transform
//!     }
//! }
//! let _lights_now = weft_scene::animation::lights_at(&scene.lights, 1.5, 0);
//! # Ok::<(), weft_scene::SceneError>(())
//! ```

#![warn(missing_docs)]

pub mod animation;
pub mod bounds;
pub mod cache;
pub mod camera;
pub mod desc;
pub mod environment;
pub mod error;
pub mod gltf_import;
mod guard;
pub mod light;
pub mod load;
pub mod material;
pub mod mesh;
pub mod model;
pub mod model_file;
mod mtl;
pub mod obj;
pub mod outside;
mod props;
pub mod report;
pub mod rng;
pub mod scene;
pub mod script;
pub mod source;
mod syntax;
pub mod tangent_frame;
pub mod tangents;
pub mod update;
mod uri;

pub use bounds::Aabb;
pub use camera::{reverse_z_projection, Camera};
pub use desc::{read_scene_desc, scene_desc_from_str, Placement, SceneDesc};
pub use error::{Diagnostics, Location, SceneError, Warning};
pub use gltf_import::load_gltf;
pub use light::{AreaLight, AreaShape, Attenuation, Light, PointLight, SpotLight, SunLight};
pub use load::{load_scene, load_scene_with};
pub use material::Material;
pub use mesh::Mesh;
pub use model::Model;
pub use model_file::{load_model, LoadOptions};
pub use obj::load_obj;
pub use report::{check_report, check_report_with, SceneReport};
pub use scene::{Instance, Scene};
pub use update::{SceneAt, SceneUpdater};
