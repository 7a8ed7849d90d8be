//! Pass kinds and the frame loop: scene meshes, materials, lights and cameras drawn by compiled weft graphs.
