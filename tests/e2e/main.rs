//! Every end-to-end test of weft in one binary (one link instead of one per file),
//! a module per subject. `cargo test -p weft-tests --test e2e -- MODULE::` runs one.

mod bloom;
mod bsdf_sampling;
mod debug_views;
mod denoise;
mod emissive;
mod environment;
mod extremes;
mod gi;
mod light_matrix;
mod lights;
mod mirrored;
mod msaa;
mod mutants;
mod normal_maps;
mod one_physics;
mod pathtrace;
mod radiance_cache;
mod ray_counts;
mod raycast;
mod render;
mod restir;
mod restir_model;
mod rt_ao;
mod rt_shadows;
mod rt_specular;
mod scripting;
mod shading;
mod shadows;
mod shipped;
mod taa;
mod transparency;
