//! Vulkan execution of compiled weft render graphs.
