#version 450
// Sun shadow map: meshes seen from the first sun through its orthographic
// matrix (forward Z; the graph clears the map to 1). Depth bias is pipeline state.
#include "include/transform.glsl"

layout(location = 0) in vec3 position;

void main() {
    gl_Position = frame.sun_shadow * world_position(gl_InstanceIndex, position);
}
