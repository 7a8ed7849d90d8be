//! Pass kinds and the frame loop: scene meshes, materials, lights and cameras
//! drawn by compiled weft graphs.
//!
//! [`render`] runs a graph over a scene for some frames; [`load_graph`] loads
//! the graph once for callers that keep it. [`GpuScene`] uploads a
//! `weft_scene::Scene` (as a `weft_scene::SceneUpdater` moves it through time);
//! [`SceneRecorder`] is the `weft_gpu::DrawRecorder` that draws it in raster
//! passes (`Meshes(filter)`, `LightVolumes(kind)`): it picks each run's
//! pipeline variant, binds the scene (set 1) and materials (set 2) and draws.
//! The scene interface it registers with the executor is [`bindings`];
//! [`FrameLoop`] and [`LiveRender`] run frames and hot reloads. The GLSL side
//! of every layout is `shaders/include/scene.glsl` and the generated
//! `shaders/include/bindings.glsl`.

#![warn(missing_docs)]

pub mod bindings;
pub mod bvh;
pub mod bvh_cache;
pub mod camera;
pub mod emitter_lights;
mod emitters;
mod error;
mod features;
mod frame;
mod frame_loop;
mod frustum;
pub mod gaussian;
pub mod geometry;
pub mod gpu_types;
mod graph_check;
pub mod lights;
pub mod materials;
mod optics;
mod prepare;
pub mod providers;
pub mod recorder;
mod reload;
mod reload_error;
mod reload_worker;
pub mod sanitize;
pub mod scene_gpu;
pub mod scene_load;
mod shadows;
pub mod sources;
mod texture;
pub mod trace_textures;
mod view_summary;
mod volumes;
pub mod watch;

pub use error::RenderError;
pub use features::scene_features;
pub use frame::{
    compile_for_scene, load_graph, render, render_with_progress, Progress, RenderSettings, Rendered,
};
pub use frame_loop::{FrameLoop, FrameRequest};
pub use graph_check::{check_graph_and_shaders, ShaderTarget};
pub use prepare::{PreparedReload, ReloadJob, ShaderChecker};
pub use recorder::SceneRecorder;
pub use reload::{startup_files, Committed, LiveRender};
pub use reload_error::ReloadError;
pub use reload_worker::{ReloadWorker, WorkerReply};
pub use scene_gpu::GpuScene;
pub use view_summary::{Bin, ViewSummary};
