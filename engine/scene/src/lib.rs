//! Scenes for weft: `.scene` files, OBJ/MTL and glTF models, lights and animation.

pub mod animation;
pub mod bounds;
pub mod camera;
pub mod desc;
pub mod error;
pub mod gltf_import;
pub mod light;
pub mod load;
pub mod material;
pub mod mesh;
pub mod model;
mod mtl;
pub mod obj;
mod props;
pub mod report;
pub mod rng;
pub mod scene;
pub mod source;
mod syntax;
pub mod tangents;
mod uri;

pub use bounds::Aabb;
pub use camera::Camera;
pub use desc::{read_scene_desc, scene_desc_from_str, Placement, SceneDesc};
pub use error::{Diagnostics, Location, SceneError, Warning};
pub use gltf_import::load_gltf;
pub use light::{AreaLight, AreaShape, Attenuation, Light, PointLight, SpotLight, SunLight};
pub use load::{load_model, load_scene, load_scene_with, LoadOptions};
pub use material::Material;
pub use mesh::Mesh;
pub use model::Model;
pub use obj::load_obj;
pub use report::{check_report, check_report_with, SceneReport};
pub use scene::{Instance, Scene};
