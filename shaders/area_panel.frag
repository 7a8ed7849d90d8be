#version 450
// What camera rays see of an area light: its emitted radiance from the side
// it emits towards (either side when two-sided), black from behind, for an
// area light is opaque, as in the path tracer (pathtrace/lights.glsl,
// `area_emitted`). Written over the lit image, depth-tested, so nearer
// geometry hides the panel.
#include "include/scene.glsl"
#include "include/hdr.glsl"

layout(location = 0) flat in uint light_index;
layout(location = 1) in vec3 world;

layout(location = 0) out vec4 color;

void main() {
    Light light = lights[light_index];
    vec3 facing = -cross(light.direction_type.xyz, light.attenuation_cos.xyz);
    bool front = dot(frame.camera_position.xyz - world, facing) > 0.0;
    bool seen = front || light.color_exponent.w > 0.5;
    color = vec4(hdr_output(seen ? light.color_exponent.rgb : vec3(0.0)), 1.0);
}
