#version 450
// Area-light panels (draw: LightVolumes(Area)): the panel mesh
// (engine/render/src/volumes.rs) placed over area light `gl_InstanceIndex`
// (one instance per area light, starting at its record), placed by
// include/area_panel.glsl.
#include "include/area_panel.glsl"

layout(location = 0) in vec3 position;

layout(location = 0) flat out uint light_index;
layout(location = 1) out vec3 world;

void main() {
    world = area_panel_point(lights[gl_InstanceIndex], position.xy);
    light_index = gl_InstanceIndex;
    gl_Position = frame.view_proj * vec4(world, 1.0);
}
