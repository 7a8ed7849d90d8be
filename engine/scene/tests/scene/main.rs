//! Every integration test of weft-scene in one binary (one link instead of one per
//! file), a module per subject. `cargo test -p weft-scene --test scene -- MODULE::` runs one.

mod common;

mod cache;
mod fuzz;
mod gltf_hostile;
mod gltf_import;
mod large_models;
mod obj_import;
mod repo_scenes;
mod scene_text;
mod scenes_462;
