#version 450
// Area-light panels (draw: LightVolumes(Area)): the panel mesh
// (engine/render/src/volumes.rs) placed over area light `gl_InstanceIndex`
// (one instance per area light, starting at its record). The mesh is a fan
// over a 32-gon on the unit circle: a rectangle pushes each outline point out
// to the square (its corners and edge midpoints are vertices, so the square is
// exact), a disc keeps it, scaled to the disc's area as ltc.glsl's 12-gon is.
#include "include/scene.glsl"

layout(location = 0) in vec3 position;

layout(location = 0) flat out uint light_index;
layout(location = 1) out vec3 world;

// sqrt(pi / (16 sin(2 pi / 32))): a regular 32-gon of this corner radius has the unit disc's area.
const float DISC_SCALE = 1.0032221;

void main() {
    Light light = lights[gl_InstanceIndex];
    vec2 q = position.xy;
    if (light.direction_type.w == LIGHT_AREA_DISC) {
        q *= DISC_SCALE;
    } else {
        float reach = max(abs(q.x), abs(q.y));
        q = reach > 0.0 ? q / reach : q;
    }
    world = light.position_range.xyz + q.x * light.direction_type.xyz + q.y * light.attenuation_cos.xyz;
    light_index = gl_InstanceIndex;
    gl_Position = frame.view_proj * vec4(world, 1.0);
}
