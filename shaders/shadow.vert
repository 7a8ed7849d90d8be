#version 450
// Shadow views (include/shadows.glsl): meshes seen through view `shadow_view`'s
// matrix (forward Z; the graph clears the map to 1). weft-render draws the pass
// once per view into the view's atlas tile, setting `shadow_view` each time.
// Depth bias is pipeline state (the pass's `raster: (depth_bias: ...)`).
#include "include/transform.glsl"
#include "include/shadows.glsl"

layout(push_constant) uniform Push {
    uint shadow_view;
};

layout(location = 0) in vec3 position;

void main() {
    gl_Position = shadow_views[shadow_view].clip * world_position(gl_InstanceIndex, position);
}
