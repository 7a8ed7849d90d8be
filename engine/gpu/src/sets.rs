//! The descriptor set numbers every pipeline shares: graph resources in set 0,
//! scene data in set 1, a material's textures in set 2.

/// The descriptor set number reserved for scene data (camera, lights): graph
/// resources are bound in set 0, and a fullscreen pass whose shaders declare
/// set 1 gets it from the draw recorder, so deferred lighting can read the scene
/// (and so can a compute pass, such as tiled light culling).
pub const SCENE_SET: u32 = 1;

/// Set number of a material's textures, which scene-drawing passes read.
pub const MATERIAL_SET: u32 = 2;
