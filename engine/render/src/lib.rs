//! Pass kinds and the frame loop: scene meshes, materials, lights and cameras
//! drawn by compiled weft graphs.
//!
//! What a caller needs:
//! - **Render**: [`render`] runs a graph over a scene for some frames;
//!   [`load_graph`] loads a graph once for callers that keep it, and
//!   [`compile_for_scene`] / [`render_with_progress`] use it.
//! - **Frame loop**: [`FrameLoop`] draws frame after frame into a window or
//!   an image; [`LiveRender`] adds hot reload ([`ReloadWorker`] prepares
//!   reloads off the frame thread; [`FileWatcher`] reports edited files).
//! - **Scene upload**: [`GpuScene`] uploads a `weft_scene::Scene` as a
//!   `weft_scene::SceneUpdater` moves it through time; [`SceneRecorder`] is
//!   the `weft_gpu::DrawRecorder` that draws it in raster passes
//!   (`Meshes(filter)`, `LightVolumes(kind)`); [`scene_interface`] is the
//!   scene's bindings as the executor sees them. The GLSL side of every
//!   layout is `shaders/include/scene.glsl` and the generated
//!   `shaders/include/bindings.glsl`.
//!
//! The other items are the building blocks those use, public for the
//! benchmarks, CPU references and tests that check them piece by piece: the
//! BVH ([`Bvh`]), scene geometry as uploaded ([`SceneGeometry`]), light and
//! draw records ([`pack_lights`], [`GpuDraw`]), the renderer's value
//! providers ([`compile_plan`]) and the files a render depends on.

#![warn(missing_docs)]

mod bindings;
mod bvh;
mod bvh_cache;
mod bvh_wide;
mod emitter_lights;
mod emitters;
pub mod environment;
pub mod environment_prefilter;
mod error;
mod features;
mod frame;
mod frame_loop;
mod frustum;
mod gaussian;
mod geometry;
mod gpu_types;
mod graph_check;
mod jitter;
mod light_bounds;
mod light_choice;
mod light_tree;
mod lights;
mod materials;
mod optics;
mod prepare;
mod providers;
mod recorder;
mod reload;
mod reload_error;
mod reload_worker;
mod sanitize;
mod scene_gpu;
mod scene_load;
mod shadows;
mod sources;
mod texture;
mod trace_textures;
mod view_summary;
pub mod vocabulary;
mod volumes;
mod watch;

pub use error::RenderError;
pub use features::scene_features;
pub use frame::{
    compile_for_scene, load_graph, render, render_with_progress, Progress, RenderSettings, Rendered,
};
pub use frame_loop::{FrameLoop, FrameRequest};
pub use graph_check::{check_graph_and_shaders, ShaderTarget};
pub use prepare::{PreparedReload, ReloadJob, ShaderChecker};
pub use providers::ray_counts::PassRays;
pub use providers::trace_backend::{TraceBackend, RAY_QUERY_FEATURE};
pub use recorder::{SceneRecorder, ViewCulling};
pub use reload::{startup_files, Committed, LiveRender};
pub use reload_error::ReloadError;
pub use reload_worker::{ReloadWorker, WorkerReply};
pub use scene_gpu::{structure_scratch_bytes, GpuScene};
pub use scene_load::load_scene;
pub use view_summary::{Bin, ViewSummary};
pub use vocabulary::{scene_feature_reason, VOCABULARY};
pub use watch::{FileWatcher, QUIET};

pub use bindings::scene_interface;
pub use bvh::{intersect, scene_triangles_where, Bvh};
pub use bvh_cache::load_or_build as load_or_build_bvh;
pub use bvh_wide::WideBvh;
pub use emitter_lights::emitter_lights;
pub use gaussian::GaussianTaps;
pub use geometry::{quantize_uv, uv_box, SceneGeometry, TraceMesh, VERTEX_BYTES};
pub use gpu_types::GpuDraw;
pub use lights::{area_shape, pack_lights, AreaGeometry, LightSet};
pub use materials::matches as material_matches;
pub use providers::{check as check_against_renderer, compile as compile_plan};
pub use sanitize::RADIANCE_MAX;
pub use sources::{
    graph_source_files, normalize as normalize_path, scene_files, scene_path_files, shader_files,
};
pub use trace_textures::gather as gather_trace_textures;
